//! Running the questions on a real line (a serial port, a TCP bridge or the built-in
//! simulator's pipe) on the caller's thread, and writing the report as a new file.

use std::io::Write as _;
use std::path::Path;
use std::time::{Duration, Instant, SystemTime};

use super::{Exchange, FirstContact, ReportHeader};
use crate::line::is_timeout;
use crate::link::transport::Transport;
use crate::protocol::Station;
use crate::session::Connection;

/// The longest single read, so a cancel is seen promptly.
const READ_SLICE: Duration = Duration::from_millis(20);

/// Questions asked so far, and how many there are.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Progress {
    pub asked: usize,
    pub total: usize,
}

/// Why no report could be written.
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    #[error("{0}")]
    Open(String),
    #[error("{0}")]
    Write(String),
}

/// Opens the line of `conn` (the built-in simulator starts with it) and asks every
/// question on it: the report's header and the exchanges, or why the line did not open.
pub fn report_on(
    conn: &mut Connection,
    station: Station,
    cancelled: impl Fn() -> bool,
    progress: impl FnMut(Progress),
) -> Result<(ReportHeader, Vec<Exchange>), RunError> {
    let mut line = (conn.connector)(conn.line).map_err(|e| RunError::Open(conn.open_error(&e)))?;
    let header = ReportHeader {
        written: SystemTime::now(),
        pendant: env!("CARGO_PKG_VERSION").to_owned(),
        line: conn.target.clone(),
        settings: conn.line.to_string(),
        station,
    };
    let exchanges = run_on(
        line.as_mut(),
        station,
        conn.line.byte_time(),
        cancelled,
        progress,
    );
    Ok((header, exchanges))
}

/// The name of a report written at `wall` in a folder the user did not choose.
pub fn file_name(wall: SystemTime) -> String {
    let stamp = humantime::format_rfc3339_seconds(wall).to_string();
    let digits: String = stamp
        .chars()
        .filter(|c| c.is_ascii_digit() || *c == 'T')
        .collect();
    format!(
        "xsel-pendant-first-contact-{}.txt",
        digits.replace('T', "-")
    )
}

/// Asks every question on `line`, one at a time; `cancelled` answering true ends the
/// run between reads (what was not asked says so). A failing line ends it too.
/// `progress` hears of each question as it goes out.
pub fn run_on(
    line: &mut dyn Transport,
    station: Station,
    byte_time: Duration,
    cancelled: impl Fn() -> bool,
    mut progress: impl FnMut(Progress),
) -> Vec<Exchange> {
    // Whatever waited on the line belongs to nobody's question.
    let _ = line.discard_input();
    let mut run = FirstContact::new(station, byte_time, Instant::now());
    let mut buf = [0u8; 4096];
    loop {
        if cancelled() {
            run.end("cancelled");
            break;
        }
        if let Some(bytes) = run.poll_transmit(Instant::now()) {
            if let Err(e) = line.write_all_bytes(&bytes) {
                run.end(&format!("the line failed: {e}"));
                break;
            }
            let (asked, total) = run.progress();
            progress(Progress { asked, total });
        }
        if run.is_done() {
            break;
        }
        let wait = run
            .poll_timeout()
            .map_or(READ_SLICE, |t| t.saturating_duration_since(Instant::now()))
            .clamp(Duration::from_millis(1), READ_SLICE);
        match line.read_timeout(&mut buf, wait) {
            Ok(0) => {
                run.end("the line was closed by the other end");
                break;
            }
            Ok(n) => run.handle_input(Instant::now(), &buf[..n]),
            Err(e) if is_timeout(&e) => {}
            Err(e) => {
                run.end(&format!("the line failed: {e}"));
                break;
            }
        }
        run.handle_timeout(Instant::now());
    }
    run.exchanges().to_vec()
}

/// Writes `text` to `path` as a new file (an existing file is never written over),
/// flushed to the disk; the error names the file, and a file cut short is removed.
pub fn write_new(path: &Path, text: &str) -> Result<(), RunError> {
    let fail = |e: std::io::Error| RunError::Write(format!("{}: {e}", path.display()));
    let mut file = std::fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(path)
        .map_err(|e| {
            if e.kind() == std::io::ErrorKind::AlreadyExists {
                RunError::Write(format!(
                    "{}: the file exists (a report never replaces one): choose another name",
                    path.display()
                ))
            } else {
                fail(e)
            }
        })?;
    let written = file
        .write_all(text.as_bytes())
        .and_then(|_| file.sync_all());
    if let Err(e) = written {
        // A report cut short (a full disk) is not left behind as if it were whole.
        drop(file);
        let _ = std::fs::remove_file(path);
        return Err(fail(e));
    }
    Ok(())
}
