//! One complete frame: header, station, message ID, data, SC, CR LF (PROTOCOL.md 1.3).

use std::borrow::Cow;
use std::fmt;

use super::checksum::{Sc, checksum};
use super::hex::parse_hex;
use super::ids::{Header, MessageId, Role, Station};

/// The longest legal frame: a 2A4H reply with 255 records of 8 axes, 16,337 bytes
/// including CR LF (PROTOCOL.md 3.16, corrected counts).
pub const MAX_FRAME_LEN: usize = 16_337;

/// The controller's reply buffer on most models, in bytes from header to LF; replies are
/// cut to fit it (PROTOCOL.md 1.7; the count from header to LF is `[inferred]`).
pub const REPLY_BUFFER: usize = 2048;
/// The reply buffer of the J/K/KE/KT/KET/JX/KX/KTX and TT models (PROTOCOL.md 1.7).
pub const SMALL_REPLY_BUFFER: usize = 1024;
/// The longest command most models receive, header to LF (PROTOCOL.md 1.7; the count
/// from header to LF is `[inferred]`): multi-record writes are sized to it.
pub const COMMAND_BUFFER: usize = 2051;
/// The longest command the J/K/KE/KT/KET/JX/KX/KTX and TT models receive.
pub const SMALL_COMMAND_BUFFER: usize = 1023;

/// The shortest legal frame: 10 bytes (a command or acknowledge without data, or an error
/// reply) (PROTOCOL.md 1.3).
pub const MIN_FRAME_LEN: usize = 10;

/// A syntactically valid frame whose SC has been checked (or was `@@`). Borrows the bytes
/// it was parsed from; [`Frame::into_owned`] makes it `'static`.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct Frame<'a> {
    raw: Cow<'a, [u8]>,
    header: Header,
    station: Station,
    id: Option<MessageId>,
    sc: Sc,
}

/// A frame that owns its bytes (what the streaming decoder yields).
pub type OwnedFrame = Frame<'static>;

impl<'a> Frame<'a> {
    /// Parses one complete frame, from the header up to and including CR LF, and verifies
    /// its SC (a literal `@@` is accepted and reported as [`Sc::AtAt`]).
    pub fn parse(bytes: &'a [u8]) -> Result<Frame<'a>, FrameError> {
        let (header, station, id, sc) = check(bytes).map_err(|kind| FrameError {
            raw: bytes.to_vec(),
            kind,
        })?;
        Ok(Frame {
            raw: Cow::Borrowed(bytes),
            header,
            station,
            id,
            sc,
        })
    }

    /// The same frame owning its bytes.
    pub fn into_owned(self) -> OwnedFrame {
        Frame {
            raw: Cow::Owned(self.raw.into_owned()),
            header: self.header,
            station: self.station,
            id: self.id,
            sc: self.sc,
        }
    }

    /// The header kind.
    pub fn header(&self) -> Header {
        self.header
    }

    /// Command (`!`) or reply (`#` and `&`).
    pub fn role(&self) -> Role {
        match self.header {
            Header::Command => Role::Command,
            Header::Reply | Header::Error => Role::Reply,
        }
    }

    /// The station field.
    pub fn station(&self) -> Station {
        self.station
    }

    /// The message ID; `None` for an error reply (`&`), which has none.
    pub fn id(&self) -> Option<MessageId> {
        self.id
    }

    /// The SC field as read.
    pub fn sc(&self) -> Sc {
        self.sc
    }

    /// The data characters: after the message ID (after the station for `&`, where they are
    /// the error code) up to the SC.
    pub fn data(&self) -> &[u8] {
        let end = self.raw.len().saturating_sub(4);
        self.raw.get(self.data_offset()..end).unwrap_or(&[])
    }

    /// The 1-based column of the first data character (7, or 4 for `&`).
    pub fn data_column(&self) -> usize {
        self.data_offset() + 1
    }

    fn data_offset(&self) -> usize {
        if self.header == Header::Error { 3 } else { 6 }
    }

    /// Every byte of the frame, header to LF.
    pub fn raw(&self) -> &[u8] {
        &self.raw
    }
}

impl fmt::Display for Frame<'_> {
    /// The frame's characters without CR LF, e.g. `#992322C`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let body = self
            .raw
            .get(..self.raw.len().saturating_sub(2))
            .unwrap_or(&[]);
        write!(f, "{}", body.escape_ascii())
    }
}

type Checked = (Header, Station, Option<MessageId>, Sc);

