//! One command's trip on the line: proving the line is in step before motion, sending,
//! pairing the reply with the command, and what a time-out means for each kind of
//! request (retry a query, re-read status after motion, stop a jog that may run on).

use std::time::{Duration, Instant};

use super::engine::{Engine, later};
use super::event::{LinkEvent, garbage_event};
use super::lease::is_continuous_jog;
use super::reason::{BadInput, IoFailure, LineDownReason, NotSentReason};
use super::request::{Origin, Pending, Priority};
use super::sync::reply_id;
use super::transport::is_timeout;
use crate::protocol::{AxisPattern, Command, ErrorCode, Frame, Header, Reply, Stop};

/// Longest single wait on the line, so control messages are seen promptly.
const READ_SLICE: Duration = Duration::from_millis(20);
/// Proving queries tried for one motion command before it is refused.
const MAX_PROOFS: u8 = 6;

/// How a transaction ended, for the caller (shutdown reports it per STOP).
#[derive(Debug, Clone, PartialEq, Eq)]
pub(super) enum Settled {
    /// A normal reply (to the request, or to the proving query sent in its place).
    Answered,
    Refused(ErrorCode),
    TimedOut,
    /// The line was lost while waiting for the reply.
    Interrupted,
    NotSent(NotSentReason),
}

/// How the wait for a reply ended.
enum Outcome {
    Answered(Option<ErrorCode>),
    /// No valid answer in time; `reply_came_damaged` when a damaged frame carrying this
    /// command's reply ID arrived (so no late reply is to be expected).
    TimedOut {
        reply_came_damaged: bool,
    },
    LineLost(LineDownReason),
}

impl Engine {
    /// Sends `pending` (or, for motion on a line out of step, a proving query first)
    /// and waits for its reply, time-out or loss.
    pub(super) fn transact(&mut self, pending: Pending) -> Settled {
        let refuse = |engine: &mut Engine, pending: &Pending, why: NotSentReason| {
            engine.not_sent(pending, why.clone());
            Settled::NotSent(why)
        };
        if is_continuous_jog(&pending.command) && self.lease.lapsed(Instant::now()) {
            // Its caller stopped renewing the lease before it went out.
            return refuse(self, &pending, NotSentReason::LeaseLapsed);
        }
        let pending = match self.prove_before_motion(pending) {
            Ok(pending) => pending,
            Err(refused) => return refused,
        };
        self.tx_buf.clear();
        if let Err(e) =
            pending
                .command
                .encode_into(self.config.station, self.config.sc_mode, &mut self.tx_buf)
        {
            return refuse(self, &pending, NotSentReason::Unencodable(e));
        }
        self.wait_for_gap();
        let Some(transport) = self.transport.as_mut() else {
            return refuse(self, &pending, NotSentReason::LineDown);
        };
        // Late replies and noise must not be taken for this command's answer.
        let stale = match transport.discard_input() {
            Ok(bytes) => bytes,
            Err(e) => {
                let settled = refuse(self, &pending, NotSentReason::LineLost);
                self.line_lost(LineDownReason::ReadFailed(IoFailure::from(&e)));
                return settled;
            }
        };
        self.report_stale(&stale);
        let Some(transport) = self.transport.as_mut() else {
            return refuse(self, &pending, NotSentReason::LineDown);
        };
        if let Err(e) = transport.write_all_bytes(&self.tx_buf) {
            let failure = IoFailure::from(&e);
            let settled = refuse(self, &pending, NotSentReason::WriteFailed(failure.clone()));
            // Part of a motion frame may have gone out: treat the motion as possible.
            self.motion_may_run |= pending.command.is_motion();
            self.line_lost(LineDownReason::WriteFailed(failure));
            return settled;
        }
        let sent_at = Instant::now();
        let mut pending = pending;
        pending.attempts = pending.attempts.saturating_add(1);
        if pending.command.is_motion() {
            self.motion_may_run = true;
        }
        self.jog_took_lease = is_continuous_jog(&pending.command) && self.lease.hold();
        self.emit(LinkEvent::FrameSent {
            id: pending.id,
            bytes: self.tx_buf.clone(),
            at: sent_at,
        });
        let timeout = self
            .config
            .timing
            .reply_timeout(self.tx_buf.len(), pending.command.max_reply_len());
        let outcome = self.await_reply(&pending, sent_at, later(sent_at, timeout));
        let ended = Instant::now();
        self.line_quiet_since = Some(ended);
        self.health
            .transaction(sent_at, ended, pending.origin == Origin::Poll);
        let settled = match outcome {
            Outcome::Answered(None) => Settled::Answered,
            Outcome::Answered(Some(code)) => Settled::Refused(code),
            Outcome::TimedOut { reply_came_damaged } => {
                self.timed_out(pending, reply_came_damaged);
                Settled::TimedOut
            }
            Outcome::LineLost(reason) => {
                self.emit(LinkEvent::Interrupted {
                    id: pending.id,
                    origin: pending.origin,
                    command: pending.command,
                });
                if matches!(pending.command, Command::Jog(_)) {
                    self.jog_may_run = true;
                }
                self.line_lost(reason);
                Settled::Interrupted
            }
        };
        self.finish_table_if_done();
        settled
    }

