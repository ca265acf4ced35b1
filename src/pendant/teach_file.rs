//! Teach-list files, CSV and JSON: written exactly, loaded all or nothing.
//!
//! CSV (RFC 4180 quoting, a header line required, a BOM and blank trailing lines
//! tolerated), positions in mm / deg with exactly 3 decimals, which parse back to the
//! same wire integers:
//!
//! ```text
//! name,x_mm,y_mm,z_mm,r_deg,arm,work,tool
//! P1,300.000,-150.000,20.000,45.000,right,0,0
//! "pick, left",12.345,-0.500,0.000,-90.000,left,1,2
//! ```
//!
//! JSON is the serde form of [`TeachList`]: `{"points": [{"name": "P1", "pose": [300000,
//! -150000, 20000, 45000], "arm": "right", "work": 0, "tool": 0}]}` (wire units).

use std::collections::HashMap;
use std::fmt;

use serde::de::{Error as _, SeqAccess, Visitor};
use serde::{Deserialize, Deserializer, Serializer};
use serde_json::value::RawValue;

use super::teach::{
    MAX_TOOL, MAX_WORK, TeachList, TeachPoint, arm_word, check_name, parse_arm_word,
};
use crate::protocol::{ArmSystem, Thou};

/// The CSV header line.
pub const CSV_HEADER: &str = "name,x_mm,y_mm,z_mm,r_deg,arm,work,tool";
const COLUMNS: [&str; 8] = [
    "name", "x_mm", "y_mm", "z_mm", "r_deg", "arm", "work", "tool",
];
const NUMBER_HINT: &str = "is not a number (use a dot, 3 decimals at most)";

/// Why a file did not load: the 1-based line, the column when one is to blame, and what
/// is wrong. Displays as `line 3, field z_mm: "12,5" is not a number (...)`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FileError {
    /// 1-based line of the file.
    pub line: usize,
    /// The column (CSV header name; for JSON the point's field) when one is to blame.
    pub field: Option<String>,
    /// What is wrong, for the operator.
    pub message: String,
}

impl FileError {
    fn new(line: usize, field: Option<&str>, message: impl Into<String>) -> FileError {
        FileError {
            line,
            field: field.map(str::to_owned),
            message: message.into(),
        }
    }
}

impl fmt::Display for FileError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.field {
            Some(field) => write!(f, "line {}, field {field}: {}", self.line, self.message),
            None => write!(f, "line {}: {}", self.line, self.message),
        }
    }
}

impl std::error::Error for FileError {}

impl TeachList {
    /// The list as CSV (header first, one point a line, LF line ends).
    pub fn to_csv(&self) -> String {
        let mut out = String::with_capacity(CSV_HEADER.len() + 1 + 64 * self.len());
        out.push_str(CSV_HEADER);
        out.push('\n');
        for p in self {
            push_csv_text(&mut out, &p.name);
            for v in p.pose {
                out.push(',');
                out.push_str(&Thou(v).to_string());
            }
            out.push(',');
            out.push_str(arm_word(p.arm));
            out.push_str(&format!(",{},{}\n", p.work, p.tool));
        }
        out
    }

    /// A list from CSV text, or the first thing wrong with it (by line).
    pub fn from_csv(text: &str) -> Result<TeachList, FileError> {
        parse_csv(text)
    }

    /// A list from the bytes of a CSV file; bytes that are not UTF-8 are refused with the
    /// line (and column) they are on.
    pub fn from_csv_bytes(bytes: &[u8]) -> Result<TeachList, FileError> {
        match std::str::from_utf8(bytes) {
            Ok(text) => parse_csv(text),
            Err(e) => Err(not_utf8(bytes, e.valid_up_to())),
        }
    }

    /// Replaces this list with the CSV file's points, only if the whole file loads.
    pub fn load_csv(&mut self, bytes: &[u8]) -> Result<(), FileError> {
        *self = TeachList::from_csv_bytes(bytes)?;
        Ok(())
    }

    /// The list as pretty-printed JSON.
    pub fn to_json(&self) -> String {
        // Serialising these types cannot fail (string keys, no maps of other keys).
        serde_json::to_string_pretty(self).unwrap_or_default()
    }

    /// A list from JSON text (the form [`TeachList::to_json`] writes), or the first thing
    /// wrong with it. Each point is read on its own so that errors name its lines.
    pub fn from_json(text: &str) -> Result<TeachList, FileError> {
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        let raw: RawList<'_> =
            serde_json::from_str(text).map_err(|e| json_error(&e, text, 0, 0))?;
        let mut names: HashMap<String, usize> = HashMap::new();
        let mut list = TeachList::new();
        for (k, point) in raw.points.iter().enumerate() {
            let s = point.get();
            // Where the point starts in `text`: its line (0-based) and column (1-based).
            let offset = (s.as_ptr() as usize).saturating_sub(text.as_ptr() as usize);
            let before = text.as_bytes().get(..offset).unwrap_or_default();
            let line0 = before.iter().filter(|&&b| b == b'\n').count();
            let col0 = before.iter().rev().take_while(|&&b| b != b'\n').count();
            let p: TeachPoint =
                serde_json::from_str(s).map_err(|e| json_error(&e, s, line0, col0))?;
            if let Some(first) = names.get(&p.name) {
                return Err(FileError::new(
                    line0 + 1,
                    Some("name"),
                    format!(
                        "\"{}\" (point {}) is already used by point {}",
                        shown(&p.name),
                        k + 1,
                        first + 1
                    ),
                ));
            }
            names.insert(p.name.clone(), k);
            list.push_checked(p);
        }
        Ok(list)
    }

