//! Connection auto-detect: tries baud rates, framings and stations with 215H and reports what answered.

mod classify;
mod error;
mod plan;

use std::io;
use std::sync::Arc;

use crossbeam_channel::Receiver;

use super::core::{CoreEvent, Input, LineChange, LinkCore, Transmit};
use super::driver::{self, Connector, DriverHandle};
use super::timing::Timing;
use super::transport::{SerialTransport, Transport};
use crate::line::LineSettings;
use crate::protocol::Command;

pub use classify::{Attempt, Outcome, classify};
pub use error::ProbeError;
pub use plan::{
    Candidate, Framing, LIKELY_BAUDS, MORE_FRAMINGS, ProbePlan, estimate_duration, station_sweep,
};

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

/// The probe as a sans-IO core for the link driver: each candidate's line opened (closed
/// first when the setting changes: the port is opened exclusively), one 215H written,
/// what comes back classified until it settles or its time-out, the 1 ms gap, the next.
/// A close (the cancel) ends it before the next candidate; `Finished` is the last event
/// and goes out as the line is closed.
pub struct ProbeCore {
    port: String,
    plan: ProbePlan,
    candidates: Vec<Candidate>,
    /// The candidate being tried (or next to try).
    next: usize,
    /// The setting the line is open at, if it is open.
    open: Option<LineSettings>,
    opening: bool,
    /// The 215H on the line and its deadline.
    waiting: Option<(Attempt, std::time::Instant)>,
    /// No command before this (the gap after an answer or time-out).
    quiet_until: Option<std::time::Instant>,
    report: ProbeReport,
    /// Set when the probe has ended: `Finished` goes out with the close.
    end: Option<ProbeEnd>,
    closed: bool,
    events: std::collections::VecDeque<ProbeEvent>,
}

impl ProbeCore {
    /// A probe of `port` (its name in messages) with `plan`.
    pub fn new(port: &str, plan: ProbePlan) -> Self {
        let candidates = plan.candidates();
        let end = plan.validate().err().map(ProbeEnd::Failed);
        Self {
            port: port.to_owned(),
            report: ProbeReport {
                port: port.to_owned(),
                results: Vec::new(),
                total: candidates.len(),
                end: ProbeEnd::Exhausted,
            },
            plan,
            candidates,
            next: 0,
            open: None,
            opening: false,
            waiting: None,
            quiet_until: None,
            end,
            closed: false,
            events: std::collections::VecDeque::new(),
        }
    }

    /// The report so far (whole once the probe is closed).
    pub fn report(&self) -> &ProbeReport {
        &self.report
    }

    fn ended(&mut self, end: ProbeEnd) {
        self.waiting = None;
        self.end.get_or_insert(end);
    }

    /// The 215H on the line has settled (or timed out) at `now`.
    fn tried(&mut self, now: std::time::Instant) {
        let Some((attempt, _)) = self.waiting.take() else {
            return;
        };
        let Some(&candidate) = self.candidates.get(self.next) else {
            return;
        };
        let outcome = attempt.finish();
        let found = outcome.is_controller();
        let result = ProbeResult { candidate, outcome };
        self.report.results.push(result.clone());
        self.next += 1;
        self.events.push_back(ProbeEvent::Tried {
            tried: self.next,
            total: self.candidates.len(),
            result,
        });
        // At least 1 ms between a reply and the next command (PROTOCOL.md 1.5).
        self.quiet_until = Some(now + Timing::default().gap);
        if found && !self.plan.probe_all {
            self.ended(ProbeEnd::Found);
        } else if self.next >= self.candidates.len() {
            self.ended(ProbeEnd::Exhausted);
        }
    }

    /// Ends the probe: the report is whole, `Finished` goes out, the line is closed.
    fn finish(&mut self) -> Option<Transmit> {
        let end = self.end.clone()?;
        self.report.end = end;
        self.events
            .push_back(ProbeEvent::Finished(self.report.clone()));
        self.closed = true;
        self.open.take().map(|_| Transmit::Close)
    }
}

impl LinkCore for ProbeCore {
    type Request = std::convert::Infallible;
    type Event = ProbeEvent;

    fn handle_request(&mut self, _now: std::time::Instant, input: Input<Self::Request>) {
        if let Input::Close = input {
            self.ended(ProbeEnd::Cancelled);
        }
    }

