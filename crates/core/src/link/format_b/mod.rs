//! Format B on one line as a sans-IO state machine: requests queued by priority, one
//! command outstanding, the 1 ms gap, motion only on a line proven in step, STOP ahead of
//! everything and on a stall, a lapsed lease, a lost line and the close. Time comes in as
//! an argument; the driver (`driver.rs`) does the IO.

mod closing;
pub mod safety;
mod transaction;

#[cfg(test)]
pub(crate) mod harness;
#[cfg(test)]
mod props;
#[cfg(test)]
mod tests;

use std::collections::VecDeque;
use std::sync::Arc;
use std::sync::atomic::AtomicU64;
use std::time::{Duration, Instant};

use super::core::{CoreEvent, Input, LineChange, LinkCore, Transmit};
use super::driver::later;
use super::event::LinkEvent;
use super::handle::LinkConfig;
use super::health::{HealthMeter, LinkHealth};
use super::lease::JogLease;
use super::poll_answers::PollAnswers;
use super::reason::{LineDownReason, NotSentReason};
use super::request::{Origin, Pending, RequestId};
use super::schedule::{Next, Polling, Scheduler};
use super::sync::LineSync;
use super::table::{TableJob, TableRequest};
use crate::protocol::{ProgramAction, StreamDecoder};

use closing::Closing;
pub use closing::{ShutdownReport, StopOutcome};
use transaction::Outstanding;

/// Health goes out this often while the reader keeps up.
const HEALTH_EVERY: Duration = Duration::from_millis(500);

/// What the application asks of a Format B link.
#[derive(Debug, Clone, PartialEq)]
pub enum Control {
    Submit(Pending),
    SetPolling(Polling),
    DownloadTable(TableRequest),
    CancelTable,
    /// Close and reopen the line (between transactions, never in the middle of one).
    Reconnect,
    SetAutoReconnect(bool),
}

/// The state of the line as the core sees it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum LineState {
    /// Closed; opened at `next_open` (never, when `None`).
    Down {
        next_open: Option<Instant>,
    },
    /// `Transmit::Open` went out; the answer is awaited.
    Opening,
    Up,
}

/// The Format B link core.
pub struct FormatB {
    config: LinkConfig,
    ids: Arc<AtomicU64>,
    line: LineState,
    ever_connected: bool,
    open_failure_reported: bool,
    reconnect_requested: bool,
    sched: Scheduler,
    /// The polls' last answers: a changed one keeps polling fast.
    poll_answers: PollAnswers,
    decoder: StreamDecoder,
    health: HealthMeter,
    next_health: Instant,
    /// Whether a late reply may still arrive (motion waits for proof that none will).
    sync: LineSync,
    /// A jog was started and no STOP has been acknowledged since.
    jog_may_run: bool,
    /// A motion command went out and no STOP of all axes has been acknowledged since
    /// (the link cannot tell when a move has ended; a STOP of a still arm is harmless).
    motion_may_run: bool,
    /// A program run, step or resume went out, or 215H said a program runs, and no
    /// 254H with `00` was acknowledged since: STOPs end programs too.
    program_may_run: bool,
    lease: JogLease,
    /// The continuous jog awaiting its reply took the lease (none was held before it): if
    /// the controller refuses it, nothing runs on the lease any more.
    jog_took_lease: bool,
    reader_behind: bool,
    events_dropped: u64,
    /// The newest STOP of all axes submitted: motion submitted before it (a lower id)
    /// never goes out after it, whenever it reaches the core.
    stopped_through: Option<RequestId>,
    /// The command on the line, awaiting its answer.
    outstanding: Option<Outstanding>,
    /// No command goes out before this (the gap after the last answer or time-out).
    quiet_until: Option<Instant>,
    /// When the scheduler next has something to send (a poll cycle).
    sched_wake: Option<Instant>,
    closing: Option<Closing>,
    closed: bool,
    events: VecDeque<LinkEvent>,
}

impl FormatB {
    /// A core that opens its line at once; `ids` numbers requests (shared with the handle).
    pub fn new(config: LinkConfig, ids: Arc<AtomicU64>, now: Instant) -> Self {
        Self {
            sched: {
                let mut sched = Scheduler::new(config.polling.clone(), now);
                sched.set_timing(config.timing);
                sched
            },
            lease: JogLease::new(config.jog_lease),
            config,
            ids,
            line: LineState::Down {
                next_open: Some(now),
            },
            ever_connected: false,
            open_failure_reported: false,
            reconnect_requested: false,
            poll_answers: PollAnswers::default(),
            decoder: StreamDecoder::new(),
            health: HealthMeter::default(),
            next_health: later(now, HEALTH_EVERY),
            sync: LineSync::default(),
            jog_may_run: false,
            motion_may_run: false,
            program_may_run: false,
            jog_took_lease: false,
            reader_behind: false,
            events_dropped: 0,
            stopped_through: None,
            outstanding: None,
            quiet_until: None,
            sched_wake: None,
            closing: None,
            closed: false,
            events: VecDeque::new(),
        }
    }

