//! The guardian process (`xsel-pendant --guardian`): reads the line to open from stdin,
//! opens it, then runs [`GuardianCore`] between the pipe and the line until the window
//! is gone and no STOP is owed; then it closes the line and exits. What it does goes to
//! stderr, one line each, prefixed `guardian:`.

use std::io::{self, BufReader, Write};
use std::process::ExitCode;
use std::time::{Duration, Instant};

use crossbeam_channel::{Receiver, TryRecvError, unbounded};

use super::core::GuardianCore;
use super::wire::{self, FromGuardian, OpenLine, ToGuardian};
use crate::link::Transport;
use crate::link::timing::Timing;
use crate::pendant::LineKind;
use crate::session::Connection;

/// Longest wait for the line's bytes before the pipe is looked at again: bounds the
/// time a window frame waits to go out.
const READ_SLICE: Duration = Duration::from_millis(2);

/// What the stdin reader hands the loop.
enum FromWindow {
    Message(ToGuardian),
    Closed(String),
}

/// Runs the guardian; the exit code says whether the line was opened.
pub fn run() -> ExitCode {
    // One reader for the whole run: what it buffered past the first message is kept.
    let mut input = BufReader::new(io::stdin());
    let open: OpenLine = match wire::receive(&mut input) {
        Ok(Some(ToGuardian::Open(open))) => open,
        Ok(other) => {
            log(&format!("expected the line to open first, got {other:?}"));
            return ExitCode::from(2);
        }
        Err(e) => {
            log(&format!("cannot read the line to open: {e}"));
            return ExitCode::from(2);
        }
    };
    let mut out = io::stdout().lock();
    let mut line = match open_line(&open) {
        Ok(line) => line,
        Err(e) => {
            log(&e);
            let _ = wire::send(&mut out, &FromGuardian::Failed(e));
            return ExitCode::from(1);
        }
    };
    let described = line.describe();
    log(&format!("{described} open"));
    let opened = FromGuardian::Opened {
        line: described,
        pid: std::process::id(),
    };
    if wire::send(&mut out, &opened).is_err() {
        return ExitCode::from(1);
    }
    let window = read_window(input);
    let settings = &open.connection;
    let timing = Timing {
        line: settings.line(),
        ..Timing::default()
    };
    let lease = Duration::from_millis(open.lease_ms);
    let mut core = GuardianCore::new(Instant::now(), settings.station(), lease, timing);
    relay(&mut core, line.as_mut(), &window, &mut out);
    drop(line);
    log("line closed; exiting");
    ExitCode::SUCCESS
}

fn log(text: &str) {
    let _ = writeln!(io::stderr(), "guardian: {text}");
}

/// Opens a serial port or a TCP bridge; the built-in simulator lives in the window.
fn open_line(open: &OpenLine) -> Result<Box<dyn Transport>, String> {
    let settings = &open.connection;
    if settings.kind == LineKind::Simulator {
        return Err("the built-in simulator runs in the window, not in a guardian".into());
    }
    settings.line().validate().map_err(|e| e.to_string())?;
    let model = crate::robot::RobotModel::default_model();
    let mut connection = Connection::prepare_in_process(settings, model);
    (connection.connector)().map_err(|e| connection.open_error(&e))
}

/// A thread that reads the window's messages until the pipe closes.
fn read_window(mut input: BufReader<io::Stdin>) -> Receiver<FromWindow> {
    let (tx, rx) = unbounded();
    let spawned = std::thread::Builder::new()
        .name("guardian-stdin".into())
        .spawn(move || {
            loop {
                let next = match wire::receive::<ToGuardian>(&mut input) {
                    Ok(Some(m)) => FromWindow::Message(m),
                    Ok(None) => FromWindow::Closed("the window's pipe closed".into()),
                    Err(e) => FromWindow::Closed(format!("the window's pipe failed: {e}")),
                };
                let last = matches!(next, FromWindow::Closed(_));
                if tx.send(next).is_err() || last {
                    return;
                }
            }
        });
    if let Err(e) = spawned {
        // No reader: act as if the window were gone (STOP if anything may move).
        log(&format!("cannot read the window's pipe: {e}"));
        let (tx, rx) = unbounded();
        let _ = tx.send(FromWindow::Closed("no reader thread".into()));
        return rx;
    }
    rx
}

/// The loop: the window's messages into the core, the core's frames onto the line, the
/// line's bytes into the core, the core's messages to the window, until it is done.
fn relay(
    core: &mut GuardianCore,
    line: &mut dyn Transport,
    window: &Receiver<FromWindow>,
    out: &mut impl Write,
) {
    let mut buf = [0u8; 1024];
    let mut window_open = true;
    loop {
        let now = Instant::now();
        while window_open {
            match window.try_recv() {
                Ok(FromWindow::Message(ToGuardian::Bytes(b))) => core.handle_window_bytes(now, &b),
                Ok(FromWindow::Message(ToGuardian::Heartbeat)) => core.handle_heartbeat(now),
                Ok(FromWindow::Message(ToGuardian::Open(_))) => {}
                Ok(FromWindow::Closed(why)) => {
                    log(&why);
                    window_open = false;
                    core.handle_window_closed(now);
                }
                Err(TryRecvError::Empty) => break,
                Err(TryRecvError::Disconnected) => {
                    window_open = false;
                    core.handle_window_closed(now);
                }
            }
        }
        core.handle_timeout(Instant::now());
        while let Some(frame) = core.poll_transmit(Instant::now()) {
            if let Err(e) = line.write_all_bytes(&frame) {
                return line_lost(core, out, &format!("cannot write to the line: {e}"));
            }
        }
        while let Some(text) = core.poll_log() {
            log(&text);
        }
        while let Some(m) = core.poll_to_window() {
            if window_open && wire::send(out, &m).is_err() {
                window_open = false;
                core.handle_window_closed(Instant::now());
            }
        }
        if core.is_done() {
            while let Some(text) = core.poll_log() {
                log(&text);
            }
            return;
        }
        let wait = core
            .poll_timeout()
            .map_or(READ_SLICE, |t| t.saturating_duration_since(Instant::now()))
            .min(READ_SLICE);
        match line.read_timeout(&mut buf, wait) {
            Ok(0) => return line_lost(core, out, "the line closed"),
            Ok(n) => core.handle_line_bytes(&buf[..n]),
            Err(e) if crate::link::transport::is_timeout(&e) => {}
            Err(e) => return line_lost(core, out, &format!("the line failed: {e}")),
        }
    }
}

/// The line is gone: the window hears it (its link reconnects with a new guardian).
fn line_lost(core: &mut GuardianCore, out: &mut impl Write, why: &str) {
    while let Some(text) = core.poll_log() {
        log(&text);
    }
    log(why);
    let _ = wire::send(out, &FromGuardian::Failed(why.to_owned()));
}
