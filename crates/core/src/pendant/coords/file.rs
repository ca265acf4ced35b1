//! Coordinate-table files: CSV, JSON and the simulator's coordinate file (TOML, as
//! `xsel-sim --coords` reads it). Written exactly; read all or nothing, an error naming
//! the line and the field.
//!
//! CSV (a header line required; a BOM, CR LF and blank lines tolerated), values in mm /
//! deg with exactly 3 decimals; rows that were never read are not written:
//!
//! ```text
//! table,number,x_mm,y_mm,z_mm,r_deg
//! work,1,300.000,-100.000,0.000,30.000
//! tool,1,0.000,0.000,-35.000,0.000
//! ```
//!
//! JSON: `{"format": "xsel-pendant coords 1", "work": [{"number": 1, "x": 300000, "y":
//! -100000, "z": 0, "r": 30000}], "tool": [...]}`, values in wire units (0.001 mm /
//! 0.001 deg), so nothing is rounded.

use serde::{Deserialize, Serialize};
use serde_json::value::RawValue;

use super::cell::{self, Column};
use super::draft::Rows;
use crate::files::coords_file;
use crate::pendant::teach::file::FileError;
use crate::robot::{CoordSystem, CoordTables, FrameKind, RobotModel};

/// The CSV header line.
pub const CSV_HEADER: &str = "table,number,x_mm,y_mm,z_mm,r_deg";
const CSV_COLUMNS: [&str; 6] = ["table", "number", "x_mm", "y_mm", "z_mm", "r_deg"];
/// The `format` of the JSON file.
pub const JSON_FORMAT: &str = "xsel-pendant coords 1";

/// A file format for the tables.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TableFormat {
    Csv,
    Json,
    /// The simulator's coordinate file (`xsel-sim --coords`).
    SimToml,
}

impl TableFormat {
    /// The format a file name's extension names: `.csv`, `.json`, `.toml`.
    pub fn of_path(path: &str) -> Option<Self> {
        let ext = std::path::Path::new(path)
            .extension()?
            .to_str()?
            .to_ascii_lowercase();
        match ext.as_str() {
            "csv" => Some(Self::Csv),
            "json" => Some(Self::Json),
            "toml" => Some(Self::SimToml),
            _ => None,
        }
    }
}

/// The work and tool rows a file holds (`None` = not in the file).
#[derive(Clone, Debug, PartialEq)]
pub struct TablePair {
    pub work: Rows,
    pub tool: Rows,
}

impl TablePair {
    /// Unread tables of the model's sizes.
    pub fn empty(work: usize, tool: usize) -> Self {
        Self {
            work: vec![None; work],
            tool: vec![None; tool],
        }
    }

    fn rows_mut(&mut self, kind: FrameKind) -> &mut Rows {
        match kind {
            FrameKind::Work => &mut self.work,
            FrameKind::Tool => &mut self.tool,
        }
    }

    fn listed(&self) -> impl Iterator<Item = (FrameKind, usize, CoordSystem)> + '_ {
        let each = |kind, rows: &'_ Rows| {
            rows.iter()
                .enumerate()
                .filter_map(move |(n, r)| r.map(|cs| (kind, n, cs)))
                .collect::<Vec<_>>()
        };
        each(FrameKind::Work, &self.work)
            .into_iter()
            .chain(each(FrameKind::Tool, &self.tool))
    }

    /// The tables as the simulator takes them: rows never read are all zeros.
    pub fn to_coord_tables(&self) -> CoordTables {
        let mut t = CoordTables {
            work: crate::robot::CoordTable::new(FrameKind::Work, self.work.len()),
            tool: crate::robot::CoordTable::new(FrameKind::Tool, self.tool.len()),
        };
        for (kind, n, cs) in self.listed() {
            let table = match kind {
                FrameKind::Work => &mut t.work,
                FrameKind::Tool => &mut t.tool,
            };
            // Work No. 0 only ever holds zeros here (the draft keeps it so).
            let _ = table.set(n, cs);
        }
        t
    }
}

