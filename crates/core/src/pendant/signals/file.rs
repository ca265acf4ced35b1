//! Watch-list files: CSV (Excel-friendly, as the pendant's other files) and JSON, read
//! whole or refused with the line and field at fault; and the list as saved between runs.
//!
//! ```text
//! Kind,Program,Number,Name,Chars,Plot
//! output,0,305,gripper close,,yes
//! string,0,300,part name,16,
//! ```
//!
//! JSON: `{"format": "xsel-signals 1", "encoding": "Plain", "rows": [{"signal": {"kind":
//! "output", "program": 0, "number": 305}, "name": "gripper close", "plot": true}]}`.

use serde::{Deserialize, Serialize};

use super::{MAX_ROWS, MAX_TEXT_CHARS, Signal, SignalKind, WatchRow, check_name};
use crate::files::csv_style::{BOM, EOL};
use crate::pendant::positions::file::{FileError, csv_lines, split_line, text_of};
use crate::protocol::RealEncoding;

/// The most a watch-list file may hold.
pub const MAX_FILE_BYTES: u64 = 4 * 1024 * 1024;
/// The `format` of the JSON file.
pub const JSON_FORMAT: &str = "xsel-signals 1";
const HEADINGS: [&str; 6] = ["Kind", "Program", "Number", "Name", "Chars", "Plot"];

/// The list (and this controller's real encoding) as a JSON file.
#[derive(Serialize, Deserialize)]
struct Saved {
    format: String,
    #[serde(default)]
    encoding: RealEncoding,
    rows: Vec<WatchRow>,
}

/// The list as JSON (the export, and the file saved between runs).
pub fn to_json(rows: &[WatchRow], encoding: RealEncoding) -> String {
    let saved = Saved {
        format: JSON_FORMAT.to_owned(),
        encoding,
        rows: rows.to_vec(),
    };
    serde_json::to_string_pretty(&saved).unwrap_or_default()
}

/// The list as CSV: a byte order mark, the header, one row a signal, CR LF.
pub fn to_csv(rows: &[WatchRow]) -> String {
    let mut out = String::from(BOM);
    out.push_str(&HEADINGS.join(","));
    out.push_str(EOL);
    for r in rows {
        let s = r.signal;
        let name = if r.name.contains([',', '"', ';']) {
            format!("\"{}\"", r.name.replace('"', "\"\""))
        } else {
            r.name.clone()
        };
        let chars = if s.kind == SignalKind::Text {
            r.chars.to_string()
        } else {
            String::new()
        };
        let plot = if r.plot { "yes" } else { "" };
        out.push_str(&format!(
            "{},{},{},{name},{chars},{plot}{EOL}",
            s.kind.key(),
            s.program,
            s.number
        ));
    }
    out
}

/// A watch-list file's rows (CSV or JSON, told apart by the first character) and the
/// encoding a JSON file names; the first thing wrong, naming line and field.
pub fn parse(bytes: &[u8]) -> Result<(Vec<WatchRow>, Option<RealEncoding>), FileError> {
    let text = text_of(bytes, MAX_FILE_BYTES, "a watch-list file")?;
    let (rows, encoding) = match text.trim_start().chars().next() {
        None => return Err(FileError::at(1, None, "the file is empty")),
        Some('{') => {
            let saved: Saved = serde_json::from_str(text).map_err(|e| {
                FileError::at(e.line(), None, format!("not a watch-list file: {e}"))
            })?;
            if saved.format != JSON_FORMAT {
                return Err(FileError::at(
                    1,
                    Some("format"),
                    format!("`{}` is not `{JSON_FORMAT}`", saved.format),
                ));
            }
            (saved.rows, Some(saved.encoding))
        }
        Some(_) => (parse_csv(text)?, None),
    };
    check_rows(&rows)?;
    Ok((rows, encoding))
}

fn parse_csv(text: &str) -> Result<Vec<WatchRow>, FileError> {
    let mut lines = csv_lines(text);
    let Some((first, header)) = lines.next() else {
        return Err(FileError::at(1, None, "the file is empty"));
    };
    let fields = split_line(header, first, &[])?;
    if fields.len() < 3
        || !fields
            .iter()
            .zip(HEADINGS)
            .all(|(f, h)| f.trim().eq_ignore_ascii_case(h))
    {
        return Err(FileError::at(
            first,
            None,
            format!("the header is not `{}`", HEADINGS.join(",")),
        ));
    }
    let mut rows = Vec::new();
    for (n, line) in lines {
        let f = split_line(line, n, &HEADINGS)?;
        if f.iter().all(|c| c.trim().is_empty()) {
            continue;
        }
        if rows.len() == MAX_ROWS {
            return Err(FileError::at(n, None, format!("more than {MAX_ROWS} rows")));
        }
        let cell = |i: usize| f.get(i).map_or("", |s| s.trim());
        let kind = SignalKind::from_key(cell(0)).ok_or_else(|| {
            FileError::at(
                n,
                Some("Kind"),
                format!(
                    "`{}` is not input, output, flag, integer, real or string",
                    cell(0)
                ),
            )
        })?;
        let number = |i: usize, heading: &str, what: &str| -> Result<u16, FileError> {
            match cell(i) {
                "" if i == 1 => Ok(0),
                s => s
                    .parse::<u16>()
                    .map_err(|_| FileError::at(n, Some(heading), format!("`{s}` is not {what}"))),
            }
        };
        let program = number(1, "Program", "a program number (0 = global)")?;
        let program = u8::try_from(program)
            .map_err(|_| FileError::at(n, Some("Program"), "programs are numbered 0-64"))?;
        let number = number(2, "Number", "a number")?;
        let chars = match cell(4) {
            "" => 16,
            s => s.parse::<u8>().map_err(|_| {
                FileError::at(
                    n,
                    Some("Chars"),
                    format!("`{s}` is not a count of characters"),
                )
            })?,
        };
        let plot = matches!(
            cell(5).to_ascii_lowercase().as_str(),
            "yes" | "1" | "true" | "x"
        );
        rows.push(WatchRow {
            signal: Signal::new(kind, if kind.has_program() { program } else { 0 }, number),
            name: cell(3).to_owned(),
            chars: if kind == SignalKind::Text { chars } else { 0 },
            plot,
        });
    }
    Ok(rows)
}

/// Every row a signal the controller has, named within bounds, once.
fn check_rows(rows: &[WatchRow]) -> Result<(), FileError> {
    if rows.len() > MAX_ROWS {
        return Err(FileError::at(1, None, format!("more than {MAX_ROWS} rows")));
    }
    let mut seen = std::collections::HashSet::new();
    for (i, r) in rows.iter().enumerate() {
        let row = i + 1;
        let bad = |field: &str, m: String| FileError {
            line: None,
            field: Some(field.to_owned()),
            message: format!("row {row} ({}): {m}", r.signal),
        };
        if r.signal.kind == SignalKind::Text && !(1..=MAX_TEXT_CHARS).contains(&r.chars) {
            return Err(bad(
                "Chars",
                format!("a string row reads 1-{MAX_TEXT_CHARS} characters"),
            ));
        }
        r.signal.check(r.chars).map_err(|m| bad("Number", m))?;
        check_name(&r.name).map_err(|m| bad("Name", m))?;
        if !seen.insert(r.signal) {
            return Err(bad("Number", "listed twice".to_owned()));
        }
    }
    Ok(())
}
