//! The pendant's text mode: opens the line, polls the controller and prints what it reads.

use std::io::{self, Write};
use std::process::ExitCode;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use crate::cli::{Args, Connection, connection};
use crate::link::event::printable;
use crate::link::{LinkConfig, LinkEvent, spawn};
use crate::protocol::{AxisUnit, HomeState, Reply, ScaraStatus, SystemStatus};

/// How long a run without `--watch` polls before printing its summary.
const ONE_SHOT: Duration = Duration::from_secs(2);
/// How often `--watch` prints the arm's position.
const WATCH_EVERY: Duration = Duration::from_millis(500);
/// At most one "bad input" line this often.
const BAD_INPUT_EVERY: Duration = Duration::from_secs(1);
/// At most this many characters of bad bytes in one line.
const BAD_INPUT_SAMPLE: usize = 200;

/// Runs the text mode with parsed flags: 0 when the controller answered, 1 when the line
/// could not be opened or nothing was read, 2 for a bad flag. A closed stdout ends the
/// run quietly (exit 0).
pub fn run(args: &Args) -> ExitCode {
    let conn = match connection(args) {
        Ok(c) => c,
        Err(e) => {
            complain(&e.to_string());
            return ExitCode::from(2);
        }
    };
    match Session::start(args, conn).and_then(Session::run) {
        Ok(code) => code,
        Err(Stop::Closed) => ExitCode::SUCCESS,
        Err(Stop::Failed(msg)) => {
            complain(&msg);
            ExitCode::FAILURE
        }
    }
}

/// One line on stderr; a closed stderr is ignored.
fn complain(msg: &str) {
    let _ = writeln!(io::stderr(), "xsel-pendant: {msg}");
}

/// Why a run ended early.
enum Stop {
    /// stdout was closed (`| head`): end quietly.
    Closed,
    /// Something to tell the user on stderr.
    Failed(String),
}

impl From<io::Error> for Stop {
    fn from(_: io::Error) -> Self {
        Stop::Closed
    }
}

/// Bad input seen since the last line about it.
#[derive(Default)]
struct BadInput {
    chunks: u64,
    bytes: u64,
    sample: String,
    /// Why the first chunk was bad (wrong length for its ID, another station...).
    reason: String,
    last_print: Option<Instant>,
}

impl BadInput {
    fn add(&mut self, bytes: &[u8], more: usize, reason: &dyn std::fmt::Display) {
        if self.chunks == 0 {
            self.reason = reason.to_string();
            let head = printable(&bytes[..bytes.len().min(BAD_INPUT_SAMPLE)]);
            self.sample = head.chars().take(BAD_INPUT_SAMPLE).collect();
            if bytes.len() > BAD_INPUT_SAMPLE || more > 0 || self.sample.len() < head.len() {
                self.sample.push_str("...");
            }
        }
        self.chunks += 1;
        self.bytes += (bytes.len() + more) as u64;
    }

    /// The line to print now, if any and if the last one is old enough.
    fn due(&mut self, now: Instant, force: bool) -> Option<String> {
        if self.chunks == 0 {
            return None;
        }
        if !force && self.last_print.is_some_and(|t| now - t < BAD_INPUT_EVERY) {
            return None;
        }
        let text = if self.chunks == 1 {
            format!(
                "link: bad input ({} bytes, {}): {}",
                self.bytes, self.reason, self.sample
            )
        } else {
            format!(
                "link: bad input: {} chunks, {} bytes{}, first ({}): {}",
                self.chunks,
                self.bytes,
                self.last_print.map_or(String::new(), |t| format!(
                    " in {:.1} s",
                    (now - t).as_secs_f64()
                )),
                self.reason,
                self.sample
            )
        };
        self.chunks = 0;
        self.bytes = 0;
        self.last_print = Some(now);
        Some(text)
    }
}

/// A running text session.
struct Session {
    watch: bool,
    link: crate::link::LinkHandle,
    /// The embedded simulator, dropped after the link.
    _sim: Option<crate::sim::SimHandle>,
    events: crossbeam_channel::Receiver<LinkEvent>,
    out: io::StdoutLock<'static>,
    stop: Arc<AtomicBool>,
    line_up: bool,
    system: Option<SystemStatus>,
    scara: Option<ScaraStatus>,
    /// A status read since the last position line.
    scara_fresh: bool,
    health: Option<crate::link::health::LinkHealth>,
    last_system_line: Option<String>,
    bad: BadInput,
}

