//! Position table files: CSV (Excel-friendly) and JSON, read whole or refused.
//!
//! CSV, as the teach list's (`files::csv_style`: a byte order mark, CR LF, a header line),
//! one row a position, the cells as the table shows them (an empty cell: no value):
//!
//! ```text
//! No,Name,X mm,Y mm,Z mm,R deg,Axis 5 mm,Axis 6 mm,Arm,Speed mm/s,Accel G,Decel G
//! 12,"pick, left",300.000,-150.000,20.000,45.000,,,right,,0.30,0.30
//! ```
//!
//! Columns `Axis 7 mm`, `Axis 8 deg` and `Arm 2` (a second SCARA's) follow only when a
//! row has them, so that nothing the controller holds is lost on the way through a file.
//!
//! JSON, one position a line: `{"format": "xsel-positions 1", "positions": [{"number": 12,
//! "name": "pick", "x": 300.000, "y": -150.000, "z": 20.000, "r": 45.000, "arm": "right",
//! "speed": 0, "accel": 0.30, "decel": 0.30}]}` (mm / deg, exact decimals; absent axes
//! and arm systems left out).
//!
//! [`parse`] also loads the teach list's own files (CSV and JSON): their points go to
//! consecutive numbers from 1 in file order, names kept, the arm system from the point's.
//! Every cell goes through [`parse_cell`], the table's own check of a typed cell.

use std::collections::HashMap;
use std::fmt;

use serde::Deserialize;
use serde::de::IgnoredAny;
use serde_json::value::RawValue;

use super::{Column, arm_text, parse_cell};
use crate::files::csv_style::{BOM, EOL};
use crate::pendant::teach::{self, TeachList, TeachPoint};
use crate::protocol::{ArmSystem, Axis, MAX_POSITIONS_4_DIGIT, PositionRecord, RecordArm};

/// The largest file read (20,000 positions with every column and 32-character names fit
/// with room to spare, as CSV and as JSON).
pub const MAX_FILE_BYTES: u64 = 16 * 1024 * 1024;
/// The `format` of the JSON file.
pub const JSON_FORMAT: &str = "xsel-positions 1";
/// The most rows a file holds: the table's numbers.
const MAX_ROWS: usize = MAX_POSITIONS_4_DIGIT as usize;
/// Fields a CSV line may have before it is refused while being split.
const MAX_FIELDS: usize = 64;

/// Why a file did not load: the 1-based line and the column when known, and what is
/// wrong. Displays as `line 7, field "Y mm": `abc` is not a number`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FileError {
    pub line: Option<usize>,
    /// The CSV heading, or the JSON key.
    pub field: Option<String>,
    pub message: String,
}

impl FileError {
    pub(crate) fn at(line: usize, field: Option<&str>, message: impl Into<String>) -> FileError {
        FileError {
            line: Some(line),
            field: field.map(str::to_owned),
            message: message.into(),
        }
    }
}

impl fmt::Display for FileError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match (self.line, &self.field) {
            (Some(l), Some(c)) => write!(f, "line {l}, field \"{c}\": {}", self.message),
            (Some(l), None) => write!(f, "line {l}: {}", self.message),
            (None, Some(c)) => write!(f, "field \"{c}\": {}", self.message),
            (None, None) => f.write_str(&self.message),
        }
    }
}

impl std::error::Error for FileError {}

impl From<teach::file::FileError> for FileError {
    fn from(e: teach::file::FileError) -> FileError {
        FileError {
            line: Some(e.line),
            field: e.field,
            message: format!("teach list: {}", e.message),
        }
    }
}

// ---- the columns ----

/// A column of the file besides No. and Name: one of the table's, or a second SCARA's.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Cell {
    Table(Column),
    Arm2,
}

/// The table's columns and, after them, the optional ones (present only when used).
const REQUIRED: usize = Column::ALL.len();
const CELLS: [Cell; REQUIRED + 3] = [
    Cell::Table(Column::ALL[0]),
    Cell::Table(Column::ALL[1]),
    Cell::Table(Column::ALL[2]),
    Cell::Table(Column::ALL[3]),
    Cell::Table(Column::ALL[4]),
    Cell::Table(Column::ALL[5]),
    Cell::Table(Column::ALL[6]),
    Cell::Table(Column::ALL[7]),
    Cell::Table(Column::ALL[8]),
    Cell::Table(Column::ALL[9]),
    Cell::Table(Column::Axis(Axis::A7)),
    Cell::Table(Column::Axis(Axis::A8)),
    Cell::Arm2,
];