    /// Motion goes out only on a line in step. Otherwise the move waits at the head of
    /// its queue while a proving query goes out; after [`MAX_PROOFS`] failed proofs the
    /// move is refused.
    fn prove_before_motion(&mut self, pending: Pending) -> Result<Pending, Settled> {
        let now = Instant::now();
        if !pending.command.is_motion() || self.sync.in_step(now) {
            return Ok(pending);
        }
        if pending.proofs >= MAX_PROOFS {
            self.not_sent(&pending, NotSentReason::OutOfStep);
            return Err(Settled::NotSent(NotSentReason::OutOfStep));
        }
        let mut waiting = pending;
        waiting.proofs += 1;
        self.sched.push_front(waiting);
        Ok(Pending::new(
            self.new_id(),
            self.sync.proving_query(now),
            Origin::Proof { before: pending.id },
            Priority::User,
        ))
    }

    fn wait_for_gap(&self) {
        if let Some(quiet) = self.line_quiet_since {
            let ready = later(quiet, self.config.timing.gap);
            let now = Instant::now();
            if ready > now {
                std::thread::sleep(ready - now);
            }
        }
    }

    fn await_reply(&mut self, pending: &Pending, sent_at: Instant, deadline: Instant) -> Outcome {
        let mut first_byte: Option<Instant> = None;
        let mut reply_came_damaged = false;
        loop {
            // A shutdown arriving now lets this transaction end (bounded by its reply
            // timeout) before the STOPs go out: the protocol allows one outstanding
            // command, and a reply still owed would otherwise be taken for the STOP's.
            self.drain_control();
            let now = Instant::now();
            if now >= deadline {
                let rest = self.decoder.take_pending();
                if !rest.is_empty() {
                    reply_came_damaged |= self.damaged_reply_seen(&rest, pending);
                    self.health.bad_frame();
                    self.emit(LinkEvent::Garbage {
                        bytes: rest,
                        error: BadInput::CutOff,
                        at: now,
                    });
                }
                return Outcome::TimedOut { reply_came_damaged };
            }
            let Some(transport) = self.transport.as_mut() else {
                return Outcome::LineLost(LineDownReason::Closed);
            };
            let n = match transport.read_timeout(&mut self.rx_buf, (deadline - now).min(READ_SLICE))
            {
                Ok(0) => return Outcome::LineLost(LineDownReason::Closed),
                Ok(n) => n,
                Err(e) if is_timeout(&e) => continue,
                Err(e) => {
                    return Outcome::LineLost(LineDownReason::ReadFailed(IoFailure::from(&e)));
                }
            };
            let at = Instant::now();
            if self.decoder.pending() == 0 {
                first_byte = Some(at);
            }
            self.decoder.push(&self.rx_buf[..n]);
            while let Some(item) = self.decoder.pull() {
                match item {
                    Ok(frame) => {
                        self.emit(LinkEvent::FrameReceived {
                            bytes: frame.raw().to_vec(),
                            first_byte: first_byte.unwrap_or(at),
                            last_byte: at,
                        });
                        if let Some(refused) = self.answers(pending, &frame, sent_at, at) {
                            return Outcome::Answered(refused);
                        }
                    }
                    Err(error) => {
                        reply_came_damaged |= self.damaged_reply_seen(error.raw(), pending);
                        self.health.bad_frame();
                        self.emit(garbage_event(&error, at));
                    }
                }
                first_byte = (self.decoder.pending() > 0).then_some(at);
            }
        }
    }

