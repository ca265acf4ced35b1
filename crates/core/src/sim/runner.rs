//! The simulator's IO thread: reads frames from a line (embedded pipe, pty, TCP), lets
//! the controller answer, applies the reply delay, faults and pacing, logs the traffic.
//! The pty and TCP servers live in [`super::servers`] (re-exported here).

use std::collections::VecDeque;
use std::io;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, MutexGuard};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use super::controller::Controller;
use super::faults::{FaultCounts, FaultInjector, FaultSpec};
use super::framing::{Assembler, Received, Silence, max_command};
use super::pipe::{PipeConfig, PipeEnd, duplex};
use super::state::{Counters, Mode};
use super::{SimSetup, describe_frame};
use crate::line::{Line, is_timeout, sleep_until, write_paced};

#[cfg(unix)]
pub use super::servers::{PtyServer, start_pty};
pub use super::servers::{TcpServer, start_tcp};

/// Direction of a logged frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Dir {
    /// Received from the client.
    In,
    /// Sent to the client (as planned: with any injected fault applied).
    Out,
}

/// One frame seen or sent, with the time since the simulator started.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TrafficEntry {
    pub at: Duration,
    pub dir: Dir,
    pub bytes: Vec<u8>,
    /// The injected fault, if any (`Out` only).
    pub fault: Option<&'static str>,
    /// Why the controller stayed silent (`In` only; `None` when it answered).
    pub silence: Option<Silence>,
}

/// How many traffic entries the core keeps (oldest dropped first).
pub const TRAFFIC_KEEP: usize = 4096;

/// What the IO thread and the control API share: the controller, the fault injector and
/// the recent traffic. Locked only for short moments (never during delays or pacing).
pub struct SimCore {
    pub controller: Controller,
    pub faults: FaultInjector,
    pub traffic: VecDeque<TrafficEntry>,
    started: Instant,
}

impl SimCore {
    pub fn new(controller: Controller, faults: FaultSpec) -> Self {
        Self {
            controller,
            faults: FaultInjector::new(faults),
            traffic: VecDeque::new(),
            started: Instant::now(),
        }
    }

    /// Time since the simulator started: the controller's clock.
    pub fn now(&self) -> Duration {
        self.started.elapsed()
    }

    /// When the simulator's clock started: [`TrafficEntry::at`] counts from here, so
    /// `started() + entry.at` is the entry's `Instant` (benches compare it with clicks).
    pub fn started(&self) -> Instant {
        self.started
    }

    fn record(&mut self, entry: TrafficEntry) {
        if self.traffic.len() >= TRAFFIC_KEEP {
            self.traffic.pop_front();
        }
        self.traffic.push_back(entry);
    }
}

/// Receives every frame in and out as it happens (the standalone binary prints them).
pub type LogFn = Box<dyn FnMut(&TrafficEntry) + Send>;

/// Receives one line about the line itself (clients, a full line, lost input); shared
/// with the line wrappers that notice such things.
pub type NoticeFn = Arc<dyn Fn(&str) + Send + Sync>;

/// How the runner treats its line.
pub struct RunOptions {
    /// Pace reply bytes at this time per byte (pty/TCP); `None` for the embedded pipe,
    /// which paces by itself.
    pub pacing: Option<Duration>,
    /// How often the world is advanced while the line is quiet and anything moves; at
    /// rest, at most every [`REST_TICK`] (a reply or a look at the controller advances
    /// it to the present first, so nothing is seen late).
    pub tick: Duration,
    /// Called for every frame in and out.
    pub log: Option<LogFn>,
    /// Called with one line for what happens to the line itself: a client connects,
    /// leaves or is refused, the line is full, input is lost.
    pub notice: Option<NoticeFn>,
    /// With pacing: write each reply piece whole when its last byte is due (TCP: one
    /// segment a reply, as serial-to-Ethernet bridges send lines) instead of byte by byte.
    pub coalesce: bool,
    /// The front panel's desk, served between frames (the window's Simulator pane).
    pub panel: Option<super::panel::PanelDesk>,
    /// TCP: a client that sends nothing for this long is dropped (logged) and the port
    /// serves the next one; `None`: never (the library's default; `xsel-sim` sets 60 s).
    pub idle_timeout: Option<Duration>,
}

/// The tick while the world is at rest: it only looks for a stop and serves the front
/// panel then, which may wait this long.
pub const REST_TICK: Duration = Duration::from_millis(100);