impl Cell {
    fn heading(self) -> &'static str {
        match self {
            Cell::Table(Column::Axis(Axis::A7)) => "Axis 7 mm",
            Cell::Table(Column::Axis(Axis::A8)) => "Axis 8 deg",
            Cell::Table(c) => c.heading(),
            Cell::Arm2 => "Arm 2",
        }
    }

    fn key(self) -> &'static str {
        match self {
            Cell::Table(Column::Axis(a)) => {
                ["x", "y", "z", "r", "axis5", "axis6", "axis7", "axis8"][a.index()]
            }
            Cell::Table(Column::Arm) => "arm",
            Cell::Table(Column::Speed) => "speed",
            Cell::Table(Column::Accel) => "accel",
            Cell::Table(Column::Decel) => "decel",
            Cell::Arm2 => "arm2",
        }
    }

    /// The cell's text for `rec` (empty: no value).
    fn text(self, rec: &PositionRecord) -> String {
        match self {
            Cell::Table(c) => c.text(rec),
            Cell::Arm2 => arm_text(rec.arms.scara2).to_owned(),
        }
    }

    /// Whether `rec` has a value in an optional column.
    fn used_by(self, rec: &PositionRecord) -> bool {
        match self {
            Cell::Table(Column::Axis(a)) => rec.coords.get(a).is_some(),
            Cell::Arm2 => rec.arms.scara2 != RecordArm::Unspecified,
            Cell::Table(_) => true,
        }
    }

    /// Reads `text` into `rec` with the table's rules for a typed cell.
    fn parse(self, rec: &mut PositionRecord, text: &str) -> Result<(), String> {
        match self {
            Cell::Table(c) => parse_cell(rec, c, text),
            Cell::Arm2 => {
                let mut scratch = PositionRecord::default();
                parse_cell(&mut scratch, Column::Arm, text)?;
                rec.arms.scara2 = scratch.arms.scara1;
                Ok(())
            }
        }
    }
}

const NO: &str = "No";
const NAME: &str = "Name";

/// The optional columns any of `rows` uses.
fn optional_cells(rows: &[(PositionRecord, Option<String>)]) -> Vec<Cell> {
    CELLS[REQUIRED..]
        .iter()
        .copied()
        .filter(|c| rows.iter().any(|(r, _)| c.used_by(r)))
        .collect()
}

// ---- writing ----

/// The rows as CSV: a byte order mark, the header, one row a position, CR LF.
pub fn to_csv(rows: &[(PositionRecord, Option<String>)]) -> String {
    let cells: Vec<Cell> = CELLS[..REQUIRED]
        .iter()
        .copied()
        .chain(optional_cells(rows))
        .collect();
    let mut out = String::with_capacity(128 * (rows.len() + 1));
    out.push_str(BOM);
    out.push_str(NO);
    out.push(',');
    out.push_str(NAME);
    for c in &cells {
        out.push(',');
        out.push_str(c.heading());
    }
    out.push_str(EOL);
    for (rec, name) in rows {
        out.push_str(&rec.number.to_string());
        out.push(',');
        let name = name.as_deref().unwrap_or("");
        if name.contains([',', '"', '\r', '\n', ';']) {
            out.push('"');
            out.push_str(&name.replace('"', "\"\""));
            out.push('"');
        } else {
            out.push_str(name);
        }
        for c in &cells {
            out.push(',');
            out.push_str(&c.text(rec));
        }
        out.push_str(EOL);
    }
    out
}

/// The rows as JSON, one position a line, values as exact decimals.
pub fn to_json(rows: &[(PositionRecord, Option<String>)]) -> String {
    let mut out = format!("{{\n  \"format\": \"{JSON_FORMAT}\",\n  \"positions\": [");
    for (i, (rec, name)) in rows.iter().enumerate() {
        out.push_str(if i == 0 { "\n    {" } else { ",\n    {" });
        out.push_str(&format!("\"number\": {}", rec.number));
        if let Some(name) = name {
            // A string always serialises.
            let quoted = serde_json::to_string(name).unwrap_or_default();
            out.push_str(&format!(", \"name\": {quoted}"));
        }
        for c in CELLS {
            let text = c.text(rec);
            match c {
                Cell::Table(Column::Axis(_)) | Cell::Table(Column::Arm) | Cell::Arm2
                    if text.is_empty() => {}
                Cell::Table(Column::Axis(_)) => out.push_str(&format!(", \"{}\": {text}", c.key())),
                Cell::Table(Column::Arm) | Cell::Arm2 => {
                    out.push_str(&format!(", \"{}\": \"{text}\"", c.key()))
                }
                Cell::Table(Column::Speed) => {
                    out.push_str(&format!(", \"speed\": {}", rec.speed.0))
                }
                Cell::Table(Column::Accel | Column::Decel) => {
                    let v = if c == Cell::Table(Column::Accel) {
                        rec.accel.0
                    } else {
                        rec.decel.0
                    };
                    out.push_str(&format!(", \"{}\": {}.{:02}", c.key(), v / 100, v % 100));
                }
            }
        }
        out.push('}');
    }
    out.push_str(if rows.is_empty() {
        "]\n}\n"
    } else {
        "\n  ]\n}\n"
    });
    out
}

// ---- reading ----

/// The rows of a position table file (CSV or JSON, told apart by the first character),
/// or of a teach-list file; the first thing wrong with it, naming line and field.
pub fn parse(bytes: &[u8]) -> Result<Vec<(PositionRecord, Option<String>)>, FileError> {
    let text = text_of(bytes, MAX_FILE_BYTES, "a position table file")?;
    match text.trim_start().chars().next() {
        None => Err(FileError::at(
            1,
            None,
            "the file is empty (a position table file starts with its header line)",
        )),
        Some('{' | '[') => parse_json(text, bytes),
        Some(_) => parse_csv(text, bytes),
    }
}

/// The lines of a CSV text that are not blank, numbered from 1, without CR LF.
pub(crate) fn csv_lines(text: &str) -> impl Iterator<Item = (usize, &str)> {
    text.split('\n')
        .map(|l| l.strip_suffix('\r').unwrap_or(l))
        .enumerate()
        .map(|(i, l)| (i + 1, l))
        .filter(|(_, l)| !l.trim().is_empty())
}

