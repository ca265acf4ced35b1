//! One command's trip on the line: proving the line is in step before motion, sending,
//! pairing the reply with the command, and what a time-out means for each kind of
//! request (retry a query, re-read status after motion, stop a jog that may run on).

use std::time::{Duration, Instant};

use super::engine::{Engine, later};
use super::event::{LinkEvent, garbage_event};
use super::request::{Origin, Pending, Priority};
use super::sync::reply_id;
use super::transport::is_timeout;
use crate::protocol::{AxisPattern, Command, Frame, Header, Reply, Stop};

/// Longest single wait on the line, so control messages are seen promptly.
const READ_SLICE: Duration = Duration::from_millis(20);
/// Proving queries tried for one motion command before it is refused.
const MAX_PROOFS: u8 = 6;

/// How a transaction ended.
enum Outcome {
    Answered,
    /// No valid answer in time; `reply_came_damaged` when a damaged frame carrying this
    /// command's reply ID arrived (so no late reply is to be expected).
    TimedOut {
        reply_came_damaged: bool,
    },
    LineLost(String),
    Shutdown,
}

impl Engine {
    /// Sends `pending` (or, for motion on a line out of step, a proving query first)
    /// and waits for its reply, time-out or loss.
    pub(super) fn transact(&mut self, pending: Pending) {
        let Some(pending) = self.prove_before_motion(pending) else {
            return;
        };
        self.tx_buf.clear();
        if let Err(e) =
            pending
                .command
                .encode_into(self.config.station, self.config.sc_mode, &mut self.tx_buf)
        {
            return self.not_sent(&pending, &e.to_string());
        }
        self.wait_for_gap();
        let Some(transport) = self.transport.as_mut() else {
            return self.not_sent(&pending, "the line is down");
        };
        // Late replies and noise must not be taken for this command's answer.
        let stale = match transport.discard_input() {
            Ok(bytes) => bytes,
            Err(e) => {
                self.not_sent(&pending, "the line failed before sending");
                return self.line_lost(e.to_string());
            }
        };
        self.report_stale(&stale);
        let Some(transport) = self.transport.as_mut() else {
            return self.not_sent(&pending, "the line is down");
        };
        if let Err(e) = transport.write_all_bytes(&self.tx_buf) {
            let reason = format!("write failed: {e}");
            self.not_sent(
                &pending,
                &format!("{reason} (part of the frame may have gone out)"),
            );
            return self.line_lost(reason);
        }
        let sent_at = Instant::now();
        let mut pending = pending;
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
        let outcome = self.await_reply(&pending, sent_at, later(sent_at, timeout));
        let ended = Instant::now();
        self.line_quiet_since = Some(ended);
        self.health
            .transaction(sent_at, ended, pending.origin == Origin::Poll);
        match outcome {
            Outcome::Answered | Outcome::Shutdown => {}
            Outcome::TimedOut { reply_came_damaged } => self.timed_out(pending, reply_came_damaged),
            Outcome::LineLost(reason) => {
                self.emit(LinkEvent::Timeout {
                    id: pending.id,
                    origin: pending.origin,
                    command: pending.command,
                    retrying: false,
                    recheck: None,
                });
                if matches!(pending.command, Command::Jog(_)) {
                    self.jog_may_run = true;
                }
                self.line_lost(reason);
            }
        }
        self.finish_table_if_done();
    }

    /// Motion goes out only on a line in step. Otherwise the move waits at the head of
    /// its queue while a proving query goes out; after [`MAX_PROOFS`] failed proofs the
    /// move is refused.
    fn prove_before_motion(&mut self, pending: Pending) -> Option<Pending> {
        let now = Instant::now();
        if !pending.command.is_motion() || self.sync.in_step(now) {
            return Some(pending);
        }
        if pending.proofs >= MAX_PROOFS {
            self.not_sent(
                &pending,
                "the controller's replies are out of step (a late reply may still come), \
                 so the move was not sent",
            );
            return None;
        }
        let mut waiting = pending;
        waiting.proofs += 1;
        self.sched.push_front(waiting);
        Some(Pending::new(
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
            self.drain_control();
            if self.shutting_down {
                return Outcome::Shutdown;
            }
            let now = Instant::now();
            if now >= deadline {
                let rest = self.decoder.take_pending();
                if !rest.is_empty() {
                    reply_came_damaged |= self.damaged_reply_seen(&rest, pending);
                    self.health.bad_frame();
                    self.emit(LinkEvent::Garbage {
                        bytes: rest,
                        error: "incomplete frame: no line end before the time-out".into(),
                        at: now,
                    });
                }
                return Outcome::TimedOut { reply_came_damaged };
            }
            let Some(transport) = self.transport.as_mut() else {
                return Outcome::LineLost("the line is down".into());
            };
            let n = match transport.read_timeout(&mut self.rx_buf, (deadline - now).min(READ_SLICE))
            {
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
                        self.emit(LinkEvent::FrameReceived {
                            bytes: frame.raw().to_vec(),
                            first_byte: first_byte.unwrap_or(at),
                            last_byte: at,
                        });
                        if self.answers(pending, &frame, sent_at, at) {
                            return Outcome::Answered;
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
        if frame.header() == Header::Command {
            self.emit(unexpected(
                "a command frame ('!') came back: is the line looped back?".into(),
            ));
            return false;
        }
        if frame.header() == Header::Reply && frame.id() != Some(expected) {
            if let Some(late) = frame.id() {
                self.sync.late_reply_arrived(late);
            }
            let id = frame.id().map_or_else(|| "?".into(), |id| id.to_string());
            self.emit(unexpected(format!(
                "reply to {id} while waiting for the reply to {expected}"
            )));
            return false;
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
                }
                self.emit(LinkEvent::ErrorReply {
                    id: pending.id,
                    origin: pending.origin,
                    command: pending.command,
                    code,
                });
            }
            Ok(reply) => {
                self.health.reply(round_trip);
                self.sync.reply_seen(expected, at);
                match pending.command {
                    Command::Jog(_) => self.jog_may_run = true,
                    Command::Stop(_) => self.jog_may_run = false,
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
            }
            Err(e) => {
                self.health.bad_frame();
                self.emit(unexpected(e.to_string()));
                return false;
            }
        }
        true
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
                    error: "late frame: not the answer to anything outstanding".into(),
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
                error: "incomplete frame: no line end".into(),
                at,
            });
        }
    }
}
