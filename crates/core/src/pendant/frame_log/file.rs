//! Saving and opening the frame log: text for people, JSON Lines with the exact bytes
//! (hex) for programs, read back into a [`FrameLog`] to view again or replay.

use std::io::{self, BufRead, Write};
use std::time::{Duration, SystemTime, UNIX_EPOCH};

use serde::{Deserialize, Serialize};

use super::entry::{MAX_NOTE_BYTES, MAX_ROW_BYTES};
use super::{Dir, FrameLog, Protocol, Row};

/// A Modbus/TCP row's `proto` in a JSON Lines log.
const MODBUS_KEY: &str = "modbus";

/// The first line of a JSON Lines log.
#[derive(Serialize, Deserialize)]
struct Header {
    xsel_pendant_frame_log: u32,
    /// Wall-clock time of the log's start, µs since the Unix epoch (UTC).
    start_unix_us: u64,
}

/// One row of a JSON Lines log.
#[derive(Serialize)]
struct Line {
    /// Nanoseconds after the start.
    t_ns: u64,
    /// `modbus` for the RMC151's rows (absent: Format B).
    #[serde(skip_serializing_if = "Option::is_none")]
    proto: Option<&'static str>,
    dir: String,
    /// The exact bytes, as hex pairs.
    hex: String,
    /// The bytes as text with control bytes escaped (for reading; `hex` is the truth).
    #[serde(default)]
    ascii: String,
    #[serde(skip_serializing_if = "String::is_empty")]
    note: String,
    #[serde(skip_serializing_if = "String::is_empty")]
    name: String,
    #[serde(skip_serializing_if = "String::is_empty")]
    checksum: String,
    #[serde(skip_serializing_if = "Option::is_none")]
    latency_us: Option<u32>,
}

fn unix_us(t: SystemTime) -> u64 {
    t.duration_since(UNIX_EPOCH)
        .map_or(0, |d| d.as_micros() as u64)
}

/// Writes rows as JSON Lines: a header line, then one object per row.
pub fn write_jsonl<'a>(
    out: &mut impl Write,
    start: SystemTime,
    rows: impl Iterator<Item = Row<'a>>,
) -> io::Result<u64> {
    let header = Header {
        xsel_pendant_frame_log: 1,
        start_unix_us: unix_us(start),
    };
    serde_json::to_writer(&mut *out, &header)?;
    out.write_all(b"\n")?;
    let mut n = 0;
    for r in rows {
        let line = Line {
            t_ns: r.t_ns(),
            proto: (r.protocol() == Protocol::Modbus).then_some(MODBUS_KEY),
            dir: r.dir().key().into(),
            hex: hex(&r.bytes()),
            ascii: r.ascii(),
            note: r.note().into(),
            name: r.name(),
            checksum: r.verdict().label().into(),
            latency_us: r.latency_us(),
        };
        serde_json::to_writer(&mut *out, &line)?;
        out.write_all(b"\n")?;
        n += 1;
    }
    out.flush()?;
    Ok(n)
}

/// Writes rows as text, one line each: time after the start, time since the previous
/// row, direction, the bytes with control bytes escaped, name, checksum, latency, note.
pub fn write_text<'a>(
    out: &mut impl Write,
    start: SystemTime,
    rows: impl Iterator<Item = Row<'a>>,
) -> io::Result<u64> {
    writeln!(out, "# xsel-pendant frame log, start {} UTC", utc(start))?;
    writeln!(
        out,
        "# seconds  +since-previous  dir  bytes  message  checksum  latency  note"
    )?;
    let mut prev: Option<u64> = None;
    let mut n = 0;
    for r in rows {
        let t = r.t_ns();
        let delta = prev.map_or(0, |p| t.saturating_sub(p));
        prev = Some(t);
        write!(
            out,
            "{:>14.6} +{:.6} {:<5} {}  {}",
            t as f64 * 1e-9,
            delta as f64 * 1e-9,
            r.dir().arrow(),
            r.ascii(),
            r.name()
        )?;
        if !r.verdict().label().is_empty() {
            write!(out, "  sc {}", r.verdict().label())?;
        }
        if let Some(us) = r.latency_us() {
            write!(out, "  {:.3} ms", us as f64 / 1000.0)?;
        }
        if !r.note().is_empty() {
            write!(out, "  ({})", r.note())?;
        }
        writeln!(out)?;
        n += 1;
    }
    out.flush()?;
    Ok(n)
}

/// The longest line a log this program wrote can have: a row's bytes as hex, its note
/// (each character escaped at worst) and the JSON around them. A longer line is refused before it is held whole.
const MAX_LINE: usize = 2 * MAX_ROW_BYTES + 6 * MAX_NOTE_BYTES + 512;