    /// A list from the bytes of a JSON file; bytes that are not UTF-8 are refused with
    /// their line.
    pub fn from_json_bytes(bytes: &[u8]) -> Result<TeachList, FileError> {
        match std::str::from_utf8(bytes) {
            Ok(text) => TeachList::from_json(text),
            Err(e) => Err(FileError {
                field: None,
                ..not_utf8(bytes, e.valid_up_to())
            }),
        }
    }

    /// Replaces this list with the JSON file's points, only if the whole file loads.
    pub fn load_json(&mut self, bytes: &[u8]) -> Result<(), FileError> {
        *self = TeachList::from_json_bytes(bytes)?;
        Ok(())
    }
}

/// At most 40 characters of `text`, for messages.
pub(super) fn shown(text: &str) -> String {
    let mut s: String = text.chars().take(40).collect();
    if s.len() < text.len() {
        s.push('…');
    }
    s
}

fn push_csv_text(out: &mut String, text: &str) {
    if text.contains([',', '"', '\r', '\n']) {
        out.push('"');
        out.push_str(&text.replace('"', "\"\""));
        out.push('"');
    } else {
        out.push_str(text);
    }
}

fn column(i: usize) -> Option<&'static str> {
    COLUMNS.get(i).copied()
}

fn not_utf8(bytes: &[u8], offset: usize) -> FileError {
    let prefix = bytes.get(..offset).unwrap_or(bytes);
    let (mut line, mut col, mut quoted) = (1, 0, false);
    for &b in prefix {
        match b {
            b'"' => quoted = !quoted,
            b',' if !quoted => col += 1,
            b'\n' => {
                line += 1;
                if !quoted {
                    col = 0;
                }
            }
            _ => {}
        }
    }
    FileError::new(
        line,
        column(col),
        format!("the file is not UTF-8 text (bad byte at offset {offset}); save it as UTF-8"),
    )
}

/// One CSV record: the line it starts on and its fields (unquoted).
struct Record {
    line: usize,
    fields: Vec<String>,
    blank: bool,
}

/// Splits CSV text into records, one at a time, tracking physical line numbers.
struct Records<'a> {
    it: std::iter::Peekable<std::str::Chars<'a>>,
    line: usize,
}

impl Records<'_> {
    fn next_record(&mut self) -> Option<Result<Record, FileError>> {
        self.it.peek()?;
        Some(self.read_record())
    }

    fn read_record(&mut self) -> Result<Record, FileError> {
        let start = self.line;
        let mut fields = Vec::new();
        let mut first_quoted = false;
        loop {
            let mut field = String::new();
            let col = column(fields.len());
            if self.it.peek() == Some(&'"') {
                if fields.is_empty() {
                    first_quoted = true;
                }
                self.read_quoted(&mut field, col)?;
                if !matches!(self.it.peek(), None | Some(',' | '\n' | '\r')) {
                    return Err(FileError::new(
                        self.line,
                        col,
                        "text after the closing quote (put the whole field in quotes)",
                    ));
                }
            } else {
                while let Some(&c) = self.it.peek() {
                    match c {
                        ',' | '\n' | '\r' => break,
                        '"' => {
                            return Err(FileError::new(
                                self.line,
                                col,
                                "a quote inside a field that does not start with one \
                                 (quote the whole field and double the quote: \"a \"\"b\"\"\")",
                            ));
                        }
                        _ => {
                            field.push(c);
                            self.it.next();
                        }
                    }
                }
            }
            fields.push(field);
            match self.it.next() {
                Some(',') => {}
                Some('\r') => {
                    self.it.next_if_eq(&'\n');
                    self.line += 1;
                    break;
                }
                Some('\n') => {
                    self.line += 1;
                    break;
                }
                _ => break,
            }
        }
        let blank =
            !first_quoted && fields.len() == 1 && fields.iter().all(|f| f.trim().is_empty());
        Ok(Record {
            line: start,
            fields,
            blank,
        })
    }

    fn read_quoted(&mut self, field: &mut String, col: Option<&str>) -> Result<(), FileError> {
        let open_line = self.line;
        self.it.next();
        loop {
            match self.it.next() {
                None => {
                    return Err(FileError::new(
                        open_line,
                        col,
                        "the quote opened here is never closed",
                    ));
                }
                Some('"') => {
                    if self.it.next_if_eq(&'"').is_some() {
                        field.push('"');
                    } else {
                        return Ok(());
                    }
                }
                Some(c) => {
                    if c == '\n' || (c == '\r' && self.it.peek() != Some(&'\n')) {
                        self.line += 1;
                    }
                    field.push(c);
                }
            }
        }
    }
}

