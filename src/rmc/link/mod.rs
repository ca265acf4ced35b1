//! The RMC151's link core (DESIGN.md "The link"): one Modbus/TCP connection, one
//! transaction at a time, run by the shared driver. It polls status, writes commands with
//! REQ toggled and trusts status only once ACK = REQ, never re-sends motion, writes zeros
//! first on every connection, and sends Stop (Closed Loop) (6) ahead of everything: on
//! STOP, on release, on a lapsed lease, after a reconnect that followed motion, on close.

mod axis;
pub mod event;
#[cfg(test)]
mod harness;
#[cfg(test)]
mod tests;

use std::collections::VecDeque;
use std::time::{Duration, Instant};

use self::axis::{Awaiting, AxisLink, Chain};
pub use self::event::{HoldJog, RmcEvent, RmcRequest, SafetyStop};
use crate::line::LineSettings;
use crate::link::RequestId;
use crate::link::core::{Input, LineChange, LinkCore, Transmit};
use crate::rmc::command::{Command, MoveRelative, ZEROS_REGISTERS};
use crate::rmc::modbus::{self, FrameBuffer, Header, Request, Response};
use crate::rmc::registers::{AxisId, CONTROLLER_STATUS, CPU_MODULE_ID, STATUS_REGISTERS};
use crate::rmc::status::{AxisStatus, ControllerStatus};
use crate::rmc::words::dword_at;
use crate::robot::RelativeTo;

/// Longest wait for ACK to equal a command's REQ once its write was answered [U: the
/// time from the write's reply to ACK is open on hardware (RMC.md section 7); one loop is
/// 0.25-4 ms]. After it the command counts as not taken, and other requests go on.
const ACK_WAIT: Duration = Duration::from_millis(500);

/// How the RMC link behaves.
#[derive(Clone, Debug, PartialEq)]
pub struct RmcLinkConfig {
    /// The Modbus unit ID (RMC.md section 1: not documented [U], default 1).
    pub unit: u8,
    /// Axes shown and polled (1-8).
    pub axes: usize,
    pub reply_timeout: Duration,
    /// Time between two status rounds.
    pub poll_interval: Duration,
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

    fn not_sent(&mut self, id: RequestId, reason: impl Into<String>) {
        self.events.push_back(RmcEvent::NotSent {
            id,
            reason: reason.into(),
        });
    }

