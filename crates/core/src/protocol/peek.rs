//! What raw bytes say before any decoding, however damaged the rest is: the header, the
//! station (columns 2-3), the message ID (columns 4-6), and the checksum's verdict
//! (PROTOCOL.md 1.3, 1.4). The one home of the frame's layout for the link, the frame
//! log, the describer and the window; its hex fields never take a sign.

use std::ops::Range;

use super::checksum::checksum;
use super::describe::ChecksumVerdict;
use super::hex::parse_hex;
use super::ids::{Header, MessageId, Station};

/// The station's bytes: columns 2-3.
pub const STATION: Range<usize> = 1..3;
/// The message ID's bytes: columns 4-6 (`!` and `#` frames; `&` carries an error code
/// there instead).
pub const MESSAGE_ID: Range<usize> = 3..6;

/// Hex digits only, either case, at most 8 of them: no sign, no space, no prefix.
pub fn hex_digits(text: &str) -> Option<u32> {
    parse_hex(text.as_bytes())
}

/// The header, if the first byte is one.
pub fn header(bytes: &[u8]) -> Option<Header> {
    bytes.first().copied().and_then(Header::from_byte)
}

/// The station of bytes that start with a header.
pub fn station(bytes: &[u8]) -> Option<Station> {
    header(bytes)?;
    let v = parse_hex(bytes.get(STATION)?)?;
    u8::try_from(v).ok().map(Station)
}

/// The message ID of a command (`!`) or normal reply (`#`); an `&` reply has none.
pub fn message_id(bytes: &[u8]) -> Option<MessageId> {
    match header(bytes)? {
        Header::Command | Header::Reply => {
            let v = parse_hex(bytes.get(MESSAGE_ID)?)?;
            u16::try_from(v).ok().map(MessageId)
        }
        Header::Error => None,
    }
}

/// The message ID of bytes that start like a normal reply (`#`): the ID a damaged or late
/// reply answers.
pub fn reply_id(bytes: &[u8]) -> Option<MessageId> {
    (header(bytes)? == Header::Reply)
        .then(|| message_id(bytes))
        .flatten()
}

/// The verdict of a frame's SC: the two characters before the line end against the sum of
/// everything before them; [`ChecksumVerdict::Absent`] for bytes too short to hold one.
pub fn checksum_verdict(bytes: &[u8]) -> ChecksumVerdict {
    let body = bytes
        .strip_suffix(b"\r\n")
        .or_else(|| bytes.strip_suffix(b"\n"))
        .unwrap_or(bytes);
    // The shortest frame: header, station, message ID or error code, SC (PROTOCOL.md 1.3).
    if header(body).is_none() || body.len() < 8 {
        return ChecksumVerdict::Absent;
    }
    let (summed, sc) = body.split_at(body.len() - 2);
    let computed = checksum(summed);
    if sc == b"@@" {
        return ChecksumVerdict::AtAt { computed };
    }
    match parse_hex(sc) {
        Some(v) if v == u32::from(computed) => ChecksumVerdict::Valid(computed),
        Some(v) => ChecksumVerdict::Wrong {
            found: v as u8,
            computed,
        },
        None => ChecksumVerdict::Unreadable { computed },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fields_are_read_from_damaged_frames() {
        assert_eq!(reply_id(b"#99215"), Some(MessageId::SYSTEM_STATUS));
        assert_eq!(reply_id(b"#9921510000XX"), Some(MessageId::SYSTEM_STATUS));
        assert_eq!(reply_id(b"!99215"), None, "a command is no reply");
        assert_eq!(message_id(b"!992A1"), Some(MessageId(0x2A1)));
        assert_eq!(message_id(b"&99B08"), None, "an error reply carries no ID");
        assert_eq!(station(b"&99B08"), Some(Station(0x99)));
        assert_eq!(reply_id(b"#9"), None);
        assert_eq!(station(b"99215"), None, "no header");
    }

    #[test]
    fn a_sign_is_never_a_hex_digit() {
        assert_eq!(hex_digits("+9"), None);
        assert_eq!(hex_digits("-1"), None);
        assert_eq!(station(b"!+9215"), None);
        assert_eq!(message_id(b"#99+12"), None);
        assert_eq!(hex_digits("0a"), Some(10));
        assert_eq!(hex_digits(""), None);
        assert_eq!(
            checksum_verdict(b"!99215+F\r\n"),
            ChecksumVerdict::Unreadable {
                computed: checksum(b"!99215")
            }
        );
    }

    #[test]
    fn the_checksum_verdict_reads_the_two_characters_before_the_line_end() {
        assert_eq!(
            checksum_verdict(b"!992152B\r\n"),
            ChecksumVerdict::Valid(0x2B)
        );
        assert_eq!(
            checksum_verdict(b"!99215@@\r\n"),
            ChecksumVerdict::AtAt { computed: 0x2B }
        );
        assert_eq!(
            checksum_verdict(b"!992152C\r\n"),
            ChecksumVerdict::Wrong {
                found: 0x2C,
                computed: 0x2B
            }
        );
        assert_eq!(checksum_verdict(b"!9921\r\n"), ChecksumVerdict::Absent);
        assert_eq!(checksum_verdict(b"junk"), ChecksumVerdict::Absent);
    }
}
