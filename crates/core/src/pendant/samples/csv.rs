//! Plots as CSV (`files::csv_style`: a byte order mark, CR LF): the shown channels over
//! the shown time, one row per poll with the exact polled values; and a capture, with its
//! trigger and roles in `#` lines above its samples, read back whole (for `--plot-png` and
//! to compare moves later).

use std::io::{self, BufRead, Write};

use super::capture::{Capture, Roles};
use super::view::{TraceChoice, exact_text};
use super::{Channel, Encoding, SampleStore};
use crate::files::csv_style::{BOM, EOL};

/// The first line of a saved capture.
const CAPTURE_MAGIC: &str = "# xsel-pendant capture 1";
/// The most samples a capture file may hold (10 minutes at 1 kHz), and the longest line.
const MAX_ROWS: usize = 600_000;
const MAX_LINE: usize = 64 * 1024;

/// A column's heading: `Axis 1 Actual Position (pu)`, `Axis 1 In Position (level)`.
fn heading(label: &str, channel: &Channel) -> String {
    if channel.step && channel.top > 1 {
        return format!("{label} (level 0-{})", channel.top);
    }
    let unit = if channel.step {
        "level"
    } else {
        channel.unit.as_str()
    };
    format!("{label} ({unit})")
}

/// Writes the samples of `choices` between `from` and `to` seconds since the store's
/// origin: a heading line, then one line per poll (time in seconds, then each chosen
/// channel; a poll of another series leaves a channel's cell empty). Returns the rows.
pub fn write_shown(
    out: &mut impl Write,
    store: &SampleStore,
    choices: &[TraceChoice],
    from: f64,
    to: f64,
) -> io::Result<u64> {
    let found: Vec<_> = choices
        .iter()
        .filter_map(|c| store.find(c).map(|f| (c, f)))
        .collect();
    let headings: Vec<String> = found
        .iter()
        .map(|(c, (s, ch))| heading(&c.label(), &s.channels[*ch]))
        .collect();
    write!(out, "{BOM}time_s,{}{EOL}", headings.join(","))?;
    // Each series once, with the columns it fills.
    let mut series: Vec<&super::Series> = Vec::new();
    for (_, (s, _)) in &found {
        if !series.iter().any(|x| std::ptr::eq(*x, *s)) {
            series.push(s);
        }
    }
    let secs = |s: f64| std::time::Duration::try_from_secs_f64(s.max(0.0)).unwrap_or_default();
    let mut rows: Vec<(std::time::Duration, usize, usize)> = Vec::new();
    for (i, s) in series.iter().enumerate() {
        for r in s.rows_between(secs(from), secs(to)) {
            if let Some(t) = s.time(r) {
                rows.push((t, i, r));
            }
        }
    }
    rows.sort_by_key(|(t, i, r)| (*t, *i, *r));
    let mut line = String::new();
    for &(t, i, r) in &rows {
        line.clear();
        line.push_str(&format!("{:.9}", t.as_secs_f64()));
        for (_, (s, ch)) in &found {
            line.push(',');
            if std::ptr::eq(*s, series[i])
                && let Some(v) = s.value(r, *ch)
            {
                line.push_str(&exact_text(s.encoding, &s.channels[*ch], v));
            }
        }
        write!(out, "{line}{EOL}")?;
    }
    out.flush()?;
    Ok(rows.len() as u64)
}

/// Writes a capture: its `#` lines, a heading, one line per sample (seconds from the
/// trigger, then every channel).
pub fn write_capture(out: &mut impl Write, c: &Capture) -> io::Result<()> {
    write!(out, "{BOM}{CAPTURE_MAGIC}{EOL}")?;
    write!(out, "# label,{}{EOL}", c.label.replace(['\n', '\r'], " "))?;
    write!(out, "# series,{}{EOL}", c.series.replace(['\n', '\r'], " "))?;
    write!(out, "# trigger_s,{}{EOL}", c.trigger_s)?;
    let encoding = match c.encoding {
        Encoding::Real => "real",
        Encoding::Milli => "milli",
    };
    write!(out, "# encoding,{encoding}{EOL}")?;
    let role = |r: Option<usize>| r.map_or(String::new(), |i| i.to_string());
    write!(
        out,
        "# roles,{},{},{},{}{EOL}",
        c.roles.actual,
        role(c.roles.command),
        role(c.roles.in_position),
        role(c.roles.phase)
    )?;
    let headings: Vec<String> = c.channels.iter().map(|ch| heading(&ch.name, ch)).collect();
    write!(out, "time_s,{}{EOL}", headings.join(","))?;
    for (i, t) in c.times.iter().enumerate() {
        let mut line = format!("{t:.9}");
        for (ch, values) in c.channels.iter().zip(&c.values) {
            line.push(',');
            if let Some(v) = values.get(i) {
                line.push_str(&exact_text(c.encoding, ch, *v));
            }
        }
        write!(out, "{line}{EOL}")?;
    }
    out.flush()
}