fn kind_word(kind: FrameKind) -> &'static str {
    match kind {
        FrameKind::Work => "work",
        FrameKind::Tool => "tool",
    }
}

// ---- CSV ----

/// The tables as CSV (header first, work rows then tool rows, LF line ends).
pub fn to_csv(tables: &TablePair) -> String {
    let mut out = String::from(CSV_HEADER);
    out.push('\n');
    for (kind, n, cs) in tables.listed() {
        out.push_str(kind_word(kind));
        out.push(',');
        out.push_str(&n.to_string());
        for v in cs.to_wire() {
            out.push(',');
            out.push_str(&cell::show(v));
        }
        out.push('\n');
    }
    out
}

/// Reads CSV bytes into tables of the given sizes; all or nothing.
pub fn from_csv(bytes: &[u8], work: usize, tool: usize) -> Result<TablePair, FileError> {
    let text = std::str::from_utf8(bytes).map_err(|e| not_utf8(bytes, e.valid_up_to()))?;
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let mut out = TablePair::empty(work, tool);
    let mut first_seen: std::collections::HashMap<(FrameKind, usize), usize> =
        std::collections::HashMap::new();
    let mut header = false;
    for (i, raw) in text.split('\n').enumerate() {
        let line = i + 1;
        let raw = raw.strip_suffix('\r').unwrap_or(raw);
        if raw.trim().is_empty() {
            continue;
        }
        let fields: Vec<&str> = raw.split(',').map(str::trim).collect();
        if !header {
            check_header(line, &fields)?;
            header = true;
            continue;
        }
        if let Some(extra) = fields.get(CSV_COLUMNS.len()) {
            return Err(err(
                line,
                None,
                format!(
                    "{} fields, the header has {} (extra \"{}\")",
                    fields.len(),
                    CSV_COLUMNS.len(),
                    shown(extra)
                ),
            ));
        }
        let field = |c: usize| {
            fields
                .get(c)
                .copied()
                .ok_or_else(|| err(line, Some(CSV_COLUMNS[c]), "missing (the row is short)"))
        };
        let kind = match field(0)?.to_ascii_lowercase().as_str() {
            "work" => FrameKind::Work,
            "tool" => FrameKind::Tool,
            other => {
                return Err(err(
                    line,
                    Some("table"),
                    format!("\"{}\" is not work or tool", shown(other)),
                ));
            }
        };
        let size = match kind {
            FrameKind::Work => work,
            FrameKind::Tool => tool,
        };
        let number =
            parse_number(field(1)?, kind, size).map_err(|m| err(line, Some("number"), m))?;
        if let Some(prev) = first_seen.insert((kind, number), line) {
            return Err(err(
                line,
                Some("number"),
                format!("{kind} No. {number} is listed twice (first on line {prev})"),
            ));
        }
        let mut w = [0; 4];
        for (c, column) in Column::ALL.into_iter().enumerate() {
            w[c] = cell::parse_entry(column, field(2 + c)?)
                .map_err(|m| err(line, Some(column.file_name()), m))?;
            if cell::read_only(kind, number) && w[c] != 0 {
                return Err(err(line, Some(column.file_name()), cell::READ_ONLY));
            }
        }
        out.rows_mut(kind)[number] = Some(CoordSystem::from_wire(w));
    }
    if !header {
        return Err(err(
            1,
            None,
            format!("the file is empty (expected the header \"{CSV_HEADER}\")"),
        ));
    }
    Ok(out)
}

