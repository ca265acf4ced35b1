//! The guardian process (`xsel-pendant --guardian`): reads the line to open from stdin,
//! opens it, then runs [`GuardianCore`] between the pipe and the line until the window
//! is gone and no STOP is owed; then it closes the line and exits. What it does goes to
//! stderr, one line each, prefixed `guardian:`.
//!
//! Its loop never blocks on the window: messages for the window go through a bounded
//! outbox that a thread of its own writes to the pipe (line bytes nobody waits for are
//! dropped and counted when the window does not read), and the line's reader hands the
//! loop bounded chunks through a bounded queue (dropped and counted when full). So a
//! stopped window and a flooding line still get the silence STOP, in flat memory.

use std::collections::VecDeque;
use std::io::{self, BufReader, Write};
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Condvar, Mutex};
use std::time::{Duration, Instant};

use crossbeam_channel::{Receiver, Sender, TrySendError, bounded, never, select};

use super::core::GuardianCore;
use super::guard::{Guard, ToWindow, WindowGone};
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
/// Bytes the line's reader takes in one read.
const READ_CHUNK: usize = 4096;
/// Chunks of line bytes waiting for the loop at most (256 KiB); more are dropped and
/// counted (the loop takes them far faster than any line delivers, unless it is starved).
const LINE_QUEUE: usize = 64;
/// The window's messages waiting for the loop at most (its pipe holds the rest).
const WINDOW_QUEUE: usize = 256;
/// Line bytes nobody waits for that wait for the window's pipe at most.
const OUTBOX_BYTES: usize = 256 * 1024;
/// How long a guardian that lost its line waits for the window to take the news.
const FAREWELL: Duration = Duration::from_secs(2);
/// A count of dropped bytes is logged this often at most.
const DROP_REPORT: Duration = Duration::from_secs(5);

/// From the window's pipe. The loop waits on the window's and the line's events at once,
/// so a frame goes out the moment it arrives ([observed] a loop that polled the line with
/// a 2 ms socket read time-out woke only every 8 ms on Linux: socket time-outs are kept
/// in kernel ticks, so frames waited 4 ms on average), and takes the window's first.
enum WindowEvent {
    Message(ToGuardian),
    Gone(WindowGone, String),
}

/// From the line.
enum LineEvent {
    Bytes(Vec<u8>),
    Lost(String),
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
    let line = match open_line(&open) {
        Ok(line) => line,
        Err(e) => {
            log(&e);
            let _ = wire::send(&mut io::stdout().lock(), &FromGuardian::Failed(e));
            return ExitCode::from(1);
        }
    };
    let Some(writer) = line.try_clone_writer() else {
        let e = "this line cannot be read and written from two threads".to_owned();
        log(&e);
        let _ = wire::send(&mut io::stdout().lock(), &FromGuardian::Failed(e));
        return ExitCode::from(1);
    };
    let described = line.describe();
    log(&format!("{described} open"));
    let opened = FromGuardian::Opened {
        line: described,
        pid: std::process::id(),
    };
    if wire::send(&mut io::stdout().lock(), &opened).is_err() {
        return ExitCode::from(1);
    }
    let (window_tx, window_rx) = bounded(WINDOW_QUEUE);
    let (line_tx, line_rx) = bounded(LINE_QUEUE);
    let outbox = Arc::new(Outbox::default());
    write_window(outbox.clone(), window_tx.clone());
    read_window(input, window_tx);
    let done = Arc::new(AtomicBool::new(false));
    let line_dropped = Arc::new(AtomicU64::new(0));
    let reader = read_line(line, line_tx, done.clone(), line_dropped.clone());
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
    let mut relay = Relay {
        core: core.as_mut(),
        writer,
        outbox: &outbox,
        line_dropped: &line_dropped,
        window_open: true,
        reported: Drops::default(),
    };
    relay.run(&window_rx, &line_rx);
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

/// Messages for the window, written to its pipe by a thread of their own: the loop never
/// waits for a window that does not read. Line bytes nobody waits for are dropped (and
/// counted) past [`OUTBOX_BYTES`]; the rest (answers the window's link waits for, the
/// guardian's own news) is bounded by the protocol (one answer per command relayed).
#[derive(Default)]
struct Outbox {
    state: Mutex<OutboxState>,
    changed: Condvar,
}

#[derive(Default)]
struct OutboxState {
    /// Each message with the droppable bytes it holds.
    queue: VecDeque<(FromGuardian, usize)>,
    droppable: usize,
    /// Messages taken but not yet written.
    writing: usize,
    dropped: u64,
    /// The writer is gone (the pipe failed): nothing more is queued.
    broken: bool,
}

impl Outbox {
    fn lock(&self) -> std::sync::MutexGuard<'_, OutboxState> {
        self.state.lock().unwrap_or_else(|p| p.into_inner())
    }

    /// Queues `m` without waiting; a droppable one is dropped if the outbox is full.
    fn push(&self, m: ToWindow) {
        let mut state = self.lock();
        if state.broken {
            return;
        }
        let len = match (&m.message, m.droppable) {
            (FromGuardian::Bytes(b), true) => b.len(),
            _ => 0,
        };
        if len > 0 && state.droppable + len > OUTBOX_BYTES {
            state.dropped += len as u64;
            return;
        }
        state.droppable += len;
        state.queue.push_back((m.message, len));
        drop(state);
        self.changed.notify_all();
    }

