//! One command's trip on the line as state: proving the line is in step before motion,
//! sending, pairing the reply with the command, and what a time-out means for each kind of
//! request (retry a query, re-read status after motion, stop a jog that may run on).

use std::time::Instant;

use super::FormatB;
use super::safety::{self, Kind, Verdict, is_stop_all, judge};
use super::starts_program;
use crate::link::driver::later;
use crate::link::event::{LinkEvent, garbage_event};
use crate::link::reason::{BadInput, LineDownReason, NotSentReason};
use crate::link::request::{Origin, Pending, Priority};
use crate::protocol::peek::reply_id;
use crate::protocol::{ALL_PROGRAMS, Command, ErrorCode, Frame, ProgramAction, ProgramCall, Reply};

/// Proving queries tried for one motion command before it is refused.
const MAX_PROOFS: u8 = 6;

/// How a transaction ended (a close reports it per STOP).
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

/// The command on the line.
#[derive(Debug)]
pub(super) struct Outstanding {
    pending: Pending,
    sent_at: Instant,
    /// The reply must be complete by then.
    pub(super) deadline: Instant,
    /// When the first byte of the frame being received came.
    first_byte: Option<Instant>,
    /// A damaged frame carrying this command's reply ID arrived (so no late reply is to
    /// be expected after a time-out).
    reply_came_damaged: bool,
}

/// A STOP of every axis, the link's own.
fn stop_all() -> Command {
    Command::Stop(safety::stop_all())
}

impl FormatB {
    /// Puts `pending` (or, for motion on a line out of step, a proving query first) on
    /// the line: the bytes to write, or `None` when it was refused (already reported).
    pub(super) fn send(&mut self, now: Instant, pending: Pending) -> Option<Vec<u8>> {
        if pending.command.is_continuous_jog() && self.lease.lapsed(now) {
            // Its caller stopped renewing the lease before it went out.
            self.refuse(&pending, NotSentReason::LeaseLapsed);
            return None;
        }
        let mut pending = self.prove_before_motion(now, pending)?;
        let mut bytes = Vec::with_capacity(64);
        if let Err(e) =
            pending
                .command
                .encode_into(self.config.station, self.config.sc_mode, &mut bytes)
        {
            self.refuse(&pending, NotSentReason::Unencodable(e));
            return None;
        }
        pending.attempts = pending.attempts.saturating_add(1);
        if !matches!(pending.origin, Origin::Poll | Origin::Table { .. }) {
            // The application's own requests (and the link's safety STOPs and proofs
            // for them) may change what the polls read: they keep the polls fast.
            self.sched.activity(now);
        }
        if Kind::of(&pending.command) == Kind::Motion {
            self.motion_may_run = true;
        }
        if starts_program(&pending.command) {
            self.program_may_run = true;
        }
        self.jog_took_lease = pending.command.is_continuous_jog() && self.lease.hold(now);
        self.emit(LinkEvent::FrameSent {
            id: pending.id,
            bytes: bytes.clone(),
            at: now,
        });
        let timeout = self
            .config
            .timing
            .reply_timeout(bytes.len(), pending.command.max_reply_len());
        self.outstanding = Some(Outstanding {
            pending,
            sent_at: now,
            deadline: later(now, timeout),
            first_byte: None,
            reply_came_damaged: false,
        });
        Some(bytes)
    }

    fn refuse(&mut self, pending: &Pending, why: NotSentReason) {
        self.not_sent(pending, why.clone());
        self.settled(pending, Settled::NotSent(why));
    }

    /// Motion goes out only on a line in step. Otherwise the move waits at the head of
    /// its queue while a proving query goes out; after [`MAX_PROOFS`] failed proofs the
    /// move is refused.
    fn prove_before_motion(&mut self, now: Instant, pending: Pending) -> Option<Pending> {
        if !pending.command.is_motion() || self.sync.in_step(now) {
            return Some(pending);
        }
        if pending.proofs >= MAX_PROOFS {
            self.refuse(&pending, NotSentReason::OutOfStep);
            return None;
        }
        let before = pending.id;
        let mut waiting = pending;
        waiting.proofs += 1;
        self.sched.push_front(waiting);
        Some(Pending::new(
            self.new_id(),
            self.sync.proving_query(now),
            Origin::Proof { before },
            Priority::User,
        ))
    }