/// The text of a file of the pendant's (`what`, at most `max` bytes): UTF-8 with or
/// without a byte order mark, refused when too big or binary.
pub(crate) fn text_of<'a>(bytes: &'a [u8], max: u64, what: &str) -> Result<&'a str, FileError> {
    if bytes.len() as u64 > max {
        return Err(FileError {
            line: None,
            field: None,
            message: format!(
                "the file is {} bytes; {what} holds at most {} MB",
                bytes.len(),
                max / (1024 * 1024)
            ),
        });
    }
    // A NUL near the start: a binary file, even where its bytes happen to be UTF-8.
    if let Some(nul) = bytes.iter().take(8192).position(|&b| b == 0) {
        return Err(not_text(bytes, nul, what));
    }
    let text = std::str::from_utf8(bytes).map_err(|e| not_text(bytes, e.valid_up_to(), what))?;
    Ok(text.strip_prefix('\u{feff}').unwrap_or(text))
}

/// Bytes that are not UTF-8: a binary file, or text in another encoding.
fn not_text(bytes: &[u8], offset: usize, what: &str) -> FileError {
    let before = bytes.get(..offset).unwrap_or(bytes);
    let line = 1 + before.iter().filter(|&&b| b == b'\n').count();
    let head = bytes.get(..8192).unwrap_or(bytes);
    let message = if line == 1 || head.contains(&0) {
        format!(
            "this is not {what}: it is not text (a binary file, or text in another \
             encoding: bad byte at offset {offset})"
        )
    } else {
        format!("the file is not UTF-8 text (bad byte at offset {offset}); save it as UTF-8")
    };
    FileError::at(line, None, message)
}

/// At most 40 characters of `text`, for messages.
fn shown(text: &str) -> String {
    let mut s: String = text.chars().take(40).collect();
    if s.len() < text.len() {
        s.push('…');
    }
    s
}

/// Checks a row's number, name and coordinates, and that its number is new.
struct Rows {
    rows: Vec<(PositionRecord, Option<String>)>,
    first_line: HashMap<u16, usize>,
}

impl Rows {
    fn new() -> Rows {
        Rows {
            rows: Vec::new(),
            first_line: HashMap::new(),
        }
    }

    fn number(text: &str) -> Result<u16, String> {
        let t = text.trim();
        let bad = || {
            format!(
                "`{}` is not a position number (a whole number from 1 to {MAX_POSITIONS_4_DIGIT})",
                shown(t)
            )
        };
        if t.is_empty() || !t.bytes().all(|b| b.is_ascii_digit()) {
            return Err(bad());
        }
        match t.parse::<u32>() {
            Ok(n) if (1..=u32::from(MAX_POSITIONS_4_DIGIT)).contains(&n) => Ok(n as u16),
            _ => Err(bad()),
        }
    }

    fn name(text: &str) -> Result<Option<String>, String> {
        if text.trim().is_empty() {
            return Ok(None);
        }
        teach::check_name(text).map(Some).map_err(|e| e.to_string())
    }

    /// Adds a row read on `line`; `no` and `name` are the fields to blame.
    fn push(
        &mut self,
        line: usize,
        no: &str,
        rec: PositionRecord,
        name: Option<String>,
    ) -> Result<(), FileError> {
        if let Some(first) = self.first_line.get(&rec.number) {
            return Err(FileError::at(
                line,
                Some(no),
                format!("No. {} is already on line {first}", rec.number),
            ));
        }
        if rec.coords.is_empty() {
            return Err(FileError::at(
                line,
                None,
                format!(
                    "No. {} has no coordinate (a position needs at least one)",
                    rec.number
                ),
            ));
        }
        if self.rows.len() == MAX_ROWS {
            return Err(FileError::at(
                line,
                None,
                format!("more than {MAX_ROWS} rows: the table has {MAX_ROWS} numbers"),
            ));
        }
        self.first_line.insert(rec.number, line);
        self.rows.push((rec, name));
        Ok(())
    }
}

// ---- CSV ----

/// Splits one line into fields (RFC 4180 quotes; a field cannot span lines: names hold no
/// line break). `headings` names the fields for errors.
pub(crate) fn split_line(
    line: &str,
    n: usize,
    headings: &[&str],
) -> Result<Vec<String>, FileError> {
    let mut fields = Vec::new();
    let mut it = line.chars().peekable();
    loop {
        let col = headings.get(fields.len()).copied();
        let mut field = String::new();
        if it.peek() == Some(&'"') {
            it.next();
            loop {
                match it.next() {
                    None => {
                        return Err(FileError::at(
                            n,
                            col,
                            "the quote opened here is never closed",
                        ));
                    }
                    Some('"') if it.next_if_eq(&'"').is_some() => field.push('"'),
                    Some('"') => break,
                    Some(c) => field.push(c),
                }
            }
            if !matches!(it.peek(), None | Some(',')) {
                return Err(FileError::at(
                    n,
                    col,
                    "text after the closing quote (put the whole field in quotes)",
                ));
            }
        } else {
            while let Some(c) = it.next_if(|&c| c != ',') {
                if c == '"' {
                    return Err(FileError::at(
                        n,
                        col,
                        "a quote inside a field that does not start with one (quote the \
                         whole field and double the quote: \"a \"\"b\"\"\")",
                    ));
                }
                field.push(c);
            }
        }
        fields.push(field);
        if fields.len() > MAX_FIELDS {
            return Err(FileError::at(
                n,
                None,
                format!("more than {MAX_FIELDS} fields on one line: this is not a position table"),
            ));
        }
        if it.next().is_none() {
            return Ok(fields);
        }
    }
}

