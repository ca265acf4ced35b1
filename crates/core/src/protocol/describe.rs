//! Field-by-field description of any frame bytes, good or bad, for the frame log.

use std::fmt;

use super::command::decode_command_data;
use super::error::Columns;
use super::frame::{MAX_FRAME_LEN, chars_at};
use super::hex::parse_hex;
use super::ids::{Header, MessageId};
use super::peek;
use super::reply::{decode_error_data, decode_reply_data};

/// One field of a described frame.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FieldDescription {
    /// Field name, e.g. `axis 2 position`.
    pub name: String,
    /// Where it is (1-based frame columns).
    pub columns: Columns,
    /// The characters as received (escaped).
    pub raw: String,
    /// The value with its unit, e.g. `-5.000 mm`, `30 %`, `1C`.
    pub value: String,
    /// Bit meanings for flag fields, e.g. `bit 3 servo on = 1`.
    pub bits: Vec<BitNote>,
}

/// The value of one bit (or bit group) of a flag field.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct BitNote {
    /// `bit 3 servo on` or `bits 1-2 home state`.
    pub label: String,
    /// The bit (group) value.
    pub value: u32,
    /// The meaning of that value, where the spec names it.
    pub meaning: Option<&'static str>,
}

impl fmt::Display for BitNote {
    /// `bit 3 servo on = 1`, `bits 1-2 home state = 2 (done)`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} = {}", self.label, self.value)?;
        if let Some(m) = self.meaning {
            write!(f, " ({m})")?;
        }
        Ok(())
    }
}

/// What the SC field says.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ChecksumVerdict {
    /// The SC matches the frame's bytes.
    Valid(u8),
    /// `@@` instead of a sum (accepted without a check).
    AtAt {
        /// What the sum would be.
        computed: u8,
    },
    /// The SC does not match.
    Wrong {
        /// The SC in the frame.
        found: u8,
        /// The sum of the frame's bytes.
        computed: u8,
    },
    /// The SC characters are neither hex digits nor `@@`.
    Unreadable {
        /// What the sum would be.
        computed: u8,
    },
    /// The frame is too short to hold an SC.
    Absent,
    /// The protocol has no checksum (Modbus/TCP: TCP checks the bytes).
    NotUsed,
}

impl fmt::Display for ChecksumVerdict {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            ChecksumVerdict::Valid(v) => write!(f, "checksum {v:02X} is correct"),
            ChecksumVerdict::AtAt { computed } => {
                write!(
                    f,
                    "checksum is '@@' (not checked); the sum would be {computed:02X}"
                )
            }
            ChecksumVerdict::Wrong { found, computed } => write!(
                f,
                "checksum is {found:02X}, but the frame's bytes sum to {computed:02X}"
            ),
            ChecksumVerdict::Unreadable { computed } => write!(
                f,
                "checksum is not 2 hex digits or '@@'; the sum would be {computed:02X}"
            ),
            ChecksumVerdict::Absent => f.write_str("no checksum (frame too short)"),
            ChecksumVerdict::NotUsed => {
                f.write_str("no checksum in Modbus/TCP (TCP checks the bytes)")
            }
        }
    }
}

/// A problem found while describing, at a column.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Problem {
    /// 1-based column.
    pub column: usize,
    /// What is wrong, in words.
    pub message: String,
}

/// The field-by-field description of a run of bytes.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FrameDescription {
    /// Header kind, if the first byte is one.
    pub header: Option<Header>,
    /// Message ID, if readable.
    pub message: Option<MessageId>,
    /// One line saying what this is, e.g. `212H axis status query — reply`.
    pub title: String,
    /// The fields, left to right, as far as they could be read.
    pub fields: Vec<FieldDescription>,
    /// The SC verdict.
    pub checksum: ChecksumVerdict,
    /// Problems found (empty for a good frame).
    pub problems: Vec<Problem>,
}

impl FrameDescription {
    /// Whether the frame is valid in every respect described.
    pub fn is_ok(&self) -> bool {
        self.problems.is_empty()
    }

    /// The field covering `column`, if any.
    pub fn field_at(&self, column: usize) -> Option<&FieldDescription> {
        self.fields
            .iter()
            .find(|f| f.columns.first <= column && column <= f.columns.last)
    }
}

impl fmt::Display for FrameDescription {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "{}", self.title)?;
        for fd in &self.fields {
            let cols = if fd.columns.last > fd.columns.first {
                format!("{}-{}", fd.columns.first, fd.columns.last)
            } else {
                fd.columns.first.to_string()
            };
            writeln!(f, "  {cols:<9} {:<10} {}: {}", fd.raw, fd.name, fd.value)?;
            for b in &fd.bits {
                writeln!(f, "  {:<9} {:<10}   {b}", "", "")?;
            }
        }
        writeln!(f, "  {}", self.checksum)?;
        for p in &self.problems {
            writeln!(f, "  problem at column {}: {}", p.column, p.message)?;
        }
        Ok(())
    }
}