impl Default for RunOptions {
    fn default() -> Self {
        Self {
            pacing: None,
            // Replies advance the world themselves; the tick only moves it (and looks
            // for a stop) while the line is quiet: 50 wake-ups a second, not 500.
            tick: Duration::from_millis(20),
            log: None,
            notice: None,
            coalesce: false,
            panel: None,
            idle_timeout: None,
        }
    }
}

impl RunOptions {
    /// Passes one line to the notice sink, if any.
    pub fn notify(&self, line: &str) {
        if let Some(n) = &self.notice {
            n(line);
        }
    }
}

/// Why [`serve`] returned.
#[derive(Debug)]
pub enum ServeEnd {
    /// The stop flag was set.
    Stopped,
    /// The other end closed the line.
    Closed,
    /// The line failed.
    Failed(io::Error),
}

pub(crate) fn lock(shared: &Mutex<SimCore>) -> MutexGuard<'_, SimCore> {
    // The core holds plain data; a panic while holding it leaves it usable.
    shared.lock().unwrap_or_else(|p| p.into_inner())
}

/// Serves one line until it closes, fails or `stop` is set.
pub fn serve(
    line: &mut dyn Line,
    shared: &Mutex<SimCore>,
    stop: &AtomicBool,
    opts: &mut RunOptions,
) -> ServeEnd {
    crate::line::wake_on_time();
    let limit = max_command(lock(shared).controller.config().reply_buffer);
    let mut assembler = Assembler::with_limit(limit);
    let mut buf = [0u8; 512];
    let mut reply = Vec::with_capacity(2048);
    loop {
        if stop.load(Ordering::Relaxed) {
            return ServeEnd::Stopped;
        }
        let tick = if lock(shared).controller.at_rest() {
            opts.tick.max(REST_TICK)
        } else {
            opts.tick
        };
        let n = match line.read_timeout(&mut buf, tick) {
            Ok(0) => return ServeEnd::Closed,
            Ok(n) => n,
            Err(e) if is_timeout(&e) => 0,
            Err(e) => return ServeEnd::Failed(e),
        };
        let arrived = Instant::now();
        for (k, &byte) in buf[..n].iter().enumerate() {
            match assembler.push(byte) {
                None => {}
                Some(Received::Frame(frame)) => {
                    if let Err(e) = answer(line, shared, frame, arrived, &mut reply, opts) {
                        let unread = n - k - 1 + assembler.pending_len();
                        lost(shared, opts, &e, unread);
                        return ServeEnd::Failed(e);
                    }
                }
                Some(Received::Dropped { bytes, reason }) => {
                    dropped(shared, bytes, reason, arrived, opts);
                }
            }
        }
        if n == 0 || opts.panel.is_some() {
            let mut core = lock(shared);
            if n == 0 {
                let now = core.now();
                core.controller.advance(now);
            }
            if let Some(desk) = opts.panel.as_mut() {
                desk.serve(&mut core.controller);
            }
        }
    }
}

/// Logs and counts what a failed write leaves unserved: the reply, and the input
/// already read after its frame (it is never answered: the line is gone).
fn lost(shared: &Mutex<SimCore>, opts: &RunOptions, e: &io::Error, unread: usize) {
    lock(shared).controller.note_lost(1, unread as u64);
    opts.notify(&format!(
        "line failed while sending a reply ({e}): that reply and {unread} bytes of input \
         already read are lost"
    ));
}

/// Logs and counts a run the assembler dropped: it never reaches the controller's parser.
fn dropped(
    shared: &Mutex<SimCore>,
    bytes: &[u8],
    reason: Silence,
    arrived: Instant,
    opts: &mut RunOptions,
) {
    let mut core = lock(shared);
    let at = arrived.saturating_duration_since(core.started);
    core.controller.note_dropped(reason, at);
    let entry = TrafficEntry {
        at,
        dir: Dir::In,
        bytes: bytes.to_vec(),
        fault: None,
        silence: Some(reason),
    };
    if let Some(log) = opts.log.as_mut() {
        log(&entry);
    }
    core.record(entry);
}

