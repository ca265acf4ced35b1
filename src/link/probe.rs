//! Connection auto-detect: tries baud rates, framings and stations with 215H and reports what answered.

mod classify;
mod error;
mod plan;

use std::io;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use crossbeam_channel::{Receiver, unbounded};

use super::line::LineSettings;
use super::timing::Timing;
use super::transport::{SerialTransport, Transport, is_timeout};
use crate::protocol::Command;

pub use classify::{Attempt, Outcome, classify};
pub use error::ProbeError;
pub use plan::{
    Candidate, Framing, LIKELY_BAUDS, MORE_FRAMINGS, ProbePlan, estimate_duration, station_sweep,
};

/// Longest single read, so a cancel is seen within about this time.
const READ_SLICE: Duration = Duration::from_millis(20);

/// One candidate tried and what it got.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ProbeResult {
    pub candidate: Candidate,
    pub outcome: Outcome,
}

/// Why a probe ended.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum ProbeEnd {
    /// A controller answered (and "probe all" was off).
    Found,
    /// Every candidate was tried.
    Exhausted,
    /// The cancel flag was set.
    Cancelled,
    /// The port could not be opened or failed; the probe stopped there.
    Failed(ProbeError),
}

/// Everything a probe learned. The port is closed by the time a report exists.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ProbeReport {
    pub port: String,
    /// Every candidate tried, in order.
    pub results: Vec<ProbeResult>,
    /// How many candidates the plan had.
    pub total: usize,
    pub end: ProbeEnd,
}

impl ProbeReport {
    /// The first candidate a controller answered (normally or with an error reply).
    pub fn found(&self) -> Option<&ProbeResult> {
        self.results.iter().find(|r| r.outcome.is_controller())
    }

    /// Every candidate a controller answered ("probe all" may find several).
    pub fn answered(&self) -> impl Iterator<Item = &ProbeResult> {
        self.results.iter().filter(|r| r.outcome.is_controller())
    }

    /// One line for the connection panel.
    pub fn summary(&self) -> String {
        let tried = self.results.len();
        let garbage = self
            .results
            .iter()
            .filter(|r| matches!(r.outcome, Outcome::Garbage { .. }))
            .count();
        let found = self
            .found()
            .map(|r| format!("{}: {}", r.candidate, r.outcome));
        match (&self.end, found) {
            (ProbeEnd::Failed(e), None) => e.to_string(),
            (ProbeEnd::Failed(e), Some(found)) => {
                format!("found on {}: {found}; then stopped: {e}", self.port)
            }
            (_, Some(found)) => format!("found on {}: {found}", self.port),
            (ProbeEnd::Cancelled, None) => {
                format!("cancelled after {tried} of {} candidates", self.total)
            }
            (_, None) if garbage > 0 => format!(
                "no controller answered on {} ({tried} tried; {garbage} got bytes that do not \
                 decode: a wrong baud rate or parity, or another device)",
                self.port
            ),
            (_, None) => format!(
                "no controller answered on {} ({tried} tried, all silent: check the cable, \
                 that the controller is in AUTO with I/O parameter 90 = 2, and its station)",
                self.port
            ),
        }
    }
}

/// Progress and results, in order; `Finished` is always the last event.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum ProbeEvent {
    /// About to send candidate number `tried + 1` of `total`.
    Trying {
        tried: usize,
        total: usize,
        candidate: Candidate,
    },
    /// `tried` of `total` candidates done; this is the latest.
    Tried {
        tried: usize,
        total: usize,
        result: ProbeResult,
    },
    /// The probe is over and the port closed.
    Finished(ProbeReport),
}

/// Opens a line with the given settings (a serial port, or a stand-in in tests).
pub type Opener<'a> = dyn FnMut(LineSettings) -> io::Result<Box<dyn Transport>> + 'a;

/// Probes the serial port `port` with `plan` on the calling thread (run it on a worker
/// thread). Reports through `on_event` and returns the same report as `Finished`.
/// Stops within about 20 ms (plus an open in progress) once `cancel` is set.
pub fn probe_port(
    port: &str,
    plan: &ProbePlan,
    cancel: &AtomicBool,
    on_event: &mut dyn FnMut(ProbeEvent),
) -> ProbeReport {
    let mut open = |line: LineSettings| {
        SerialTransport::open(port, line).map(|t| Box::new(t) as Box<dyn Transport>)
    };
    probe_with(&mut open, port, plan, cancel, on_event)
}

