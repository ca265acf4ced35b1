//! The link thread: owns the line, sends one command at a time, pairs each reply with its
//! command, applies the retry and STOP rules, polls, and reports everything as events.

use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

use crossbeam_channel::{Receiver, RecvTimeoutError, Sender};

use super::event::{LinkEvent, garbage_event};
use super::handle::{Connector, Control, LinkConfig, Repaint};
use super::health::HealthMeter;
use super::request::{Origin, Pending, Priority, RequestId};
use super::schedule::{Next, Scheduler};
use super::table::TableJob;
use super::transport::{Transport, is_timeout};
use crate::protocol::{Frame, Header, Reply, StreamDecoder};

/// Longest single wait on the line, so control messages are seen promptly.
const READ_SLICE: Duration = Duration::from_millis(20);
/// While idle, the line is checked this often (a vanished port shows within a second).
const IDLE_CHECK: Duration = Duration::from_millis(200);
const HEALTH_EVERY: Duration = Duration::from_millis(500);

/// How a transaction ended.
enum Outcome {
    Answered,
    TimedOut,
    LineLost(String),
    Shutdown,
}

pub(crate) struct Engine {
    connector: Connector,
    config: LinkConfig,
    control: Receiver<Control>,
    events: Sender<LinkEvent>,
    repaint: Repaint,
    ids: Arc<AtomicU64>,
    transport: Option<Box<dyn Transport>>,
    sched: Scheduler,
    decoder: StreamDecoder,
    health: HealthMeter,
    tx_buf: Vec<u8>,
    rx_buf: Vec<u8>,
    /// When the last reply (or time-out) ended: the next command waits for the gap.
    line_quiet_since: Option<Instant>,
    ever_connected: bool,
    next_reconnect: Option<Instant>,
    last_health: Instant,
    shutting_down: bool,
}

impl Engine {
    pub(crate) fn new(
        connector: Connector,
        config: LinkConfig,
        control: Receiver<Control>,
        events: Sender<LinkEvent>,
        repaint: Repaint,
        ids: Arc<AtomicU64>,
    ) -> Self {
        let now = Instant::now();
        Self {
            connector,
            sched: Scheduler::new(config.polling.clone(), now),
            config,
            control,
            events,
            repaint,
            ids,
            transport: None,
            decoder: StreamDecoder::new(),
            health: HealthMeter::default(),
            tx_buf: Vec::with_capacity(128),
            rx_buf: vec![0; 4096],
            line_quiet_since: None,
            ever_connected: false,
            next_reconnect: Some(now),
            last_health: now,
            shutting_down: false,
        }
    }

    fn emit(&self, event: LinkEvent) {
        // A dropped receiver only means nobody listens any more.
        let _ = self.events.send(event);
        (self.repaint)();
    }

    fn new_id(ids: &AtomicU64) -> RequestId {
        RequestId(ids.fetch_add(1, Ordering::Relaxed))
    }

    pub(crate) fn run(mut self) {
        while !self.shutting_down {
            let now = Instant::now();
            // Connecting comes first, so requests submitted while the line opens are
            // judged against the opened line, not refused.
            if self.transport.is_none() {
                self.try_reconnect(now);
            }
            self.drain_control();
            if self.shutting_down {
                break;
            }
            if self.transport.is_none() {
                let wait = self
                    .next_reconnect
                    .map_or(IDLE_CHECK, |t| t.saturating_duration_since(now))
                    .min(IDLE_CHECK);
                self.wait_for_control(wait);
                continue;
            }
            if now.duration_since(self.last_health) >= HEALTH_EVERY {
                self.last_health = now;
                let health = self.health.snapshot(now);
                self.emit(LinkEvent::Health(health));
            }
            let ids = self.ids.clone();
            match self.sched.next(now, &mut || Self::new_id(&ids)) {
                Next::Send(pending) => self.transact(pending),
                Next::Wait(until) => {
                    let wait = until
                        .map_or(IDLE_CHECK, |t| t.saturating_duration_since(now))
                        .min(IDLE_CHECK);
                    if !self.wait_for_control(wait) && until.is_none_or(|t| t > now + wait) {
                        self.idle_check();
                    }
                }
            }
        }
        self.transport = None;
    }