/// Handles one frame: controller, delay, faults, pacing, logging.
fn answer(
    line: &mut dyn Line,
    shared: &Mutex<SimCore>,
    frame: &[u8],
    arrived: Instant,
    reply: &mut Vec<u8>,
    opts: &mut RunOptions,
) -> io::Result<()> {
    let (delivery, delay, started) = {
        let mut core = lock(shared);
        let at = arrived.saturating_duration_since(core.started);
        let silence = core.controller.answer(frame, at, reply).err();
        let entry = TrafficEntry {
            at,
            dir: Dir::In,
            bytes: frame.to_vec(),
            fault: None,
            silence,
        };
        if let Some(log) = opts.log.as_mut() {
            log(&entry);
        }
        core.record(entry);
        if silence.is_some() {
            return Ok(());
        }
        let delivery = core.faults.plan(reply);
        (delivery, core.controller.reply_delay(), core.started)
    };
    let mut start = arrived + delay;
    for piece in &delivery.pieces {
        start += piece.pause;
        sleep_until(start);
        match opts.pacing {
            Some(bt) if opts.coalesce => {
                // The whole piece leaves when its last byte would have left the wire.
                start += bt.saturating_mul(piece.bytes.len() as u32);
                sleep_until(start);
                line.write_all_bytes(&piece.bytes)?;
            }
            Some(bt) => {
                write_paced(line, &piece.bytes, bt, start)?;
                start += bt.saturating_mul(piece.bytes.len() as u32);
            }
            None => line.write_all_bytes(&piece.bytes)?,
        }
    }
    let entry = TrafficEntry {
        at: start.saturating_duration_since(started),
        dir: Dir::Out,
        bytes: delivery
            .pieces
            .iter()
            .flat_map(|p| p.bytes.iter().copied())
            .collect(),
        fault: delivery.fault.map(|f| f.key()),
        silence: None,
    };
    if let Some(log) = opts.log.as_mut() {
        log(&entry);
    }
    lock(shared).record(entry);
    Ok(())
}

/// Formats a traffic entry as one log line: time, direction, bytes, decoded summary.
pub fn format_entry(entry: &TrafficEntry) -> String {
    format_entry_cut(entry, usize::MAX)
}

/// As [`format_entry`], showing at most the first `shown` bytes followed by
/// "… (N more bytes)"; the summary is always of the whole entry, so a cut never makes up
/// a reason (such as a missing CR LF).
pub fn format_entry_cut(entry: &TrafficEntry, shown: usize) -> String {
    let arrow = match entry.dir {
        Dir::In => "rx",
        Dir::Out => "tx",
    };
    let head = entry.bytes.get(..shown).unwrap_or(&entry.bytes);
    let more = match entry.bytes.len() - head.len() {
        0 => String::new(),
        n => format!("… ({n} more bytes)"),
    };
    let text: String = head
        .iter()
        .map(|&b| match b {
            b'\r' => "\\r".to_owned(),
            b'\n' => "\\n".to_owned(),
            0x20..=0x7E => (b as char).to_string(),
            _ => format!("\\x{b:02X}"),
        })
        .collect();
    let fault = entry
        .fault
        .map(|f| format!("  [fault: {f}]"))
        .unwrap_or_default();
    let silence = entry
        .silence
        .map(|s| format!("  [silent: {}]", s.text()))
        .unwrap_or_default();
    format!(
        "[{:>10.6}] {arrow} {text}{more}  {}{fault}{silence}",
        entry.at.as_secs_f64(),
        describe_frame(&entry.bytes)
    )
}

/// Options of the embedded simulator.
pub struct EmbeddedOptions {
    pub setup: SimSetup,
    /// Wire time of one byte on the pipe, both directions (`None` = instant).
    pub byte_time: Option<Duration>,
    /// Read timeout of the pendant's end of the pipe.
    pub read_timeout: Duration,
    pub faults: FaultSpec,
    /// Called for every frame in and out (on the simulator's thread).
    pub log: Option<LogFn>,
    /// The front panel's desk, served between frames.
    pub panel: Option<super::panel::PanelDesk>,
}

impl Default for EmbeddedOptions {
    fn default() -> Self {
        Self {
            setup: SimSetup::default(),
            byte_time: None,
            read_timeout: Duration::from_millis(50),
            faults: FaultSpec::none(),
            log: None,
            panel: None,
        }
    }
}

/// Starts the simulator on its own thread, joined to the returned pipe end by an
/// in-memory duplex line; the world ticks in real time. Dropping the pipe end or the
/// handle ends the thread.
pub fn start_embedded(opts: EmbeddedOptions) -> (PipeEnd, SimHandle) {
    let config = PipeConfig {
        byte_time: opts.byte_time,
        read_timeout: opts.read_timeout,
    };
    let (pendant, mut sim_end) = duplex(config);
    let core = SimCore::new(Controller::new(opts.setup), opts.faults);
    let mut run = RunOptions {
        pacing: None,
        log: opts.log,
        panel: opts.panel,
        ..RunOptions::default()
    };
    let handle = SimHandle::spawn(core, move |shared, stop| {
        serve(&mut sim_end, shared, stop, &mut run);
    });
    (pendant, handle)
}