    /// Bytes that came while the command is outstanding: frames are paired with it, the
    /// rest reported; whatever follows its answer is stale.
    pub(super) fn answer_bytes(&mut self, now: Instant, bytes: &[u8]) {
        let Some(out) = self.outstanding.as_mut() else {
            return self.report_stale(now, bytes);
        };
        if self.decoder.pending() == 0 {
            out.first_byte = Some(now);
        }
        self.decoder.push(bytes);
        while let Some(item) = self.decoder.pull() {
            let Some(out) = self.outstanding.as_mut() else {
                // Answered already: the rest came after it.
                self.report_stale_item(now, item);
                continue;
            };
            let first_byte = out.first_byte.unwrap_or(now);
            out.first_byte = (self.decoder.pending() > 0).then_some(now);
            match item {
                Ok(frame) => {
                    if let Some(settled) = self.answers(&frame, first_byte, now) {
                        self.end_transaction(now, settled);
                        self.finish_table_if_done();
                    }
                }
                Err(error) => {
                    if self.damaged_reply_seen(error.raw())
                        && let Some(out) = self.outstanding.as_mut()
                    {
                        out.reply_came_damaged = true;
                    }
                    self.health.bad_frame();
                    self.emit(garbage_event(&error, now));
                }
            }
        }
    }