fn header_text() -> String {
    let mut h = format!("{NO},{NAME}");
    for c in &CELLS[..REQUIRED] {
        h.push(',');
        h.push_str(c.heading());
    }
    h
}

/// The header's cells after No. and Name; refuses a header that is not the table's.
fn check_header(fields: &[String], n: usize) -> Result<Vec<Cell>, FileError> {
    let expected = header_text();
    let found = || shown(&fields.join(","));
    if fields.len() == 1 && fields[0].contains(';') {
        return Err(FileError::at(
            n,
            None,
            format!(
                "the columns are separated by ';' (\"{}\"): save the file as CSV with commas \
                 and decimal points (the header is {expected})",
                found()
            ),
        ));
    }
    let mut cells = Vec::new();
    for (i, f) in fields.iter().enumerate() {
        let f = f.trim();
        let ok = match i {
            0 => f.eq_ignore_ascii_case(NO) || f.eq_ignore_ascii_case("No."),
            1 => f.eq_ignore_ascii_case(NAME),
            _ if i < REQUIRED + 2 => {
                let c = CELLS[i - 2];
                cells.push(c);
                f.eq_ignore_ascii_case(c.heading())
            }
            _ => match CELLS[REQUIRED..]
                .iter()
                .find(|c| f.eq_ignore_ascii_case(c.heading()))
            {
                Some(c) if !cells.contains(c) => {
                    cells.push(*c);
                    true
                }
                _ => false,
            },
        };
        if !ok {
            return Err(FileError::at(
                n,
                None,
                format!(
                    "column {} of the header is \"{}\": the first line must be the header \
                     {expected} (optionally followed by Axis 7 mm, Axis 8 deg, Arm 2)",
                    i + 1,
                    shown(f)
                ),
            ));
        }
    }
    if fields.len() < REQUIRED + 2 {
        return Err(FileError::at(
            n,
            None,
            format!(
                "the header has {} columns, not {}: the first line must be the header {expected}",
                fields.len(),
                REQUIRED + 2
            ),
        ));
    }
    Ok(cells)
}

fn parse_csv(text: &str, bytes: &[u8]) -> Result<Vec<(PositionRecord, Option<String>)>, FileError> {
    let mut lines = csv_lines(text);
    let Some((first, header)) = lines.next() else {
        return Err(FileError::at(1, None, "the file is empty"));
    };
    let fields = split_line(header, first, &[])?;
    if fields
        .first()
        .is_some_and(|f| f.trim().eq_ignore_ascii_case("name"))
    {
        return from_teach(TeachList::from_csv_bytes(bytes)?);
    }
    let cells = check_header(&fields, first)?;
    let headings: Vec<&str> = [NO, NAME]
        .into_iter()
        .chain(cells.iter().map(|c| c.heading()))
        .collect();
    let mut rows = Rows::new();
    for (n, line) in lines {
        let fields = split_line(line, n, &headings)?;
        // Excel writes a cleared row as commas only.
        if fields.iter().all(|f| f.trim().is_empty()) {
            continue;
        }
        if fields.len() != headings.len() {
            return Err(FileError::at(
                n,
                None,
                format!(
                    "the line has {} fields, the header {} (a name with a comma must be in quotes)",
                    fields.len(),
                    headings.len()
                ),
            ));
        }
        let number = Rows::number(&fields[0]).map_err(|m| FileError::at(n, Some(NO), m))?;
        let name = Rows::name(&fields[1]).map_err(|m| FileError::at(n, Some(NAME), m))?;
        let mut rec = PositionRecord {
            number,
            ..PositionRecord::default()
        };
        for (c, text) in cells.iter().zip(&fields[2..]) {
            c.parse(&mut rec, text)
                .map_err(|m| FileError::at(n, Some(c.heading()), m))?;
        }
        rows.push(n, NO, rec, name)?;
    }
    Ok(rows.rows)
}

// ---- JSON ----

/// The top level: a position table (`positions`) or a teach list (`points`).
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawDoc<'a> {
    #[serde(default)]
    format: Option<String>,
    #[serde(borrow, default)]
    positions: Option<Vec<&'a RawValue>>,
    #[serde(default)]
    points: Option<IgnoredAny>,
}

/// One position, each value kept as its text.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawEntry<'a> {
    #[serde(borrow)]
    number: Option<&'a RawValue>,
    #[serde(borrow, default)]
    name: Option<&'a RawValue>,
    #[serde(borrow, default)]
    x: Option<&'a RawValue>,
    #[serde(borrow, default)]
    y: Option<&'a RawValue>,
    #[serde(borrow, default)]
    z: Option<&'a RawValue>,
    #[serde(borrow, default)]
    r: Option<&'a RawValue>,
    #[serde(borrow, default)]
    axis5: Option<&'a RawValue>,
    #[serde(borrow, default)]
    axis6: Option<&'a RawValue>,
    #[serde(borrow, default)]
    axis7: Option<&'a RawValue>,
    #[serde(borrow, default)]
    axis8: Option<&'a RawValue>,
    #[serde(borrow, default)]
    arm: Option<&'a RawValue>,
    #[serde(borrow, default)]
    arm2: Option<&'a RawValue>,
    #[serde(borrow, default)]
    speed: Option<&'a RawValue>,
    #[serde(borrow, default)]
    accel: Option<&'a RawValue>,
    #[serde(borrow, default)]
    decel: Option<&'a RawValue>,
}