fn parse_csv(text: &str) -> Result<TeachList, FileError> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let mut records = Records {
        it: text.chars().peekable(),
        line: 1,
    };
    let mut header_seen = false;
    let mut first_blank: Option<usize> = None;
    let mut names: HashMap<String, usize> = HashMap::new();
    let mut list = TeachList::new();
    while let Some(record) = records.next_record() {
        let record = record?;
        if record.blank {
            first_blank.get_or_insert(record.line);
            continue;
        }
        if let Some(blank) = first_blank {
            return Err(FileError::new(
                blank,
                None,
                "blank line (blank lines are allowed only at the end of the file)",
            ));
        }
        if !header_seen {
            check_header(&record)?;
            header_seen = true;
            continue;
        }
        let point = parse_point(&record)?;
        if let Some(first) = names.get(&point.name) {
            return Err(FileError::new(
                record.line,
                Some("name"),
                format!("\"{}\" is already used on line {first}", shown(&point.name)),
            ));
        }
        names.insert(point.name.clone(), record.line);
        list.push_checked(point);
    }
    if !header_seen {
        return Err(FileError::new(
            1,
            None,
            format!("the file is empty (a teach list starts with the line {CSV_HEADER})"),
        ));
    }
    Ok(list)
}

fn check_header(r: &Record) -> Result<(), FileError> {
    let wrong =
        (0..COLUMNS.len().max(r.fields.len())).find(|&i| match (r.fields.get(i), column(i)) {
            (Some(found), Some(want)) => !found.trim().eq_ignore_ascii_case(want),
            _ => true,
        });
    match wrong {
        None => Ok(()),
        Some(i) => Err(FileError::new(
            r.line,
            column(i),
            format!(
                "the first line must be the header {CSV_HEADER} (found \"{}\")",
                shown(&r.fields.join(","))
            ),
        )),
    }
}

fn parse_point(r: &Record) -> Result<TeachPoint, FileError> {
    let n = r.fields.len();
    if n < COLUMNS.len() {
        return Err(FileError::new(
            r.line,
            column(n),
            format!("missing column: the line has {n} fields, expected 8 ({CSV_HEADER})"),
        ));
    }
    if n > COLUMNS.len() {
        return Err(FileError::new(
            r.line,
            None,
            format!(
                "extra column: the line has {n} fields, expected 8 ({CSV_HEADER}); \
                 a name with a comma must be in quotes"
            ),
        ));
    }
    let f = |i: usize| r.fields.get(i).map(String::as_str).unwrap_or("");
    let at = |i: usize, message: String| FileError::new(r.line, column(i), message);
    let name = check_name(f(0)).map_err(|e| at(0, e.to_string()))?;
    let mut pose = [0i32; 4];
    for (i, slot) in pose.iter_mut().enumerate() {
        *slot = parse_thou(f(i + 1)).map_err(|m| at(i + 1, m))?;
    }
    let arm = parse_arm_word(f(5)).ok_or_else(|| {
        at(
            5,
            format!(
                "\"{}\" is not an arm system (use right, left or undetermined)",
                shown(f(5))
            ),
        )
    })?;
    let work = parse_frame(f(6), "work", MAX_WORK).map_err(|m| at(6, m))?;
    let tool = parse_frame(f(7), "tool", MAX_TOOL).map_err(|m| at(7, m))?;
    let point = TeachPoint {
        name,
        pose,
        arm,
        work,
        tool,
    };
    point
        .checked()
        .map_err(|e| FileError::new(r.line, e.field(), e.to_string()))
}

/// A decimal in mm or deg with at most 3 decimals, exactly to 0.001 units.
pub fn parse_thou(text: &str) -> Result<i32, String> {
    let t = text.trim();
    let bad = || format!("\"{}\" {NUMBER_HINT}", shown(t));
    let (neg, digits) = match (t.strip_prefix('-'), t.strip_prefix('+')) {
        (Some(rest), _) => (true, rest),
        (None, Some(rest)) => (false, rest),
        (None, None) => (false, t),
    };
    let (int, frac) = match digits.split_once('.') {
        Some((i, f)) => (i, f),
        None => (digits, ""),
    };
    let all_digits = |s: &str| s.bytes().all(|b| b.is_ascii_digit());
    if (int.is_empty() && frac.is_empty()) || !all_digits(int) || !all_digits(frac) {
        return Err(bad());
    }
    if frac.len() > 3 {
        return Err(format!(
            "\"{}\" has more than 3 decimals (the resolution is 0.001)",
            shown(t)
        ));
    }
    let range = || {
        format!(
            "\"{}\" is out of range (-2147483.648 to 2147483.647)",
            shown(t)
        )
    };
    let int = int.trim_start_matches('0');
    if int.len() > 10 {
        return Err(range());
    }
    let whole: i64 = if int.is_empty() {
        0
    } else {
        int.parse().map_err(|_| bad())?
    };
    let mut part: i64 = if frac.is_empty() {
        0
    } else {
        frac.parse().map_err(|_| bad())?
    };
    for _ in frac.len()..3 {
        part *= 10;
    }
    let v = whole * 1000 + part;
    let v = if neg { -v } else { v };
    i32::try_from(v).map_err(|_| range())
}