fn field(name: &str, first: usize, last: usize, raw: &[u8], value: String) -> FieldDescription {
    FieldDescription {
        name: name.to_string(),
        columns: Columns::new(first, last.max(first)),
        raw: chars_at(raw, first, last),
        value,
        bits: Vec::new(),
    }
}

/// Describes any bytes as a Format B frame, field by field: header, station, message ID,
/// each data field (name, columns, raw characters, value with unit, bit meanings), SC with
/// its verdict, CR LF. Unknown message IDs get a generic description; a malformed frame is
/// described as far as it parses, with each problem at its column. Never fails.
pub fn describe(bytes: &[u8]) -> FrameDescription {
    let mut d = FrameDescription {
        header: None,
        message: None,
        title: String::new(),
        fields: Vec::new(),
        checksum: ChecksumVerdict::Absent,
        problems: Vec::new(),
    };
    let problem = |d: &mut FrameDescription, column: usize, message: String| {
        d.problems.push(Problem { column, message });
    };
    let Some(&first) = bytes.first() else {
        d.title = "empty (no bytes)".into();
        problem(&mut d, 1, "no bytes".into());
        return d;
    };
    let Some(header) = Header::from_byte(first) else {
        d.title = "not a frame".into();
        d.fields.push(field(
            "bytes (not a frame)",
            1,
            bytes.len(),
            bytes,
            format!("{} bytes", bytes.len()),
        ));
        problem(
            &mut d,
            1,
            format!(
                "starts with '{}', expected '!' (command), '#' (reply) or '&' (error reply)",
                [first].escape_ascii()
            ),
        );
        return d;
    };
    d.header = Some(header);
    d.fields
        .push(field("header", 1, 1, bytes, header.describe().to_string()));
    if bytes.len() > MAX_FRAME_LEN {
        problem(
            &mut d,
            MAX_FRAME_LEN + 1,
            format!(
                "frame is {} bytes long, longer than the longest legal frame ({MAX_FRAME_LEN})",
                bytes.len()
            ),
        );
    }

    // Line end.
    let len = bytes.len();
    let body_len = if bytes.ends_with(b"\r\n") {
        len - 2
    } else if bytes.ends_with(b"\n") {
        problem(
            &mut d,
            len,
            "the frame ends with LF but no CR before it".into(),
        );
        len - 1
    } else {
        problem(&mut d, len + 1, "the frame does not end with CR LF".into());
        len
    };
    let body = bytes.get(..body_len).unwrap_or(&[]);

    // Station.
    match body.get(peek::STATION) {
        Some(s) => match parse_hex(s) {
            Some(v) => d
                .fields
                .push(field("station", 2, 3, bytes, format!("{v:02X}"))),
            None => {
                d.fields
                    .push(field("station", 2, 3, bytes, "not hex".into()));
                problem(
                    &mut d,
                    2,
                    format!("station is '{}', expected 2 hex digits", s.escape_ascii()),
                );
            }
        },
        None => {
            problem(
                &mut d,
                body.len() + 1,
                "the frame ends before the station (columns 2-3)".into(),
            );
            d.title = format!("{} (cut short)", header.describe());
            return d;
        }
    }

    // Message ID.
    let data_start = if header == Header::Error { 3 } else { 6 };
    if header != Header::Error {
        match body.get(peek::MESSAGE_ID) {
            Some(s) => match parse_hex(s) {
                Some(v) => {
                    let id = MessageId(v as u16);
                    d.message = Some(id);
                    let value = match id.name() {
                        Some(n) => format!("{id} ({n})"),
                        None => format!("{id} (unknown message)"),
                    };
                    d.fields.push(field("message ID", 4, 6, bytes, value));
                }
                None => {
                    d.fields
                        .push(field("message ID", 4, 6, bytes, "not hex".into()));
                    problem(
                        &mut d,
                        4,
                        format!(
                            "message ID is '{}', expected 3 hex digits",
                            s.escape_ascii()
                        ),
                    );
                }
            },
            None => {
                problem(
                    &mut d,
                    body.len() + 1,
                    "the frame ends before the message ID (columns 4-6)".into(),
                );
            }
        }
    }
    d.title = match (header, d.message) {
        (Header::Error, _) => "error reply".to_string(),
        (h, Some(id)) => match id.name() {
            Some(n) => format!("{id} {n} — {}", h.describe()),
            None => format!("{id} unknown message — {}", h.describe()),
        },
        (h, None) => format!("{} with unreadable message ID", h.describe()),
    };

    // SC and data.
    if body.len() < data_start + 2 {
        problem(
            &mut d,
            body.len() + 1,
            format!("frame is too short: {len} bytes, the shortest frame has 10"),
        );
        return d;
    }
    let sc_at = body.len() - 2;
    let data = body.get(data_start..sc_at).unwrap_or(&[]);
    let col0 = data_start + 1;
    let mut recorded = Vec::new();
    let decoded = match (header, d.message) {
        (Header::Error, _) => Some(decode_error_data(data, col0, Some(&mut recorded)).map(|_| ())),
        (Header::Command, Some(id)) if id.name().is_some() => {
            Some(decode_command_data(id, data, col0, Some(&mut recorded)).map(|_| ()))
        }
        (Header::Reply, Some(id)) if id.name().is_some() => {
            Some(decode_reply_data(id, data, col0, Some(&mut recorded)).map(|_| ()))
        }
        _ => None,
    };
    d.fields.append(&mut recorded);
    match decoded {
        None => {
            if !data.is_empty() {
                d.fields.push(field(
                    "data (unknown message)",
                    col0,
                    col0 + data.len() - 1,
                    bytes,
                    format!("{} characters", data.len()),
                ));
            }
        }
        Some(Ok(())) => {}
        Some(Err(e)) => {
            let column = e.column().unwrap_or(col0);
            problem(&mut d, column, e.to_string());
            let described_to = d.fields.last().map_or(col0 - 1, |f| f.columns.last);
            let last = col0 + data.len();
            if described_to + 1 < last {
                d.fields.push(field(
                    "data (not decoded)",
                    described_to + 1,
                    last - 1,
                    bytes,
                    format!("{} characters", last - 1 - described_to),
                ));
            }
        }
    }

    // SC.
    let sc_col = sc_at + 1;
    d.checksum = peek::checksum_verdict(bytes);
    d.fields.push(field(
        "SC (checksum)",
        sc_col,
        sc_col + 1,
        bytes,
        d.checksum.to_string(),
    ));
    match d.checksum {
        ChecksumVerdict::Wrong { .. } | ChecksumVerdict::Unreadable { .. } => {
            let msg = d.checksum.to_string();
            problem(&mut d, sc_col, msg);
        }
        _ => {}
    }
    if body_len < len {
        d.fields
            .push(field("line end", body_len + 1, len, bytes, "CR LF".into()));
    }
    d.problems.sort_by_key(|p| p.column);
    d
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn describes_a_scara_move_with_units() {
        let d = describe(b"!992D50F0000000000320300000000FFFFEC780000000000000000EB\r\n");
        assert!(d.is_ok(), "{d}");
        assert_eq!(d.title, "2D5H SCARA relative move — command");
        let speed = d.fields.iter().find(|f| f.name == "speed").unwrap();
        assert_eq!(speed.value, "50 mm/s");
        assert_eq!(speed.columns, Columns::new(17, 20));
        let y = d
            .fields
            .iter()
            .find(|f| f.name == "axis 2 distance")
            .unwrap();
        assert_eq!(y.value, "-5.000 mm");
        assert_eq!(y.raw, "FFFFEC78");
        assert_eq!(d.checksum, ChecksumVerdict::Valid(0xEB));
    }

    #[test]
    fn describes_bits_of_a_status_reply() {
        let d = describe(b"#99212011C0000000000C350BA\r\n");
        let st = d.fields.iter().find(|f| f.name == "axis 1 status").unwrap();
        let notes: Vec<String> = st.bits.iter().map(ToString::to_string).collect();
        assert!(
            notes.contains(&"bit 3 servo on = 1".to_string()),
            "{notes:?}"
        );
        assert!(
            notes.contains(&"bits 1-2 home state = 2 (done)".to_string()),
            "{notes:?}"
        );
        let pos = d
            .fields
            .iter()
            .find(|f| f.name == "axis 1 position")
            .unwrap();
        assert_eq!(pos.value, "50.000 mm");
    }

    #[test]
    fn unknown_messages_are_described_not_rejected() {
        let d = describe(b"!992FF00100001D3\r\n");
        assert!(d.is_ok(), "{d}");
        assert!(d.title.contains("2FFH unknown message"));
        let data = d
            .fields
            .iter()
            .find(|f| f.name == "data (unknown message)")
            .unwrap();
        assert_eq!(data.raw, "00100001");
        assert_eq!(data.columns, Columns::new(7, 14));
    }

    #[test]
    fn malformed_frames_are_described_as_far_as_they_parse() {
        let d = describe(b"!992D50F00000000G0 10300000000FFFFEC780000000000000000EB\r\n");
        assert!(!d.is_ok());
        let p = &d.problems[0];
        assert_eq!(p.column, 17);
        assert!(
            p.message
                .contains("field 'speed' at columns 17-20 is 'G0 1'"),
            "{}",
            p.message
        );
        assert!(d.fields.iter().any(|f| f.name == "deceleration"));
        assert!(d.fields.iter().any(|f| f.name == "data (not decoded)"));
        assert!(matches!(d.checksum, ChecksumVerdict::Wrong { .. }));
    }

    #[test]
    fn garbage_and_fragments_never_fail() {
        for b in [
            &b""[..],
            b"hello",
            b"!",
            b"#9",
            b"&99",
            b"!99212",
            b"\r\n",
            b"#992A4FF00001",
        ] {
            let d = describe(b);
            assert!(!d.is_ok(), "{b:?}");
            let _ = d.to_string();
        }
    }

    #[test]
    fn at_at_is_reported_with_the_real_sum() {
        let d = describe(b"!99232071@@\r\n");
        assert_eq!(d.checksum, ChecksumVerdict::AtAt { computed: 0xC2 });
        assert!(d.is_ok());
    }
}