    /// Whether `frame` is the answer to `pending` (`Some(error code if refused)`); if so
    /// it is reported. A frame for another station or message is reported as unexpected
    /// and the wait goes on.
    fn answers(
        &mut self,
        pending: &Pending,
        frame: &Frame<'_>,
        sent_at: Instant,
        at: Instant,
    ) -> Option<Option<ErrorCode>> {
        let expected = pending.command.id();
        let unexpected = |why: BadInput| LinkEvent::Garbage {
            bytes: frame.raw().to_vec(),
            error: why,
            at,
        };
        if frame.station() != self.config.station {
            self.emit(unexpected(BadInput::WrongStation {
                got: frame.station(),
                expected: self.config.station,
            }));
            return None;
        }
        if frame.header() == Header::Command {
            self.emit(unexpected(BadInput::Echo));
            return None;
        }
        if frame.header() == Header::Reply && frame.id() != Some(expected) {
            if let Some(late) = frame.id() {
                self.sync.late_reply_arrived(late);
            }
            self.emit(unexpected(BadInput::OtherReply {
                got: frame.id(),
                expected,
            }));
            return None;
        }
        let round_trip = at.saturating_duration_since(sent_at);
        match Reply::decode(frame) {
            Ok(Reply::Error(code)) => {
                self.health.error_reply();
                if !self.sync.in_step(at) {
                    // This `&` may be an earlier command's late error; then this
                    // command's own reply is still to come.
                    let until = later(at, self.config.timing.late_reply_window);
                    self.sync.may_answer_late(expected, until);
                } else if self.jog_took_lease && is_continuous_jog(&pending.command) {
                    // In step, this is the jog's own refusal: it never ran, and no other
                    // jog holds the lease, so the lease has nothing to stop (a STOP on
                    // its lapse would be news of nothing).
                    self.lease.release();
                }
                self.emit(LinkEvent::ErrorReply {
                    id: pending.id,
                    origin: pending.origin,
                    command: pending.command,
                    code,
                });
                Some(Some(code))
            }
            Ok(reply) => {
                self.health.reply(round_trip);
                self.sync.reply_seen(expected, at);
                match pending.command {
                    Command::Jog(_) => self.jog_may_run = true,
                    // Only a STOP of every axis ends what the link may have started.
                    Command::Stop(stop) if stop.axes == AxisPattern::ALL => {
                        self.jog_may_run = false;
                        self.motion_may_run = false;
                        self.lease.release();
                    }
                    _ => {}
                }
                self.store_table_chunk(pending, &reply);
                self.emit(LinkEvent::Reply {
                    id: pending.id,
                    origin: pending.origin,
                    command: pending.command,
                    reply,
                    round_trip,
                });
                Some(None)
            }
            Err(e) => {
                self.health.bad_frame();
                self.emit(unexpected(BadInput::BadMessage(e)));
                None
            }
        }
    }