    /// Handles control messages already waiting, without blocking.
    fn drain_control(&mut self) {
        while let Ok(msg) = self.control.try_recv() {
            self.handle_control(msg);
        }
    }

    /// Waits up to `wait` for one control message; false when none came.
    fn wait_for_control(&mut self, wait: Duration) -> bool {
        match self.control.recv_timeout(wait) {
            Ok(msg) => {
                self.handle_control(msg);
                true
            }
            Err(RecvTimeoutError::Timeout) => false,
            Err(RecvTimeoutError::Disconnected) => {
                self.shutting_down = true;
                true
            }
        }
    }

    fn handle_control(&mut self, msg: Control) {
        match msg {
            Control::Submit(pending, _) if self.transport.is_none() => {
                self.emit(LinkEvent::NotSent {
                    id: pending.id,
                    command: pending.command,
                    reason: "the line is down".into(),
                });
            }
            Control::Submit(pending, priority) => self.sched.push(pending, priority),
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
            }
            Control::CancelTable => {
                if let Some(job) = self.sched.abort_table() {
                    self.report_table(job);
                }
            }
            Control::Reconnect => {
                if self.transport.take().is_some() {
                    self.line_lost("closed to reconnect".into());
                }
                self.next_reconnect = Some(Instant::now());
            }
            Control::SetAutoReconnect(on) => self.config.auto_reconnect = on,
            Control::Shutdown => self.shutting_down = true,
        }
    }

    fn try_reconnect(&mut self, now: Instant) {
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
                self.sched.set_polling(self.sched.polling().clone(), now);
                self.emit(if self.ever_connected {
                    LinkEvent::Reconnected { line }
                } else {
                    LinkEvent::Connected { line }
                });
                self.ever_connected = true;
            }
            Err(e) => {
                if !self.ever_connected && self.next_reconnect == Some(at) {
                    self.emit(LinkEvent::Disconnected {
                        reason: format!("cannot open the line: {e}"),
                    });
                    // Reported once; further attempts stay quiet until one succeeds.
                    self.ever_connected = true;
                }
                self.next_reconnect = self
                    .config
                    .auto_reconnect
                    .then(|| now + self.config.reconnect_interval);
            }
        }
    }

    /// The line is gone: report it, refuse what is queued (none of it may go out later,
    /// least of all motion), and plan a reconnect.
    fn line_lost(&mut self, reason: String) {
        self.transport = None;
        self.emit(LinkEvent::Disconnected { reason });
        for pending in self.sched.drain_queued() {
            if pending.origin == Origin::User {
                self.emit(LinkEvent::NotSent {
                    id: pending.id,
                    command: pending.command,
                    reason: "the line was lost before it could be sent".into(),
                });
            }
        }
        if let Some(job) = self.sched.abort_table() {
            self.report_table(job);
        }
        self.next_reconnect = self
            .config
            .auto_reconnect
            .then(|| Instant::now() + self.config.reconnect_interval);
    }

    /// Reads whatever arrived unasked while idle; notices a vanished line.
    fn idle_check(&mut self) {
        let Some(transport) = self.transport.as_mut() else {
            return;
        };
        match transport.read_timeout(&mut self.rx_buf, Duration::ZERO) {
            Ok(0) => self.line_lost("the line was closed".into()),
            Ok(n) => {
                let bytes = self.rx_buf[..n].to_vec();
                self.health.bad_frame();
                self.emit(LinkEvent::Garbage {
                    bytes,
                    error: "bytes arrived while no command was outstanding".into(),
                    at: Instant::now(),
                });
            }
            Err(e) if is_timeout(&e) => {}
            Err(e) => self.line_lost(e.to_string()),
        }
    }

    fn wait_for_gap(&self) {
        if let Some(quiet) = self.line_quiet_since {
            let ready = quiet + self.config.timing.gap;
            let now = Instant::now();
            if ready > now {
                std::thread::sleep(ready - now);
            }
        }
    }

    /// One command on the line and its reply, time-out or loss.
    fn transact(&mut self, mut pending: Pending) {
        self.tx_buf.clear();
        if let Err(e) =
            pending
                .command
                .encode_into(self.config.station, self.config.sc_mode, &mut self.tx_buf)
        {
            self.emit(LinkEvent::NotSent {
                id: pending.id,
                command: pending.command,
                reason: e.to_string(),
            });
            return;
        }
        self.wait_for_gap();
        let Some(transport) = self.transport.as_mut() else {
            return;
        };
        // Late replies and noise must not be taken for this command's answer.
        let stale = match transport.discard_input() {
            Ok(bytes) => bytes,
            Err(e) => return self.line_lost(e.to_string()),
        };
        self.report_stale(&stale);
        let Some(transport) = self.transport.as_mut() else {
            return;
        };
        if let Err(e) = transport.write_all_bytes(&self.tx_buf) {
            let reason = format!("write failed: {e}");
            self.emit(LinkEvent::NotSent {
                id: pending.id,
                command: pending.command,
                reason: format!("{reason} (part of the frame may have gone out)"),
            });
            return self.line_lost(reason);
        }
        let sent_at = Instant::now();
        pending.attempts = pending.attempts.saturating_add(1);
        self.emit(LinkEvent::FrameSent {
            id: pending.id,
            bytes: self.tx_buf.clone(),
            at: sent_at,
        });
        let timeout = self
            .config
            .timing
            .reply_timeout(self.tx_buf.len(), pending.command.max_reply_len());
        let outcome = self.await_reply(&pending, sent_at, sent_at + timeout);
        let ended = Instant::now();
        self.line_quiet_since = Some(ended);
        self.health
            .transaction(sent_at, ended, pending.origin == Origin::Poll);
        match outcome {
            Outcome::Answered => {}
            Outcome::TimedOut => self.timed_out(pending),
            Outcome::LineLost(reason) => {
                self.emit(LinkEvent::Timeout {
                    id: pending.id,
                    origin: pending.origin,
                    command: pending.command,
                    retrying: false,
                    recheck: None,
                });
                self.line_lost(reason);
            }
            Outcome::Shutdown => {}
        }
        if let Some(job) = self.sched.take_finished_table() {
            self.report_table(job);
        }
    }

    /// Reports bytes that arrived while no command waited for them, frame by frame: a
    /// late reply, a frame with a bad checksum, noise, or a frame cut short.
    fn report_stale(&mut self, stale: &[u8]) {
        let at = Instant::now();
        self.decoder.push(stale);
        while let Some(item) = self.decoder.pull() {
            self.health.bad_frame();
            match item {
                Ok(frame) => self.emit(LinkEvent::Garbage {
                    bytes: frame.raw().to_vec(),
                    error: "late frame: not the answer to anything outstanding".into(),
                    at,
                }),
                Err(error) => self.emit(garbage_event(&error, at)),
            }
        }
        let rest = self.decoder.take_pending();
        if !rest.is_empty() {
            self.health.bad_frame();
            self.emit(LinkEvent::Garbage {
                bytes: rest,
                error: "incomplete frame: no line end".into(),
                at,
            });
        }
    }

    fn await_reply(&mut self, pending: &Pending, sent_at: Instant, deadline: Instant) -> Outcome {
        let mut first_byte: Option<Instant> = None;
        loop {
            self.drain_control();
            if self.shutting_down {
                return Outcome::Shutdown;
            }
            let now = Instant::now();
            if now >= deadline {
                let rest = self.decoder.take_pending();
                if !rest.is_empty() {
                    self.health.bad_frame();
                    self.emit(LinkEvent::Garbage {
                        bytes: rest,
                        error: "incomplete frame: no line end before the time-out".into(),
                        at: now,
                    });
                }
                return Outcome::TimedOut;
            }
            let Some(transport) = self.transport.as_mut() else {
                return Outcome::LineLost("the line is down".into());
            };
            let slice = (deadline - now).min(READ_SLICE);
            let n = match transport.read_timeout(&mut self.rx_buf, slice) {
                Ok(0) => return Outcome::LineLost("the line was closed".into()),
                Ok(n) => n,
                Err(e) if is_timeout(&e) => continue,
                Err(e) => return Outcome::LineLost(e.to_string()),
            };
            let at = Instant::now();
            if self.decoder.pending() == 0 {
                first_byte = Some(at);
            }
            self.decoder.push(&self.rx_buf[..n]);
            while let Some(item) = self.decoder.pull() {
                match item {
                    Ok(frame) => {
                        let frame_first = first_byte.unwrap_or(at);
                        first_byte = None;
                        self.emit(LinkEvent::FrameReceived {
                            bytes: frame.raw().to_vec(),
                            first_byte: frame_first,
                            last_byte: at,
                        });
                        if self.answers(pending, &frame, sent_at, at) {
                            return Outcome::Answered;
                        }
                    }
                    Err(error) => {
                        first_byte = None;
                        self.health.bad_frame();
                        self.emit(garbage_event(&error, at));
                    }
                }
                if self.decoder.pending() > 0 && first_byte.is_none() {
                    first_byte = Some(at);
                }
            }
        }
    }

    /// Whether `frame` is the answer to `pending`; if so it is reported. A frame for
    /// another station or message is reported as unexpected and the wait goes on.
    fn answers(
        &mut self,
        pending: &Pending,
        frame: &Frame<'_>,
        sent_at: Instant,
        at: Instant,
    ) -> bool {
        let expected = pending.command.id();
        let unexpected = |why: String| LinkEvent::Garbage {
            bytes: frame.raw().to_vec(),
            error: why,
            at,
        };
        if frame.station() != self.config.station {
            self.emit(unexpected(format!(
                "reply from station {} while talking to station {}",
                frame.station(),
                self.config.station
            )));
            return false;
        }
        match frame.header() {
            Header::Command => {
                self.emit(unexpected(
                    "a command frame ('!') came back: is the line looped back?".into(),
                ));
                false
            }
            Header::Reply if frame.id() != Some(expected) => {
                self.emit(unexpected(format!(
                    "reply to {} while waiting for the reply to {expected}",
                    frame.id().map_or_else(|| "?".into(), |id| id.to_string())
                )));
                false
            }
            _ => match Reply::decode(frame) {
                Ok(Reply::Error(code)) => {
                    self.health.error_reply();
                    self.after_reply(pending, None);
                    self.emit(LinkEvent::ErrorReply {
                        id: pending.id,
                        origin: pending.origin,
                        command: pending.command,
                        code,
                    });
                    true
                }
                Ok(reply) => {
                    self.health.reply(at.saturating_duration_since(sent_at));
                    self.after_reply(pending, Some(&reply));
                    self.emit(LinkEvent::Reply {
                        id: pending.id,
                        origin: pending.origin,
                        command: pending.command,
                        reply,
                        round_trip: at.saturating_duration_since(sent_at),
                    });
                    true
                }
                Err(e) => {
                    self.health.bad_frame();
                    self.emit(unexpected(e.to_string()));
                    false
                }
            },
        }
    }

    /// Book-keeping of a table chunk's answer.
    fn after_reply(&mut self, pending: &Pending, reply: Option<&Reply>) {
        let Origin::Table { .. } = pending.origin else {
            return;
        };
        let Some(job) = self.sched.table_mut() else {
            return;
        };
        if let Some(Reply::CoordTable2(table)) = reply {
            job.accept(table.axes, table.first, &table.records);
        }
        let (kind, received, total) = (job.request.kind, job.received(), job.request.records);
        self.emit(LinkEvent::TableProgress {
            kind,
            received,
            total,
        });
    }

    /// A time-out: retry a query, recheck status after motion, give up on a table chunk.
    fn timed_out(&mut self, pending: Pending) {
        self.health.timeout();
        let retrying = pending.may_retry(self.config.query_retries);
        let mut recheck = None;
        if retrying {
            self.health.retry();
            let priority = match pending.origin {
                Origin::Table { .. } => Priority::Background,
                _ if pending.command.is_stop() => Priority::Stop,
                _ => Priority::User,
            };
            self.sched.push_front(pending, priority);
        } else if pending.command.is_motion() {
            // Never re-send motion: it may have been executed. Read the status instead.
            let id = Self::new_id(&self.ids);
            recheck = Some(id);
            self.sched.push_front(
                Pending {
                    id,
                    command: self.config.recheck,
                    origin: Origin::Recheck { after: pending.id },
                    attempts: 0,
                },
                Priority::User,
            );
        }
        self.emit(LinkEvent::Timeout {
            id: pending.id,
            origin: pending.origin,
            command: pending.command,
            retrying,
            recheck,
        });
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
            records: job.records,
            missing,
        });
    }
}