fn check_header(line: usize, fields: &[&str]) -> Result<(), FileError> {
    for (i, name) in CSV_COLUMNS.iter().enumerate() {
        match fields.get(i) {
            Some(f) if f.eq_ignore_ascii_case(name) => {}
            Some(f) => {
                return Err(err(
                    line,
                    Some(name),
                    format!(
                        "the header has \"{}\" where \"{name}\" belongs (expected \"{CSV_HEADER}\")",
                        shown(f)
                    ),
                ));
            }
            None => {
                return Err(err(
                    line,
                    Some(name),
                    format!("column missing from the header (expected \"{CSV_HEADER}\")"),
                ));
            }
        }
    }
    if let Some(extra) = fields.get(CSV_COLUMNS.len()) {
        return Err(err(
            line,
            None,
            format!(
                "unknown column \"{}\" (expected \"{CSV_HEADER}\")",
                shown(extra)
            ),
        ));
    }
    Ok(())
}

fn parse_number(text: &str, kind: FrameKind, size: usize) -> Result<usize, String> {
    let n = text
        .parse::<usize>()
        .map_err(|_| format!("\"{}\" is not a {kind} number", shown(text)))?;
    if n >= size {
        return Err(format!(
            "there is no {kind} No. {n} (the table has 0 to {})",
            size - 1
        ));
    }
    Ok(n)
}

fn err(line: usize, field: Option<&str>, message: impl Into<String>) -> FileError {
    FileError {
        line,
        field: field.map(str::to_owned),
        message: message.into(),
    }
}

fn shown(text: &str) -> String {
    let mut s: String = text.chars().take(40).collect();
    if s.len() < text.len() {
        s.push_str("...");
    }
    s
}

fn not_utf8(bytes: &[u8], offset: usize) -> FileError {
    let before = bytes.get(..offset).unwrap_or(bytes);
    let line = 1 + before.iter().filter(|&&b| b == b'\n').count();
    let line_start = before
        .iter()
        .rposition(|&b| b == b'\n')
        .map_or(0, |p| p + 1);
    let col = before[line_start..].iter().filter(|&&b| b == b',').count();
    err(
        line,
        CSV_COLUMNS.get(col).copied(),
        format!("the file is not UTF-8 text (bad byte at offset {offset}); save it as UTF-8"),
    )
}

// ---- JSON ----

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct JsonEntry {
    number: usize,
    x: i32,
    y: i32,
    z: i32,
    r: i32,
}

#[derive(Serialize)]
struct JsonDoc {
    format: &'static str,
    work: Vec<JsonEntry>,
    tool: Vec<JsonEntry>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawDoc<'a> {
    #[serde(default)]
    format: Option<String>,
    #[serde(borrow, default)]
    work: Vec<&'a RawValue>,
    #[serde(borrow, default)]
    tool: Vec<&'a RawValue>,
}

/// The tables as JSON (wire units).
pub fn to_json(tables: &TablePair) -> String {
    let entries = |rows: &Rows| {
        rows.iter()
            .enumerate()
            .filter_map(|(number, r)| {
                r.map(|cs| {
                    let [x, y, z, r] = cs.to_wire();
                    JsonEntry { number, x, y, z, r }
                })
            })
            .collect()
    };
    let doc = JsonDoc {
        format: JSON_FORMAT,
        work: entries(&tables.work),
        tool: entries(&tables.tool),
    };
    serde_json::to_string_pretty(&doc).unwrap_or_default() + "\n"
}