    /// What the close did; complete once [`LinkCore::is_closed`].
    pub fn shutdown_report(&self) -> ShutdownReport {
        self.closing
            .as_ref()
            .map(|c| c.report.clone())
            .unwrap_or_default()
    }

    fn emit(&mut self, event: LinkEvent) {
        self.events.push_back(event);
    }

    fn new_id(&self) -> RequestId {
        RequestId::next(&self.ids)
    }

    fn is_up(&self) -> bool {
        self.line == LineState::Up
    }

    fn not_sent(&mut self, pending: &Pending, reason: NotSentReason) {
        self.emit(LinkEvent::NotSent {
            id: pending.id,
            command: pending.command.clone(),
            reason,
        });
    }

    fn handle_control(&mut self, now: Instant, control: Control) {
        match control {
            Control::Submit(pending) => self.submitted(now, pending),
            Control::SetPolling(polling) => {
                self.sched.set_polling(polling, now);
                self.sched_wake = Some(now);
            }
            Control::DownloadTable(request) => {
                if let Some(old) = self.sched.start_table(request) {
                    self.report_table(old);
                }
                if !self.takes_requests(now)
                    && let Some(job) = self.sched.abort_table()
                {
                    self.report_table(job);
                }
                self.finish_table_if_done();
                self.sched_wake = Some(now);
            }
            Control::CancelTable => {
                if let Some(job) = self.sched.abort_table() {
                    self.report_table(job);
                }
            }
            Control::Reconnect => self.reconnect_requested = true,
            Control::SetAutoReconnect(on) => {
                self.config.auto_reconnect = on;
                if on && let LineState::Down { next_open: None } = self.line {
                    self.line = LineState::Down {
                        next_open: Some(now),
                    };
                }
            }
        }
    }

    /// A request from the application: queued while the line is up or about to open
    /// (judged against the opened line), refused while it is down.
    fn submitted(&mut self, now: Instant, pending: Pending) {
        if let Some(closing) = self.closing.as_mut()
            && closing.started()
        {
            if let Some(refused) = closing.submitted(pending) {
                self.not_sent(&refused, NotSentReason::ShuttingDown);
            }
            return;
        }
        if !self.takes_requests(now) {
            return self.not_sent(&pending, NotSentReason::LineDown);
        }
        if ends_motion(&pending.command) {
            self.stop_ends_queued_motion(pending.id);
            let origin = pending.origin;
            self.sched.push(pending);
            return self.follow_stop(origin, ProgramAction::End);
        } else if stopped_by(&pending.command)
            && self.stopped_through.is_some_and(|stop| pending.id < stop)
        {
            // Submitted before the STOP, though it reached the core after it (STOPs take
            // a channel of their own).
            return self.not_sent(&pending, NotSentReason::StopCameFirst);
        }
        self.sched.push(pending);
    }

    /// A STOP of all axes (`stop`) is on its way: the motion still queued never goes out
    /// (each is answered "STOP came first"), nor does any submitted before it that is
    /// still on its way to the core.
    pub(super) fn stop_ends_queued_motion(&mut self, stop: RequestId) {
        self.stopped_through = self.stopped_through.max(Some(stop));
        for pending in self.sched.take_user(|p| stopped_by(&p.command)) {
            self.not_sent(&pending, NotSentReason::StopCameFirst);
        }
    }

    /// Whether the line is up or about to open now (so requests are judged against the
    /// opened line rather than refused).
    fn takes_requests(&self, now: Instant) -> bool {
        match self.line {
            LineState::Up | LineState::Opening => true,
            LineState::Down { next_open } => next_open.is_some_and(|t| t <= now),
        }
    }