    fn handle_line(&mut self, _now: std::time::Instant, change: LineChange) {
        let line = self
            .candidates
            .get(self.next)
            .map_or_else(LineSettings::default, |c| c.line);
        match change {
            LineChange::Opened { .. } => {
                self.opening = false;
                self.open = Some(line);
            }
            LineChange::OpenFailed(failure) => {
                self.opening = false;
                let error = io::Error::new(failure.kind, failure.detail);
                self.ended(ProbeEnd::Failed(ProbeError::from_open(
                    &self.port, line, error,
                )));
            }
            LineChange::Lost(reason) => {
                self.open = None;
                let error = io::Error::other(reason.to_string());
                self.ended(ProbeEnd::Failed(ProbeError::from_line(
                    &self.port, line, error,
                )));
            }
            LineChange::GuardianStopped(_) => {}
        }
    }

    fn handle_bytes(&mut self, now: std::time::Instant, bytes: &[u8]) {
        // Leftovers of an earlier candidate (or noise from opening) count for nobody.
        let Some((attempt, _)) = self.waiting.as_mut() else {
            return;
        };
        attempt.push(bytes);
        if attempt.is_settled() {
            self.tried(now);
        }
    }

    fn handle_timeout(&mut self, now: std::time::Instant) {
        if self
            .waiting
            .as_ref()
            .is_some_and(|(_, deadline)| now >= *deadline)
        {
            self.tried(now);
        }
        if self.quiet_until.is_some_and(|t| now >= t) {
            self.quiet_until = None;
        }
    }

    fn poll_transmit(&mut self, now: std::time::Instant) -> Option<Transmit> {
        if self.closed || self.opening || self.waiting.is_some() {
            return None;
        }
        if self.end.is_some() {
            return self.finish();
        }
        let &candidate = self.candidates.get(self.next)?;
        if self.open != Some(candidate.line) {
            // Close first: the port is opened exclusively.
            if self.open.take().is_some() {
                return Some(Transmit::Close);
            }
            self.opening = true;
            return Some(Transmit::Open(candidate.line));
        }
        if self.quiet_until.is_some_and(|t| t > now) {
            return None;
        }
        self.quiet_until = None;
        let attempt = Attempt::new(candidate.station);
        let timing = Timing {
            line: candidate.line,
            margin: self.plan.margin,
            ..Timing::default()
        };
        let timeout = timing.reply_timeout(
            attempt.command().len(),
            Command::SystemStatus.max_reply_len(),
        );
        let bytes = attempt.command().to_vec();
        self.events.push_back(ProbeEvent::Trying {
            tried: self.next,
            total: self.candidates.len(),
            candidate,
        });
        self.waiting = Some((attempt, now + timeout));
        Some(Transmit::Write(bytes))
    }

    fn poll_event(&mut self) -> Option<ProbeEvent> {
        self.events.pop_front()
    }

    fn poll_timeout(&self) -> Option<std::time::Instant> {
        if self.closed {
            return None;
        }
        self.waiting
            .as_ref()
            .map(|(_, deadline)| *deadline)
            .or(self.quiet_until)
    }

    fn awaits_bytes(&self) -> bool {
        self.waiting.is_some()
    }

    fn is_closed(&self) -> bool {
        self.closed
    }
}

impl CoreEvent for ProbeEvent {
    fn is_traffic(&self) -> bool {
        false
    }

    fn dropped(_frames: u64) -> Option<Self> {
        None
    }
}

/// A probe running on the link driver's thread: read `events` (the last is `Finished`),
/// cancel with [`ProbeHandle::cancel`]. Dropping the handle cancels the probe without
/// waiting.
pub struct ProbeHandle {
    pub events: Receiver<ProbeEvent>,
    driver: DriverHandle<ProbeCore>,
}

impl ProbeHandle {
    /// Asks the probe to stop; `Finished` (with `ProbeEnd::Cancelled`) follows shortly.
    pub fn cancel(&self) {
        let _ = self.driver.control.send(Input::Close);
    }

    /// Whether the thread has ended (the port is closed then).
    pub fn is_finished(&self) -> bool {
        !self.driver.is_running()
    }

    /// Waits for the probe to end and gives its report (blocks: not for the UI thread).
    pub fn join(mut self) -> Option<ProbeReport> {
        self.driver.wait().map(|core| core.report().clone())
    }
}

impl Drop for ProbeHandle {
    fn drop(&mut self) {
        self.cancel();
    }
}

/// Probes the serial port `port` with `plan` on the link driver's thread; `repaint` is
/// called after every event so the window wakes up to show it.
pub fn spawn_probe(
    port: String,
    plan: ProbePlan,
    repaint: Arc<dyn Fn() + Send + Sync>,
) -> io::Result<ProbeHandle> {
    spawn_probe_with(
        &port.clone(),
        plan,
        Box::new(move |line| {
            SerialTransport::open(&port, line).map(|t| Box::new(t) as Box<dyn Transport>)
        }),
        repaint,
    )
}