fn parse_frame(text: &str, what: &str, max: u8) -> Result<u8, String> {
    let t = text.trim();
    if t.is_empty() || !t.bytes().all(|b| b.is_ascii_digit()) {
        return Err(format!(
            "\"{}\" is not a {what} coordinate system number (0-{max})",
            shown(t)
        ));
    }
    match t.parse::<u32>() {
        Ok(v) if v <= u32::from(max) => Ok(v as u8),
        _ => Err(format!(
            "{what} coordinate system \"{}\" is out of range (0-{max})",
            shown(t)
        )),
    }
}

/// The top level of a JSON file, each point kept as its text.
#[derive(Deserialize)]
struct RawList<'a> {
    #[serde(borrow, default)]
    points: Vec<&'a RawValue>,
}

/// A serde_json error in `text` as a [`FileError`], for text that starts at 0-based `line0`
/// and 0-based byte column `col0` of the file. Our own messages start "field NAME: ".
fn json_error(e: &serde_json::Error, text: &str, line0: usize, col0: usize) -> FileError {
    let full = e.to_string();
    let suffix = format!(" at line {} column {}", e.line(), e.column());
    let msg = full.strip_suffix(&suffix).unwrap_or(&full);
    let (field, msg) = match msg.strip_prefix("field ").and_then(|m| m.split_once(": ")) {
        Some((f, m)) if !f.contains(' ') => (Some(f), m),
        _ => (None, msg),
    };
    if e.line() == 0 {
        return FileError::new(line0 + 1, field, msg);
    }
    let (mut line, mut column) = (e.line(), e.column());
    if field.is_some() {
        // serde_json reports a field's error after the whitespace that follows its value,
        // which may be the next line: step back to the end of the value.
        (line, column) = end_of_value(text, line, column);
    }
    if line == 1 {
        column += col0;
    }
    FileError::new(line0 + line, field, format!("{msg} (column {column})"))
}

/// Where a field's value ends, from the position serde_json gives for an error raised
/// after the value: past the whitespace that follows it and, for the last field, the
/// point's closing brace (its `line`:`column` is the last byte read, 1-based).
fn end_of_value(text: &str, line: usize, column: usize) -> (usize, usize) {
    let start: usize = text
        .split_inclusive('\n')
        .take(line.saturating_sub(1))
        .map(str::len)
        .sum();
    let read = text
        .as_bytes()
        .get(..(start + column).min(text.len()))
        .unwrap_or_default();
    let read = read.trim_ascii_end();
    let read = read.strip_suffix(b"}").unwrap_or(read).trim_ascii_end();
    let line = 1 + read.iter().filter(|&&b| b == b'\n').count();
    let column = read.iter().rev().take_while(|&&b| b != b'\n').count();
    (line, column.max(1))
}

/// A checked name (trimmed).
pub(super) fn de_name<'de, D: Deserializer<'de>>(d: D) -> Result<String, D::Error> {
    let name = String::deserialize(d)?;
    check_name(&name).map_err(|e| D::Error::custom(format!("field name: {e}")))
}

/// Four positions in wire units; a value outside i32 gets our message.
pub(super) fn de_pose<'de, D: Deserializer<'de>>(d: D) -> Result<[i32; 4], D::Error> {
    let wide = <[i64; 4]>::deserialize(d)?;
    let mut pose = [0i32; 4];
    for (slot, v) in pose.iter_mut().zip(wide) {
        *slot = i32::try_from(v).map_err(|_| {
            D::Error::custom(format!(
                "field pose: {v} is out of range (-2147483648 to 2147483647)"
            ))
        })?;
    }
    Ok(pose)
}

/// The arm system as its file word.
pub(super) fn ser_arm<S: Serializer>(arm: &ArmSystem, s: S) -> Result<S::Ok, S::Error> {
    s.serialize_str(arm_word(*arm))
}

/// The arm system from its file word (any letter case).
pub(super) fn de_arm<'de, D: Deserializer<'de>>(d: D) -> Result<ArmSystem, D::Error> {
    let w = String::deserialize(d)?;
    parse_arm_word(&w).ok_or_else(|| {
        D::Error::custom(format!(
            "field arm: \"{}\" is not an arm system (use right, left or undetermined)",
            shown(&w)
        ))
    })
}

fn de_frame<'de, D: Deserializer<'de>>(d: D, what: &str, max: u8) -> Result<u8, D::Error> {
    let v = i64::deserialize(d)?;
    u8::try_from(v)
        .ok()
        .filter(|n| *n <= max)
        .ok_or_else(|| D::Error::custom(format!("field {what}: {v} is out of range (0-{max})")))
}

/// A work coordinate system number, 0-31.
pub(super) fn de_work<'de, D: Deserializer<'de>>(d: D) -> Result<u8, D::Error> {
    de_frame(d, "work", MAX_WORK)
}