    fn opened(&mut self, now: Instant, name: String) {
        self.line = LineState::Up;
        self.decoder = StreamDecoder::new();
        self.quiet_until = None;
        self.poll_answers.clear();
        self.sched.set_polling(self.sched.polling().clone(), now);
        self.sched_wake = Some(now);
        self.emit(if self.ever_connected {
            LinkEvent::Reconnected { line: name }
        } else {
            LinkEvent::Connected { line: name }
        });
        self.ever_connected = true;
        self.open_failure_reported = false;
        // A jog or move started before the loss may still be running: stop it first
        // (a STOP of a still arm is harmless).
        // A program is paused rather than ended: the operator may resume it.
        if self.motion_may_run || self.jog_may_run || self.program_may_run {
            self.queue_stop_then(Origin::SafetyStop, ProgramAction::Pause);
        }
    }

    fn open_failed(&mut self, now: Instant, failure: super::reason::IoFailure) {
        if !self.open_failure_reported {
            // Reported once; further attempts stay quiet until one succeeds.
            self.open_failure_reported = true;
            self.emit(LinkEvent::Disconnected {
                reason: LineDownReason::OpenFailed(failure),
            });
        }
        self.line = LineState::Down {
            next_open: self.reopen_at(now),
        };
        // Requests that waited for this open are answered now.
        self.refuse_queued(NotSentReason::LineDown);
        if let Some(job) = self.sched.abort_table() {
            self.report_table(job);
        }
    }

    fn reopen_at(&self, now: Instant) -> Option<Instant> {
        self.config
            .auto_reconnect
            .then(|| later(now, self.config.reconnect_interval))
    }

    /// The line is gone: report it, refuse what is queued (none of it may go out later,
    /// least of all motion), and plan a reopen. Does nothing if it is already down.
    fn line_lost(&mut self, now: Instant, reason: LineDownReason) {
        if !self.is_up() {
            return;
        }
        self.line = LineState::Down {
            next_open: self.reopen_at(now),
        };
        self.cut_off_partial(now);
        self.emit(LinkEvent::Disconnected { reason });
        self.refuse_queued(NotSentReason::LineLost);
        if let Some(job) = self.sched.abort_table() {
            self.report_table(job);
        }
    }

    /// Every id a caller or an event announced gets its answer; polls and table chunks
    /// are the link's own (the table is reported as a whole).
    fn refuse_queued(&mut self, reason: NotSentReason) {
        for pending in self.sched.drain_queued() {
            if !matches!(pending.origin, Origin::Poll | Origin::Table { .. }) {
                self.not_sent(&pending, reason.clone());
            }
        }
    }

    fn finish_table_if_done(&mut self) {
        if let Some(job) = self.sched.take_finished_table() {
            self.report_table(job);
        }
    }

    fn report_table(&mut self, job: TableJob) {
        let missing = job.missing();
        self.emit(LinkEvent::TableDone {
            kind: job.request.kind,
            axes: if job.answered_axes.is_empty() {
                job.request.axes
            } else {
                job.answered_axes
            },
            first: job.request.first,
            records: job.records,
            missing,
        });
    }

    fn health_now(&mut self, now: Instant) -> LinkHealth {
        let mut health = self.health.snapshot(now);
        health.events_dropped = self.events_dropped;
        health
    }

    fn backlog(&mut self, now: Instant, behind: bool, dropped: u64) {
        self.events_dropped = dropped;
        if behind == self.reader_behind {
            return;
        }
        // Polls are the link's own, and their replies are never left out: paused while
        // the reader is far behind, due at once when it catches up.
        self.reader_behind = behind;
        self.sched.pause_polls(behind, now);
        self.health.polling_paused(behind);
        self.sched_wake = Some(now);
        if behind {
            // Sent once as the pause begins, so the reader learns why status is stale.
            let health = self.health_now(now);
            self.emit(LinkEvent::Health(health));
        }
    }

    /// The next request to send at `now`, after the close's and the lease's claims.
    fn next_request(&mut self, now: Instant) -> Option<Pending> {
        if let Some(closing) = self.closing.as_mut() {
            return closing.next_stop();
        }
        let ids = self.ids.clone();
        match self.sched.next(now, &mut || RequestId::next(&ids)) {
            Next::Send(pending) => {
                self.sched_wake = None;
                Some(pending)
            }
            Next::Wait(until) => {
                self.sched_wake = until;
                None
            }
        }
    }
}

impl LinkCore for FormatB {
    type Request = Control;
    type Event = LinkEvent;

    fn handle_request(&mut self, now: Instant, input: Input<Control>) {
        match input {
            Input::App(control) => self.handle_control(now, control),
            Input::LeaseRenewed(at) => {
                // A held jog: the operator is moving the arm.
                self.lease.renewed(at);
                self.sched.activity(now);
            }
            Input::Backlog { behind, dropped } => self.backlog(now, behind, dropped),
            Input::Close => self.close(now),
        }
    }