    /// Notes a damaged frame that starts like a reply: true if it carries `pending`'s
    /// reply ID (its reply came, damaged); otherwise an earlier late reply has arrived.
    fn damaged_reply_seen(&mut self, raw: &[u8], pending: &Pending) -> bool {
        match reply_id(raw) {
            Some(id) if id == pending.command.id() => true,
            Some(id) => {
                self.sync.late_reply_arrived(id);
                false
            }
            None => false,
        }
    }

    /// Files a table chunk's records under its download, if that is still running.
    fn store_table_chunk(&mut self, pending: &Pending, reply: &Reply) {
        let Origin::Table { generation, .. } = pending.origin else {
            return;
        };
        let Some(job) = self.sched.table_for(generation) else {
            return;
        };
        if let Reply::CoordTable2(table) = reply {
            job.accept(table.axes, table.first, &table.records);
        }
        let (kind, received, total) = (job.request.kind, job.received(), job.request.records);
        self.emit(LinkEvent::TableProgress {
            kind,
            received,
            total,
        });
    }

    /// A time-out: retry a query, re-read status after motion (never re-send it), stop
    /// a jog that may still be running.
    fn timed_out(&mut self, pending: Pending, reply_came_damaged: bool) {
        self.health.timeout();
        if !reply_came_damaged {
            let until = later(Instant::now(), self.config.timing.late_reply_window);
            self.sync.may_answer_late(pending.command.id(), until);
        }
        let stale_chunk = matches!(pending.origin, Origin::Table { generation, .. }
            if self.sched.table_for(generation).is_none());
        let retrying = pending.may_retry(self.config.query_retries) && !stale_chunk;
        let mut recheck = None;
        if retrying {
            self.health.retry();
            self.sched.push_front(pending);
        } else if pending.command.is_motion() {
            let id = self.new_id();
            recheck = Some(id);
            self.sched.push_front(Pending::new(
                id,
                self.config.recheck,
                Origin::Recheck { after: pending.id },
                Priority::User,
            ));
        }
        if matches!(pending.command, Command::Jog(_)) {
            self.jog_may_run = true;
        }
        self.emit(LinkEvent::Timeout {
            id: pending.id,
            origin: pending.origin,
            command: pending.command,
            retrying,
            recheck,
        });
        // A stalled line must not leave a jog running (DESIGN.md: STOP wins).
        self.queue_safety_stop();
    }

    /// Queues a STOP of all axes at the head of the queue if a jog may still be running.
    pub(super) fn queue_safety_stop(&mut self) {
        if self.jog_may_run && !self.sched.stop_queued() {
            let stop = Command::Stop(Stop {
                axes: AxisPattern::ALL,
                cancel_held_outputs: false,
            });
            self.sched.push(Pending::new(
                self.new_id(),
                stop,
                Origin::SafetyStop,
                Priority::Stop,
            ));
        }
    }

    /// Reports bytes that arrived while no command waited for them, frame by frame: a
    /// late reply, a frame with a bad checksum, noise, or a frame cut short.
    pub(super) fn report_stale(&mut self, stale: &[u8]) {
        let at = Instant::now();
        self.decoder.push(stale);
        while let Some(item) = self.decoder.pull() {
            self.health.bad_frame();
            let raw = match &item {
                Ok(frame) => frame.raw(),
                Err(error) => error.raw(),
            };
            if let Some(id) = reply_id(raw) {
                self.sync.late_reply_arrived(id);
            }
            match item {
                Ok(frame) => self.emit(LinkEvent::Garbage {
                    bytes: frame.raw().to_vec(),
                    error: BadInput::Late,
                    at,
                }),
                Err(error) => self.emit(garbage_event(&error, at)),
            }
        }
        let rest = self.decoder.take_pending();
        if !rest.is_empty() {
            if let Some(id) = reply_id(&rest) {
                self.sync.late_reply_arrived(id);
            }
            self.health.bad_frame();
            self.emit(LinkEvent::Garbage {
                bytes: rest,
                error: BadInput::CutOff,
                at,
            });
        }
    }
}