    /// The next message to write (waits for one).
    fn take(&self) -> Option<FromGuardian> {
        let mut state = self.lock();
        loop {
            if state.broken {
                return None;
            }
            if let Some((m, len)) = state.queue.pop_front() {
                state.droppable -= len;
                state.writing += 1;
                return Some(m);
            }
            state = self.changed.wait(state).unwrap_or_else(|p| p.into_inner());
        }
    }

    fn written(&self, ok: bool) {
        let mut state = self.lock();
        state.writing -= 1;
        if !ok {
            state.broken = true;
            state.queue.clear();
            state.droppable = 0;
        }
        drop(state);
        self.changed.notify_all();
    }

    /// Line bytes dropped because the window did not read its pipe.
    fn dropped(&self) -> u64 {
        self.lock().dropped
    }

    /// Waits until everything queued was written (or the pipe failed), until `deadline`.
    fn flush(&self, deadline: Instant) {
        let mut state = self.lock();
        while !state.broken && (state.writing > 0 || !state.queue.is_empty()) {
            let left = deadline.saturating_duration_since(Instant::now());
            if left.is_zero() {
                return;
            }
            state = self
                .changed
                .wait_timeout(state, left)
                .unwrap_or_else(|p| p.into_inner())
                .0;
        }
    }
}

/// The thread that writes the outbox to the window's pipe (stdout); a pipe that fails
/// means the window is gone.
fn write_window(outbox: Arc<Outbox>, events: Sender<WindowEvent>) {
    let spawned = std::thread::Builder::new()
        .name("guardian-stdout".into())
        .spawn({
            let outbox = outbox.clone();
            let events = events.clone();
            move || {
                let mut out = io::stdout().lock();
                while let Some(m) = outbox.take() {
                    let sent = wire::send(&mut out, &m);
                    outbox.written(sent.is_ok());
                    if let Err(e) = sent {
                        let why = format!("cannot write to the window's pipe: {e}");
                        let _ = events.send(WindowEvent::Gone(WindowGone::Ended, why));
                        return;
                    }
                }
            }
        });
    if let Err(e) = spawned {
        outbox.lock().broken = true;
        let why = format!("no thread to write to the window's pipe: {e}");
        let _ = events.send(WindowEvent::Gone(WindowGone::Ended, why));
    }
}

/// A thread that reads the window's messages until the pipe closes or the window lets
/// go of the line. Its queue is bounded: a window that floods waits on its own pipe.
fn read_window(mut input: BufReader<io::Stdin>, events: Sender<WindowEvent>) {
    let spawned = std::thread::Builder::new()
        .name("guardian-stdin".into())
        .spawn({
            let events = events.clone();
            move || {
                loop {
                    let next = match wire::receive::<ToGuardian>(&mut input) {
                        Ok(Some(ToGuardian::LetGo)) => WindowEvent::Gone(
                            WindowGone::LetGo,
                            "the window let go of the line".into(),
                        ),
                        Ok(Some(m)) => WindowEvent::Message(m),
                        Ok(None) => WindowEvent::Gone(
                            WindowGone::Ended,
                            "the window's pipe closed without a word".into(),
                        ),
                        Err(e) => WindowEvent::Gone(
                            WindowGone::Ended,
                            format!("the window's pipe failed: {e}"),
                        ),
                    };
                    let last = matches!(next, WindowEvent::Gone(..));
                    if events.send(next).is_err() || last {
                        return;
                    }
                }
            }
        });
    if let Err(e) = spawned {
        // No reader: act as if the window were gone (STOP if anything may move).
        let _ = events.send(WindowEvent::Gone(
            WindowGone::Ended,
            format!("cannot read the window's pipe: {e}"),
        ));
    }
}

/// A thread that owns the line's reading side until the loop is done or the line fails.
/// It never waits for the loop: a chunk that finds the queue full is dropped and counted.
fn read_line(
    mut line: Box<dyn Transport>,
    events: Sender<LineEvent>,
    done: Arc<AtomicBool>,
    dropped: Arc<AtomicU64>,
) -> Option<std::thread::JoinHandle<()>> {
    let spawned = std::thread::Builder::new()
        .name("guardian-line".into())
        .spawn({
            let events = events.clone();
            move || {
                let mut buf = vec![0u8; READ_CHUNK];
                while !done.load(Ordering::Relaxed) {
                    let lost = match line.read_timeout(&mut buf, READ_SLICE) {
                        Ok(0) => Some("the line closed".to_owned()),
                        Ok(n) => match events.try_send(LineEvent::Bytes(buf[..n].to_vec())) {
                            Ok(()) => None,
                            Err(TrySendError::Full(_)) => {
                                dropped.fetch_add(n as u64, Ordering::Relaxed);
                                None
                            }
                            Err(TrySendError::Disconnected(_)) => return,
                        },
                        Err(e) if crate::link::transport::is_timeout(&e) => None,
                        Err(e) => Some(format!("the line failed: {e}")),
                    };
                    if let Some(why) = lost {
                        let _ = events.send(LineEvent::Lost(why));
                        return;
                    }
                }
            }
        });
    match spawned {
        Ok(handle) => Some(handle),
        Err(e) => {
            let _ = events.send(LineEvent::Lost(format!("cannot read the line: {e}")));
            None
        }
    }
}