    fn handle_line(&mut self, now: Instant, change: LineChange) {
        match change {
            LineChange::Opened { name } => self.opened(now, name),
            LineChange::OpenFailed(failure) => self.open_failed(now, failure),
            LineChange::Lost(reason) => {
                self.settle_on_loss(now, &reason);
                self.line_lost(now, reason);
            }
            LineChange::GuardianStopped(why) => self.emit(LinkEvent::GuardianStopped(why)),
        }
    }

    fn handle_bytes(&mut self, now: Instant, bytes: &[u8]) {
        if self.outstanding.is_some() {
            self.answer_bytes(now, bytes);
        } else {
            self.report_stale(now, bytes);
        }
    }

    fn handle_timeout(&mut self, now: Instant) {
        if self.outstanding.as_ref().is_some_and(|o| now >= o.deadline) {
            self.reply_timed_out(now);
        }
        if self.is_up() && self.lease.take_lapse(now) {
            self.lease_lapsed();
        }
        if now >= self.next_health {
            self.next_health = later(now, HEALTH_EVERY);
            if self.is_up() && !self.reader_behind {
                let health = self.health_now(now);
                self.emit(LinkEvent::Health(health));
            }
        }
    }

    fn poll_transmit(&mut self, now: Instant) -> Option<Transmit> {
        if self.closed || self.outstanding.is_some() {
            return None;
        }
        if self.closing.as_ref().is_some_and(|c| !c.started()) {
            self.start_closing();
        }
        match self.line {
            LineState::Opening => None,
            LineState::Down { next_open } => {
                let wanted = match self.closing.as_mut() {
                    Some(closing) => closing.wants_reopen(),
                    None => next_open.is_some_and(|t| t <= now),
                };
                if wanted {
                    self.line = LineState::Opening;
                    return Some(Transmit::Open(self.config.timing.line));
                }
                self.finish_closing()
            }
            LineState::Up => {
                if self.closing.is_none() && std::mem::take(&mut self.reconnect_requested) {
                    self.line_lost(now, LineDownReason::ReconnectRequested);
                    self.line = LineState::Down {
                        next_open: Some(now),
                    };
                    return Some(Transmit::Close);
                }
                if self.quiet_until.is_some_and(|t| t > now) {
                    return None;
                }
                self.quiet_until = None;
                while let Some(pending) = self.next_request(now) {
                    if let Some(bytes) = self.send(now, pending) {
                        return Some(Transmit::Write(bytes));
                    }
                }
                self.finish_closing()
            }
        }
    }

    fn poll_event(&mut self) -> Option<LinkEvent> {
        self.events.pop_front()
    }

    fn poll_timeout(&self) -> Option<Instant> {
        if self.closed {
            return None;
        }
        let line = match self.line {
            // A close reopens the line only to deliver its STOPs, when they are due.
            LineState::Down { next_open } => next_open.filter(|_| self.closing.is_none()),
            LineState::Opening => None,
            LineState::Up => {
                let waiting = match &self.outstanding {
                    Some(o) => Some(o.deadline),
                    None => self.quiet_until.or(self.sched_wake),
                };
                [waiting, self.lease.deadline()].into_iter().flatten().min()
            }
        };
        [line, Some(self.next_health)].into_iter().flatten().min()
    }

    fn awaits_bytes(&self) -> bool {
        self.outstanding.is_some()
    }

    fn is_closed(&self) -> bool {
        self.closed
    }
}

/// A STOP of all axes: it ends the motion queued before it.
fn ends_motion(command: &crate::protocol::Command) -> bool {
    safety::is_stop_all(command)
}

/// What a STOP of all axes ends while it still waits: moves, jogs and homing, and writes
/// to the controller's data (automatic operation, behind STOP like motion).
fn stopped_by(command: &crate::protocol::Command) -> bool {
    command.moves_arm()
        || command.writes_data()
        || matches!(command, crate::protocol::Command::Home(_))
        || starts_program(command)
}

/// A program run, one step or resume (253H, 256H, 257H): the program may move the arm.
pub(super) fn starts_program(command: &crate::protocol::Command) -> bool {
    command.is_program_start()
}

impl CoreEvent for LinkEvent {
    fn is_traffic(&self) -> bool {
        LinkEvent::is_traffic(self)
    }

    fn dropped(frames: u64) -> Option<Self> {
        Some(LinkEvent::Dropped { frames })
    }
}