/// A tool coordinate system number, 0-127.
pub(super) fn de_tool<'de, D: Deserializer<'de>>(d: D) -> Result<u8, D::Error> {
    de_frame(d, "tool", MAX_TOOL)
}

/// Deserialises the points of a [`TeachList`], refusing a duplicate name where it occurs.
pub(super) fn de_points<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<TeachPoint>, D::Error> {
    struct Points;
    impl<'de> Visitor<'de> for Points {
        type Value = Vec<TeachPoint>;

        fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
            f.write_str("a list of teach points")
        }

        fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Self::Value, A::Error> {
            let mut names: HashMap<String, usize> = HashMap::new();
            let mut points = Vec::new();
            while let Some(p) = seq.next_element::<TeachPoint>()? {
                if let Some(first) = names.get(&p.name) {
                    return Err(A::Error::custom(format!(
                        "field name: \"{}\" is already used by point {}",
                        shown(&p.name),
                        first + 1
                    )));
                }
                names.insert(p.name.clone(), points.len());
                points.push(p);
            }
            Ok(points)
        }
    }
    d.deserialize_seq(Points)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pendant::teach::TaughtPose;
    use proptest::prelude::*;

    const H: &str = "name,x_mm,y_mm,z_mm,r_deg,arm,work,tool\n";

    fn sample() -> TeachList {
        let mut l = TeachList::new();
        let p = |pose, arm, work, tool| TaughtPose {
            pose,
            arm,
            work,
            tool,
        };
        l.record(
            "P1",
            p([300_000, -150_000, 20_000, 45_000], ArmSystem::Right, 0, 0),
        )
        .unwrap();
        l.record(
            "pick, left",
            p([12_345, -500, 0, -90_000], ArmSystem::Left, 1, 2),
        )
        .unwrap();
        l.record(
            "say \"hi\"",
            p(
                [i32::MIN, i32::MAX, -1, 1],
                ArmSystem::Undetermined,
                31,
                127,
            ),
        )
        .unwrap();
        l.record("Überführung 位置", p([0; 4], ArmSystem::Right, 3, 4))
            .unwrap();
        l
    }

    #[test]
    fn csv_is_written_with_3_decimals_and_rfc_4180_quotes() {
        assert_eq!(
            sample().to_csv(),
            "name,x_mm,y_mm,z_mm,r_deg,arm,work,tool\n\
             P1,300.000,-150.000,20.000,45.000,right,0,0\n\
             \"pick, left\",12.345,-0.500,0.000,-90.000,left,1,2\n\
             \"say \"\"hi\"\"\",-2147483.648,2147483.647,-0.001,0.001,undetermined,31,127\n\
             Überführung 位置,0.000,0.000,0.000,0.000,right,3,4\n"
        );
        assert_eq!(TeachList::new().to_csv(), H);
    }

    #[test]
    fn csv_and_json_round_trip_exactly() {
        let l = sample();
        assert_eq!(TeachList::from_csv(&l.to_csv()), Ok(l.clone()));
        assert_eq!(TeachList::from_json(&l.to_json()), Ok(l.clone()));
        assert_eq!(TeachList::from_csv(H), Ok(TeachList::new()));
        assert_eq!(TeachList::from_json("{}"), Ok(TeachList::new()));
        assert!(l.to_json().contains("\"pose\": [\n        300000,"));
        assert!(l.to_json().contains("\"arm\": \"undetermined\""));
    }

    #[test]
    fn csv_tolerates_bom_crlf_blank_trailing_lines_spaces_and_short_decimals() {
        let text = "\u{feff}Name, X_mm ,y_mm,z_mm,r_deg,arm,work,tool\r\n\
                    \" P1 \", 1.5 ,-.25,+7,0.,RIGHT, 3 ,4\r\n\r\n  \n";
        let l = TeachList::from_csv(text).unwrap();
        let p = l.get(0).unwrap();
        assert_eq!(p.name, "P1");
        assert_eq!(p.pose, [1500, -250, 7000, 0]);
        assert_eq!((p.arm, p.work, p.tool), (ArmSystem::Right, 3, 4));
        assert_eq!(l.len(), 1);
        // A lone CR ends a line too.
        assert_eq!(
            TeachList::from_csv(&H.replace('\n', "\r")).map(|l| l.len()),
            Ok(0)
        );
    }

    #[test]
    fn parse_thou_is_exact() {
        for (t, v) in [
            ("12.345", 12_345),
            ("-0.500", -500),
            ("0.001", 1),
            ("-2147483.648", i32::MIN),
            ("2147483.647", i32::MAX),
            ("000012.3", 12_300),
            ("5", 5_000),
            ("-0", 0),
        ] {
            assert_eq!(parse_thou(t), Ok(v), "{t}");
        }
        for t in [
            "", "-", ".", "1e3", "12,5", "1.2.3", "--1", "0x10", "1 000", "inf", "NaN",
        ] {
            assert_eq!(
                parse_thou(t),
                Err(format!(
                    "\"{t}\" is not a number (use a dot, 3 decimals at most)"
                )),
            );
        }
        assert_eq!(
            parse_thou("1.0005"),
            Err("\"1.0005\" has more than 3 decimals (the resolution is 0.001)".into())
        );
        for t in ["2147483.648", "-2147483.649", "99999999999999999999999"] {
            assert!(parse_thou(t).unwrap_err().contains("out of range"), "{t}");
        }
    }

    /// Loads `text` into a list that already holds points: it must fail with `line` and
    /// `field` and leave the list as it was.
    fn refused(text: &str, line: usize, field: Option<&str>) -> String {
        let mut l = sample();
        let e = l.load_csv(text.as_bytes()).unwrap_err();
        assert_eq!(l, sample(), "{text:?}");
        assert_eq!((e.line, e.field.as_deref()), (line, field), "{text:?}: {e}");
        e.to_string()
    }

    #[test]
    fn broken_csv_names_line_and_field_and_changes_nothing() {
        let ok = "P1,1.000,2.000,3.000,4.000,right,0,0\n";
        assert_eq!(
            refused(
                &format!("{H}{ok}P2,1,2,\"12,5\",4,left,0,0\n"),
                3,
                Some("z_mm")
            ),
            "line 3, field z_mm: \"12,5\" is not a number (use a dot, 3 decimals at most)"
        );
        assert_eq!(
            refused(&format!("{H}{ok}P2,1,2,3\n"), 3, Some("r_deg")),
            "line 3, field r_deg: missing column: the line has 4 fields, expected 8 \
             (name,x_mm,y_mm,z_mm,r_deg,arm,work,tool)"
        );
        assert!(refused(&format!("{H}a, b,1,2,3,4,right,0,0\n"), 2, None).contains("extra column"));
        refused(&format!("{H}P2,1.0005,2,3,4,left,0,0\n"), 2, Some("x_mm"));
        refused(&format!("{H}P2,1,3000000,3,4,left,0,0\n"), 2, Some("y_mm"));
        assert_eq!(
            refused(&format!("{H}P2,1,2,3,4,elbow,0,0\n"), 2, Some("arm")),
            "line 2, field arm: \"elbow\" is not an arm system (use right, left or undetermined)"
        );
        assert_eq!(
            refused(&format!("{H}P2,1,2,3,4,left,32,0\n"), 2, Some("work")),
            "line 2, field work: work coordinate system \"32\" is out of range (0-31)"
        );
        refused(&format!("{H}P2,1,2,3,4,left,-1,0\n"), 2, Some("work"));
        refused(&format!("{H}P2,1,2,3,4,left,0,128\n"), 2, Some("tool"));
        refused(
            &format!("{H}P2,1,2,3,4,left,0,99999999999\n"),
            2,
            Some("tool"),
        );
        refused(&format!("{H}P2,1,2,3,4,left,0,\n"), 2, Some("tool"));
        assert_eq!(
            refused(&format!("{H}{ok}\n P1 ,1,2,3,4,left,0,0\n"), 3, None),
            "line 3: blank line (blank lines are allowed only at the end of the file)"
        );
        assert_eq!(
            refused(&format!("{H}{ok}{ok}"), 3, Some("name")),
            "line 3, field name: \"P1\" is already used on line 2"
        );
        refused(&format!("{H}{ok}  ,1,2,3,4,left,0,0\n"), 3, Some("name"));
        refused(
            &format!("{H}{}", ok.replace("P1", &"n".repeat(33))),
            2,
            Some("name"),
        );
        refused(&format!("{H}\"a\nb\",1,2,3,4,left,0,0\n"), 2, Some("name"));
        // Quotes.
        assert!(
            refused(
                &format!("{H}{ok}\"P2,1,2,3,4,left,0,0\n{ok}"),
                3,
                Some("name")
            )
            .contains("never closed")
        );
        assert!(
            refused(&format!("{H}P\"2,1,2,3,4,left,0,0\n"), 2, Some("name"))
                .contains("quote inside")
        );
        assert!(
            refused(&format!("{H}\"P2\"x,1,2,3,4,left,0,0\n"), 2, Some("name"))
                .contains("after the closing quote")
        );
        refused(&format!("{H}P2,1,2,3,4,\"left\"\"\",0,0\n"), 2, Some("arm"));
        // Line numbers are counted inside a quoted field that spans lines.
        refused(
            &format!("{H}\"a\r\nb\"x,1,2,3,4,left,0,0\n"),
            3,
            Some("name"),
        );
        refused(
            &format!("{H}\"a\r\nb\",1,2,3,4,left,0,0\n"),
            2,
            Some("name"),
        );
        // Header and emptiness.
        assert_eq!(
            refused("", 1, None),
            "line 1: the file is empty (a teach list starts with the line \
             name,x_mm,y_mm,z_mm,r_deg,arm,work,tool)"
        );
        refused("\u{feff}\n\n", 1, None);
        assert_eq!(
            refused(ok, 1, Some("name")),
            "line 1, field name: the first line must be the header \
             name,x_mm,y_mm,z_mm,r_deg,arm,work,tool (found \"P1,1.000,2.000,3.000,4.000,right,0,0\")"
        );
        refused("name,x_mm,y_mm,z_mm,r_deg,arm,work\n", 1, Some("tool"));
        refused("name,x_mm,y_mm,z_mm,r_deg,arm,work,tool,note\n", 1, None);
        refused("name,x,y_mm,z_mm,r_deg,arm,work,tool\n", 1, Some("x_mm"));
    }

    #[test]
    fn non_utf8_names_the_line_and_field() {
        let mut bytes = format!("{H}P1,1,2,3,4,left,0,0\n\"a,b\",1,").into_bytes();
        bytes.extend_from_slice(b"\xFF,3,4,left,0,0\n");
        let mut l = sample();
        let e = l.load_csv(&bytes).unwrap_err();
        assert_eq!(l, sample());
        assert_eq!((e.line, e.field.as_deref()), (3, Some("y_mm")));
        assert!(e.message.contains("not UTF-8"), "{e}");
        assert!(
            e.message.contains(&format!("offset {}", bytes.len() - 15)),
            "{e}"
        );
        let e = TeachList::from_csv_bytes(b"\xC3").unwrap_err();
        assert_eq!((e.line, e.field.as_deref()), (1, Some("name")));
        // A BOM in bytes is fine.
        let mut bom = b"\xEF\xBB\xBF".to_vec();
        bom.extend_from_slice(H.as_bytes());
        assert_eq!(TeachList::from_csv_bytes(&bom), Ok(TeachList::new()));
    }

    #[test]
    fn load_replaces_only_on_success() {
        let mut l = sample();
        l.load_csv(format!("{H}Q,1,2,3,4,left,0,0\n").as_bytes())
            .unwrap();
        assert_eq!(l.len(), 1);
        l.load_json(sample().to_json().as_bytes()).unwrap();
        assert_eq!(l, sample());
        assert!(l.load_json(b"{\"points\": [1]}").is_err());
        assert_eq!(l, sample());
    }

    fn json_refused(text: &str) -> FileError {
        let mut l = sample();
        let e = l.load_json(text.as_bytes()).unwrap_err();
        assert_eq!(l, sample());
        e
    }

    #[test]
    fn broken_json_names_line_and_field() {
        let point = |name: &str, work: i64, line_end: &str| {
            format!(
                "{{\"name\": \"{name}\", \"pose\": [1, 2, 3, 4], \"arm\": \"left\",{line_end}\
                 \"work\": {work}, \"tool\": 0}}"
            )
        };
        let e = json_refused(&format!(
            "{{\"points\": [\n{},\n{}\n]}}",
            point("A", 0, ""),
            point("B", 40, "\n")
        ));
        assert_eq!((e.line, e.field.as_deref()), (4, Some("work")), "{e}");
        assert!(e.message.starts_with("40 is out of range (0-31)"), "{e}");
        let e = json_refused(&format!(
            "{{\"points\": [\n{},\n{}\n]}}",
            point("A", 0, ""),
            point(" A ", 0, "")
        ));
        assert_eq!((e.line, e.field.as_deref()), (3, Some("name")), "{e}");
        assert!(e.message.contains("already used by point 1"), "{e}");
        let e = json_refused(
            "{\"points\": [\n{\"name\": \"A\", \"pose\": [1, 2, 3, 3000000000], \"arm\": \"left\", \"work\": 0, \"tool\": 0}]}",
        );
        assert_eq!((e.line, e.field.as_deref()), (2, Some("pose")), "{e}");
        let e = json_refused(
            "{\"points\": [\n{\"name\": \"A\", \"pose\": [1, 2, 3, 4], \"arm\": \"up\", \"work\": 0, \"tool\": 0}]}",
        );
        assert_eq!((e.line, e.field.as_deref()), (2, Some("arm")), "{e}");
        let e = json_refused(
            "{\"points\": [\n{\"name\": \"\", \"pose\": [1, 2, 3, 4], \"arm\": \"up\"}]}",
        );
        assert_eq!(e.line, 2, "{e}");
        let e = json_refused("{\"points\": [\n{\"name\": \"A\"}]}");
        assert_eq!((e.line, e.field.as_deref()), (2, None), "{e}");
        assert!(e.message.contains("missing field"), "{e}");
        let e = json_refused("{\n\"points\": [,]}");
        assert_eq!(e.line, 2, "{e}");
        assert!(e.to_string().starts_with("line 2: "), "{e}");
        let e = json_refused("");
        assert_eq!(e.line, 1, "{e}");
        let e = TeachList::from_json_bytes(b"{\"points\": [{\"name\": \"\xFF\"}]}").unwrap_err();
        assert_eq!(e.line, 1, "{e}");
    }

    #[test]
    fn pretty_json_errors_point_at_the_value() {
        let mut l = TeachList::new();
        let at = |x, work, tool| TaughtPose {
            pose: [x, 2, 3, 4],
            arm: ArmSystem::Left,
            work,
            tool,
        };
        l.record("P1", at(1, 0, 0)).unwrap();
        l.record("pick", at(12_345, 31, 127)).unwrap();
        let j = l.to_json();
        let line_of = |needle: &str| 1 + j[..j.find(needle).unwrap()].matches('\n').count();
        for (from, to, field, line) in [
            (
                "\"work\": 31",
                "\"work\": 32",
                Some("work"),
                line_of("\"work\": 31"),
            ),
            (
                "\"tool\": 127",
                "\"tool\": 128",
                Some("tool"),
                line_of("\"tool\": 127"),
            ),
            ("\"pick\"", "\"P1\"", Some("name"), line_of("\"pick\"") - 1),
            ("\"pick\"", "\" \"", Some("name"), line_of("\"pick\"")),
            ("\"pick\"", "5", None, line_of("\"pick\"")),
            ("12345", "1.5", None, line_of("12345")),
            ("12345", "-2147483649", Some("pose"), line_of("12345") + 4),
        ] {
            let e = json_refused(&j.replacen(from, to, 1));
            assert_eq!((e.line, e.field.as_deref()), (line, field), "{to}: {e}");
        }
        assert_eq!(
            json_refused(&j.replacen("\"work\": 31", "\"work\": 32", 1)).to_string(),
            format!(
                "line {}, field work: 32 is out of range (0-31) (column 16)",
                line_of("\"work\": 31")
            )
        );
    }

    #[test]
    fn the_derived_serde_form_checks_too() {
        // What eframe persistence uses: the plain Deserialize of TeachList.
        let l = sample();
        let v: TeachList = serde_json::from_str(&l.to_json()).unwrap();
        assert_eq!(v, l);
        assert_eq!(
            serde_json::from_str::<TeachList>("{}").unwrap(),
            TeachList::new()
        );
        let p = |n: &str, w: u8| {
            format!(
                "{{\"name\":\"{n}\",\"pose\":[0,0,0,0],\"arm\":\"right\",\"work\":{w},\"tool\":0}}"
            )
        };
        let dup = format!("{{\"points\":[{},{}]}}", p("A", 0), p(" A", 0));
        let e = serde_json::from_str::<TeachList>(&dup).unwrap_err();
        assert!(e.to_string().contains("already used by point 1"), "{e}");
        let bad = format!("{{\"points\":[{}]}}", p("A", 32));
        assert!(serde_json::from_str::<TeachList>(&bad).is_err());
        let trimmed = format!("{{\"points\":[{}]}}", p(" A ", 0));
        let t: TeachList = serde_json::from_str(&trimmed).unwrap();
        assert_eq!(t.get(0).map(|p| p.name.as_str()), Some("A"));
    }

    fn arb_arm() -> impl Strategy<Value = ArmSystem> {
        prop_oneof![
            Just(ArmSystem::Right),
            Just(ArmSystem::Left),
            Just(ArmSystem::Undetermined)
        ]
    }

    fn arb_list() -> impl Strategy<Value = TeachList> {
        let name = "[a-zA-Z0-9 ,\"'éü位置;\t]{1,32}";
        let point = (name, any::<[i32; 4]>(), arb_arm(), 0u8..=31, 0u8..=127);
        prop::collection::vec(point, 0..12).prop_map(|points| {
            let mut l = TeachList::new();
            for (name, pose, arm, work, tool) in points {
                let name = name.replace('\t', "");
                let at = TaughtPose {
                    pose,
                    arm,
                    work,
                    tool,
                };
                // Blank and duplicate names are refused; the rest go in.
                let _ = l.record(&name, at);
            }
            l
        })
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 256, failure_persistence: None, ..ProptestConfig::default() })]

        #[test]
        fn files_round_trip_exactly(l in arb_list()) {
            prop_assert_eq!(TeachList::from_csv(&l.to_csv()), Ok(l.clone()));
            prop_assert_eq!(TeachList::from_csv_bytes(l.to_csv().as_bytes()), Ok(l.clone()));
            prop_assert_eq!(TeachList::from_json(&l.to_json()), Ok(l.clone()));
        }

        #[test]
        fn positions_parse_back_exactly(v in any::<i32>()) {
            prop_assert_eq!(parse_thou(&Thou(v).to_string()), Ok(v));
        }

        #[test]
        fn csv_never_panics_on_any_text(s in any::<String>()) {
            let _ = TeachList::from_csv(&s);
            let _ = TeachList::from_json(&s);
        }

        #[test]
        fn csv_never_panics_on_any_bytes(b in prop::collection::vec(any::<u8>(), 0..300)) {
            let _ = TeachList::from_csv_bytes(&b);
            let _ = TeachList::from_json_bytes(&b);
        }

        #[test]
        fn csv_like_text_fails_cleanly(body in "[a-z0-9,\"\\.\\-\r\n é]{0,200}") {
            let mut l = sample();
            match l.load_csv(format!("{H}{body}").as_bytes()) {
                Ok(()) => prop_assert_eq!(TeachList::from_csv(&l.to_csv()), Ok(l)),
                Err(e) => {
                    prop_assert_eq!(l, sample());
                    prop_assert!(e.line >= 1);
                    prop_assert!(!e.message.is_empty());
                }
            }
        }
    }
}