/// Reads a capture written by [`write_capture`]; the error names the line.
pub fn read_capture(input: impl BufRead) -> Result<Capture, String> {
    let mut lines = input.lines().enumerate();
    let mut next = || -> Result<Option<(usize, String)>, String> {
        match lines.next() {
            None => Ok(None),
            Some((i, Ok(l))) if l.len() <= MAX_LINE => {
                Ok(Some((i + 1, l.trim_end_matches('\r').to_string())))
            }
            Some((i, Ok(_))) => Err(format!("line {}: longer than {MAX_LINE} bytes", i + 1)),
            Some((i, Err(e))) => Err(format!("line {}: {e}", i + 1)),
        }
    };
    match next()? {
        Some((_, l)) if l.trim_start_matches('\u{feff}').trim_end() == CAPTURE_MAGIC => {}
        _ => return Err("line 1: not an xsel-pendant capture".into()),
    }
    let (mut label, mut series, mut trigger_s) = (String::new(), String::new(), 0.0);
    let (mut encoding, mut roles) = (Encoding::Real, Roles::default());
    let heading = loop {
        let Some((n, l)) = next()? else {
            return Err("the file ends before its samples' heading".into());
        };
        let Some(meta) = l.strip_prefix("# ") else {
            break (n, l);
        };
        let (key, value) = meta.split_once(',').unwrap_or((meta, ""));
        let bad = |what: &str| format!("line {n}: {what} '{value}'");
        match key {
            "label" => label = value.to_string(),
            "series" => series = value.to_string(),
            "trigger_s" => trigger_s = value.parse().map_err(|_| bad("bad trigger time"))?,
            "encoding" => {
                encoding = match value {
                    "real" => Encoding::Real,
                    "milli" => Encoding::Milli,
                    _ => return Err(bad("unknown encoding")),
                }
            }
            "roles" => {
                let parts: Vec<&str> = value.split(',').collect();
                let opt = |i: usize| -> Result<Option<usize>, String> {
                    match parts.get(i).map(|p| p.trim()) {
                        None | Some("") => Ok(None),
                        Some(p) => p.parse().map(Some).map_err(|_| bad("bad roles")),
                    }
                };
                roles = Roles {
                    actual: opt(0)?.unwrap_or(0),
                    command: opt(1)?,
                    in_position: opt(2)?,
                    phase: opt(3)?,
                };
            }
            _ => {}
        }
    };
    let (n, heading) = heading;
    let mut columns = heading.split(',');
    if columns.next() != Some("time_s") {
        return Err(format!("line {n}: the heading does not start with time_s"));
    }
    let channels: Vec<Channel> = columns
        .map(|h| {
            let (name, unit) = h
                .rsplit_once(" (")
                .map_or((h, ""), |(n, u)| (n, u.trim_end_matches(')')));
            if unit == "level" {
                Channel::level(name)
            } else if let Some(top) = unit.strip_prefix("level 0-").and_then(|t| t.parse().ok()) {
                Channel::levels(name, top)
            } else {
                Channel::new(name, unit)
            }
        })
        .collect();
    if channels.is_empty() || roles.actual >= channels.len() {
        return Err(format!("line {n}: no channel for the capture's position"));
    }
    let (mut times, mut values) = (Vec::new(), vec![Vec::new(); channels.len()]);
    while let Some((n, l)) = next()? {
        if l.trim().is_empty() {
            continue;
        }
        if times.len() == MAX_ROWS {
            return Err(format!("line {n}: more than {MAX_ROWS} samples"));
        }
        let mut cells = l.split(',');
        let number = |cell: Option<&str>| -> Result<f64, String> {
            let cell = cell.unwrap_or("").trim();
            cell.parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| format!("line {n}: '{cell}' is not a number"))
        };
        times.push(number(cells.next())?);
        for (v, channel) in values.iter_mut().zip(&channels) {
            let value = number(cells.next())?;
            // A REAL was written in its shortest exact form: read back as the f32 it was.
            v.push(match encoding {
                Encoding::Real if !channel.step => f64::from(value as f32),
                _ => value,
            });
        }
    }
    let mut capture = Capture {
        number: 0,
        label,
        series,
        channels,
        encoding,
        trigger_s,
        times,
        values,
        roles,
        summary: Default::default(),
    };
    capture.summary = capture.summarise();
    Ok(capture)
}