/// As [`probe_port`], opening each setting with `open` (`name` is the port's name in
/// messages). The line is dropped before the next setting is opened, and before
/// `Finished` is reported.
pub fn probe_with(
    open: &mut Opener<'_>,
    name: &str,
    plan: &ProbePlan,
    cancel: &AtomicBool,
    on_event: &mut dyn FnMut(ProbeEvent),
) -> ProbeReport {
    let candidates = plan.candidates();
    let mut report = ProbeReport {
        port: name.to_owned(),
        results: Vec::new(),
        total: candidates.len(),
        end: ProbeEnd::Exhausted,
    };
    if let Err(e) = plan.validate() {
        report.end = ProbeEnd::Failed(e);
    } else {
        report.end = run(open, name, plan, &candidates, cancel, &mut |ev| {
            if let ProbeEvent::Tried { result, .. } = &ev {
                report.results.push(result.clone());
            }
            on_event(ev);
        });
    }
    on_event(ProbeEvent::Finished(report.clone()));
    report
}

/// The candidate loop; the open line lives only inside it.
fn run(
    open: &mut Opener<'_>,
    name: &str,
    plan: &ProbePlan,
    candidates: &[Candidate],
    cancel: &AtomicBool,
    emit: &mut dyn FnMut(ProbeEvent),
) -> ProbeEnd {
    let total = candidates.len();
    let mut line: Option<(LineSettings, Box<dyn Transport>)> = None;
    for (tried, &candidate) in candidates.iter().enumerate() {
        if cancel.load(Ordering::Relaxed) {
            return ProbeEnd::Cancelled;
        }
        if line.as_ref().map(|(s, _)| *s) != Some(candidate.line) {
            // Close first: the port is opened exclusively.
            drop(line.take());
            match open(candidate.line) {
                Ok(t) => line = Some((candidate.line, t)),
                Err(e) => return ProbeEnd::Failed(ProbeError::from_open(name, candidate.line, e)),
            }
        }
        let Some((_, transport)) = line.as_mut() else {
            return ProbeEnd::Exhausted;
        };
        emit(ProbeEvent::Trying {
            tried,
            total,
            candidate,
        });
        let outcome = match probe_one(transport.as_mut(), candidate, plan.margin, cancel) {
            Ok(Some(outcome)) => outcome,
            Ok(None) => return ProbeEnd::Cancelled,
            Err(e) => return ProbeEnd::Failed(ProbeError::from_line(name, candidate.line, e)),
        };
        let found = outcome.is_controller();
        emit(ProbeEvent::Tried {
            tried: tried + 1,
            total,
            result: ProbeResult { candidate, outcome },
        });
        if found && !plan.probe_all {
            return ProbeEnd::Found;
        }
    }
    ProbeEnd::Exhausted
}

/// Sends one 215H and classifies what comes back before the reply time-out; `None` when
/// cancelled.
fn probe_one(
    t: &mut dyn Transport,
    candidate: Candidate,
    margin: Duration,
    cancel: &AtomicBool,
) -> io::Result<Option<Outcome>> {
    // Leftovers of an earlier candidate (or noise from opening) must not count here.
    t.discard_input()?;
    let mut attempt = Attempt::new(candidate.station);
    t.write_all_bytes(attempt.command())?;
    let timing = Timing {
        line: candidate.line,
        margin,
        ..Timing::default()
    };
    let timeout = timing.reply_timeout(
        attempt.command().len(),
        Command::SystemStatus.max_reply_len(),
    );
    let deadline = Instant::now() + timeout;
    let mut buf = [0u8; 256];
    while !attempt.is_settled() {
        if cancel.load(Ordering::Relaxed) {
            return Ok(None);
        }
        let left = deadline.saturating_duration_since(Instant::now());
        if left.is_zero() {
            break;
        }
        match t.read_timeout(&mut buf, left.min(READ_SLICE)) {
            Ok(0) => {
                return Err(io::Error::new(
                    io::ErrorKind::UnexpectedEof,
                    "the line closed",
                ));
            }
            Ok(n) => {
                attempt.push(buf.get(..n).unwrap_or(&buf));
            }
            Err(e) if is_timeout(&e) => {}
            Err(e) => return Err(e),
        }
    }
    // At least 1 ms between a reply and the next command (PROTOCOL.md 1.5).
    std::thread::sleep(timing.gap);
    Ok(Some(attempt.finish()))
}