fn check(b: &[u8]) -> Result<Checked, FrameErrorKind> {
    let len = b.len();
    let Some(&first) = b.first() else {
        return Err(FrameErrorKind::TooShort { len });
    };
    let header = Header::from_byte(first).ok_or(FrameErrorKind::BadHeader { found: first })?;
    if len > MAX_FRAME_LEN {
        return Err(FrameErrorKind::TooLong { len });
    }
    match b.last() {
        Some(b'\n') => {
            if len < 2 || b.get(len - 2) != Some(&b'\r') {
                return Err(FrameErrorKind::MissingCr {
                    column: len.saturating_sub(1).max(1),
                });
            }
        }
        Some(b'\r') => return Err(FrameErrorKind::MissingLf { column: len + 1 }),
        _ => return Err(FrameErrorKind::MissingLineEnd { column: len + 1 }),
    }
    if len < MIN_FRAME_LEN {
        return Err(FrameErrorKind::TooShort { len });
    }
    let station = b
        .get(1..3)
        .and_then(parse_hex)
        .ok_or(FrameErrorKind::BadStation)?;
    let id = if header == Header::Error {
        None
    } else {
        let v = b
            .get(3..6)
            .and_then(parse_hex)
            .ok_or(FrameErrorKind::BadMessageId)?;
        Some(MessageId(v as u16))
    };
    let sc_at = len - 4;
    let sc_raw = b.get(sc_at..sc_at + 2).unwrap_or(&[]);
    let sc = if sc_raw == b"@@" {
        Sc::AtAt
    } else {
        let found = parse_hex(sc_raw).ok_or(FrameErrorKind::BadSc { column: sc_at + 1 })? as u8;
        let computed = checksum(b.get(..sc_at).unwrap_or(&[]));
        if found != computed {
            return Err(FrameErrorKind::Checksum {
                found,
                computed,
                column: sc_at + 1,
            });
        }
        Sc::Valid(found)
    };
    Ok((header, Station(station as u8), id, sc))
}

/// Why a run of bytes is not a valid frame, with the bytes themselves.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct FrameError {
    /// The bytes that were examined.
    pub raw: Vec<u8>,
    /// What is wrong, and where.
    pub kind: FrameErrorKind,
}

/// What is wrong with a frame. Columns are 1-based, as in the spec's tables.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum FrameErrorKind {
    /// The first byte is not `!`, `#` or `&`.
    BadHeader {
        /// The byte found.
        found: u8,
    },
    /// Fewer bytes than the shortest frame (10).
    TooShort {
        /// Bytes present.
        len: usize,
    },
    /// More bytes than the longest legal frame ([`MAX_FRAME_LEN`]).
    TooLong {
        /// Bytes present.
        len: usize,
    },
    /// The frame ends with LF but the byte before it is not CR.
    MissingCr {
        /// Column where CR was expected.
        column: usize,
    },
    /// The frame ends with CR and no LF.
    MissingLf {
        /// Column where LF was expected.
        column: usize,
    },
    /// The frame does not end with CR LF at all (cut short, or a new header came first).
    MissingLineEnd {
        /// Column where CR was expected.
        column: usize,
    },
    /// The station (columns 2-3) is not 2 hex digits.
    BadStation,
    /// The message ID (columns 4-6) is not 3 hex digits.
    BadMessageId,
    /// The SC is neither 2 hex digits nor `@@`.
    BadSc {
        /// First column of the SC.
        column: usize,
    },
    /// The SC does not match the sum of the frame's bytes.
    Checksum {
        /// The SC the frame carries.
        found: u8,
        /// The sum of the frame's bytes (what the SC should be).
        computed: u8,
        /// First column of the SC.
        column: usize,
    },
}

impl FrameErrorKind {
    /// The 1-based column the problem is at.
    pub fn column(&self) -> usize {
        match *self {
            FrameErrorKind::BadHeader { .. } => 1,
            FrameErrorKind::TooShort { len } => len.max(1),
            FrameErrorKind::TooLong { .. } => MAX_FRAME_LEN + 1,
            FrameErrorKind::MissingCr { column }
            | FrameErrorKind::MissingLf { column }
            | FrameErrorKind::MissingLineEnd { column }
            | FrameErrorKind::BadSc { column }
            | FrameErrorKind::Checksum { column, .. } => column,
            FrameErrorKind::BadStation => 2,
            FrameErrorKind::BadMessageId => 4,
        }
    }
}

impl FrameError {
    /// The 1-based column the problem is at.
    pub fn column(&self) -> usize {
        self.kind.column()
    }

    /// The bytes that were examined.
    pub fn raw(&self) -> &[u8] {
        &self.raw
    }
}

/// The characters of `raw` at 1-based columns `first..=last`, escaped for display.
pub(crate) fn chars_at(raw: &[u8], first: usize, last: usize) -> String {
    let a = first.saturating_sub(1).min(raw.len());
    let b = last.min(raw.len()).max(a);
    raw.get(a..b).unwrap_or(&[]).escape_ascii().to_string()
}

