//! The link thread's life: opening and reopening the line, taking requests from the
//! handle, choosing what goes out next, watching an idle line, reporting its health.

use std::sync::Arc;
use std::sync::atomic::AtomicU64;
use std::time::{Duration, Instant};

use crossbeam_channel::{Receiver, TryRecvError, select};

use super::event::LinkEvent;
use super::events::EventOut;
use super::handle::{Connector, Control, LinkConfig};
use super::health::HealthMeter;
use super::lease::JogLease;
use super::reason::{IoFailure, LineDownReason, NotSentReason};
use super::request::{Origin, Pending, Priority, RequestId};
use super::schedule::{Next, Scheduler};
use super::shutdown::ShutdownReport;
use super::sync::LineSync;
use super::table::TableJob;
use super::transport::{Transport, is_timeout};
use crate::protocol::{AxisPattern, Command, Stop, StreamDecoder};

/// While idle, the line is checked this often (a vanished port shows within a second).
pub(super) const IDLE_CHECK: Duration = Duration::from_millis(200);
const HEALTH_EVERY: Duration = Duration::from_millis(500);

/// `at + d`, or a time far enough ahead when a huge setting would overflow.
pub(super) fn later(at: Instant, d: Duration) -> Instant {
    at.checked_add(d)
        .or_else(|| at.checked_add(Duration::from_secs(24 * 3600)))
        .unwrap_or(at)
}

pub(crate) struct Engine {
    pub(super) connector: Connector,
    pub(super) config: LinkConfig,
    pub(super) control: Receiver<Control>,
    /// STOPs travel apart from everything else, so none waits behind other messages.
    pub(super) stops: Receiver<Pending>,
    pub(super) events: EventOut,
    pub(super) ids: Arc<AtomicU64>,
    pub(super) transport: Option<Box<dyn Transport>>,
    pub(super) sched: Scheduler,
    pub(super) decoder: StreamDecoder,
    pub(super) health: HealthMeter,
    pub(super) tx_buf: Vec<u8>,
    pub(super) rx_buf: Vec<u8>,
    /// Whether a late reply may still arrive (motion waits for proof that none will).
    pub(super) sync: LineSync,
    /// A jog was started and no STOP has been acknowledged since.
    pub(super) jog_may_run: bool,
    /// A motion command went out and no STOP of all axes has been acknowledged since
    /// (the link cannot tell when a move has ended; a STOP of a still arm is harmless).
    pub(super) motion_may_run: bool,
    pub(super) lease: JogLease,
    /// The continuous jog awaiting its reply took the lease (none was held before it): if
    /// the controller refuses it, nothing runs on the lease any more.
    pub(super) jog_took_lease: bool,
    /// Polling is paused because the event reader is far behind.
    polls_paused: bool,
    /// When the last reply (or time-out) ended: the next command waits for the gap.
    pub(super) line_quiet_since: Option<Instant>,
    pub(super) shutting_down: bool,
    reconnect_requested: bool,
    ever_connected: bool,
    open_failure_reported: bool,
    pub(super) next_reconnect: Option<Instant>,
    last_health: Instant,
    last_line_check: Instant,
}

impl Engine {
    pub(crate) fn new(
        connector: Connector,
        config: LinkConfig,
        control: Receiver<Control>,
        stops: Receiver<Pending>,
        events: EventOut,
        lease: JogLease,
        ids: Arc<AtomicU64>,
    ) -> Self {
        let now = Instant::now();
        Self {
            connector,
            sched: Scheduler::new(config.polling.clone(), now),
            config,
            control,
            stops,
            events,
            lease,
            jog_took_lease: false,
            ids,
            transport: None,
            decoder: StreamDecoder::new(),
            health: HealthMeter::default(),
            tx_buf: Vec::with_capacity(128),
            rx_buf: vec![0; 4096],
            sync: LineSync::default(),
            jog_may_run: false,
            motion_may_run: false,
            polls_paused: false,
            line_quiet_since: None,
            shutting_down: false,
            reconnect_requested: false,
            ever_connected: false,
            open_failure_reported: false,
            next_reconnect: Some(now),
            last_health: now,
            last_line_check: now,
        }
    }

    pub(super) fn emit(&self, event: LinkEvent) {
        self.events.send(event);
    }

    pub(super) fn new_id(&self) -> RequestId {
        RequestId::next(&self.ids)
    }