/// As [`spawn_probe`], opening each setting with `connector` (`name` is the port's name
/// in messages).
pub fn spawn_probe_with(
    name: &str,
    plan: ProbePlan,
    connector: Connector,
    repaint: Arc<dyn Fn() + Send + Sync>,
) -> io::Result<ProbeHandle> {
    let core = ProbeCore::new(name, plan);
    let (driver, events) = driver::spawn(
        "xsel-probe",
        core,
        connector,
        Arc::new(move |_: &ProbeEvent| repaint()),
        usize::MAX,
    )?;
    Ok(ProbeHandle { events, driver })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::link::reason::IoFailure;
    use crate::protocol::{Reply, Station, SystemStatus};
    use std::time::{Duration, Instant};

    /// What the stand-in line does: a "controller" that answers 215H at one setting and
    /// station, sends junk at 38400 baud, and is silent otherwise.
    struct Run {
        report: ProbeReport,
        events: Vec<ProbeEvent>,
        opened: Vec<u32>,
        /// Virtual time the probe took.
        took: Duration,
    }

    /// Drives a probe on a virtual clock against the stand-in line.
    fn run_fake(
        plan: &ProbePlan,
        answer_at: Candidate,
        fail_open_at: Option<u32>,
        cancel_at: Option<usize>,
    ) -> Run {
        let t0 = Instant::now();
        let mut now = t0;
        let mut core = ProbeCore::new("fake", plan.clone());
        let mut line: Option<LineSettings> = None;
        let mut inbound: Option<(Instant, Vec<u8>)> = None;
        let mut events = Vec::new();
        let mut opened = Vec::new();
        for _ in 0..100_000 {
            while let Some(transmit) = core.poll_transmit(now) {
                match transmit {
                    Transmit::Open(settings) => {
                        assert!(line.is_none(), "opened twice: the port is exclusive");
                        opened.push(settings.baud);
                        let change = if Some(settings.baud) == fail_open_at {
                            LineChange::OpenFailed(IoFailure {
                                kind: io::ErrorKind::NotFound,
                                detail: "cannot open fake: No such file or directory".into(),
                            })
                        } else {
                            line = Some(settings);
                            LineChange::Opened {
                                name: "fake".into(),
                            }
                        };
                        core.handle_line(now, change);
                    }
                    Transmit::Write(bytes) => {
                        let at = line.expect("written on an open line");
                        let asked = Attempt::new(answer_at.station);
                        let reply = if at == answer_at.line && bytes == asked.command() {
                            Reply::SystemStatus(SystemStatus::default())
                                .to_bytes(answer_at.station)
                                .unwrap_or_default()
                        } else if at.baud == 38_400 {
                            b"\x80\x00\xe6x\x00\x80".to_vec()
                        } else {
                            Vec::new()
                        };
                        inbound =
                            (!reply.is_empty()).then(|| (now + Duration::from_millis(2), reply));
                    }
                    Transmit::Close => {
                        line = None;
                        inbound = None;
                    }
                }
            }
            while let Some(event) = core.poll_event() {
                if let ProbeEvent::Trying { tried, .. } = event
                    && Some(tried) == cancel_at
                {
                    core.handle_request(now, Input::Close);
                }
                if matches!(event, ProbeEvent::Finished(_)) {
                    assert!(line.is_none(), "the port is closed before Finished");
                }
                events.push(event);
            }
            if core.is_closed() {
                break;
            }
            let next = [inbound.as_ref().map(|(t, _)| *t), core.poll_timeout()]
                .into_iter()
                .flatten()
                .min()
                .expect("a probe that is not closed waits for something");
            now = now.max(next);
            if let Some((_, bytes)) = inbound.take_if(|(t, _)| *t <= now) {
                core.handle_bytes(now, &bytes);
            }
            if core.poll_timeout().is_some_and(|t| t <= now) {
                core.handle_timeout(now);
            }
        }
        assert!(core.is_closed(), "the probe ended");
        Run {
            report: core.report().clone(),
            events,
            opened,
            took: now - t0,
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
    fn a_silent_candidate_takes_its_reply_time_out_and_no_longer() {
        let plan = ProbePlan {
            bauds: vec![115_200],
            ..ProbePlan::default()
        };
        let run = run_fake(&plan, at(9_600, 0x99), None, None);
        assert_eq!(run.report.end, ProbeEnd::Exhausted);
        let timing = Timing {
            margin: plan.margin,
            ..Timing::default()
        };
        let timeout = timing.reply_timeout(10, Command::SystemStatus.max_reply_len());
        assert_eq!(
            run.took, timeout,
            "the last candidate needs no gap after it"
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
        let plan = ProbePlan {
            bauds: vec![115_200, 9_600],
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
        assert_eq!(run.report.results.len(), 1);
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
