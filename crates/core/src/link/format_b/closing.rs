//! The link's last act: every owed STOP goes out (each tried once, bounded by its reply
//! timeout) before the line is closed, and a report says what was done and what could not
//! be. A close asked for during a transaction begins when that transaction has ended.

use std::collections::VecDeque;
use std::fmt;
use std::time::Instant;

use super::super::reason::NotSentReason;
use super::super::request::{Origin, Pending, Priority, RequestId};
use super::transaction::Settled;
use super::{FormatB, LineState};
use crate::link::core::Transmit;
use crate::link::event::LinkEvent;
use crate::protocol::{AxisPattern, Command, ErrorCode, ProgramAction, ProgramCall, Stop};

/// What became of one STOP sent at shutdown.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum StopOutcome {
    /// The controller acknowledged it.
    Acknowledged,
    /// The controller refused it with an `&` error code.
    Refused(ErrorCode),
    /// It went out but no reply came within its timeout.
    TimedOut,
    /// The line was lost while waiting for its reply.
    Interrupted,
    /// It never went out.
    NotSent(NotSentReason),
}

impl From<Settled> for StopOutcome {
    fn from(settled: Settled) -> Self {
        match settled {
            Settled::Answered => StopOutcome::Acknowledged,
            Settled::Refused(code) => StopOutcome::Refused(code),
            Settled::TimedOut => StopOutcome::TimedOut,
            Settled::Interrupted => StopOutcome::Interrupted,
            Settled::NotSent(why) => StopOutcome::NotSent(why),
        }
    }
}

/// What the link did on its way out ([`LinkHandle::shutdown`](crate::link::LinkHandle::shutdown),
/// and the last event, [`LinkEvent::ShutDown`]).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct ShutdownReport {
    /// Each STOP owed at shutdown (the caller's queued ones, then the link's own if a jog
    /// or move may still be running), in the order they were tried.
    pub stops: Vec<(RequestId, StopOutcome)>,
    /// Other requests still queued, not sent (each also got a `NotSent` event).
    pub abandoned: usize,
    /// No STOP of all axes was acknowledged after the last motion command: the arm may
    /// still be moving. The window should say so loudly.
    pub motion_may_run: bool,
    /// The link thread ended abnormally (the report is then all that is known).
    pub thread_failed: bool,
}

impl ShutdownReport {
    /// What is known when the link thread failed: nothing, so the arm may be moving.
    pub fn thread_failed() -> Self {
        Self {
            motion_may_run: true,
            thread_failed: true,
            ..Self::default()
        }
    }

    /// Everything owed was done: every STOP acknowledged, nothing may still move.
    pub fn is_clean(&self) -> bool {
        !self.motion_may_run
            && !self.thread_failed
            && self
                .stops
                .iter()
                .all(|(_, o)| *o == StopOutcome::Acknowledged)
    }
}

impl fmt::Display for ShutdownReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.thread_failed {
            return f.write_str("the link thread failed; the arm may still be moving");
        }
        let acked = self
            .stops
            .iter()
            .filter(|(_, o)| *o == StopOutcome::Acknowledged)
            .count();
        write!(f, "{acked} of {} STOP(s) acknowledged", self.stops.len())?;
        for (id, outcome) in &self.stops {
            match outcome {
                StopOutcome::Acknowledged => {}
                StopOutcome::Refused(code) => write!(f, "; STOP {id} refused with {code}")?,
                StopOutcome::TimedOut => write!(f, "; STOP {id} timed out")?,
                StopOutcome::Interrupted => write!(f, "; line lost during STOP {id}")?,
                StopOutcome::NotSent(why) => write!(f, "; STOP {id} not sent: {why}")?,
            }
        }
        if self.abandoned > 0 {
            write!(f, "; {} queued request(s) not sent", self.abandoned)?;
        }
        if self.motion_may_run {
            f.write_str("; the arm may still be moving")?;
        }
        Ok(())
    }
}

/// The close in progress.
#[derive(Debug, Default)]
pub(super) struct Closing {
    /// The owed STOPs have been gathered (the transaction in flight had ended).
    started: bool,
    stops: VecDeque<Pending>,
    /// The STOP on the line now.
    current: Option<RequestId>,
    reopen_tried: bool,
    pub(super) report: ShutdownReport,
}

impl Closing {
    pub(super) fn started(&self) -> bool {
        self.started
    }

