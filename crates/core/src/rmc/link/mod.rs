//! The RMC151's link core (DESIGN.md "The link"): one Modbus/TCP connection, one
//! transaction at a time, run by the shared driver. It polls status, writes commands with
//! REQ toggled and trusts status only once ACK = REQ, never re-sends motion, writes zeros
//! first on every connection, and sends Stop (Closed Loop) (6) ahead of everything: on
//! STOP, on release, on a lapsed lease, after a reconnect that followed motion, on close.

mod axis;
pub mod event;
#[cfg(test)]
pub(crate) mod harness;
mod outgoing;
mod replies;
mod requests;
#[cfg(test)]
mod tests;

use std::collections::VecDeque;
use std::time::{Duration, Instant};

use self::axis::AxisLink;
pub use self::event::{HoldJog, RmcEvent, RmcRequest, SafetyStop};
pub use self::requests::HELD_JOG;
use crate::line::LineSettings;
use crate::link::RequestId;
use crate::link::core::{Input, LineChange, LinkCore, Transmit};
use crate::rmc::command::Command;
use crate::rmc::modbus::{self, FrameBuffer, Header};
use crate::rmc::registers::AxisId;
use crate::rmc::status::AxisStatus;

/// Longest wait for ACK to equal a command's REQ once its write was answered [U: the
/// time from the write's reply to ACK is open on hardware (RMC.md section 7); one loop is
/// 0.25-4 ms]. After it the command counts as not taken, and other requests go on.
const ACK_WAIT: Duration = Duration::from_millis(500);

/// The longest wait between two requests to a device that keeps answering badly
/// (exceptions, replies of the wrong size or to another request, no reply, bytes that
/// are not Modbus/TCP): the wait starts at the poll interval and doubles up to it.
pub const BACKOFF_MAX: Duration = Duration::from_secs(1);

/// Bad replies in a row before the health line says the link is backing off (fewer are
/// spaced out too, unsaid: a device that refuses one axis of several only slows that
/// axis's read).
const BACKOFF_SAID_AFTER: u32 = 3;

/// How the RMC link behaves.
#[derive(Clone, Debug, PartialEq)]
pub struct RmcLinkConfig {
    /// The Modbus unit ID (RMC.md section 1: not documented [U], default 1).
    pub unit: u8,
    /// Axes shown and polled (1-8).
    pub axes: usize,
    pub reply_timeout: Duration,
    /// Time between two status rounds while an axis moves or a command is awaited.
    pub poll_interval: Duration,
    /// Time between two status rounds while every axis stands still, nothing is owed
    /// and nothing awaited [I: motion started elsewhere (RMCTools, a PLC program) shows
    /// within one of them, and the fast rounds follow it]; never below `poll_interval`.
    pub idle_poll_interval: Duration,
    /// Stop (Closed Loop) (6)'s deceleration for STOP, pu/s².
    pub stop_decel: f32,
    /// A held jog stops when its lease is not renewed for this long.
    pub lease: Duration,
    pub reconnect_interval: Duration,
    /// Requests in a row with no reply before the connection is dropped and reopened.
    pub stall_after: u8,
}

impl Default for RmcLinkConfig {
    fn default() -> Self {
        Self {
            unit: 1,
            axes: 2,
            reply_timeout: Duration::from_millis(100),
            poll_interval: Duration::from_millis(20),
            // As the X-SEL's (`session::IDLE_POLL_INTERVAL`).
            idle_poll_interval: Duration::from_millis(250),
            stop_decel: 1000.0,
            lease: crate::link::JOG_LEASE,
            reconnect_interval: Duration::from_millis(500),
            stall_after: 3,
        }
    }
}