/// A second view of a simulator's controller and traffic; see [`SimHandle::watch`].
#[derive(Clone)]
pub struct SimWatch(Arc<Mutex<SimCore>>);

impl SimWatch {
    /// Runs `f` on the controller, after advancing it to the present.
    pub fn with<R>(&self, f: impl FnOnce(&mut Controller) -> R) -> R {
        let mut core = lock(&self.0);
        let now = core.now();
        core.controller.advance(now);
        f(&mut core.controller)
    }

    /// The recent traffic, oldest first.
    pub fn traffic(&self) -> Vec<TrafficEntry> {
        lock(&self.0).traffic.iter().cloned().collect()
    }
}

/// Owner's handle of a running simulator: control API, counters, stop/join.
/// Dropping it stops the thread and waits for it.
pub struct SimHandle {
    shared: Arc<Mutex<SimCore>>,
    stop: Arc<AtomicBool>,
    thread: Option<JoinHandle<()>>,
}

impl SimHandle {
    /// Runs `body` on a new thread with the shared core and the stop flag.
    pub fn spawn(
        core: SimCore,
        body: impl FnOnce(&Mutex<SimCore>, &AtomicBool) + Send + 'static,
    ) -> SimHandle {
        let shared = Arc::new(Mutex::new(core));
        let stop = Arc::new(AtomicBool::new(false));
        let thread = {
            let shared = shared.clone();
            let stop = stop.clone();
            std::thread::Builder::new()
                .name("xsel-sim".into())
                .spawn(move || body(&shared, &stop))
                .ok()
        };
        SimHandle {
            shared,
            stop,
            thread,
        }
    }

    /// Runs `f` on the controller, after advancing it to the present.
    pub fn with<R>(&self, f: impl FnOnce(&mut Controller) -> R) -> R {
        self.watch().with(f)
    }

    /// A view of the controller that outlives this handle: a test can read what the
    /// arm did after the pendant (and the simulator with it) was closed.
    pub fn watch(&self) -> SimWatch {
        SimWatch(self.shared.clone())
    }

    /// Runs `f` on the whole core (controller, faults, traffic).
    pub fn with_core<R>(&self, f: impl FnOnce(&mut SimCore) -> R) -> R {
        f(&mut lock(&self.shared))
    }

    pub fn set_emergency_stop(&self, on: bool) {
        self.with(|c| c.set_emergency_stop(on));
    }

    pub fn set_mode(&self, mode: Mode) {
        self.with(|c| c.set_mode(mode));
    }

    pub fn set_drive_cut_off(&self, on: bool) {
        self.with(|c| c.set_drive_cut_off(on));
    }

    /// Replaces the work and tool coordinate tables (as `--coords` would at start):
    /// the next 2A4H answers from them.
    pub fn set_coords(&self, tables: crate::robot::CoordTables) {
        self.with(|c| c.set_coords(tables));
    }

    /// Selects the work coordinate system number; `false` if it is outside the table.
    pub fn select_work(&self, number: usize) -> bool {
        self.with(|c| c.select_work(number))
    }

    /// Selects the tool coordinate system number; `false` if it is outside the table.
    pub fn select_tool(&self, number: usize) -> bool {
        self.with(|c| c.select_tool(number))
    }

    /// Raises an alarm: servos go off, moves are cancelled, commands that act are
    /// refused until 252H resets it.
    pub fn raise_alarm(&self, code: u16, axis: Option<u8>) {
        self.with(|c| c.raise_alarm(code, axis, "alarm raised through the control API"));
    }

    pub fn counters(&self) -> Counters {
        self.with(|c| *c.counters())
    }

    pub fn fault_counts(&self) -> FaultCounts {
        lock(&self.shared).faults.counts()
    }

    /// Replaces the fault spec (counts are kept).
    pub fn set_faults(&self, spec: FaultSpec) {
        lock(&self.shared).faults.set_spec(spec);
    }

    /// The recent traffic, oldest first.
    pub fn traffic(&self) -> Vec<TrafficEntry> {
        self.watch().traffic()
    }

    /// Asks the thread to stop (it notices within one tick).
    pub fn stop(&self) {
        self.stop.store(true, Ordering::Relaxed);
    }

    /// Stops the thread and waits for it.
    pub fn join(mut self) {
        self.stop_and_join();
    }

    fn stop_and_join(&mut self) {
        self.stop();
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }

    /// True while the thread runs.
    pub fn is_running(&self) -> bool {
        self.thread.as_ref().is_some_and(|t| !t.is_finished())
    }
}

impl Drop for SimHandle {
    fn drop(&mut self) {
        self.stop_and_join();
    }
}
