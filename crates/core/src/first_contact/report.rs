//! The first-contact report as plain text: what was asked, what came back with its
//! time, what it settles, and every frame in order.

use std::fmt::Write as _;
use std::time::{Duration, SystemTime};

use super::probes::findings;
use super::{Answer, Exchange, ReceivedKind};
use crate::protocol::{Station, describe};

/// What the report says of where it was taken.
#[derive(Clone, Debug)]
pub struct ReportHeader {
    /// When the run began.
    pub written: SystemTime,
    /// The pendant's version.
    pub pendant: String,
    /// The line, as the connection panel names it ("serial port COM3", ...).
    pub line: String,
    /// Its settings ("115200 8N1").
    pub settings: String,
    pub station: Station,
}

/// The whole report.
pub fn render(header: &ReportHeader, exchanges: &[Exchange]) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "xsel-pendant first-contact report");
    let _ = writeln!(s, "=================================");
    let _ = writeln!(
        s,
        "Taken:    {} (UTC)",
        humantime::format_rfc3339_seconds(header.written)
    );
    let _ = writeln!(s, "Pendant:  xsel-pendant {}", header.pendant);
    if header.line.contains(&header.settings) {
        let _ = writeln!(s, "Line:     {}", header.line);
    } else {
        let _ = writeln!(s, "Line:     {} ({})", header.line, header.settings);
    }
    let _ = writeln!(s, "Station:  {}", header.station);
    let _ = writeln!(s);
    let _ = writeln!(
        s,
        "Only queries were sent, one at a time: nothing moved and nothing was written."
    );
    let _ = writeln!(
        s,
        "Each question tests what PROTOCOL.md (the pendant's protocol reference) could only"
    );
    let _ = writeln!(
        s,
        "infer; the section is named. Times are from the command handed to the line to the"
    );
    let _ = writeln!(s, "reply's last byte read, on this computer's clock.");
    let _ = writeln!(s);
    summary(&mut s, exchanges);
    let _ = writeln!(s);
    let _ = writeln!(s, "Questions");
    let _ = writeln!(s, "---------");
    for (n, e) in exchanges.iter().enumerate() {
        question(&mut s, n + 1, e);
    }
    let _ = writeln!(s, "Every frame, in order");
    let _ = writeln!(s, "---------------------");
    for e in exchanges {
        if !e.sent.is_empty() {
            let _ = writeln!(s, "{:>10}  ->  {}", ms(e.sent_at), shown(&e.sent));
        }
        for r in &e.received {
            let _ = writeln!(s, "{:>10}  <-  {}", ms(r.at), shown(&r.bytes));
        }
    }
    s
}

/// The summary alone (what the CLI prints and the window shows).
pub fn summary_text(exchanges: &[Exchange]) -> String {
    let mut s = String::new();
    summary(&mut s, exchanges);
    s
}

/// One line per kind of question: the five status queries as one.
fn summary(s: &mut String, exchanges: &[Exchange]) {
    let _ = writeln!(s, "Summary");
    let _ = writeln!(s, "-------");
    let status: Vec<&Exchange> = exchanges
        .iter()
        .filter(|e| e.question().is_status())
        .collect();
    let answered: Vec<Duration> = status.iter().filter_map(|e| e.delay()).collect();
    let mut delays = answered.clone();
    delays.sort();
    let asked = status
        .iter()
        .filter(|e| !matches!(e.answer, Answer::NotAsked(_)))
        .count();
    if let (Some(first), Some(last)) = (delays.first(), delays.last()) {
        let median = delays[delays.len() / 2];
        let _ = writeln!(
            s,
            "- 215H: {} of {asked} answered; reply complete after {} median (fastest {}, slowest {})",
            answered.len(),
            ms(median),
            ms(*first),
            ms(*last)
        );
        if let Some(e) = status.iter().find(|e| e.delay().is_some())
            && let Some(sc) = findings(e).get(1)
        {
            let _ = writeln!(s, "  {sc}");
        }
    } else {
        let _ = writeln!(
            s,
            "- 215H: none of {asked} answered. Check the port, baud rate, framing and station (the window's Detect tries them)."
        );
    }
    for e in exchanges.iter().filter(|e| !e.question().is_status()) {
        let found = findings(e);
        let last = found.last().cloned().unwrap_or_default();
        let _ = writeln!(
            s,
            "- {}: {}",
            short(e.question().title),
            if found.len() > 1 && matches!(e.answer, Answer::Reply(_)) {
                last
            } else {
                found.first().cloned().unwrap_or_default()
            }
        );
    }
}

/// A question's title without its question mark.
fn short(title: &str) -> &str {
    title.trim_end_matches('?')
}

fn question(s: &mut String, n: usize, e: &Exchange) {
    let q = e.question();
    let _ = writeln!(s, "{n}. {} [PROTOCOL.md {}]", q.title, q.section);
    if !e.sent.is_empty() {
        let _ = writeln!(s, "   sent      {}", shown(&e.sent));
    }
    for r in &e.received {
        let what = match &r.kind {
            ReceivedKind::Answer => "got".to_string(),
            ReceivedKind::Echo => "echo".to_string(),
            ReceivedKind::Other(why) => format!("other ({why})"),
            ReceivedKind::Late => "late".to_string(),
            ReceivedKind::Bad(why) => format!("bad ({why})"),
        };
        let _ = writeln!(
            s,
            "   {what:<9} {}   after {}",
            shown(&r.bytes),
            ms(r.at.saturating_sub(e.sent_at))
        );
    }
    for f in findings(e) {
        let _ = writeln!(s, "   => {f}");
    }
    if let Answer::Reply(frame) = &e.answer {
        let _ = writeln!(s, "   as the pendant reads it:");
        for line in describe(frame.raw()).to_string().lines() {
            let _ = writeln!(s, "     {line}");
        }
    }
    let _ = writeln!(s);
}

/// Bytes as printable text, CR LF dropped at the end, anything else escaped.
fn shown(bytes: &[u8]) -> String {
    let body = bytes.strip_suffix(b"\r\n").unwrap_or(bytes);
    body.escape_ascii().to_string()
}

fn ms(d: Duration) -> String {
    format!("{:.1} ms", d.as_secs_f64() * 1e3)
}