/// The next line (without its end), at most [`MAX_LINE`] bytes; `None` at the end.
fn bounded_line(input: &mut impl BufRead) -> Result<Option<String>, String> {
    let mut line = Vec::new();
    let read = std::io::Read::take(&mut *input, MAX_LINE as u64 + 1)
        .read_until(b'\n', &mut line)
        .map_err(|e| format!("cannot read: {e}"))?;
    if read == 0 {
        return Ok(None);
    }
    if line.len() > MAX_LINE && line.last() != Some(&b'\n') {
        return Err(format!(
            "a line longer than any this program writes (more than {MAX_LINE} bytes): not read further"
        ));
    }
    while matches!(line.last(), Some(b'\n' | b'\r')) {
        line.pop();
    }
    String::from_utf8(line)
        .map(Some)
        .map_err(|_| "not UTF-8 text".to_owned())
}

/// Reads a JSON Lines log into a new log (times as recorded). The error names the line.
pub fn read_jsonl(mut input: impl BufRead, cap: usize) -> Result<FrameLog, String> {
    let mut next_line = move || bounded_line(&mut input);
    let mut lines = std::iter::from_fn(move || next_line().transpose()).enumerate();
    let first = match lines.next() {
        Some((_, Ok(l))) => l,
        Some((_, Err(e))) => return Err(format!("line 1: {e}")),
        None => return Err("the file is empty".into()),
    };
    let header: Header = serde_json::from_str(&first)
        .map_err(|_| "line 1: not an xsel-pendant frame log (JSON Lines header missing)")?;
    if header.xsel_pendant_frame_log != 1 {
        return Err(format!(
            "line 1: frame log format {} (this version reads format 1)",
            header.xsel_pendant_frame_log
        ));
    }
    let mut log = FrameLog::new(cap);
    log.set_origin(
        None,
        UNIX_EPOCH + Duration::from_micros(header.start_unix_us),
    );
    for (i, line) in lines {
        let line = line.map_err(|e| format!("line {}: {e}", i + 1))?;
        if line.trim().is_empty() {
            continue;
        }
        let row: LineIn =
            serde_json::from_str(&line).map_err(|e| format!("line {}: {e}", i + 1))?;
        let bytes = unhex(&row.hex).ok_or_else(|| format!("line {}: bad hex bytes", i + 1))?;
        if bytes.len() > MAX_ROW_BYTES || row.note.len() > MAX_NOTE_BYTES {
            return Err(format!(
                "line {}: a row longer than any on the line ({} bytes, note {} bytes; \
                 at most {MAX_ROW_BYTES} and {MAX_NOTE_BYTES})",
                i + 1,
                bytes.len(),
                row.note.len()
            ));
        }
        let protocol = match row.proto.as_deref() {
            None => Protocol::FormatB,
            Some(MODBUS_KEY) => Protocol::Modbus,
            Some(other) => {
                return Err(format!("line {}: unknown protocol '{other}'", i + 1));
            }
        };
        let Some(dir) = Dir::from_key(&row.dir) else {
            return Err(format!("line {}: unknown direction '{}'", i + 1, row.dir));
        };
        log.push_row(protocol, dir, &bytes, &row.note, row.t_ns);
    }
    Ok(log)
}

/// What is read back of a row (the rest is derived again from the bytes).
#[derive(Deserialize)]
struct LineIn {
    t_ns: u64,
    #[serde(default)]
    proto: Option<String>,
    dir: String,
    hex: String,
    #[serde(default)]
    note: String,
}

fn hex(bytes: &[u8]) -> String {
    use std::fmt::Write as _;
    let mut s = String::with_capacity(bytes.len() * 2);
    for b in bytes {
        let _ = write!(s, "{b:02X}");
    }
    s
}

fn unhex(s: &str) -> Option<Vec<u8>> {
    if !s.len().is_multiple_of(2) {
        return None;
    }
    (0..s.len())
        .step_by(2)
        .map(|i| {
            s.get(i..i + 2)
                .and_then(crate::protocol::peek::hex_digits)
                .map(|v| v as u8)
        })
        .collect()
}

/// `2026-11-28 22:00:43.123456` (UTC) for a wall-clock time.
pub fn utc(t: SystemTime) -> String {
    let us = unix_us(t);
    let secs = us / 1_000_000;
    let (days, rem) = (secs / 86_400, secs % 86_400);
    // Civil date from days since 1970-01-01 (Howard Hinnant's algorithm).
    let z = days as i64 + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z.rem_euclid(146_097);
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    let y = yoe + era * 400 + i64::from(m <= 2);
    format!(
        "{y:04}-{m:02}-{d:02} {:02}:{:02}:{:02}.{:06}",
        rem / 3600,
        rem / 60 % 60,
        rem % 60,
        us % 1_000_000
    )
}