    /// A request that came after the STOPs were gathered: a STOP joins them, anything
    /// else is refused (returned) and counted.
    pub(super) fn submitted(&mut self, pending: Pending) -> Option<Pending> {
        if pending.command.is_stop() {
            self.stops.push_back(pending);
            None
        } else {
            self.report.abandoned += 1;
            Some(pending)
        }
    }

    /// One attempt to reopen a lost line, only to deliver the STOPs.
    pub(super) fn wants_reopen(&mut self) -> bool {
        let wanted = self.started && !self.stops.is_empty() && !self.reopen_tried;
        self.reopen_tried |= wanted;
        wanted
    }

    pub(super) fn next_stop(&mut self) -> Option<Pending> {
        let stop = self.stops.pop_front()?;
        self.current = Some(stop.id);
        Some(stop)
    }

    /// Records how `id`'s transaction ended, if it is the STOP on the line.
    pub(super) fn settled(&mut self, id: RequestId, settled: &Settled) {
        if self.current == Some(id) {
            self.current = None;
            self.report.stops.push((id, settled.clone().into()));
        }
    }
}

impl FormatB {
    /// Asks for the close; it begins once the transaction in flight has ended.
    pub(super) fn close(&mut self, _now: Instant) {
        self.closing.get_or_insert_with(Closing::default);
    }

    /// Gathers what is owed: every queued STOP and, if a jog or move may still run, one
    /// of the link's own; everything else queued is refused.
    pub(super) fn start_closing(&mut self) {
        let mut stops = VecDeque::new();
        let mut abandoned = Vec::new();
        for pending in self.sched.drain_queued() {
            if pending.command.is_stop() || ends_programs(&pending.command) {
                stops.push_back(pending);
            } else if !matches!(pending.origin, Origin::Poll | Origin::Table { .. }) {
                abandoned.push(pending);
            }
        }
        for pending in &abandoned {
            self.not_sent(pending, NotSentReason::ShuttingDown);
        }
        if let Some(job) = self.sched.abort_table() {
            self.report_table(job);
        }
        let covered = stops
            .iter()
            .any(|p| matches!(p.command, Command::Stop(s) if s.axes == AxisPattern::ALL));
        if (self.motion_may_run || self.program_may_run) && !covered {
            stops.push_back(Pending::new(
                self.new_id(),
                Command::Stop(Stop {
                    axes: AxisPattern::ALL,
                    cancel_held_outputs: false,
                }),
                Origin::SafetyStop,
                Priority::Stop,
            ));
        }
        // A program that may run is ended on the way out, then the arm stopped again.
        let programs_covered = stops
            .iter()
            .any(|p| p.command == Command::Program(ProgramCall::END_ALL));
        if self.program_may_run && !programs_covered {
            for command in [
                Command::Program(ProgramCall::END_ALL),
                Command::Stop(Stop {
                    axes: AxisPattern::ALL,
                    cancel_held_outputs: false,
                }),
            ] {
                stops.push_back(Pending::new(
                    self.new_id(),
                    command,
                    Origin::SafetyStop,
                    Priority::Stop,
                ));
            }
        }
        let closing = self.closing.get_or_insert_with(Closing::default);
        closing.started = true;
        closing.stops = stops;
        closing.report.abandoned += abandoned.len();
    }

    /// Ends the close once every owed STOP was tried: STOPs that could not go out are
    /// reported, the report is the last event, and the line is closed.
    pub(super) fn finish_closing(&mut self) -> Option<Transmit> {
        let closing = self.closing.as_mut()?;
        if !closing.started || closing.current.is_some() {
            return None;
        }
        let unsent: Vec<Pending> = closing.stops.drain(..).collect();
        for pending in &unsent {
            closing
                .report
                .stops
                .push((pending.id, StopOutcome::NotSent(NotSentReason::LineDown)));
        }
        closing.report.motion_may_run = self.motion_may_run || self.program_may_run;
        let report = closing.report.clone();
        for pending in &unsent {
            self.not_sent(pending, NotSentReason::LineDown);
        }
        self.emit(LinkEvent::ShutDown(report));
        self.closed = true;
        let was_up = self.is_up();
        self.line = LineState::Down { next_open: None };
        was_up.then_some(Transmit::Close)
    }
}

/// 254H or 255H for every program: part of a STOP while a program may run.
fn ends_programs(command: &Command) -> bool {
    matches!(command, Command::Program(c)
        if c.is_all() && matches!(c.action, ProgramAction::End | ProgramAction::Pause))
}
