//! The guardian process (`xsel-pendant --guardian`): reads the line to open from stdin,
//! opens it, then runs [`GuardianCore`] between the pipe and the line until the window
//! is gone and no STOP is owed; then it closes the line and exits. What it does goes to
//! stderr, one line each, prefixed `guardian:`.

use std::io::{self, BufReader, Write};
use std::process::ExitCode;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use crossbeam_channel::{Receiver, RecvTimeoutError, Sender, unbounded};

use super::core::GuardianCore;
use super::guard::Guard;
use super::rmc_core::RmcGuardianCore;
use super::wire::{self, FromGuardian, OpenLine, ToGuardian};
use crate::line::LineKind;
use crate::link::Transport;
use crate::link::timing::Timing;
use crate::session::Connection;

/// How long the line's reader waits in one read before it looks whether it should end.
const READ_SLICE: Duration = Duration::from_millis(100);
/// Longest sleep of the loop when nothing is due (it wakes at once on any event).
const IDLE_WAIT: Duration = Duration::from_secs(1);

/// What the loop waits for: from the window's pipe or from the line, on one channel,
/// so a frame goes out the moment it arrives. ([observed] A loop that polled the line
/// with a 2 ms socket read time-out woke only every 8 ms on Linux: socket time-outs are
/// kept in kernel ticks, so frames waited 4 ms on average.)
enum Event {
    Window(ToGuardian),
    WindowClosed(String),
    Line(Vec<u8>),
    LineLost(String),
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
    let line = match open_line(&open) {
        Ok(line) => line,
        Err(e) => {
            log(&e);
            let _ = wire::send(&mut out, &FromGuardian::Failed(e));
            return ExitCode::from(1);
        }
    };
    let Some(writer) = line.try_clone_writer() else {
        let e = "this line cannot be read and written from two threads".to_owned();
        log(&e);
        let _ = wire::send(&mut out, &FromGuardian::Failed(e.clone()));
        return ExitCode::from(1);
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
    let (events, from) = unbounded();
    read_window(input, events.clone());
    let done = Arc::new(AtomicBool::new(false));
    let reader = read_line(line, events, done.clone());
    let settings = &open.connection;
    let lease = Duration::from_millis(open.lease_ms);
    let mut core: Box<dyn Guard> = match &open.rmc {
        Some(rmc) => Box::new(RmcGuardianCore::new(
            Instant::now(),
            rmc.unit,
            lease,
            rmc.stop_decel,
        )),
        None => {
            let timing = Timing {
                line: settings.line(),
                ..Timing::default()
            };
            Box::new(GuardianCore::new(
                Instant::now(),
                crate::protocol::Station(settings.station),
                lease,
                timing,
            ))
        }
    };
    relay(core.as_mut(), writer, &from, &mut out);
    done.store(true, Ordering::Relaxed);
    if let Some(reader) = reader {
        let _ = reader.join();
    }
    log("line closed; exiting");
    ExitCode::SUCCESS
}

fn log(text: &str) {
    let _ = writeln!(io::stderr(), "guardian: {text}");
}

/// Opens a serial port or a TCP bridge; the built-in simulator lives in the window.
fn open_line(open: &OpenLine) -> Result<Box<dyn Transport>, String> {
    if let Some(rmc) = &open.rmc {
        return crate::link::TcpTransport::connect(&rmc.address, Duration::from_secs(2))
            .map(|t| Box::new(t) as Box<dyn Transport>)
            .map_err(|e| format!("cannot connect to the RMC151: {e}"));
    }
    let settings = &open.connection;
    if settings.kind == LineKind::Simulator {
        return Err("the built-in simulator runs in the window, not in a guardian".into());
    }
    settings.line().validate().map_err(|e| e.to_string())?;
    let model = crate::robot::RobotModel::default_model();
    let mut connection = Connection::prepare_in_process(settings, model);
    (connection.connector)(connection.line).map_err(|e| connection.open_error(&e))
}

/// A thread that reads the window's messages until the pipe closes.
fn read_window(mut input: BufReader<io::Stdin>, events: Sender<Event>) {
    let spawned = std::thread::Builder::new()
        .name("guardian-stdin".into())
        .spawn({
            let events = events.clone();
            move || {
                loop {
                    let next = match wire::receive::<ToGuardian>(&mut input) {
                        Ok(Some(m)) => Event::Window(m),
                        Ok(None) => Event::WindowClosed("the window's pipe closed".into()),
                        Err(e) => Event::WindowClosed(format!("the window's pipe failed: {e}")),
                    };
                    let last = matches!(next, Event::WindowClosed(_));
                    if events.send(next).is_err() || last {
                        return;
                    }
                }
            }
        });
    if let Err(e) = spawned {
        // No reader: act as if the window were gone (STOP if anything may move).
        let _ = events.send(Event::WindowClosed(format!(
            "cannot read the window's pipe: {e}"
        )));
    }
}

/// A thread that owns the line's reading side until the loop is done or the line fails.
fn read_line(
    mut line: Box<dyn Transport>,
    events: Sender<Event>,
    done: Arc<AtomicBool>,
) -> Option<std::thread::JoinHandle<()>> {
    let spawned = std::thread::Builder::new()
        .name("guardian-line".into())
        .spawn({
            let events = events.clone();
            move || {
                let mut buf = [0u8; 1024];
                while !done.load(Ordering::Relaxed) {
                    let lost = match line.read_timeout(&mut buf, READ_SLICE) {
                        Ok(0) => Some("the line closed".to_owned()),
                        Ok(n) => {
                            let _ = events.send(Event::Line(buf[..n].to_vec()));
                            None
                        }
                        Err(e) if crate::link::transport::is_timeout(&e) => None,
                        Err(e) => Some(format!("the line failed: {e}")),
                    };
                    if let Some(why) = lost {
                        let _ = events.send(Event::LineLost(why));
                        return;
                    }
                }
            }
        });
    match spawned {
        Ok(handle) => Some(handle),
        Err(e) => {
            let _ = events.send(Event::LineLost(format!("cannot read the line: {e}")));
            None
        }
    }
}

/// The loop: each event into the core, then the core's frames onto the line and its
/// messages to the window, until it is done (or the line is lost).
fn relay(
    core: &mut dyn Guard,
    mut writer: Box<dyn Write + Send>,
    events: &Receiver<Event>,
    out: &mut impl Write,
) {
    let mut window_open = true;
    loop {
        let wait = core
            .poll_timeout()
            .map_or(IDLE_WAIT, |t| t.saturating_duration_since(Instant::now()))
            .min(IDLE_WAIT);
        let event = match events.recv_timeout(wait) {
            Ok(e) => Some(e),
            Err(RecvTimeoutError::Timeout) => None,
            Err(RecvTimeoutError::Disconnected) => {
                Some(Event::WindowClosed("no more events".into()))
            }
        };
        let now = Instant::now();
        match event {
            Some(Event::Window(ToGuardian::Bytes(b))) => core.handle_window_bytes(now, &b),
            Some(Event::Window(ToGuardian::Heartbeat)) => core.handle_heartbeat(now),
            Some(Event::Window(ToGuardian::Open(_))) | None => {}
            Some(Event::WindowClosed(why)) => {
                if window_open {
                    log(&why);
                    window_open = false;
                    core.handle_window_closed(now);
                }
            }
            Some(Event::Line(bytes)) => core.handle_line_bytes(&bytes),
            Some(Event::LineLost(why)) => return line_lost(core, out, &why),
        }
        core.handle_timeout(Instant::now());
        while let Some(frame) = core.poll_transmit(Instant::now()) {
            if let Err(e) = writer.write_all(&frame).and_then(|()| writer.flush()) {
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
    }
}

/// The line is gone: the window hears it (its link reconnects with a new guardian).
fn line_lost(core: &mut dyn Guard, out: &mut impl Write, why: &str) {
    while let Some(text) = core.poll_log() {
        log(&text);
    }
    log(why);
    let _ = wire::send(out, &FromGuardian::Failed(why.to_owned()));
}
