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
//! -150000, 20000, 45000], "arm": "right", "work": 0, "tool": 0}]}` (wire units), read
//! in `teach_json`.

use crate::files::csv_style::{BOM, EOL};
use std::collections::HashMap;
use std::fmt;

use super::{
    MAX_FRAME_NUMBER, MAX_POINTS, TeachList, TeachPoint, arm_word, check_name, parse_arm_word,
};
use crate::protocol::Milli;

/// The CSV header line.
pub const CSV_HEADER: &str = "name,x_mm,y_mm,z_mm,r_deg,arm,work,tool";
const COLUMNS: [&str; 8] = [
    "name", "x_mm", "y_mm", "z_mm", "r_deg", "arm", "work", "tool",
];
/// Fields a line may have before it is refused while being split.
const MAX_FIELDS: usize = 64;
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
    pub(super) fn new(line: usize, field: Option<&str>, message: impl Into<String>) -> FileError {
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
    /// The list as CSV: a byte order mark, the header, one point a line, CR LF line ends
    /// (`files::csv_style`).
    pub fn to_csv(&self) -> String {
        let mut out = String::with_capacity(CSV_HEADER.len() + 4 + 64 * self.len());
        out.push_str(BOM);
        // RMC axes' columns, as many as the point with the most (none: the plain header).
        let axes = self.iter().map(|p| p.axes.len()).max().unwrap_or(0);
        out.push_str(&header_line(axes));
        out.push_str(EOL);
        for p in self {
            push_csv_text(&mut out, &p.name);
            for v in p.pose {
                out.push(',');
                out.push_str(&Milli(v).to_string());
            }
            out.push(',');
            out.push_str(arm_word(p.arm));
            out.push_str(&format!(",{},{}", p.work, p.tool));
            for k in 0..axes {
                out.push(',');
                if let Some(v) = p.axes.get(k) {
                    out.push_str(&Milli(*v).to_string());
                }
            }
            out.push_str(EOL);
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
    COLUMNS
        .get(i)
        .copied()
        .or_else(|| AXIS_COLUMNS.get(i.checked_sub(COLUMNS.len())?).copied())
}

/// The optional RMC axes' columns after `tool`, in 0.001 position units (as decimals).
const AXIS_COLUMNS: [&str; crate::rmc::MAX_AXES] = [
    "axis1_pu", "axis2_pu", "axis3_pu", "axis4_pu", "axis5_pu", "axis6_pu", "axis7_pu", "axis8_pu",
];

/// The header of a file with `axes` RMC axes' columns.
fn header_line(axes: usize) -> String {
    (1..=axes).fold(CSV_HEADER.to_string(), |h, k| h + "," + axis_column(k))
}

/// The header name of RMC axis `k` (1-based).
fn axis_column(k: usize) -> &'static str {
    AXIS_COLUMNS
        .get(k.saturating_sub(1))
        .copied()
        .unwrap_or("axis_pu")
}

pub(super) fn not_utf8(bytes: &[u8], offset: usize) -> FileError {
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
    // A bad byte on the first line (the header, plain ASCII in every teach file) or a NUL
    // near the start: a binary file or another kind of file, not a field to fix.
    let head = bytes.get(..8192).unwrap_or(bytes);
    if line == 1 || head.contains(&0) {
        return FileError::new(
            line,
            None,
            format!(
                "this is not a teach list: it is not text (a binary file, or text in \
                 another encoding: bad byte at offset {offset}); save the list as UTF-8"
            ),
        );
    }
    FileError::new(
        line,
        column(col),
        format!("the file is not UTF-8 text (bad byte at offset {offset}); save it as UTF-8"),
    )
}

/// A file with more points than a list holds (`points` when counted).
pub(super) fn too_many(points: Option<usize>) -> FileError {
    let held = points.map_or(format!("more than {MAX_POINTS}"), |n| n.to_string());
    FileError::new(
        1,
        None,
        format!("the file holds {held} points; a list holds at most {MAX_POINTS}: split the file"),
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
            // Checked as the line is split: a line of a million commas stops here (a
            // few extra fields get the exact count from the point's check).
            if fields.len() > MAX_FIELDS {
                return Err(FileError::new(
                    start,
                    None,
                    format!(
                        "more than {MAX_FIELDS} fields on one line: this is not a teach list \
                         (its lines have 8 fields: {CSV_HEADER})"
                    ),
                ));
            }
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
    let mut header: Option<usize> = None;
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
        let Some(axes) = header else {
            header = Some(check_header(&record)?);
            continue;
        };
        let point = parse_point(&record, axes)?;
        if let Some(first) = names.get(&point.name) {
            return Err(FileError::new(
                record.line,
                Some("name"),
                format!("\"{}\" is already used on line {first}", shown(&point.name)),
            ));
        }
        if list.len() == MAX_POINTS {
            return Err(too_many(None));
        }
        names.insert(point.name.clone(), record.line);
        list.push_checked(point);
    }
    if header.is_none() {
        return Err(FileError::new(
            1,
            None,
            format!("the file is empty (a teach list starts with the line {CSV_HEADER})"),
        ));
    }
    Ok(list)
}

/// Checks the header; answers how many RMC axes' columns follow `tool` (0 to 8).
fn check_header(r: &Record) -> Result<usize, FileError> {
    let axes = r.fields.len().saturating_sub(COLUMNS.len());
    let wrong =
        (0..COLUMNS.len().max(r.fields.len())).find(|&i| match (r.fields.get(i), column(i)) {
            (Some(found), Some(want)) => !found.trim().eq_ignore_ascii_case(want),
            _ => true,
        });
    match wrong {
        None => Ok(axes),
        // A column after `tool` that is not the next RMC axis's: no one field to blame.
        Some(i) if i >= COLUMNS.len() => Err(FileError::new(
            r.line,
            None,
            format!(
                "the first line must be the header {CSV_HEADER}, optionally followed by \
                 RMC axes' columns axis1_pu, axis2_pu... (found \"{}\")",
                shown(&r.fields.join(","))
            ),
        )),
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

fn parse_point(r: &Record, axes: usize) -> Result<TeachPoint, FileError> {
    let n = r.fields.len();
    let expected = COLUMNS.len() + axes;
    if n < expected {
        return Err(FileError::new(
            r.line,
            column(n),
            format!(
                "missing column: the line has {n} fields, expected {expected} ({})",
                header_line(axes)
            ),
        ));
    }
    if n > expected {
        return Err(FileError::new(
            r.line,
            None,
            format!(
                "extra column: the line has {n} fields, expected {expected} ({}); \
                 a name with a comma must be in quotes",
                header_line(axes)
            ),
        ));
    }
    let f = |i: usize| r.fields.get(i).map(String::as_str).unwrap_or("");
    let at = |i: usize, message: String| FileError::new(r.line, column(i), message);
    let name = check_name(f(0)).map_err(|e| at(0, e.to_string()))?;
    let mut pose = [0i32; 4];
    for (i, slot) in pose.iter_mut().enumerate() {
        *slot = parse_milli(f(i + 1)).map_err(|m| at(i + 1, m))?;
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
    let work = parse_frame(f(6), "work", MAX_FRAME_NUMBER).map_err(|m| at(6, m))?;
    let tool = parse_frame(f(7), "tool", MAX_FRAME_NUMBER).map_err(|m| at(7, m))?;
    // The RMC axes' positions: the first columns filled, the rest empty.
    let mut axis_values = Vec::new();
    for i in COLUMNS.len()..expected {
        let text = f(i).trim();
        if text.is_empty() {
            continue;
        }
        if axis_values.len() + COLUMNS.len() != i {
            return Err(at(
                i,
                "an RMC axis after an empty one (fill the axes' columns from axis1_pu on)".into(),
            ));
        }
        axis_values.push(parse_milli(text).map_err(|m| at(i, m))?);
    }
    let point = TeachPoint {
        name,
        pose,
        arm,
        work,
        tool,
        axes: axis_values,
    };
    point
        .checked()
        .map_err(|e| FileError::new(r.line, e.field(), e.to_string()))
}

/// A decimal in mm or deg with at most 3 decimals, exactly to 0.001 units.
pub fn parse_milli(text: &str) -> Result<i32, String> {
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

#[cfg(test)]
#[path = "file_tests.rs"]
mod tests;