enum Line {
    Down { retry_at: Instant },
    Opening,
    Up,
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum WriteKind {
    User,
    Stop,
    Chunk,
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Purpose {
    Zeros(AxisId),
    Module,
    Controller,
    Status(AxisId),
    Write {
        axis: AxisId,
        id: Option<RequestId>,
        command: Command,
        kind: WriteKind,
    },
}

/// The link backing off from a device that keeps answering badly: one retry rate for
/// every request but the STOPs owed (and the zeros before them), reset by a good reply.
#[derive(Clone, Debug)]
struct Backoff {
    bad_in_row: u32,
    /// The wait after the last bad reply.
    wait: Duration,
    /// No request (but an owed STOP) goes out before this; cleared once passed.
    until: Option<Instant>,
    /// The health line said so (it says when the device answers well again).
    said: bool,
    /// Good replies since the last bad one (a whole round of them ends a said back-off).
    good_in_row: u32,
}

struct InFlight {
    transaction: u16,
    purpose: Purpose,
    deadline: Instant,
}

/// The RMC151 protocol as a state machine (quinn-proto's shape, like Format B's core).
pub struct RmcCore {
    config: RmcLinkConfig,
    line: Line,
    /// The connection is to be closed before anything else (a stall, bad bytes).
    drop_line: bool,
    closing: Option<Instant>,
    closed: bool,
    transaction: u16,
    in_flight: Option<InFlight>,
    rx: FrameBuffer,
    axes: Vec<AxisLink>,
    queue: VecDeque<(RequestId, AxisId, Command)>,
    /// Next in the status round: an axis index, or `axes.len()` for the controller.
    round_at: usize,
    next_round: Instant,
    module_read: bool,
    lease_renewed: Option<Instant>,
    timeouts_in_row: u8,
    reader_behind: bool,
    events: VecDeque<RmcEvent>,
    /// The connection's name as its [`RmcEvent::LineUp`] gave it (the health line).
    line_name: String,
    backoff: Option<Backoff>,
}

impl RmcCore {
    pub fn new(config: RmcLinkConfig, now: Instant) -> Self {
        let axes = AxisId::first(config.axes.max(1))
            .map(AxisLink::new)
            .collect();
        Self {
            config,
            line: Line::Down { retry_at: now },
            drop_line: false,
            closing: None,
            closed: false,
            transaction: 0,
            in_flight: None,
            rx: FrameBuffer::default(),
            axes,
            queue: VecDeque::new(),
            round_at: 0,
            next_round: now,
            module_read: false,
            lease_renewed: None,
            timeouts_in_row: 0,
            reader_behind: false,
            events: VecDeque::new(),
            line_name: String::new(),
            backoff: None,
        }
    }

    fn axis(&mut self, id: AxisId) -> Option<&mut AxisLink> {
        self.axes.get_mut(id.index())
    }

    fn lease_secs(&self) -> f32 {
        self.config.lease.as_secs_f32()
    }

    fn lease_lapsed(&self, now: Instant) -> bool {
        self.lease_renewed
            .is_none_or(|at| now.saturating_duration_since(at) >= self.config.lease)
    }

    fn not_sent(
        &mut self,
        id: RequestId,
        axis: AxisId,
        what: &'static str,
        reason: impl Into<String>,
    ) {
        self.events.push_back(RmcEvent::NotSent {
            id,
            axis,
            what,
            reason: reason.into(),
        });
    }

    /// Queued motion is dropped (it is never sent later by itself).
    fn drop_queued_motion(&mut self, why: &str) {
        let queue = std::mem::take(&mut self.queue);
        for (id, axis, command) in queue {
            if command.moves() {
                let text = format!("{why}: {} to {axis} not sent", command.name());
                self.not_sent(id, axis, command.name(), text);
            } else {
                self.queue.push_back((id, axis, command));
            }
        }
    }

    /// Stop (6) owed to every axis that may be moving, reported as the core's own.
    fn owe_safety_stops(&mut self, why: SafetyStop) {
        let mut stopped = Vec::new();
        for a in &mut self.axes {
            if a.chain.take().is_some() || a.may_move {
                a.stop_owed = true;
                stopped.push(a.id);
            }
        }
        if !stopped.is_empty() {
            self.events
                .push_back(RmcEvent::SafetyStop { why, axes: stopped });
        }
    }

    fn lose_line(&mut self, now: Instant, reason: String) {
        self.in_flight = None;
        self.rx.clear();
        let wait = self.backoff.as_ref().map_or(Duration::ZERO, |b| b.wait);
        self.line = Line::Down {
            retry_at: now + self.config.reconnect_interval.max(wait),
        };
        // Nothing queued is sent later by itself; a held jog ends (its STOP goes out
        // when the line is back).
        self.drop_queued_motion("the connection went down");
        for a in &mut self.axes {
            if a.chain.take().is_some() {
                a.stop_owed = true;
            }
        }
        self.events
            .push_back(RmcEvent::LineDown { reason, at: now });
    }

    fn finish(&mut self) -> Option<Transmit> {
        self.closed = true;
        self.events.push_back(RmcEvent::Closed);
        matches!(self.line, Line::Up).then_some(Transmit::Close)
    }

    /// The application's view: the last trusted status of an axis (tests, benches).
    pub fn last_status(&self, axis: AxisId) -> Option<AxisStatus> {
        self.axes.get(axis.index()).and_then(|a| a.last)
    }

    /// The wait between requests while the link backs off from a device answering
    /// badly; `None` while it answers well.
    pub fn backoff(&self) -> Option<Duration> {
        self.backoff.as_ref().map(|b| b.wait)
    }

    /// A bad reply (or none): the next request waits, twice as long as after the last
    /// bad one, from the poll interval up to [`BACKOFF_MAX`]; the health line says so
    /// after [`BACKOFF_SAID_AFTER`] in a row.
    pub(super) fn bad_reply(&mut self, now: Instant, what: &str) {
        let first = self.config.poll_interval.max(Duration::from_millis(1));
        let b = self.backoff.get_or_insert(Backoff {
            bad_in_row: 0,
            wait: Duration::ZERO,
            until: None,
            said: false,
            good_in_row: 0,
        });
        b.bad_in_row = b.bad_in_row.saturating_add(1);
        b.good_in_row = 0;
        b.wait = if b.wait.is_zero() {
            first
        } else {
            (b.wait * 2).min(BACKOFF_MAX.max(first))
        };
        b.until = Some(now + b.wait);
        if !b.said && b.bad_in_row >= BACKOFF_SAID_AFTER {
            b.said = true;
            let n = b.bad_in_row;
            let name = format!(
                "{} - backing off: {n} bad replies in a row (the last: {what}); requests \
                 spaced out to one a second at most until a good reply",
                self.line_name
            );
            self.events.push_back(RmcEvent::LineUp { name, at: now });
        }
    }

    /// A good reply: the normal pace again (the health line says so once a whole round
    /// answered well).
    pub(super) fn good_reply(&mut self, now: Instant) {
        let Some(b) = self.backoff.as_mut() else {
            return;
        };
        b.good_in_row += 1;
        if !b.said {
            self.backoff = None;
            return;
        }
        // The pace is back at once; the line's word waits for a whole round.
        b.wait = Duration::ZERO;
        b.until = None;
        b.bad_in_row = 0;
        if b.good_in_row as usize > self.axes.len() {
            self.backoff = None;
            let name = self.line_name.clone();
            self.events.push_back(RmcEvent::LineUp { name, at: now });
        }
    }

    /// Whether a request waits for the back-off now: everything but owed STOPs (and the
    /// zeros ahead of them) and a closing link's last writes.
    fn held_back(&self, now: Instant) -> bool {
        let until = self.backoff.as_ref().and_then(|b| b.until);
        until.is_some_and(|t| now < t)
            && self.closing.is_none()
            && !self.axes.iter().any(|a| a.stop_owed)
    }
}

impl LinkCore for RmcCore {
    type Request = RmcRequest;
    type Event = RmcEvent;

    fn handle_request(&mut self, now: Instant, input: Input<RmcRequest>) {
        match input {
            Input::App(request) => self.handle_app(now, request),
            Input::LeaseRenewed(at) => self.lease_renewed = Some(at),
            Input::Backlog { behind, .. } => self.reader_behind = behind,
            Input::Close => {
                if self.closing.is_none() {
                    let bound = self.config.reply_timeout * (2 * self.axes.len() as u32 + 2);
                    self.closing = Some(now + bound);
                    self.drop_queued_motion("the link closed");
                    self.queue.clear();
                    self.owe_safety_stops(SafetyStop::Closing);
                }
            }
        }
    }

    fn handle_line(&mut self, now: Instant, change: LineChange) {
        match change {
            LineChange::Opened { name } => {
                self.line_name = name.clone();
                self.line = Line::Up;
                self.drop_line = false;
                self.in_flight = None;
                self.rx.clear();
                self.module_read = false;
                self.timeouts_in_row = 0;
                self.round_at = 0;
                self.next_round = now;
                for a in &mut self.axes {
                    a.reconnected();
                }
                self.events.push_back(RmcEvent::LineUp { name, at: now });
                if self.closing.is_none() {
                    self.owe_safety_stops(SafetyStop::Reconnected);
                }
            }
            LineChange::OpenFailed(e) => {
                self.line = Line::Down {
                    retry_at: now + self.config.reconnect_interval,
                };
                self.events.push_back(RmcEvent::LineDown {
                    reason: format!("cannot connect: {e}"),
                    at: now,
                });
            }
            LineChange::Lost(reason) => self.lose_line(now, reason.to_string()),
            LineChange::GuardianStopped(why) => {
                // The guardian wrote Stop (6) with REQs of its own: held jogs end, and
                // zeros go out again so REQ and ACK are in step before anything else.
                let mut stopped = Vec::new();
                for a in &mut self.axes {
                    if a.chain.take().is_some() || a.may_move {
                        stopped.push(a.id);
                    }
                    a.may_move = false;
                    a.reconnected();
                }
                self.events.push_back(RmcEvent::SafetyStop {
                    why: SafetyStop::Guardian,
                    axes: stopped,
                });
                self.events.push_back(RmcEvent::Ignored {
                    why: format!("the guardian process stopped the axes: {why}"),
                });
            }
        }
    }

    fn handle_bytes(&mut self, now: Instant, bytes: &[u8]) {
        if !matches!(self.line, Line::Up) {
            return;
        }
        self.rx.push(bytes);
        while let Some(frame) = self.rx.next_frame() {
            let decoded = match frame {
                Ok(f) => {
                    let decoded = modbus::decode_response(&f);
                    let (at, bytes) = (now, f);
                    match &decoded {
                        Ok(_) => self.events.push_back(RmcEvent::FrameReceived { bytes, at }),
                        Err(e) => self.events.push_back(RmcEvent::Garbage {
                            bytes,
                            error: e.to_string(),
                            at,
                        }),
                    }
                    decoded
                }
                Err(e) => {
                    self.events.push_back(RmcEvent::Garbage {
                        bytes: self.rx.discarded().to_vec(),
                        error: e.to_string(),
                        at: now,
                    });
                    Err(e)
                }
            };
            match decoded {
                Err(e) => {
                    self.bad_reply(now, "bytes that are not Modbus/TCP");
                    self.lose_line(
                        now,
                        format!("the RMC sent bytes that are not Modbus/TCP: {e}"),
                    );
                    self.drop_line = true;
                    return;
                }
                Ok((header, response)) => match self.in_flight.take() {
                    Some(flight) if flight.transaction == header.transaction => {
                        self.complete(now, flight, response)
                    }
                    other => {
                        self.in_flight = other;
                        self.events.push_back(RmcEvent::Ignored {
                            why: format!(
                                "a late reply to transaction {} (nothing waits for it)",
                                header.transaction
                            ),
                        });
                    }
                },
            }
        }
    }

    fn handle_timeout(&mut self, now: Instant) {
        if let Some(b) = self.backoff.as_mut() {
            b.until.take_if(|t| *t <= now);
        }
        if let Some(flight) = self.in_flight.take_if(|f| f.deadline <= now) {
            self.timeouts_in_row = self.timeouts_in_row.saturating_add(1);
            self.bad_reply(now, "no reply in time");
            self.events.push_back(RmcEvent::Timeout {
                what: format!(
                    "no reply to transaction {} within {} ms",
                    flight.transaction,
                    self.config.reply_timeout.as_millis()
                ),
                at: now,
            });
            match flight.purpose {
                Purpose::Write { axis, kind, .. } => {
                    if let Some(a) = self.axis(axis) {
                        if let Some(w) = a.awaiting.as_mut() {
                            w.timed_out = true;
                        }
                        a.read_wanted = true;
                        // A STOP is no motion: it is owed until its ACK is seen.
                        if kind == WriteKind::Stop {
                            a.stop_owed = true;
                            a.awaiting = None;
                            a.req = !a.req;
                        }
                    }
                }
                Purpose::Zeros(axis) => {
                    if let Some(a) = self.axis(axis) {
                        a.zeroed = false;
                    }
                }
                _ => {}
            }
            if self.timeouts_in_row >= self.config.stall_after {
                let n = self.timeouts_in_row;
                self.lose_line(now, format!("no reply to {n} requests in a row"));
                self.drop_line = true;
            }
        }
        let lapsed = self.axes.iter().any(|a| a.chain.is_some()) && self.lease_lapsed(now);
        if lapsed {
            self.owe_safety_stops(SafetyStop::LeaseLapsed);
        }
    }

    fn poll_transmit(&mut self, now: Instant) -> Option<Transmit> {
        if self.closed {
            return None;
        }
        if std::mem::take(&mut self.drop_line) {
            return Some(Transmit::Close);
        }
        let closing_due = self.closing.is_some_and(|t| now >= t);
        match self.line {
            Line::Down { retry_at } => {
                if self.closing.is_some() {
                    return self.finish();
                }
                if now < retry_at {
                    return None;
                }
                self.line = Line::Opening;
                // A TCP connection takes no line settings (the driver's connector knows
                // the address).
                Some(Transmit::Open(LineSettings::default()))
            }
            Line::Opening => None,
            Line::Up => {
                if self.in_flight.is_some() && !closing_due {
                    return None;
                }
                if self.closing.is_some() && (closing_due || !self.owes_more()) {
                    return self.finish();
                }
                if self.held_back(now) {
                    return None;
                }
                let purpose = self.next_purpose(now)?;
                let request = self.request_of(purpose);
                self.transaction = self.transaction.wrapping_add(1);
                let header = Header {
                    transaction: self.transaction,
                    unit: self.config.unit,
                };
                let bytes = modbus::encode_request(header, &request);
                self.events.push_back(RmcEvent::FrameSent {
                    bytes: bytes.clone(),
                    at: now,
                });
                self.wrote(now, purpose);
                self.in_flight = Some(InFlight {
                    transaction: self.transaction,
                    purpose,
                    deadline: now + self.config.reply_timeout,
                });
                Some(Transmit::Write(bytes))
            }
        }
    }

    fn poll_event(&mut self) -> Option<RmcEvent> {
        self.events.pop_front()
    }

    fn poll_timeout(&self) -> Option<Instant> {
        if self.closed {
            return None;
        }
        let flight = self.in_flight.as_ref().map(|f| f.deadline);
        let line = match self.line {
            Line::Down { retry_at } => Some(retry_at),
            Line::Opening => None,
            // Backing off, the next request waits for the gate (then the round, if due).
            Line::Up if self.in_flight.is_none() => {
                match self.backoff.as_ref().and_then(|b| b.until) {
                    Some(until) => Some(until),
                    None if !self.reader_behind => Some(self.next_round),
                    None => None,
                }
            }
            Line::Up => None,
        };
        let lease = self
            .axes
            .iter()
            .any(|a| a.chain.is_some())
            .then(|| self.lease_renewed.map(|at| at + self.config.lease))
            .flatten();
        [flight, line, lease, self.closing]
            .into_iter()
            .flatten()
            .min()
    }

    fn awaits_bytes(&self) -> bool {
        self.in_flight.is_some()
    }

    fn is_closed(&self) -> bool {
        self.closed
    }
}

impl RmcCore {
    /// Closing: whether a STOP or zeros before it are still owed.
    fn owes_more(&self) -> bool {
        self.in_flight.is_some() || self.axes.iter().any(|a| a.stop_owed)
    }
}