impl<'a> RawEntry<'a> {
    fn value(&self, c: Cell) -> Option<&'a RawValue> {
        match c.key() {
            "x" => self.x,
            "y" => self.y,
            "z" => self.z,
            "r" => self.r,
            "axis5" => self.axis5,
            "axis6" => self.axis6,
            "axis7" => self.axis7,
            "axis8" => self.axis8,
            "arm" => self.arm,
            "arm2" => self.arm2,
            "speed" => self.speed,
            "accel" => self.accel,
            _ => self.decel,
        }
    }
}

/// Line numbers of offsets into one text.
struct Lines(Vec<usize>);

impl Lines {
    fn of(text: &str) -> Lines {
        Lines(memchr::memchr_iter(b'\n', text.as_bytes()).collect())
    }

    /// The 1-based line of `part`, a slice of `text`.
    fn line(&self, text: &str, part: &str) -> usize {
        let offset = (part.as_ptr() as usize).saturating_sub(text.as_ptr() as usize);
        1 + self.0.partition_point(|&p| p < offset)
    }
}

/// A serde_json error in text that starts on 1-based `line` of the file.
fn json_error(e: &serde_json::Error, line: usize) -> FileError {
    let full = e.to_string();
    let suffix = format!(" at line {} column {}", e.line(), e.column());
    let msg = full
        .strip_suffix(&suffix)
        .unwrap_or(&full)
        .replace(
            "struct RawDoc",
            "a position table file ({\"format\": ..., \"positions\": [...]})",
        )
        .replace(
            "struct RawEntry",
            "a position ({\"number\": ..., \"x\": ...})",
        );
    let msg = if e.is_eof() {
        format!("{msg}: the file ends too early (cut short?)")
    } else {
        msg.to_owned()
    };
    FileError::at(line + e.line().saturating_sub(1), None, msg)
}

fn parse_json(
    text: &str,
    bytes: &[u8],
) -> Result<Vec<(PositionRecord, Option<String>)>, FileError> {
    let doc: RawDoc = serde_json::from_str(text).map_err(|e| json_error(&e, 1))?;
    let lines = Lines::of(text);
    let Some(positions) = doc.positions else {
        if doc.points.is_some() && doc.format.is_none() {
            return from_teach(TeachList::from_json_bytes(bytes)?);
        }
        return Err(FileError::at(
            1,
            Some("positions"),
            format!(
                "missing: this is not a position table file ({{\"format\": \"{JSON_FORMAT}\", \"positions\": [...]}})"
            ),
        ));
    };
    if doc.points.is_some() {
        return Err(FileError::at(
            1,
            Some("points"),
            "a position table file has positions, not points",
        ));
    }
    if let Some(f) = doc.format.as_deref().filter(|f| *f != JSON_FORMAT) {
        return Err(FileError::at(
            1,
            Some("format"),
            format!("\"{}\" is not \"{JSON_FORMAT}\"", shown(f)),
        ));
    }
    if positions.len() > MAX_ROWS {
        return Err(FileError::at(
            1,
            Some("positions"),
            format!(
                "{} positions: the table has {MAX_ROWS} numbers",
                positions.len()
            ),
        ));
    }
    let mut rows = Rows::new();
    for raw in positions {
        let line = lines.line(text, raw.get());
        let e: RawEntry = serde_json::from_str(raw.get()).map_err(|e| json_error(&e, line))?;
        let at = |v: &RawValue| lines.line(text, v.get());
        let Some(number) = e.number else {
            return Err(FileError::at(line, Some("number"), "missing"));
        };
        let number =
            Rows::number(number.get()).map_err(|m| FileError::at(at(number), Some("number"), m))?;
        let name = match e.name.filter(|v| v.get() != "null") {
            None => None,
            Some(v) => {
                let s: String = serde_json::from_str(v.get()).map_err(|_| {
                    FileError::at(
                        at(v),
                        Some("name"),
                        format!("`{}` is not text", shown(v.get())),
                    )
                })?;
                Rows::name(&s).map_err(|m| FileError::at(at(v), Some("name"), m))?
            }
        };
        let mut rec = PositionRecord {
            number,
            ..PositionRecord::default()
        };
        for c in CELLS {
            let Some(v) = e.value(c).filter(|v| v.get() != "null") else {
                continue;
            };
            let raw = v.get();
            let is_text = raw.starts_with('"');
            let want_text = matches!(c, Cell::Table(Column::Arm) | Cell::Arm2);
            let cell = if want_text && is_text {
                serde_json::from_str::<String>(raw).unwrap_or_default()
            } else if !want_text && !is_text {
                raw.to_owned()
            } else {
                let what = if want_text { "text" } else { "a number" };
                return Err(FileError::at(
                    at(v),
                    Some(c.key()),
                    format!("`{}` is not {what}", shown(raw)),
                ));
            };
            c.parse(&mut rec, &cell)
                .map_err(|m| FileError::at(at(v), Some(c.key()), m))?;
        }
        rows.push(line, "number", rec, name)?;
    }
    Ok(rows.rows)
}

// ---- teach-list files ----

/// A teach list's points as rows at 1, 2, 3... in list order: names kept, X Y Z R and the
/// arm system taken over (work and tool frames and RMC axes have no place in the table).
fn from_teach(list: TeachList) -> Result<Vec<(PositionRecord, Option<String>)>, FileError> {
    if list.len() > MAX_ROWS {
        return Err(FileError::at(
            1,
            None,
            format!("{} points: the table has {MAX_ROWS} numbers", list.len()),
        ));
    }
    Ok(list
        .iter()
        .zip(1u16..)
        .map(|(p, n)| (teach_record(p, n), Some(p.name.clone())))
        .collect())
}