    /// Runs until shut down (by the handle, or because it was dropped), then sends the
    /// STOPs owed and closes the line.
    pub(crate) fn run(mut self) -> ShutdownReport {
        while !self.shutting_down {
            let now = Instant::now();
            if std::mem::take(&mut self.reconnect_requested) {
                self.line_lost(LineDownReason::ReconnectRequested);
                self.next_reconnect = Some(now);
            }
            // Connecting comes first, so requests submitted while the line opens are
            // judged against the opened line, not refused.
            if self.transport.is_none() {
                self.try_reconnect(now);
            }
            self.drain_control();
            if self.shutting_down || self.reconnect_requested {
                continue;
            }
            if self.transport.is_none() {
                let wait = self
                    .next_reconnect
                    .map_or(IDLE_CHECK, |t| t.saturating_duration_since(now))
                    .min(IDLE_CHECK);
                self.wait_for_control(wait);
                continue;
            }
            self.check_lease(now);
            self.follow_reader(now);
            self.pass_guardian_stops();
            let ids = self.ids.clone();
            match self.sched.next(now, &mut || RequestId::next(&ids)) {
                Next::Send(pending) => {
                    self.transact(pending);
                }
                Next::Wait(until) => {
                    let until = match (until, self.lease.deadline()) {
                        (Some(a), Some(b)) => Some(a.min(b)),
                        (a, b) => a.or(b),
                    };
                    let wait = until
                        .map_or(IDLE_CHECK, |t| t.saturating_duration_since(now))
                        .min(IDLE_CHECK);
                    if !wait.is_zero() {
                        self.wait_for_control(wait);
                    }
                    if self.last_line_check.elapsed() >= IDLE_CHECK {
                        self.idle_check();
                    }
                }
            }
        }
        self.shut_down()
    }

    /// Health twice a second while the reader keeps up; polling paused while it is far
    /// behind (polls are the link's own, and their replies are never left out).
    fn follow_reader(&mut self, now: Instant) {
        let behind = self.events.behind();
        if behind != self.polls_paused {
            self.polls_paused = behind;
            self.sched.pause_polls(behind, now);
            self.health.polling_paused(behind);
            if behind {
                // Sent once as the pause begins, so the reader learns why status is stale.
                let health = self.health_now(now);
                self.emit(LinkEvent::Health(health));
            }
        }
        if !behind && now.duration_since(self.last_health) >= HEALTH_EVERY {
            self.last_health = now;
            let health = self.health_now(now);
            self.emit(LinkEvent::Health(health));
        }
    }

    fn health_now(&mut self, now: Instant) -> super::health::LinkHealth {
        let mut health = self.health.snapshot(now);
        health.events_dropped = self.events.dropped_total();
        health
    }

    /// Hands on the STOPs a guardian sent of its own.
    fn pass_guardian_stops(&mut self) {
        let stops = self
            .transport
            .as_mut()
            .map(|t| t.take_guardian_stops())
            .unwrap_or_default();
        for why in stops {
            self.emit(LinkEvent::GuardianStopped(why));
        }
    }

    /// Stops a continuous jog whose lease was not renewed in time.
    fn check_lease(&mut self, now: Instant) {
        if self.lease.take_lapse(now) && !self.sched.stop_queued() {
            let stop = Command::Stop(Stop {
                axes: AxisPattern::ALL,
                cancel_held_outputs: false,
            });
            let id = self.new_id();
            self.sched
                .push(Pending::new(id, stop, Origin::LeaseLapsed, Priority::Stop));
        }
    }

    /// Handles STOPs and control messages already waiting, without blocking; STOPs first.
    pub(super) fn drain_control(&mut self) {
        while let Ok(stop) = self.stops.try_recv() {
            self.submitted(stop);
        }
        loop {
            let msg = match self.control.try_recv() {
                Ok(msg) => msg,
                Err(TryRecvError::Empty) => break,
                // The handle is gone without a word: shut down all the same.
                Err(TryRecvError::Disconnected) => {
                    self.shutting_down = true;
                    break;
                }
            };
            self.handle_control(msg);
            // A STOP sent meanwhile overtakes the rest of a long backlog.
            while let Ok(stop) = self.stops.try_recv() {
                self.submitted(stop);
            }
        }
    }

    /// Waits up to `wait` for one STOP or control message.
    fn wait_for_control(&mut self, wait: Duration) {
        select! {
            recv(self.stops) -> stop => match stop {
                Ok(stop) => self.submitted(stop),
                Err(_) => self.shutting_down = true,
            },
            recv(self.control) -> msg => match msg {
                Ok(msg) => self.handle_control(msg),
                Err(_) => self.shutting_down = true,
            },
            default(wait) => {}
        }
    }

