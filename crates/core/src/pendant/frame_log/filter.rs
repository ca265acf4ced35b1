//! Which rows of the frame log to show: line, message ID, direction, problems only, a
//! time range and free text over the raw bytes, the message name and (optionally) the decoded
//! fields. Pure: [`Filter::matches`] judges one row; the window runs it off its thread.

use std::cell::RefCell;

use super::{Dir, Protocol, Row};
use crate::protocol::MessageId;

/// Which directions to show.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum DirFilter {
    #[default]
    Both,
    Sent,
    Received,
}

/// A filter over rows; the default shows everything.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Filter {
    /// Only the rows of this line (the X-SEL's Format B or the RMC151's Modbus/TCP).
    pub protocol: Option<Protocol>,
    /// Only this message ID (`&` replies and time-outs take their request's).
    pub id: Option<u16>,
    pub dir: DirFilter,
    /// Only error replies, garbage, bad checksums and time-outs.
    pub problems_only: bool,
    /// Seconds after the log's start, inclusive.
    pub from_s: Option<f64>,
    pub to_s: Option<f64>,
    /// Free text, case-insensitive (empty: any).
    pub text: String,
    /// Also look for the text in the field-by-field decode (slower).
    pub decoded: bool,
}

impl Filter {
    /// Whether it lets every row through.
    pub fn is_empty(&self) -> bool {
        self.id.is_none()
            && self.protocol.is_none()
            && self.dir == DirFilter::Both
            && !self.problems_only
            && self.from_s.is_none()
            && self.to_s.is_none()
            && self.text.trim().is_empty()
    }

    /// A matcher ready to run over many rows.
    pub fn matcher(&self) -> Matcher {
        let needle = self.text.trim().to_ascii_lowercase();
        Matcher {
            filter: self.clone(),
            escaped: needle.contains('\\'),
            needle: needle.into_bytes(),
            scratch: RefCell::default(),
        }
    }
}

/// A filter compiled for repeated use.
#[derive(Clone, Debug)]
pub struct Matcher {
    filter: Filter,
    needle: Vec<u8>,
    /// The needle names an escape (`\r`): match the escaped text.
    escaped: bool,
    /// Room for one row's bytes, reused from row to row.
    scratch: RefCell<Vec<u8>>,
}

impl Matcher {
    pub fn filter(&self) -> &Filter {
        &self.filter
    }

    /// Whether `row` passes.
    pub fn matches(&self, row: &Row<'_>) -> bool {
        let f = &self.filter;
        if f.id.is_some() && row.id() != f.id {
            return false;
        }
        if f.protocol.is_some_and(|p| p != row.protocol()) {
            return false;
        }
        let dir_ok = match f.dir {
            DirFilter::Both => true,
            DirFilter::Sent => row.dir() == Dir::Sent,
            DirFilter::Received => row.dir() != Dir::Sent,
        };
        if !dir_ok || (f.problems_only && !row.is_problem()) {
            return false;
        }
        let t = row.t_ns() as f64 * 1e-9;
        if f.from_s.is_some_and(|s| t < s) || f.to_s.is_some_and(|s| t > s) {
            return false;
        }
        self.needle.is_empty() || self.text_matches(row)
    }

    fn text_matches(&self, row: &Row<'_>) -> bool {
        let n = &self.needle;
        if row.protocol() == Protocol::Modbus {
            // Binary bytes: the text is looked for in their hex and the row's name.
            return contains(row.ascii().as_bytes(), n)
                || contains(row.name().as_bytes(), n)
                || contains(row.note().as_bytes(), n)
                || contains(row.dir().key().as_bytes(), n)
                || (self.filter.decoded && self.decoded_matches(row));
        }
        let hit = if self.escaped {
            contains(row.ascii().as_bytes(), n)
        } else {
            let mut bytes = self.scratch.borrow_mut();
            bytes.clear();
            row.write_bytes(&mut bytes);
            contains(&bytes, n)
        };
        if hit || contains(row.note().as_bytes(), n) || contains(row.dir().key().as_bytes(), n) {
            return true;
        }
        if let Some(id) = row.id() {
            let name = MessageId(id).name().unwrap_or("");
            if contains(&id_text(id), n) || contains(name.as_bytes(), n) {
                return true;
            }
        }
        if contains(b"error reply", n) && row.is_error_reply() {
            return true;
        }
        self.filter.decoded && row.dir() != Dir::Timeout && self.decoded_matches(row)
    }

    fn decoded_matches(&self, row: &Row<'_>) -> bool {
        let d = row.describe();
        let n = &self.needle;
        contains(d.title.as_bytes(), n)
            || d.fields.iter().any(|f| {
                contains(f.name.as_bytes(), n)
                    || contains(f.value.as_bytes(), n)
                    || f.bits.iter().any(|b| contains(b.to_string().as_bytes(), n))
            })
    }
}

/// `212h`: a message ID as the name column shows it (lower case), without allocating.
fn id_text(id: u16) -> [u8; 4] {
    let hex = |v: u16| b"0123456789abcdef"[usize::from(v & 0xF)];
    [hex(id >> 8), hex(id >> 4), hex(id), b'h']
}

/// ASCII case-insensitive substring test; `needle` is lower case.
fn contains(hay: &[u8], needle: &[u8]) -> bool {
    let Some((&first, rest)) = needle.split_first() else {
        return true;
    };
    if hay.len() < needle.len() {
        return false;
    }
    let last_start = hay.len() - needle.len();
    memchr::memchr2_iter(first, first.to_ascii_uppercase(), &hay[..=last_start]).any(|i| {
        hay[i + 1..i + needle.len()]
            .iter()
            .zip(rest)
            .all(|(h, n)| h.to_ascii_lowercase() == *n)
    })
}

/// Parses a message ID as typed: `212`, `212H`, `0x212`.
pub fn parse_id(text: &str) -> Result<Option<u16>, String> {
    let t = text.trim();
    if t.is_empty() {
        return Ok(None);
    }
    let t = t.trim_start_matches("0x").trim_end_matches(['H', 'h']);
    crate::protocol::peek::hex_digits(t)
        .filter(|_| t.len() <= 3)
        .map(|id| Some(id as u16))
        .ok_or_else(|| format!("'{text}' is not a message ID (3 hex digits, e.g. 212)"))
}

/// Parses seconds as typed (empty: no bound).
pub fn parse_seconds(text: &str) -> Result<Option<f64>, String> {
    let t = text.trim().trim_end_matches('s').trim();
    if t.is_empty() {
        return Ok(None);
    }
    t.parse::<f64>()
        .ok()
        .filter(|v| v.is_finite())
        .map(Some)
        .ok_or_else(|| format!("'{text}' is not a time in seconds"))
}