fn teach_record(p: &TeachPoint, number: u16) -> PositionRecord {
    let arm = match p.arm {
        ArmSystem::Right => RecordArm::Right,
        ArmSystem::Left => RecordArm::Left,
        ArmSystem::Undetermined => RecordArm::Unspecified,
    };
    super::record_of_pose(number, p.pose, arm)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::protocol::{CentiG, Milli, MmPerSec, PerAxis, RecordArms};
    use proptest::prelude::*;

    fn rec(number: u16, coords: &[(Axis, i32)]) -> PositionRecord {
        PositionRecord {
            number,
            coords: PerAxis::from_pairs(coords.iter().map(|&(a, v)| (a, Milli(v)))),
            ..PositionRecord::default()
        }
    }

    fn hand_rows() -> Vec<(PositionRecord, Option<String>)> {
        let full = PositionRecord {
            number: 20_000,
            coords: PerAxis::from_pairs(
                [Axis::A1, Axis::A2, Axis::A3, Axis::A4, Axis::A5, Axis::A6]
                    .into_iter()
                    .zip([-99_999_999, 99_999_999, -1, 0, 1, -1000].map(Milli)),
            ),
            accel: CentiG(65_535),
            decel: CentiG(1),
            speed: MmPerSec(65_535),
            arms: RecordArms {
                scara1: RecordArm::Left,
                scara2: RecordArm::Unspecified,
            },
        };
        vec![
            (
                rec(12, &[(Axis::A1, 300_000), (Axis::A2, -150_000)]),
                Some("pick".into()),
            ),
            (rec(1, &[(Axis::A3, -1)]), None),
            (full, Some("a, \"quoted\" name; with ü and 漢字".into())),
            (rec(7, &[(Axis::A6, 5)]), Some("=1+1".into())),
        ]
    }

    fn assert_round_trips(rows: &[(PositionRecord, Option<String>)]) {
        let csv = to_csv(rows);
        assert_eq!(parse(csv.as_bytes()).as_deref(), Ok(rows), "{csv}");
        let json = to_json(rows);
        assert_eq!(parse(json.as_bytes()).as_deref(), Ok(rows), "{json}");
    }

    #[test]
    fn hand_rows_round_trip_through_csv_and_json() {
        assert_round_trips(&hand_rows());
        assert_round_trips(&[]);
        let mut second = rec(3, &[(Axis::A7, -7), (Axis::A8, 8)]);
        second.arms.scara2 = RecordArm::Right;
        assert_round_trips(&[(second, None)]);
    }

    #[test]
    fn csv_is_excel_friendly_and_json_is_a_line_a_position() {
        let rows = hand_rows();
        let csv = to_csv(&rows);
        assert!(csv.starts_with(
            "\u{feff}No,Name,X mm,Y mm,Z mm,R deg,Axis 5 mm,Axis 6 mm,Arm,Speed mm/s,Accel G,Decel G\r\n"
        ));
        assert!(
            csv.contains("\r\n12,pick,300.000,-150.000,,,,,,,,\r\n"),
            "{csv}"
        );
        assert!(csv.contains("\"a, \"\"quoted\"\" name; with ü and 漢字\""));
        assert!(!csv.replace("\r\n", "").contains('\n'));
        let json = to_json(&rows);
        assert!(json.contains(
            "{\"number\": 12, \"name\": \"pick\", \"x\": 300.000, \"y\": -150.000, \"speed\": 0, \"accel\": 0.00, \"decel\": 0.00}"
        ), "{json}");
        assert!(
            json.contains(
                "\"arm\": \"left\", \"speed\": 65535, \"accel\": 655.35, \"decel\": 0.01"
            )
        );
        let v: serde_json::Value = serde_json::from_str(&json).unwrap();
        assert_eq!(v["format"], JSON_FORMAT);
        assert_eq!(v["positions"][0]["x"], 300.0);
    }

    #[test]
    fn hand_written_files_load_with_the_cells_rules() {
        let csv = "No,Name,X mm,Y mm,Z mm,R deg,Axis 5 mm,Axis 6 mm,Arm,Speed mm/s,Accel G,Decel G\n\
                   5, spaced ,+1.5, -0.001 ,,,,,R,100,0.3,\n\
                   ,,,,,,,,,,,\n";
        let rows = parse(csv.as_bytes()).unwrap();
        let mut want = rec(5, &[(Axis::A1, 1500), (Axis::A2, -1)]);
        want.arms.scara1 = RecordArm::Right;
        want.speed = MmPerSec(100);
        want.accel = CentiG(30);
        assert_eq!(rows, vec![(want, Some("spaced".into()))]);
        let json = r#"{"positions": [{"number": 5, "name": "spaced", "x": 1.5, "y": -0.001, "axis5": null, "arm": "right", "speed": 100, "accel": 0.3}]}"#;
        assert_eq!(parse(json.as_bytes()).unwrap(), rows);
    }

    fn err(file: &str) -> FileError {
        parse(file.as_bytes()).expect_err("refused")
    }

    const HEAD: &str =
        "No,Name,X mm,Y mm,Z mm,R deg,Axis 5 mm,Axis 6 mm,Arm,Speed mm/s,Accel G,Decel G\r\n";

    #[test]
    fn csv_errors_name_line_and_field() {
        let e = err(&format!("{HEAD}1,,1,2,,,,,,,,\r\n2,,1,abc,,,,,,,,\r\n"));
        assert_eq!(
            e.to_string(),
            "line 3, field \"Y mm\": \"abc\" is not a number (use a dot, 3 decimals at most)"
        );
        let e = err(&format!("{HEAD}1,,1.2345,,,,,,,,,\r\n"));
        assert_eq!((e.line, e.field.as_deref()), (Some(2), Some("X mm")));
        assert!(e.message.contains("3 decimals"), "{e}");
        let e = err(&format!("{HEAD}1,,1,,,,,,,,0.301,\r\n"));
        assert_eq!((e.line, e.field.as_deref()), (Some(2), Some("Accel G")));
        let e = err(&format!("{HEAD}9,,1,,,,,,,,,\r\n\r\n9,,2,,,,,,,,,\r\n"));
        assert_eq!(
            e.to_string(),
            "line 4, field \"No\": No. 9 is already on line 2"
        );
        for n in ["0", "20001", "-1", "1.0", "x"] {
            let e = err(&format!("{HEAD}{n},,1,,,,,,,,,\r\n"));
            assert_eq!((e.line, e.field.as_deref()), (Some(2), Some("No")), "{n}");
            assert!(e.message.contains("1 to 20000"), "{e}");
        }
        let e = err(&format!("{HEAD}4,name,,,,,,,right,,,\r\n"));
        assert_eq!(e.line, Some(2));
        assert!(e.message.contains("no coordinate"), "{e}");
        let long = "n".repeat(teach::MAX_NAME_CHARS + 1);
        let e = err(&format!("{HEAD}4,{long},1,,,,,,,,,\r\n"));
        assert_eq!((e.line, e.field.as_deref()), (Some(2), Some("Name")));
        let e = err(&format!("{HEAD}4,\"a\tb\",1,,,,,,,,,\r\n"));
        assert!(e.message.contains("control"), "{e}");
        let e = err(&format!("{HEAD}4,,1,,,,,,up,,,\r\n"));
        assert_eq!(e.field.as_deref(), Some("Arm"));
        let e = err(&format!("{HEAD}4,a,b,1,,,,,,,,,\r\n"));
        assert!(e.message.contains("13 fields"), "{e}");
        let e = err(&format!("{HEAD}4,\"open,1,,,,,,,,,\r\n"));
        assert_eq!((e.line, e.field.as_deref()), (Some(2), Some("Name")));
        let e = err("No;Name;X mm\r\n1;;1,5\r\n");
        assert!(e.message.contains("';'"), "{e}");
        let e = err("No,Name,X mm\r\n");
        assert_eq!(e.line, Some(1));
        assert!(err("").message.contains("empty"));
    }

    #[test]
    fn json_errors_name_line_and_field() {
        let file = "{\"format\": \"xsel-positions 1\", \"positions\": [\n  {\"number\": 1, \"x\": 1},\n  {\"number\": 2,\n   \"y\": 1.0001}\n]}";
        let e = err(file);
        assert_eq!((e.line, e.field.as_deref()), (Some(4), Some("y")), "{e}");
        let e = err(&file.replace("1.0001", "\"abc\""));
        assert_eq!(
            e.to_string(),
            "line 4, field \"y\": `\"abc\"` is not a number"
        );
        let good = file.replace("1.0001", "1.5");
        assert_eq!(parse(good.as_bytes()).map(|r| r.len()), Ok(2));
        let e = err(&good.replace("\"number\": 2", "\"number\": 1"));
        assert_eq!(
            (e.line, e.field.as_deref()),
            (Some(3), Some("number")),
            "{e}"
        );
        for n in ["0", "20001", "1.5", "\"3\""] {
            let e = err(&good.replace("\"number\": 2", &format!("\"number\": {n}")));
            assert_eq!(
                (e.line, e.field.as_deref()),
                (Some(3), Some("number")),
                "{n}"
            );
        }
        let e = err(&good.replace("\"x\": 1", "\"q\": 1"));
        assert_eq!(e.line, Some(2));
        assert!(e.message.contains("unknown field"), "{e}");
        let e = err(&file[..file.len() - 10]);
        assert!(e.message.contains("cut short"), "{e}");
        assert!(e.line.is_some());
        let e = err(&file.replace("xsel-positions 1", "xsel-positions 9"));
        assert_eq!(e.field.as_deref(), Some("format"));
        let e = err("[]");
        assert!(e.message.contains("position table file ({"), "{e}");
        let e = err("{\"positions\": [7]}");
        assert!(e.message.contains("a position ({"), "{e}");
        let e = err("{\"format\": \"xsel-positions 1\"}");
        assert_eq!(e.field.as_deref(), Some("positions"));
        let e = err("{\"positions\": [{\"number\": 3, \"arm\": \"right\"}]}");
        assert!(e.message.contains("no coordinate"), "{e}");
    }

    #[test]
    fn binary_junk_and_too_big_files_are_refused() {
        let junk: Vec<u8> = (0..=255u8).cycle().take(4096).collect();
        let e = parse(&junk).unwrap_err();
        assert!(e.message.contains("not text"), "{e}");
        let e = parse(b"\x7fELF\x02\x01\x01\0\0\0").unwrap_err();
        assert!(e.line.is_some(), "{e}");
        let big = vec![b' '; MAX_FILE_BYTES as usize + 1];
        let e = parse(&big).unwrap_err();
        assert_eq!(e.line, None);
        assert!(e.to_string().contains("at most 16 MB"), "{e}");
    }

    #[test]
    fn the_largest_table_fits_the_file_limit_and_more_rows_are_refused() {
        let name = "漢".repeat(teach::MAX_NAME_CHARS);
        let mut rows: Vec<_> = (1..=MAX_POSITIONS_4_DIGIT)
            .map(|n| {
                let mut r = hand_rows()[2].0;
                r.number = n;
                r.coords = PerAxis::from_pairs(
                    (1..=8).map(|k| (Axis::new(k).unwrap(), Milli(-99_999_999))),
                );
                r.arms.scara2 = RecordArm::Right;
                (r, Some(name.clone()))
            })
            .collect();
        let (csv, json) = (to_csv(&rows), to_json(&rows));
        assert!((json.len() as u64) < MAX_FILE_BYTES && (csv.len() as u64) < MAX_FILE_BYTES);
        assert_eq!(parse(csv.as_bytes()).unwrap().len(), rows.len());
        rows.push(rows[0].clone());
        let e = parse(to_csv(&rows).as_bytes()).unwrap_err();
        assert_eq!(e.line, Some(20_002));
        let many = format!(
            "{{\"positions\": [{}]}}",
            vec!["{}"; MAX_ROWS + 1].join(",")
        );
        let e = parse(many.as_bytes()).unwrap_err();
        assert!(e.message.contains("20001 positions"), "{e}");
    }

    #[test]
    fn teach_list_files_load_at_consecutive_numbers() {
        let csv = "name,x_mm,y_mm,z_mm,r_deg,arm,work,tool\r\n\
                   P1,300.000,-150.000,20.000,45.000,right,0,0\r\n\
                   \"pick, left\",12.345,-0.500,0.000,-90.000,left,1,2\r\n\
                   P3,1,2,3,4,undetermined,0,0\r\n";
        let rows = parse(csv.as_bytes()).unwrap();
        let want = vec![
            (
                super::super::record_of_pose(
                    1,
                    [300_000, -150_000, 20_000, 45_000],
                    RecordArm::Right,
                ),
                Some("P1".to_string()),
            ),
            (
                super::super::record_of_pose(2, [12_345, -500, 0, -90_000], RecordArm::Left),
                Some("pick, left".to_string()),
            ),
            (
                super::super::record_of_pose(3, [1000, 2000, 3000, 4000], RecordArm::Unspecified),
                Some("P3".to_string()),
            ),
        ];
        assert_eq!(rows, want);
        let list = TeachList::from_csv(csv).unwrap();
        assert_eq!(parse(list.to_json().as_bytes()).unwrap(), want);
        // The teach list's reader says what is wrong, with its line and field.
        let e = parse(csv.replace("-0.500", "-0.5x").as_bytes()).unwrap_err();
        assert_eq!((e.line, e.field.as_deref()), (Some(3), Some("y_mm")), "{e}");
        let e = parse(list.to_json().replace("\"P3\"", "\"P1\"").as_bytes()).unwrap_err();
        assert_eq!(e.field.as_deref(), Some("name"), "{e}");
    }

    fn arb_arm() -> impl Strategy<Value = RecordArm> {
        prop_oneof![
            Just(RecordArm::Unspecified),
            Just(RecordArm::Right),
            Just(RecordArm::Left)
        ]
    }

    fn arb_row() -> impl Strategy<Value = (PositionRecord, Option<String>)> {
        let coord = prop_oneof![
            Just(None),
            Just(Some(-99_999_999)),
            Just(Some(99_999_999)),
            Just(Some(-1)),
            (-1_000_000i32..1_000_000).prop_map(Some),
            (-99_999_999i32..=99_999_999).prop_map(Some),
        ];
        let name = proptest::option::of("[a-zA-Z0-9 ,;\"'ü漢=+-]{0,32}")
            .prop_map(|n| n.map(|s| s.trim().to_owned()).filter(|s| !s.is_empty()));
        (
            1..=MAX_POSITIONS_4_DIGIT,
            proptest::array::uniform8(coord),
            any::<u16>(),
            any::<u16>(),
            any::<u16>(),
            arb_arm(),
            arb_arm(),
            name,
        )
            .prop_filter("a coordinate", |(_, c, ..)| c.iter().any(Option::is_some))
            .prop_map(|(number, c, a, d, s, arm1, arm2, name)| {
                let coords = PerAxis::from_pairs(
                    (1..=8u8)
                        .zip(c)
                        .filter_map(|(k, v)| Some((Axis::new(k)?, Milli(v?)))),
                );
                let rec = PositionRecord {
                    number,
                    coords,
                    accel: CentiG(a),
                    decel: CentiG(d),
                    speed: MmPerSec(s),
                    arms: RecordArms {
                        scara1: arm1,
                        scara2: arm2,
                    },
                };
                (rec, name)
            })
    }

    proptest! {
        #[test]
        fn any_rows_round_trip_exactly(rows in proptest::collection::vec(arb_row(), 0..40)) {
            let mut seen = std::collections::HashSet::new();
            let rows: Vec<_> = rows.into_iter().filter(|(r, _)| seen.insert(r.number)).collect();
            prop_assert_eq!(parse(to_csv(&rows).as_bytes()), Ok(rows.clone()));
            prop_assert_eq!(parse(to_json(&rows).as_bytes()), Ok(rows));
        }
    }
}