    /// Queued motion is dropped (it is never sent later by itself).
    fn drop_queued_motion(&mut self, why: &str) {
        let queue = std::mem::take(&mut self.queue);
        for (id, axis, command) in queue {
            if command.moves() {
                self.not_sent(id, format!("{why}: {} to {axis} not sent", command.name()));
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

    fn handle_app(&mut self, now: Instant, request: RmcRequest) {
        match request {
            RmcRequest::Send { id, axis, command } => self.submit(id, axis, command),
            RmcRequest::Hold { id, axis, jog } => self.hold(now, id, axis, jog),
            RmcRequest::Release { axis } => {
                if let Some(a) = self.axis(axis)
                    && a.chain.take().is_some()
                {
                    a.stop_owed = true;
                }
            }
            RmcRequest::StopAll => {
                self.drop_queued_motion("STOP");
                for a in &mut self.axes {
                    a.chain = None;
                    if a.stoppable() {
                        a.stop_owed = true;
                    }
                }
            }
            RmcRequest::Reconnect => {
                if matches!(self.line, Line::Up) {
                    self.lose_line(now, "closed to reconnect on request".into());
                    self.drop_line = true;
                }
                self.line = Line::Down { retry_at: now };
            }
            RmcRequest::SetPollInterval(d) => self.config.poll_interval = d,
        }
    }

    /// Why motion cannot be queued for `axis` now, if it cannot.
    fn motion_refusal(&self, axis: AxisId) -> Option<String> {
        let Some(a) = self.axes.get(axis.index()) else {
            return Some(format!(
                "{axis} is not one of the {} axes polled",
                self.axes.len()
            ));
        };
        if self.closing.is_some() {
            return Some("the link is closing".into());
        }
        if !matches!(self.line, Line::Up) {
            return Some("the RMC is not connected".into());
        }
        if a.last.is_some_and(|s| !s.bits.enabled()) {
            return Some(format!("{axis} is not enabled: enable it first"));
        }
        if a.chain.is_some() {
            return Some(format!("a jog runs on {axis}"));
        }
        None
    }

    fn submit(&mut self, id: RequestId, axis: AxisId, command: Command) {
        if let Err(e) = command.check() {
            return self.not_sent(id, e.to_string());
        }
        let refusal = if command.moves() {
            self.motion_refusal(axis)
        } else if axis.index() >= self.axes.len() {
            Some(format!(
                "{axis} is not one of the {} axes polled",
                self.axes.len()
            ))
        } else if self.closing.is_some() {
            Some("the link is closing".into())
        } else {
            None
        };
        match refusal {
            Some(why) => self.not_sent(id, why),
            None => self.queue.push_back((id, axis, command)),
        }
    }

    fn hold(&mut self, now: Instant, id: RequestId, axis: AxisId, jog: HoldJog) {
        let probe = Command::MoveRelative(MoveRelative {
            distance: jog.direction,
            speed: jog.speed,
            accel: jog.accel,
            decel: jog.decel,
            relative_to: RelativeTo::Target,
        });
        if let Err(e) = probe.check() {
            return self.not_sent(id, e.to_string());
        }
        if let Some(why) = self.motion_refusal(axis) {
            return self.not_sent(id, why);
        }
        // The request itself renews the lease (as submitting a jog does on Format B).
        self.lease_renewed = Some(now);
        let lease = self.lease_secs();
        if let Some(a) = self.axis(axis) {
            a.chain = Some(Chain::new(id, jog, lease));
        }
    }

    /// What goes out next on an open line with nothing in flight.
    fn next_purpose(&mut self, now: Instant) -> Option<Purpose> {
        // Zeros first on a new connection (ACK to 0), then every STOP owed.
        if let Some(a) = self.axes.iter().find(|a| !a.zeroed) {
            return Some(Purpose::Zeros(a.id));
        }
        if let Some(a) = self.axes.iter().find(|a| a.stop_owed) {
            let command = Command::Stop {
                decel: self.config.stop_decel,
            };
            return Some(Purpose::Write {
                axis: a.id,
                id: None,
                command,
                kind: WriteKind::Stop,
            });
        }
        if self.closing.is_some() {
            return None;
        }
        if !self.module_read {
            return Some(Purpose::Module);
        }
        if let Some(a) = self
            .axes
            .iter()
            .find(|a| a.read_wanted || a.awaiting.is_some())
        {
            return Some(Purpose::Status(a.id));
        }
        if let Some(&(id, axis, command)) = self.queue.front() {
            let a = self.axes.get(axis.index())?;
            if command.moves() && !a.fresh {
                return Some(Purpose::Status(axis));
            }
            self.queue.pop_front();
            return Some(Purpose::Write {
                axis,
                id: Some(id),
                command,
                kind: WriteKind::User,
            });
        }
        if let Some(a) = self.axes.iter().find(|a| {
            a.chain
                .is_some_and(|c| c.due(a.last.as_ref().filter(|_| a.fresh)))
        }) {
            if !a.fresh {
                return Some(Purpose::Status(a.id));
            }
            let chain = a.chain?;
            let command = Command::MoveRelative(MoveRelative {
                distance: chain.jog.direction * chain.chunk,
                speed: chain.jog.speed,
                accel: chain.jog.accel,
                decel: chain.jog.decel,
                relative_to: RelativeTo::Target,
            });
            return Some(Purpose::Write {
                axis: a.id,
                id: (!chain.started).then_some(chain.id),
                command,
                kind: WriteKind::Chunk,
            });
        }
        self.next_poll(now)
    }

    /// The next read of the status round, when it is due.
    fn next_poll(&mut self, now: Instant) -> Option<Purpose> {
        if self.reader_behind || now < self.next_round {
            return None;
        }
        let purpose = match self.axes.get(self.round_at) {
            Some(a) => Purpose::Status(a.id),
            None => Purpose::Controller,
        };
        self.round_at += 1;
        if self.round_at > self.axes.len() {
            self.round_at = 0;
            self.next_round = now + self.config.poll_interval;
        }
        Some(purpose)
    }

    fn request_of(&mut self, purpose: Purpose) -> Request {
        match purpose {
            Purpose::Zeros(axis) => Request::Write {
                address: axis.command_block(),
                words: vec![0; ZEROS_REGISTERS],
            },
            Purpose::Module => Request::Read {
                address: CPU_MODULE_ID,
                count: 2,
            },
            Purpose::Controller => Request::Read {
                address: CONTROLLER_STATUS,
                count: 2,
            },
            Purpose::Status(axis) => Request::Read {
                address: axis.status_block(),
                count: STATUS_REGISTERS,
            },
            Purpose::Write { axis, command, .. } => {
                let req = self.axis(axis).map(|a| !a.req).unwrap_or(true);
                Request::Write {
                    address: axis.command_block(),
                    words: command.block(req),
                }
            }
        }
    }

    /// A write goes out: REQ toggled, its ACK awaited.
    fn wrote(&mut self, now: Instant, purpose: Purpose) {
        let Purpose::Write {
            axis,
            id,
            command,
            kind,
        } = purpose
        else {
            return;
        };
        let Some(a) = self.axis(axis) else {
            return;
        };
        a.req = !a.req;
        let req = a.req;
        a.awaiting = Some(Awaiting {
            id,
            req,
            timed_out: false,
            until: now + ACK_WAIT,
        });
        match kind {
            WriteKind::Stop => a.stop_owed = false,
            WriteKind::Chunk => {
                if let Some(c) = a.chain.as_mut() {
                    c.started = true;
                }
                a.may_move = true;
            }
            WriteKind::User => a.may_move |= command.moves(),
        }
        self.events.push_back(RmcEvent::Sent {
            id,
            axis,
            command,
            req,
            at: now,
        });
    }

    fn lose_line(&mut self, now: Instant, reason: String) {
        self.in_flight = None;
        self.rx.clear();
        self.line = Line::Down {
            retry_at: now + self.config.reconnect_interval,
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

    fn complete(&mut self, now: Instant, flight: InFlight, response: Response) {
        self.timeouts_in_row = 0;
        let id = match flight.purpose {
            Purpose::Write { id, .. } => id,
            _ => None,
        };
        match (flight.purpose, response) {
            (purpose, Response::Exception { function, code }) => {
                if let Purpose::Write { axis, kind, .. } = purpose
                    && let Some(a) = self.axis(axis)
                {
                    // Refused: not run, so REQ is what ACK still is.
                    a.req = !a.req;
                    a.awaiting = None;
                    if kind == WriteKind::Chunk {
                        a.chain = None;
                    }
                }
                if let Purpose::Zeros(axis) = purpose
                    && let Some(a) = self.axis(axis)
                {
                    a.zeroed = true;
                }
                if purpose == Purpose::Module {
                    self.module_read = true;
                }
                self.events
                    .push_back(RmcEvent::Exception { id, function, code });
            }
            (Purpose::Zeros(axis), Response::Written { .. }) => {
                if let Some(a) = self.axis(axis) {
                    a.zeroed = true;
                    a.req = false;
                    a.ack = Some(false);
                }
            }
            (Purpose::Module, Response::Registers { words, .. }) => {
                self.module_read = true;
                let cpu_id = dword_at(&words, 0).unwrap_or(0);
                self.events.push_back(RmcEvent::Module { cpu_id });
            }
            (Purpose::Controller, Response::Registers { words, .. }) => {
                let status = ControllerStatus(dword_at(&words, 0).unwrap_or(0));
                self.events
                    .push_back(RmcEvent::Controller { status, at: now });
            }
            (Purpose::Status(axis), Response::Registers { words, .. }) => {
                match AxisStatus::decode(&words) {
                    Some(status) => self.on_status(now, axis, status),
                    None => self.events.push_back(RmcEvent::Ignored {
                        why: format!("{axis}'s status came back with {} registers", words.len()),
                    }),
                }
            }
            (Purpose::Write { .. }, Response::Written { .. }) => {}
            (_, other) => self.events.push_back(RmcEvent::Ignored {
                why: format!("a reply that does not answer its request: {other:?}"),
            }),
        }
    }

    fn on_status(&mut self, now: Instant, axis: AxisId, status: AxisStatus) {
        let Some(a) = self.axes.get_mut(axis.index()) else {
            return;
        };
        let ack = status.bits.ack();
        a.fresh = true;
        a.read_wanted = false;
        a.ack = Some(ack);
        let mut trusted = true;
        if let Some(w) = a.awaiting {
            if ack == w.req {
                a.awaiting = None;
                self.events.push_back(RmcEvent::Acknowledged {
                    id: w.id,
                    axis,
                    at: now,
                });
            } else if w.timed_out || now >= w.until {
                // Requests are handled in order (RMC.md section 1): a read after the
                // write that still shows the old ACK means the write never arrived. It
                // is not sent again.
                a.req = ack;
                a.awaiting = None;
                // A jog whose move may not have arrived is not carried on: it stops.
                if a.chain.take().is_some() {
                    a.stop_owed = true;
                }
                self.events
                    .push_back(RmcEvent::Unconfirmed { id: w.id, axis });
            } else {
                trusted = false;
            }
        }
        if trusted && (status.bits.halted() || status.errors.any()) && a.chain.take().is_some() {
            // A halted axis (a travel limit, a fault) is not pushed on by more moves.
            self.events.push_back(RmcEvent::JogEnded {
                axis,
                why: format!("{axis} halted: {}", status.errors.names().join(", ")),
            });
        }
        if trusted {
            let still = status.bits.tg_done() && status.target_velocity == 0.0;
            if still && a.chain.is_none() {
                a.may_move = false;
            }
            a.last = Some(status);
        }
        self.events.push_back(RmcEvent::Status {
            axis,
            status,
            trusted,
            at: now,
        });
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
            let decoded = frame.and_then(|f| modbus::decode_response(&f));
            match decoded {
                Err(e) => {
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
        if let Some(flight) = self.in_flight.take_if(|f| f.deadline <= now) {
            self.timeouts_in_row = self.timeouts_in_row.saturating_add(1);
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
                let purpose = self.next_purpose(now)?;
                let request = self.request_of(purpose);
                self.transaction = self.transaction.wrapping_add(1);
                let header = Header {
                    transaction: self.transaction,
                    unit: self.config.unit,
                };
                let bytes = modbus::encode_request(header, &request);
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
            Line::Up if self.in_flight.is_none() && !self.reader_behind => Some(self.next_round),
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