/// A probe running on its own thread: read `events` (the last is `Finished`), cancel
/// with [`ProbeHandle::cancel`]. Dropping the handle cancels the probe without waiting.
pub struct ProbeHandle {
    pub events: Receiver<ProbeEvent>,
    cancel: Arc<AtomicBool>,
    thread: Option<JoinHandle<()>>,
}

impl ProbeHandle {
    /// Asks the probe to stop; `Finished` (with `ProbeEnd::Cancelled`) follows shortly.
    pub fn cancel(&self) {
        self.cancel.store(true, Ordering::Relaxed);
    }

    /// Whether the thread has ended (the port is closed then).
    pub fn is_finished(&self) -> bool {
        self.thread.as_ref().is_none_or(|t| t.is_finished())
    }

    /// Waits for the thread to end (blocks: not for the UI thread).
    pub fn join(mut self) {
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

impl Drop for ProbeHandle {
    fn drop(&mut self) {
        self.cancel();
    }
}

/// Starts [`probe_port`] on a new thread; `repaint` is called after every event so the
/// window wakes up to show it.
pub fn spawn_probe(
    port: String,
    plan: ProbePlan,
    repaint: Arc<dyn Fn() + Send + Sync>,
) -> io::Result<ProbeHandle> {
    let (tx, events) = unbounded();
    let cancel = Arc::new(AtomicBool::new(false));
    let flag = Arc::clone(&cancel);
    let thread = std::thread::Builder::new()
        .name("xsel-probe".into())
        .spawn(move || {
            probe_port(&port, &plan, &flag, &mut |ev| {
                // A dropped receiver only means nobody is watching any more.
                let _ = tx.send(ev);
                repaint();
            });
        })?;
    Ok(ProbeHandle {
        events,
        cancel,
        thread: Some(thread),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::protocol::{Reply, Station, SystemStatus};
    use std::sync::Mutex;

    /// A stand-in line: a "controller" that answers 215H at one setting and station,
    /// sends junk at `junk_baud`, and is silent otherwise.
    struct FakeLine {
        line: LineSettings,
        answer_at: Candidate,
        junk_baud: u32,
        pending: Vec<u8>,
    }

    impl Transport for FakeLine {
        fn read_timeout(&mut self, buf: &mut [u8], timeout: Duration) -> io::Result<usize> {
            if self.pending.is_empty() {
                std::thread::sleep(timeout.min(Duration::from_millis(2)));
                return Err(io::ErrorKind::TimedOut.into());
            }
            let n = buf.len().min(self.pending.len());
            buf[..n].copy_from_slice(&self.pending[..n]);
            self.pending.drain(..n);
            Ok(n)
        }

        fn write_all_bytes(&mut self, bytes: &[u8]) -> io::Result<()> {
            let asked = Attempt::new(self.answer_at.station);
            if self.line == self.answer_at.line && bytes == asked.command() {
                self.pending = Reply::SystemStatus(SystemStatus::default())
                    .to_bytes(self.answer_at.station)
                    .unwrap_or_default();
            } else if self.line.baud == self.junk_baud {
                self.pending = b"\x80\x00\xe6x\x00\x80".to_vec();
            }
            Ok(())
        }

        fn discard_input(&mut self) -> io::Result<Vec<u8>> {
            Ok(std::mem::take(&mut self.pending))
        }

        fn describe(&self) -> String {
            format!("fake {}", self.line)
        }
    }

    struct Run {
        report: ProbeReport,
        events: Vec<ProbeEvent>,
        opened: Vec<u32>,
    }

    fn run_fake(
        plan: &ProbePlan,
        answer_at: Candidate,
        fail_open_at: Option<u32>,
        cancel_at: Option<usize>,
    ) -> Run {
        let opened = Arc::new(Mutex::new(Vec::new()));
        let log = Arc::clone(&opened);
        let mut open = move |line: LineSettings| -> io::Result<Box<dyn Transport>> {
            if let Ok(mut l) = log.lock() {
                l.push(line.baud);
            }
            if Some(line.baud) == fail_open_at {
                return Err(io::Error::other(
                    "cannot open fake: No such file or directory",
                ));
            }
            Ok(Box::new(FakeLine {
                line,
                answer_at,
                junk_baud: 38_400,
                pending: Vec::new(),
            }))
        };
        let cancel = AtomicBool::new(false);
        let mut events = Vec::new();
        let report = probe_with(&mut open, "fake", plan, &cancel, &mut |ev| {
            if let ProbeEvent::Trying { tried, .. } = ev
                && Some(tried) == cancel_at
            {
                cancel.store(true, Ordering::Relaxed);
            }
            events.push(ev);
        });
        let opened = opened.lock().map(|l| l.clone()).unwrap_or_default();
        Run {
            report,
            events,
            opened,
        }
    }

    fn at(baud: u32, station: u8) -> Candidate {
        Candidate {
            line: Framing::EIGHT_N_ONE.at(baud),
            station: Station(station),
        }
    }

    #[test]
    fn stops_at_the_first_answer_after_garbage_and_silence() {
        let run = run_fake(&ProbePlan::default(), at(9_600, 0x99), None, None);
        assert_eq!(run.report.end, ProbeEnd::Found);
        assert_eq!(run.opened, [115_200, 38_400, 9_600]);
        let outcomes: Vec<&Outcome> = run.report.results.iter().map(|r| &r.outcome).collect();
        assert_eq!(outcomes[0], &Outcome::Silence);
        assert!(matches!(outcomes[1], Outcome::Garbage { bytes: 6, .. }));
        assert!(outcomes[2].is_controller());
        assert_eq!(
            run.report.found().map(|r| r.candidate),
            Some(at(9_600, 0x99))
        );
        assert!(
            run.report
                .summary()
                .starts_with("found on fake: 9600 8N1, station 99")
        );
        // Trying/Tried pairs with progress, then Finished with the same report.
        assert_eq!(run.events.len(), 7);
        assert!(matches!(
            run.events[5],
            ProbeEvent::Tried {
                tried: 3,
                total: 6,
                ..
            }
        ));
        assert_eq!(
            run.events.last(),
            Some(&ProbeEvent::Finished(run.report.clone()))
        );
    }

    #[test]
    fn probe_all_goes_on_to_the_end() {
        let plan = ProbePlan {
            probe_all: true,
            ..ProbePlan::default()
        };
        let run = run_fake(&plan, at(115_200, 0x99), None, None);
        assert_eq!(run.report.end, ProbeEnd::Exhausted);
        assert_eq!(run.report.results.len(), 6);
        assert_eq!(run.report.answered().count(), 1);
    }

    #[test]
    fn another_station_is_found_only_by_a_sweep() {
        // A short margin: the fake answers at once, and 263 silent waits add up.
        let plan = ProbePlan {
            bauds: vec![115_200, 9_600],
            margin: Duration::from_millis(2),
            ..ProbePlan::default()
        };
        let run = run_fake(&plan, at(9_600, 0x05), None, None);
        assert_eq!(run.report.end, ProbeEnd::Exhausted);
        assert!(
            run.report.summary().contains("all silent"),
            "{}",
            run.report.summary()
        );
        let run = run_fake(&plan.with_station_sweep(), at(9_600, 0x05), None, None);
        assert_eq!(run.report.end, ProbeEnd::Found);
        // 99 at both rates, then 00..FF at 115200, then 00..05 at 9600.
        assert_eq!(run.report.results.len(), 2 + 255 + 6);
        assert_eq!(run.opened, [115_200, 9_600, 115_200, 9_600]);
    }

    #[test]
    fn a_failed_open_ends_the_probe_with_what_was_learned() {
        let run = run_fake(&ProbePlan::default(), at(9_600, 0x99), Some(38_400), None);
        assert!(matches!(
            run.report.end,
            ProbeEnd::Failed(ProbeError::NotFound { .. })
        ));
        assert_eq!(run.report.results.len(), 1);
        assert!(run.report.summary().contains("no such port"));
    }

    #[test]
    fn a_cancel_stops_before_the_next_candidate() {
        let run = run_fake(&ProbePlan::default(), at(9_600, 0x99), None, Some(1));
        assert_eq!(run.report.end, ProbeEnd::Cancelled);
        assert!(run.report.results.len() <= 2);
        assert!(matches!(run.events.last(), Some(ProbeEvent::Finished(_))));
        assert!(run.report.summary().starts_with("cancelled after"));
    }

    #[test]
    fn an_empty_plan_is_refused_without_opening() {
        let plan = ProbePlan {
            bauds: Vec::new(),
            ..ProbePlan::default()
        };
        let run = run_fake(&plan, at(9_600, 0x99), None, None);
        assert!(matches!(
            run.report.end,
            ProbeEnd::Failed(ProbeError::Plan(_))
        ));
        assert!(run.opened.is_empty());
        assert_eq!(run.events.len(), 1);
    }
}
