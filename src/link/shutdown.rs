//! The link's last act: every owed STOP goes out (bounded by its reply timeout) before the
//! line is closed, and a report says what was done and what could not be.

use std::fmt;

use super::engine::Engine;
use super::event::LinkEvent;
use super::reason::NotSentReason;
use super::request::{Origin, Pending, Priority, RequestId};
use super::transaction::Settled;
use crate::protocol::{AxisPattern, Command, ErrorCode, Stop};

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

/// What the link did on its way out ([`LinkHandle::shutdown`](super::LinkHandle::shutdown),
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

impl Engine {
    /// Called once the loop has ended (the transaction in flight, if any, has run to its
    /// end). Sends every queued STOP and, if a jog or move may still run, one of its own;
    /// each is tried once, bounded by its reply timeout. Then closes the line.
    pub(super) fn shut_down(&mut self) -> ShutdownReport {
        let mut report = ShutdownReport::default();
        // Requests that arrived after the shutdown message are settled too.
        self.shutting_down = true;
        self.drain_control();
        let mut stops = Vec::new();
        for pending in self.sched.drain_queued() {
            if pending.command.is_stop() {
                stops.push(pending);
            } else if !matches!(pending.origin, Origin::Poll | Origin::Table { .. }) {
                report.abandoned += 1;
                self.not_sent(&pending, NotSentReason::ShuttingDown);
            }
        }
        if let Some(job) = self.sched.abort_table() {
            self.report_table(job);
        }
        let covered = stops
            .iter()
            .any(|p| matches!(p.command, Command::Stop(s) if s.axes == AxisPattern::ALL));
        if self.motion_may_run && !covered {
            let stop = Command::Stop(Stop {
                axes: AxisPattern::ALL,
                cancel_held_outputs: false,
            });
            stops.push(Pending::new(
                self.new_id(),
                stop,
                Origin::SafetyStop,
                Priority::Stop,
            ));
        }
        if !stops.is_empty() && self.transport.is_none() {
            // One attempt to reopen the line, only to deliver the STOP.
            self.next_reconnect = Some(std::time::Instant::now());
            self.try_reconnect(std::time::Instant::now());
            // Reopening queues a STOP of its own when a jog may run: ours covers it.
            self.sched.drain_queued();
        }
        for pending in stops {
            let outcome = if self.transport.is_none() {
                self.not_sent(&pending, NotSentReason::LineDown);
                StopOutcome::NotSent(NotSentReason::LineDown)
            } else {
                match self.transact(pending) {
                    Settled::Answered => StopOutcome::Acknowledged,
                    Settled::Refused(code) => StopOutcome::Refused(code),
                    Settled::TimedOut => StopOutcome::TimedOut,
                    Settled::Interrupted => StopOutcome::Interrupted,
                    Settled::NotSent(why) => StopOutcome::NotSent(why),
                }
            };
            // Tried once: retries and rechecks the transaction queued are not sent.
            self.sched.drain_queued();
            report.stops.push((pending.id, outcome));
        }
        report.motion_may_run = self.motion_may_run;
        self.transport = None;
        self.events.report_dropped();
        self.emit(LinkEvent::ShutDown(report.clone()));
        report
    }
}
