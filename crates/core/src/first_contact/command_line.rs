//! `xsel-pendant --first-contact FILE`: the report run on the line the flags name,
//! progress on stderr, the summary on stdout, the report in a new file.

use std::io::Write as _;
use std::process::ExitCode;
use std::sync::atomic::AtomicBool;
use std::time::SystemTime;

use super::{Answer, ReportHeader, render, run_on, write_new};
use crate::cli::{Args, connection};

/// Runs the report for parsed flags: 0 when it is written and the controller answered,
/// 1 when the line could not be opened, nothing answered or the file could not be
/// written, 2 for a bad flag.
pub fn run(args: &Args) -> ExitCode {
    let Some(path) = &args.first_contact else {
        return ExitCode::from(2);
    };
    let mut conn = match connection(args) {
        Ok(c) => c,
        Err(e) => return fail(2, &e.to_string()),
    };
    let mut line = match (conn.connector)(conn.line) {
        Ok(line) => line,
        Err(e) => return fail(1, &conn.open_error(&e)),
    };
    let header = ReportHeader {
        written: SystemTime::now(),
        pendant: env!("CARGO_PKG_VERSION").to_owned(),
        line: conn.target.clone(),
        settings: conn.line.to_string(),
        station: args.station,
    };
    let _ = writeln!(
        std::io::stderr(),
        "first contact on {}: read-only queries, one at a time",
        conn.target
    );
    // Ctrl-C ends the process as usual: nothing the run sends needs undoing.
    let cancel = AtomicBool::new(false);
    let exchanges = run_on(
        line.as_mut(),
        args.station,
        conn.line.byte_time(),
        &cancel,
        |p| {
            let _ = write!(std::io::stderr(), "\r  question {} of {}", p.asked, p.total);
        },
    );
    let _ = writeln!(std::io::stderr());
    drop(line);
    drop(conn);
    let text = render(&header, &exchanges);
    if let Err(e) = write_new(path, &text) {
        return fail(1, &format!("--first-contact {e}"));
    }
    let summary = text
        .split("\nSummary\n")
        .nth(1)
        .and_then(|rest| rest.split("\nQuestions\n").next())
        .unwrap_or("");
    let mut out = std::io::stdout().lock();
    let _ = write!(out, "Summary\n{summary}");
    let _ = writeln!(out, "report written: {}", path.display());
    let answered = exchanges
        .iter()
        .any(|e| matches!(e.answer, Answer::Reply(_) | Answer::Refused(_)));
    if answered {
        ExitCode::SUCCESS
    } else {
        fail(
            1,
            "the controller did not answer (the report says what was tried)",
        )
    }
}

fn fail(code: u8, msg: &str) -> ExitCode {
    let _ = writeln!(std::io::stderr(), "xsel-pendant: {msg}");
    ExitCode::from(code)
}