    /// Whether `frame` (received from `first_byte` to `at`) answers the outstanding
    /// command (how it settled it); if so it is reported as received, then as the
    /// answer. A frame for another station or message is reported once, as unexpected,
    /// and the wait goes on.
    fn answers(&mut self, frame: &Frame<'_>, first_byte: Instant, at: Instant) -> Option<Settled> {
        let out = self.outstanding.as_ref()?;
        let (pending, sent_at) = (out.pending.clone(), out.sent_at);
        let expected = pending.command.id();
        let unexpected = |why: BadInput| crate::link::event::garbage(frame.raw(), why, at);
        // Which frame answers the command on the line: the rule the guardian keeps too.
        match judge(frame, self.config.station, Some(expected)) {
            Verdict::Answers(_) => {}
            Verdict::WrongStation(got) => {
                self.emit(unexpected(BadInput::WrongStation {
                    got,
                    expected: self.config.station,
                }));
                return None;
            }
            Verdict::Echo => {
                self.emit(unexpected(BadInput::Echo));
                return None;
            }
            Verdict::OtherReply(got) => {
                if let Some(late) = got {
                    self.sync.late_reply_arrived(late);
                }
                self.emit(unexpected(BadInput::OtherReply { got, expected }));
                return None;
            }
        }
        let round_trip = at.saturating_duration_since(sent_at);
        let reply = Reply::decode(frame);
        if reply.is_ok() {
            self.emit(LinkEvent::FrameReceived {
                bytes: frame.raw().to_vec(),
                first_byte,
                last_byte: at,
            });
        }
        match reply {
            Ok(Reply::Error(code)) => {
                self.health.error_reply();
                self.sched.activity(at);
                if !self.sync.in_step(at) {
                    // This `&` may be an earlier command's late error; then this
                    // command's own reply is still to come.
                    let until = later(at, self.config.timing.late_reply_window);
                    self.sync.may_answer_late(expected, until);
                } else if self.jog_took_lease && pending.command.is_continuous_jog() {
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
                Some(Settled::Refused(code))
            }
            Ok(reply) => {
                self.health.reply(round_trip);
                if pending.origin == Origin::Poll
                    && self.poll_answers.changed(&pending.command, &reply)
                {
                    self.sched.activity(at);
                }
                self.sync.reply_seen(expected, at);
                match pending.command {
                    Command::Jog(_) => self.jog_may_run = true,
                    // Every running program ended: none may start motion any more.
                    Command::Program(call) if call == ProgramCall::END_ALL => {
                        self.program_may_run = false;
                    }
                    // Only a STOP of every axis ends what the link may have started.
                    ref stop if is_stop_all(stop) => {
                        self.jog_may_run = false;
                        self.motion_may_run = false;
                        self.lease.release();
                    }
                    _ => {}
                }
                if let Reply::SystemStatus(status) = &reply {
                    // The controller's own word: a program started elsewhere counts too.
                    self.program_may_run = status.status2.program_running();
                }
                self.store_table_chunk(&pending, &reply);
                self.emit(LinkEvent::Reply {
                    id: pending.id,
                    origin: pending.origin,
                    command: pending.command,
                    reply,
                    round_trip,
                });
                Some(Settled::Answered)
            }
            Err(e) => {
                self.health.bad_frame();
                self.emit(unexpected(BadInput::BadMessage(e)));
                None
            }
        }
    }

    /// The transaction on the line has ended at `now`.
    fn end_transaction(&mut self, now: Instant, settled: Settled) {
        let Some(out) = self.outstanding.take() else {
            return;
        };
        self.quiet_until = Some(later(now, self.config.timing.gap));
        self.health
            .transaction(out.sent_at, now, out.pending.origin == Origin::Poll);
        self.settled(&out.pending, settled);
    }

    /// Tells a close how a STOP it sent ended.
    pub(super) fn settled(&mut self, pending: &Pending, settled: Settled) {
        if let Some(closing) = self.closing.as_mut() {
            closing.settled(pending.id, &settled);
        }
    }

    /// Notes a damaged frame that starts like a reply: true if it carries the
    /// outstanding command's reply ID (its reply came, damaged); otherwise an earlier
    /// late reply has arrived.
    fn damaged_reply_seen(&mut self, raw: &[u8]) -> bool {
        let expected = self.outstanding.as_ref().map(|o| o.pending.command.id());
        match reply_id(raw) {
            Some(id) if Some(id) == expected => true,
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

    /// No answer by the deadline: a query is retried, motion is followed by a status read (never re-sent), and a jog that may
    /// still run is stopped.
    pub(super) fn reply_timed_out(&mut self, now: Instant) {
        // A frame half-received stays with the decoder: if the rest comes, the late reply
        // is reported once, whole; if the next command goes out first, it is cut off then.
        let Some(out) = self.outstanding.as_ref() else {
            return;
        };
        let (pending, reply_came_damaged) = (out.pending.clone(), out.reply_came_damaged);
        self.end_transaction(now, Settled::TimedOut);
        self.health.timeout();
        self.sched.activity(now);
        if !reply_came_damaged {
            let until = later(now, self.config.timing.late_reply_window);
            self.sync.may_answer_late(pending.command.id(), until);
        }
        let stale_chunk = matches!(pending.origin, Origin::Table { generation, .. }
            if self.sched.table_for(generation).is_none());
        let retrying = pending.may_retry(self.config.query_retries) && !stale_chunk;
        let mut recheck = None;
        if retrying {
            self.health.retry();
            self.sched.push_front(pending.clone());
        } else if pending.command.is_motion() {
            let id = self.new_id();
            recheck = Some(id);
            self.sched.push_front(Pending::new(
                id,
                self.config.recheck.clone(),
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
            command: pending.command.clone(),
            retrying,
            recheck,
            at: now,
        });
        // A stalled line must not leave a jog running (DESIGN.md: STOP wins).
        self.queue_safety_stop();
        self.finish_table_if_done();
    }

    /// The line was lost with a command on it: a failed write never (wholly) went out;
    /// otherwise its answer never came and it may or may not have been carried out.
    pub(super) fn settle_on_loss(&mut self, now: Instant, reason: &LineDownReason) {
        let Some(out) = self.outstanding.as_ref() else {
            return;
        };
        let pending = out.pending.clone();
        if let LineDownReason::WriteFailed(failure) = reason {
            if self.jog_took_lease {
                self.lease.release();
            }
            self.outstanding = None;
            self.refuse(&pending, NotSentReason::WriteFailed(failure.clone()));
            return;
        }
        self.emit(LinkEvent::Interrupted {
            id: pending.id,
            origin: pending.origin,
            command: pending.command.clone(),
        });
        if matches!(pending.command, Command::Jog(_)) {
            self.jog_may_run = true;
        }
        self.end_transaction(now, Settled::Interrupted);
        self.finish_table_if_done();
    }

    /// A running jog's lease was not renewed in time: STOP it.
    pub(super) fn lease_lapsed(&mut self) {
        self.queue_stop(Origin::LeaseLapsed);
    }

    /// Queues a STOP of all axes at the head of the queue if a jog may still be running.
    pub(super) fn queue_safety_stop(&mut self) {
        if self.jog_may_run {
            self.queue_stop(Origin::SafetyStop);
        }
    }

    /// Queues a STOP of all axes of the link's own, unless a STOP already waits.
    pub(super) fn queue_stop(&mut self, origin: Origin) {
        self.queue_stop_then(origin, ProgramAction::End);
    }

    /// As [`Self::queue_stop`]; while a program may run, the STOP is followed by `then`
    /// (end or pause) for every program and a second STOP (see [`Self::follow_stop`]).
    pub(super) fn queue_stop_then(&mut self, origin: Origin, then: ProgramAction) {
        if !self.sched.stop_queued() {
            let id = self.new_id();
            self.stop_ends_queued_motion(id);
            self.sched
                .push(Pending::new(id, stop_all(), origin, Priority::Stop));
            self.follow_stop(origin, then);
        }
    }

    /// A STOP of all axes was just queued. While a program may run, it is followed at the
    /// same priority by `then` (254H end or 255H pause) with `00`, every running program,
    /// and by a second STOP of all axes: the first STOP halts the arm without waiting, the
    /// program operation keeps the program from commanding the next move, and the second
    /// STOP halts a move it commanded in between (README: "STOP ends programs").
    pub(super) fn follow_stop(&mut self, origin: Origin, then: ProgramAction) {
        if !self.program_may_run {
            return;
        }
        let call = Command::Program(ProgramCall {
            action: then,
            program: ALL_PROGRAMS,
        });
        for command in [call, stop_all()] {
            let id = self.new_id();
            self.sched
                .push(Pending::new(id, command, origin, Priority::Stop));
        }
    }

    /// Reports bytes that arrived while no command waited for them, frame by frame: a
    /// late reply, a frame with a bad checksum, or noise. A frame begun is kept until it
    /// ends or the next command goes out.
    pub(super) fn report_stale(&mut self, now: Instant, stale: &[u8]) {
        self.decoder.push(stale);
        while let Some(item) = self.decoder.pull() {
            self.report_stale_item(now, item);
        }
    }

    fn report_stale_item(
        &mut self,
        now: Instant,
        item: Result<crate::protocol::OwnedFrame, crate::protocol::DecodeError>,
    ) {
        self.health.bad_frame();
        let raw = match &item {
            Ok(frame) => frame.raw(),
            Err(error) => error.raw(),
        };
        if let Some(id) = reply_id(raw) {
            self.sync.late_reply_arrived(id);
        }
        match item {
            Ok(frame) => self.emit(crate::link::event::garbage(
                frame.raw(),
                BadInput::Late,
                now,
            )),
            Err(error) => self.emit(garbage_event(&error, now)),
        }
    }

    /// Reports a frame begun but never ended as cut off (the line it came on is gone).
    pub(super) fn cut_off_partial(&mut self, now: Instant) {
        let rest = self.decoder.take_pending();
        if rest.is_empty() {
            return;
        }
        if reply_id(&rest).is_some_and(|id| {
            self.outstanding
                .as_ref()
                .is_some_and(|o| o.pending.command.id() == id)
        }) {
            if let Some(out) = self.outstanding.as_mut() {
                out.reply_came_damaged = true;
            }
        } else if let Some(id) = reply_id(&rest) {
            self.sync.late_reply_arrived(id);
        }
        self.health.bad_frame();
        self.emit(crate::link::event::garbage(&rest, BadInput::CutOff, now));
    }
}