impl Session {
    fn start(args: &Args, mut conn: Connection) -> Result<Session, Stop> {
        conn.open_now().map_err(Stop::Failed)?;
        let Connection {
            connector,
            sim,
            line,
            ..
        } = conn;
        let mut config = LinkConfig {
            station: args.station,
            auto_reconnect: args.watch,
            ..LinkConfig::default()
        };
        config.timing.line = line;
        let (link, events) = spawn(connector, config, Arc::new(|_| {}))
            .map_err(|e| Stop::Failed(format!("cannot start the link thread: {e}")))?;
        let stop = Arc::new(AtomicBool::new(false));
        if args.watch {
            let stop = stop.clone();
            // Ctrl-C ends the watch loop, so the link shuts down (and stops any motion).
            let _ = ctrlc::set_handler(move || stop.store(true, Ordering::Relaxed));
        }
        let mut out = io::stdout().lock();
        writeln!(out, "xsel-pendant {}", env!("CARGO_PKG_VERSION"))?;
        writeln!(
            out,
            "text mode: the X-SEL controller only; the RMC151's axes are shown in the window"
        )?;
        Ok(Session {
            watch: args.watch,
            link,
            _sim: sim,
            events,
            out,
            stop,
            line_up: false,
            system: None,
            scara: None,
            scara_fresh: false,
            health: None,
            last_system_line: None,
            bad: BadInput::default(),
        })
    }

    fn run(mut self) -> Result<ExitCode, Stop> {
        let start = Instant::now();
        let mut next_watch = start + WATCH_EVERY;
        while !self.stop.load(Ordering::Relaxed) && (self.watch || start.elapsed() < ONE_SHOT) {
            if let Ok(ev) = self.events.recv_timeout(Duration::from_millis(100)) {
                self.handle(ev)?;
                // Keep up with a burst: take what is already there without waiting.
                for _ in 0..10_000 {
                    let Ok(ev) = self.events.try_recv() else {
                        break;
                    };
                    self.handle(ev)?;
                }
            }
            let now = Instant::now();
            if let Some(line) = self.bad.due(now, false) {
                writeln!(self.out, "{line}")?;
            }
            if self.watch && now >= next_watch {
                next_watch = now + WATCH_EVERY;
                self.print_watch()?;
            }
        }
        if let Some(line) = self.bad.due(Instant::now(), true) {
            writeln!(self.out, "{line}")?;
        }
        self.summary(start.elapsed())
    }

    fn handle(&mut self, ev: LinkEvent) -> Result<(), Stop> {
        match ev {
            LinkEvent::Reply {
                reply: Reply::SystemStatus(s),
                ..
            } => self.system = Some(s),
            LinkEvent::Reply {
                reply: Reply::ScaraStatus(s),
                ..
            } => {
                self.scara = Some(s);
                self.scara_fresh = true;
            }
            LinkEvent::Health(h) => self.health = Some(h),
            LinkEvent::Garbage {
                ref bytes,
                more,
                ref error,
                ..
            } => self.bad.add(bytes, more, error),
            LinkEvent::Connected { .. } | LinkEvent::Reconnected { .. } => {
                self.line_up = true;
                writeln!(self.out, "link: {}", ev.summary())?;
            }
            LinkEvent::Disconnected { .. } => {
                // What was read before is no longer current.
                self.line_up = false;
                self.scara_fresh = false;
                self.last_system_line = None;
                writeln!(self.out, "link: {}", ev.summary())?;
            }
            LinkEvent::Timeout { .. } | LinkEvent::ErrorReply { .. } => {
                writeln!(self.out, "link: {}", ev.summary())?;
            }
            _ => {}
        }
        Ok(())
    }

    /// `--watch`: the controller line when it changed, the position when freshly read.
    fn print_watch(&mut self) -> Result<(), Stop> {
        if !self.line_up {
            return Ok(());
        }
        if let Some(s) = &self.system {
            let line = system_line(s);
            if self.last_system_line.as_ref() != Some(&line) {
                writeln!(self.out, "{line}")?;
                self.last_system_line = Some(line);
            }
        }
        if let Some(s) = self.scara.as_ref().filter(|_| self.scara_fresh) {
            writeln!(self.out, "{}", scara_line(s))?;
            self.scara_fresh = false;
        }
        Ok(())
    }