    fn submitted(&mut self, pending: Pending) {
        if self.transport.is_none() {
            self.not_sent(&pending, NotSentReason::LineDown);
        } else {
            self.sched.push(pending);
        }
    }

    fn handle_control(&mut self, msg: Control) {
        match msg {
            Control::Submit(pending) => self.submitted(pending),
            Control::SetPolling(polling) => self.sched.set_polling(polling, Instant::now()),
            Control::DownloadTable(request) => {
                if let Some(old) = self.sched.start_table(request) {
                    self.report_table(old);
                }
                if self.transport.is_none()
                    && let Some(job) = self.sched.abort_table()
                {
                    self.report_table(job);
                }
                self.finish_table_if_done();
            }
            Control::CancelTable => {
                if let Some(job) = self.sched.abort_table() {
                    self.report_table(job);
                }
            }
            // Acted on between transactions, never in the middle of one.
            Control::Reconnect => self.reconnect_requested = true,
            Control::SetAutoReconnect(on) => {
                self.config.auto_reconnect = on;
                if on && self.transport.is_none() {
                    self.next_reconnect.get_or_insert_with(Instant::now);
                }
            }
            Control::Shutdown => self.shutting_down = true,
        }
    }

    pub(super) fn not_sent(&self, pending: &Pending, reason: NotSentReason) {
        self.emit(LinkEvent::NotSent {
            id: pending.id,
            command: pending.command,
            reason,
        });
    }

    pub(super) fn try_reconnect(&mut self, now: Instant) {
        let Some(at) = self.next_reconnect else {
            return;
        };
        if now < at {
            return;
        }
        match (self.connector)() {
            Ok(transport) => {
                let line = transport.describe();
                self.transport = Some(transport);
                self.decoder = StreamDecoder::new();
                self.next_reconnect = None;
                self.line_quiet_since = None;
                self.last_line_check = now;
                self.sched.set_polling(self.sched.polling().clone(), now);
                self.emit(if self.ever_connected {
                    LinkEvent::Reconnected { line }
                } else {
                    LinkEvent::Connected { line }
                });
                self.ever_connected = true;
                self.open_failure_reported = false;
                // A jog started before the loss may still be running: stop it first.
                self.queue_safety_stop();
            }
            Err(e) => {
                if !self.open_failure_reported {
                    // Reported once; further attempts stay quiet until one succeeds.
                    self.open_failure_reported = true;
                    self.emit(LinkEvent::Disconnected {
                        reason: LineDownReason::OpenFailed(IoFailure::from(&e)),
                    });
                }
                self.next_reconnect = self
                    .config
                    .auto_reconnect
                    .then(|| later(now, self.config.reconnect_interval));
            }
        }
    }

    /// The line is gone: report it, refuse what is queued (none of it may go out later,
    /// least of all motion), and plan a reconnect. Does nothing if it is already down.
    pub(super) fn line_lost(&mut self, reason: LineDownReason) {
        if self.transport.take().is_none() {
            return;
        }
        self.emit(LinkEvent::Disconnected { reason });
        // Every id a caller or an event announced gets its answer; polls and table
        // chunks are the link's own (the table is reported as a whole below).
        for pending in self.sched.drain_queued() {
            if !matches!(pending.origin, Origin::Poll | Origin::Table { .. }) {
                self.not_sent(&pending, NotSentReason::LineLost);
            }
        }
        if let Some(job) = self.sched.abort_table() {
            self.report_table(job);
        }
        self.next_reconnect = self
            .config
            .auto_reconnect
            .then(|| later(Instant::now(), self.config.reconnect_interval));
    }

    /// Reads whatever arrived unasked while idle; notices a vanished line.
    fn idle_check(&mut self) {
        self.last_line_check = Instant::now();
        let Some(transport) = self.transport.as_mut() else {
            return;
        };
        let mut buf = [0u8; 512];
        match transport.read_timeout(&mut buf, Duration::ZERO) {
            Ok(0) => self.line_lost(LineDownReason::Closed),
            Ok(n) => self.report_stale(&buf[..n]),
            Err(e) if is_timeout(&e) => {}
            Err(e) => self.line_lost(LineDownReason::ReadFailed(IoFailure::from(&e))),
        }
    }

    pub(super) fn finish_table_if_done(&mut self) {
        if let Some(job) = self.sched.take_finished_table() {
            self.report_table(job);
        }
    }

    pub(super) fn report_table(&mut self, job: TableJob) {
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
}