impl fmt::Display for FrameError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let raw = &self.raw;
        match self.kind {
            FrameErrorKind::BadHeader { found } => write!(
                f,
                "frame starts with '{}', expected '!' (command), '#' (reply) or '&' (error reply) (column 1)",
                [found].escape_ascii()
            ),
            FrameErrorKind::TooShort { len } => write!(
                f,
                "frame is only {len} characters long, the shortest frame has {MIN_FRAME_LEN} (column {})",
                len.max(1)
            ),
            FrameErrorKind::TooLong { len } => write!(
                f,
                "frame is {len} characters long, longer than the longest legal frame ({MAX_FRAME_LEN}) (column {})",
                MAX_FRAME_LEN + 1
            ),
            FrameErrorKind::MissingCr { column } => write!(
                f,
                "frame ends with LF but the character before it is '{}', expected CR (column {column})",
                chars_at(raw, column, column)
            ),
            FrameErrorKind::MissingLf { column } => {
                write!(f, "frame ends with CR but no LF follows (column {column})")
            }
            FrameErrorKind::MissingLineEnd { column } => write!(
                f,
                "frame does not end with CR LF: it stops after {} characters (column {column})",
                column.saturating_sub(1)
            ),
            FrameErrorKind::BadStation => write!(
                f,
                "station is '{}', expected 2 hex digits (column 2)",
                chars_at(raw, 2, 3)
            ),
            FrameErrorKind::BadMessageId => write!(
                f,
                "message ID is '{}', expected 3 hex digits (column 4)",
                chars_at(raw, 4, 6)
            ),
            FrameErrorKind::BadSc { column } => write!(
                f,
                "checksum is '{}', expected 2 hex digits or '@@' (column {column})",
                chars_at(raw, column, column + 1)
            ),
            FrameErrorKind::Checksum {
                found,
                computed,
                column,
            } => write!(
                f,
                "checksum is {found:02X}, but the frame's bytes sum to {computed:02X} (column {column})"
            ),
        }
    }
}

impl std::error::Error for FrameError {}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_a_reply_with_data() {
        let f = Frame::parse(b"#99212021C00000000002715AF\r\n").unwrap();
        assert_eq!(f.header(), Header::Reply);
        assert_eq!(f.station(), Station(0x99));
        assert_eq!(f.id(), Some(MessageId::AXIS_STATUS));
        assert_eq!(f.data(), b"021C00000000002715");
        assert_eq!(f.data_column(), 7);
        assert_eq!(f.sc(), Sc::Valid(0xAF));
        assert_eq!(f.to_string(), "#99212021C00000000002715AF");
    }

    #[test]
    fn parses_an_error_reply_without_id() {
        let f = Frame::parse(b"&99CC14F\r\n").unwrap();
        assert_eq!(f.id(), None);
        assert_eq!(f.data(), b"CC1");
        assert_eq!(f.role(), Role::Reply);
    }

    #[test]
    fn accepts_at_at_and_reports_it() {
        let f = Frame::parse(b"!9921201@@\r\n").unwrap();
        assert_eq!(f.sc(), Sc::AtAt);
    }

    #[test]
    fn wrong_checksum_says_both_sums_and_the_column() {
        let e = Frame::parse(b"#9921202040000000000270EAF\r\n").unwrap_err();
        assert_eq!(
            e.kind,
            FrameErrorKind::Checksum {
                found: 0xAF,
                computed: 0xAE,
                column: 25
            }
        );
        assert_eq!(
            e.to_string(),
            "checksum is AF, but the frame's bytes sum to AE (column 25)"
        );
        assert_eq!(e.raw(), b"#9921202040000000000270EAF\r\n");
    }

    #[test]
    fn each_malformation_is_named() {
        let k = |b: &[u8]| Frame::parse(b).unwrap_err().kind;
        assert_eq!(k(b":0103\r\n"), FrameErrorKind::BadHeader { found: b':' });
        assert_eq!(k(b"!99\r\n"), FrameErrorKind::TooShort { len: 5 });
        assert_eq!(
            k(b"!992120189"),
            FrameErrorKind::MissingLineEnd { column: 11 }
        );
        assert_eq!(k(b"!992120189\r"), FrameErrorKind::MissingLf { column: 12 });
        assert_eq!(k(b"!992120189\n"), FrameErrorKind::MissingCr { column: 10 });
        assert_eq!(k(b"!9G2120189\r\n"), FrameErrorKind::BadStation);
        assert_eq!(k(b"!99X120189\r\n"), FrameErrorKind::BadMessageId);
        assert_eq!(k(b"!9921201Z9\r\n"), FrameErrorKind::BadSc { column: 9 });
        let long = [b'!'; MAX_FRAME_LEN + 1];
        assert_eq!(
            k(&long),
            FrameErrorKind::TooLong {
                len: MAX_FRAME_LEN + 1
            }
        );
        assert_eq!(k(b""), FrameErrorKind::TooShort { len: 0 });
    }

    #[test]
    fn messages_quote_the_bad_characters() {
        let e = Frame::parse(b"!9G2120189\r\n").unwrap_err();
        assert_eq!(
            e.to_string(),
            "station is '9G', expected 2 hex digits (column 2)"
        );
        let e = Frame::parse(b"!9921201Z9\r\n").unwrap_err();
        assert_eq!(
            e.to_string(),
            "checksum is 'Z9', expected 2 hex digits or '@@' (column 9)"
        );
    }

    #[test]
    fn lower_case_hex_is_accepted() {
        let f = Frame::parse(b"!992a10f01d\r\n").unwrap();
        assert_eq!(f.id(), Some(MessageId::SCARA_STATUS));
    }
}