    fn summary(mut self, ran: Duration) -> Result<ExitCode, Stop> {
        let stale = if self.line_up {
            ""
        } else {
            " (last known; the line is down)"
        };
        match (&self.system, &self.scara) {
            (Some(sys), Some(sc)) => {
                writeln!(self.out, "{}{stale}\n{}", system_line(sys), scara_line(sc))?
            }
            _ => writeln!(
                self.out,
                "no status was read from the controller in {:.1} s",
                ran.as_secs_f64()
            )?,
        }
        if let Some(h) = &self.health {
            writeln!(
                self.out,
                "link: {} transactions, {} timeouts, {:.0} polls/s, median round trip {}",
                h.transactions,
                h.timeouts,
                h.polls_per_second,
                h.median_round_trip
                    .map_or("-".into(), |d| format!("{:.1} ms", d.as_secs_f64() * 1e3))
            )?;
        }
        writeln!(
            self.out,
            "\nText mode: the X-SEL controller's state once. The window (run without --headless)\n\
             jogs, edits coordinate tables and shows the arm, the traffic and the RMC151's axes;\n\
             `--watch` keeps polling; `xsel-sim --help` serves the simulator on its own\n\
             (`cargo run --bin xsel-sim -- --help` from the source tree)."
        )?;
        self.out.flush()?;
        drop(self.link);
        Ok(if self.system.is_some() {
            ExitCode::SUCCESS
        } else {
            ExitCode::FAILURE
        })
    }
}

fn system_line(s: &SystemStatus) -> String {
    format!(
        "controller: {} mode, {}, E-stop {}, drive source {}, errors: critical {} latest {}",
        s.mode.name().unwrap_or("unknown"),
        if s.status3.ready() {
            "ready"
        } else {
            "not ready"
        },
        if s.status1.emergency_stop() {
            "ACTIVE"
        } else {
            "off"
        },
        if s.status3.drive_cut_off() {
            "CUT OFF"
        } else {
            "on"
        },
        s.critical_error,
        s.latest_error,
    )
}

fn scara_line(s: &ScaraStatus) -> String {
    let names = ["X", "Y", "Z", "R"];
    let mut text = format!(
        "SCARA: work #{} tool #{}, arm {:?}, {:?} coordinates:",
        s.work, s.tool, s.common.arm, s.common.system
    );
    for (i, (axis, state)) in s.axes.iter().enumerate() {
        let unit = if axis.is_scara_r() {
            AxisUnit::Deg
        } else {
            AxisUnit::Mm
        };
        let home = match state.status.home_state() {
            HomeState::Done => "homed",
            HomeState::Homing => "homing",
            _ => "not homed",
        };
        let servo = if state.status.servo_on() {
            "servo on"
        } else {
            "servo off"
        };
        text.push_str(&format!(
            "\n  {} {:>12}  {servo}, {home}",
            names.get(i).copied().unwrap_or("?"),
            state.position.with_unit(unit).to_string()
        ));
    }
    text
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bad_input_is_summed_and_printed_at_most_once_a_second() {
        let mut bad = BadInput::default();
        let t0 = Instant::now();
        assert_eq!(bad.due(t0, false), None);
        bad.add(&[b'x'; 16 * 1024], 0, &"no ! header");
        let first = bad.due(t0, false).unwrap();
        assert!(
            first.contains("16384 bytes, no ! header") && first.len() < 300,
            "{first}"
        );
        for _ in 0..100 {
            bad.add(&[0xFF; 16 * 1024], 0, &"reply from station 03, not 99");
        }
        assert_eq!(bad.due(t0 + Duration::from_millis(500), false), None);
        let later = bad.due(t0 + BAD_INPUT_EVERY, false).unwrap();
        assert!(later.contains("100 chunks, 1638400 bytes"), "{later}");
        assert!(later.contains("first (reply from station 03"), "{later}");
        assert!(later.len() < 300, "{} characters", later.len());
        assert_eq!(bad.due(t0 + 3 * BAD_INPUT_EVERY, true), None);
    }
}
