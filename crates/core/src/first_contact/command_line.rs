//! `xsel-pendant --first-contact FILE`: the report run on the line the flags name,
//! progress on stderr, the summary on stdout, the report in a new file.

use super::{Answer, Progress, render, report_on, summary_text, write_new};
use crate::cli::{Args, connection};
use std::io::Write as _;
use std::process::ExitCode;

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
    let _ = writeln!(
        std::io::stderr(),
        "first contact on {}: read-only queries, one at a time",
        conn.target
    );
    // Ctrl-C ends the process as usual: nothing the run sends needs undoing.
    let progress = |p: Progress| {
        let _ = write!(std::io::stderr(), "\r  question {} of {}", p.asked, p.total);
    };
    let (header, exchanges) = match report_on(&mut conn, args.station, || false, progress) {
        Ok(done) => done,
        Err(e) => return fail(1, &e.to_string()),
    };
    let _ = writeln!(std::io::stderr());
    drop(conn);
    let text = render(&header, &exchanges);
    if let Err(e) = write_new(path, &text) {
        return fail(1, &format!("--first-contact {e}"));
    }
    let mut out = std::io::stdout().lock();
    let _ = write!(out, "{}", summary_text(&exchanges));
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