/// Reads JSON bytes into tables of the given sizes; all or nothing.
pub fn from_json(bytes: &[u8], work: usize, tool: usize) -> Result<TablePair, FileError> {
    let text = std::str::from_utf8(bytes).map_err(|e| {
        let before = &bytes[..e.valid_up_to()];
        err(
            1 + before.iter().filter(|&&b| b == b'\n').count(),
            None,
            "the file is not UTF-8 text; save it as UTF-8",
        )
    })?;
    let doc: RawDoc = serde_json::from_str(text).map_err(|e| json_error(&e, 0))?;
    if let Some(f) = &doc.format
        && f != JSON_FORMAT
    {
        return Err(err(
            1,
            Some("format"),
            format!("\"{}\" is not \"{JSON_FORMAT}\"", shown(f)),
        ));
    }
    let mut out = TablePair::empty(work, tool);
    let mut seen = std::collections::HashSet::new();
    for (kind, list, size) in [
        (FrameKind::Work, &doc.work, work),
        (FrameKind::Tool, &doc.tool, tool),
    ] {
        for raw in list {
            // The entry's line in the file: its text lies inside `text`.
            let offset = (raw.get().as_ptr() as usize).saturating_sub(text.as_ptr() as usize);
            let line0 = text.get(..offset).map_or(0, |t| t.matches('\n').count());
            let e: JsonEntry =
                serde_json::from_str(raw.get()).map_err(|e| json_error(&e, line0))?;
            let line = line0 + 1;
            let number = parse_number(&e.number.to_string(), kind, size)
                .map_err(|m| err(line, Some("number"), m))?;
            if !seen.insert((kind, number)) {
                return Err(err(
                    line,
                    Some("number"),
                    format!("{kind} No. {number} is listed twice"),
                ));
            }
            let w = [e.x, e.y, e.z, e.r];
            for (c, column) in Column::ALL.into_iter().enumerate() {
                let name = ["x", "y", "z", "r"][c];
                cell::check_range(column, w[c]).map_err(|m| err(line, Some(name), m))?;
                if cell::read_only(kind, number) && w[c] != 0 {
                    return Err(err(line, Some(name), cell::READ_ONLY));
                }
            }
            out.rows_mut(kind)[number] = Some(CoordSystem::from_wire(w));
        }
    }
    Ok(out)
}

/// A serde_json error as a [`FileError`], for text starting at 0-based line `line0`.
fn json_error(e: &serde_json::Error, line0: usize) -> FileError {
    let full = e.to_string();
    let suffix = format!(" at line {} column {}", e.line(), e.column());
    let message = full.strip_suffix(&suffix).unwrap_or(&full).to_owned();
    // "missing field `z`", "unknown field `q`, expected ...", "invalid type ..."
    let field = message
        .split('`')
        .nth(1)
        .filter(|_| message.contains("field `"))
        .map(str::to_owned);
    FileError {
        line: line0 + e.line().max(1),
        field,
        message,
    }
}

// ---- the simulator's coordinate file ----

/// The tables as the simulator's coordinate file (`xsel-sim --coords`); rows never
/// read are left out, which the simulator takes as zeros.
pub fn to_sim_toml(tables: &TablePair) -> String {
    coords_file::to_toml(
        &tables.to_coord_tables(),
        &Default::default(),
        &Default::default(),
    )
}

/// Reads a simulator coordinate file (its tables; 2D6H positions are ignored). Every row
/// is then known: the file lists non-zero rows, the others are zeros.
pub fn from_sim_toml(bytes: &[u8], model: &RobotModel) -> Result<TablePair, FileError> {
    let text = std::str::from_utf8(bytes)
        .map_err(|_| err(1, None, "the file is not UTF-8 text; save it as UTF-8"))?;
    let f = coords_file::parse(text, model).map_err(|e| {
        let message = e.to_string();
        // toml's messages carry "at line N, column M" or "line N".
        let line = message
            .split("line ")
            .nth(1)
            .and_then(|t| t.split(|c: char| !c.is_ascii_digit()).next())
            .and_then(|n| n.parse().ok())
            .unwrap_or(1);
        err(line, None, message.replace('\n', " "))
    })?;
    let rows =
        |t: &crate::robot::CoordTable| -> Rows { t.entries().iter().map(|c| Some(*c)).collect() };
    let out = TablePair {
        work: rows(&f.tables.work),
        tool: rows(&f.tables.tool),
    };
    for (kind, n, cs) in out.listed() {
        for column in Column::ALL {
            cell::check_range(column, column.get(&cs))
                .map_err(|m| err(1, Some(column.file_name()), format!("{kind} No. {n}: {m}")))?;
        }
    }
    Ok(out)
}