/// What was dropped when it was last logged.
#[derive(Default)]
struct Drops {
    line: u64,
    window: u64,
    at: Option<Instant>,
}

/// The loop and what it drives: each event into the core, then the core's frames onto
/// the line, its messages into the outbox, until it is done (or the line is lost).
struct Relay<'a> {
    core: &'a mut dyn Guard,
    writer: Box<dyn Write + Send>,
    outbox: &'a Outbox,
    line_dropped: &'a AtomicU64,
    window_open: bool,
    reported: Drops,
}

enum Next {
    Window(WindowEvent),
    Line(LineEvent),
    Idle,
}

impl Relay<'_> {
    fn run(&mut self, window: &Receiver<WindowEvent>, line: &Receiver<LineEvent>) {
        let none = never();
        loop {
            let wait = self
                .core
                .poll_timeout()
                .map_or(IDLE_WAIT, |t| t.saturating_duration_since(Instant::now()))
                .min(IDLE_WAIT);
            // The window's events first: its end or its heartbeat never waits behind the
            // line's bytes. A channel whose senders are gone is waited on no more.
            let from_window = if self.window_open { window } else { &none };
            let next = match from_window.try_recv() {
                Ok(e) => Next::Window(e),
                Err(_) => select! {
                    recv(from_window) -> e => match e {
                        Ok(e) => Next::Window(e),
                        Err(_) => Next::Window(WindowEvent::Gone(
                            WindowGone::Ended,
                            "the window's pipe reader ended".into(),
                        )),
                    },
                    recv(line) -> e => Next::Line(
                        e.unwrap_or_else(|_| LineEvent::Lost("the line's reader ended".into())),
                    ),
                    default(wait) => Next::Idle,
                },
            };
            let now = Instant::now();
            match next {
                Next::Window(WindowEvent::Message(ToGuardian::Bytes(b))) => {
                    self.core.handle_window_bytes(now, &b);
                }
                Next::Window(WindowEvent::Message(ToGuardian::Heartbeat)) => {
                    self.core.handle_heartbeat(now);
                }
                Next::Window(WindowEvent::Message(ToGuardian::Open(_) | ToGuardian::LetGo))
                | Next::Idle => {}
                Next::Window(WindowEvent::Gone(how, why)) => self.window_gone(now, how, &why),
                Next::Line(LineEvent::Bytes(bytes)) => self.core.handle_line_bytes(&bytes),
                Next::Line(LineEvent::Lost(why)) => return self.line_lost(&why),
            }
            self.core.handle_timeout(Instant::now());
            while let Some(frame) = self.core.poll_transmit(Instant::now()) {
                if let Err(e) = self
                    .writer
                    .write_all(&frame)
                    .and_then(|()| self.writer.flush())
                {
                    return self.line_lost(&format!("cannot write to the line: {e}"));
                }
            }
            while let Some(text) = self.core.poll_log() {
                log(&text);
            }
            while let Some(m) = self.core.poll_for_window() {
                if self.window_open {
                    self.outbox.push(m);
                }
            }
            self.report_drops(Instant::now());
            if self.core.is_done() {
                while let Some(text) = self.core.poll_log() {
                    log(&text);
                }
                return;
            }
        }
    }

    fn window_gone(&mut self, now: Instant, how: WindowGone, why: &str) {
        if self.window_open {
            log(why);
            self.window_open = false;
            self.core.handle_window_gone(now, how);
        }
    }

    /// Says how many line bytes were dropped since it last did (at most every
    /// [`DROP_REPORT`]).
    fn report_drops(&mut self, now: Instant) {
        if self.reported.at.is_some_and(|at| now < at + DROP_REPORT) {
            return;
        }
        let line = self.line_dropped.load(Ordering::Relaxed);
        let window = self.outbox.dropped();
        if line > self.reported.line {
            log(&format!(
                "{} line bytes dropped: the line delivered faster than the guardian took them",
                line - self.reported.line
            ));
        }
        if window > self.reported.window {
            log(&format!(
                "{} line bytes dropped for the window: it does not read its pipe",
                window - self.reported.window
            ));
        }
        if line > self.reported.line || window > self.reported.window {
            self.reported = Drops {
                line,
                window,
                at: Some(now),
            };
        }
    }

    /// The line is gone: the window hears it (its link reconnects with a new guardian).
    fn line_lost(&mut self, why: &str) {
        while let Some(text) = self.core.poll_log() {
            log(&text);
        }
        log(why);
        if self.window_open {
            self.outbox.push(ToWindow {
                message: FromGuardian::Failed(why.to_owned()),
                droppable: false,
            });
            self.outbox.flush(Instant::now() + FAREWELL);
        }
    }
}
