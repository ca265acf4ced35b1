//! What the RMC link core asks for and reports: the application's requests and the events
//! that answer them.

use std::time::{Duration, Instant};

use crate::link::RequestId;
use crate::link::core::CoreEvent;
use crate::rmc::modbus::ExceptionCode;
use crate::rmc::{AxisId, AxisStatus, Command, ControllerStatus};

/// A held jog on one axis: a chain of short Move Relative (21) moves relative to the
/// Target, renewed while the lease is (RMC.md section 6).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HoldJog {
    /// +1.0 or −1.0.
    pub direction: f32,
    /// pu/s.
    pub speed: f32,
    pub accel: f32,
    pub decel: f32,
}

/// A request from the application.
#[derive(Clone, Debug, PartialEq)]
pub enum RmcRequest {
    /// Send one command to one axis (checked first; motion only once the axis's
    /// positions have been read on this connection).
    Send {
        id: RequestId,
        axis: AxisId,
        command: Command,
    },
    /// Start a held jog on `axis`; it runs while the lease is renewed.
    Hold {
        id: RequestId,
        axis: AxisId,
        jog: HoldJog,
    },
    /// The held jog's input let go: Stop (Closed Loop) (6) for that axis.
    Release { axis: AxisId },
    /// STOP: Stop (Closed Loop) (6) for every enabled axis, ahead of everything; queued
    /// motion is dropped.
    StopAll,
    /// Sent behind a [`RmcRequest::Release`] (`axis`) or [`RmcRequest::StopAll`] (`None`)
    /// on the ordinary channel, after the same on the STOP channel, which may have
    /// overtaken a Hold or a move sent before it: what it overtook ends here (a jog not
    /// yet written and queued motion are not sent; one written gets its Stop (6)).
    StopsInOrder { axis: Option<AxisId> },
    /// Close and reopen the connection.
    Reconnect,
    /// Time between two status rounds (every shown axis, then the controller).
    SetPollInterval(Duration),
}

/// Why the core sent Stop (6) of its own.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SafetyStop {
    /// The held jog's lease was not renewed in time.
    LeaseLapsed,
    /// The connection came back while motion may have been running.
    Reconnected,
    /// The link is closing.
    Closing,
    /// The guardian process that owns the connection stopped the axes (the window fell
    /// silent).
    Guardian,
}

impl SafetyStop {
    pub fn text(self) -> &'static str {
        match self {
            SafetyStop::LeaseLapsed => "the jog lease lapsed",
            SafetyStop::Reconnected => "the connection came back after motion",
            SafetyStop::Closing => "the link is closing",
            SafetyStop::Guardian => "the guardian process stopped them (the window was silent)",
        }
    }
}

/// What the core reports.
#[derive(Clone, Debug, PartialEq)]
pub enum RmcEvent {
    /// The connection is open; sent again, with the back-off said after the name, when
    /// the link starts backing off from a device that keeps answering badly, and with
    /// the bare name once a whole round answered well again (the connection's health
    /// line).
    LineUp { name: String, at: Instant },
    /// The connection is down, and why.
    LineDown { reason: String, at: Instant },
    /// The CPU Module ID read after connecting (17 on an RMC151E).
    Module { cpu_id: u32 },
    /// Controller Status Bits, polled.
    Controller {
        status: ControllerStatus,
        at: Instant,
    },
    /// An axis's status as polled; `trusted` is false while a command's ACK is awaited
    /// (its In Position and TG bits are not valid then, RMC.md section 5).
    Status {
        axis: AxisId,
        status: AxisStatus,
        trusted: bool,
        at: Instant,
    },
    /// A command went out (`id` is `None` for the core's own: zeros, STOP, hold chunks).
    Sent {
        id: Option<RequestId>,
        axis: AxisId,
        command: Command,
        req: bool,
        at: Instant,
    },
    /// A status read showed ACK = REQ for that command.
    Acknowledged {
        id: Option<RequestId>,
        axis: AxisId,
        at: Instant,
    },
    /// A request that never reached the controller, and why: its axis and what it was
    /// (a command's name, or [`super::HELD_JOG`] for a hold).
    NotSent {
        id: RequestId,
        axis: AxisId,
        what: &'static str,
        reason: String,
    },
    /// A command written whose ACK never came to equal its REQ: the RMC may or may not
    /// have taken it; it is not sent again. `answered`: the write itself had its reply
    /// (it reached the controller); else no reply came in time.
    Unconfirmed {
        id: Option<RequestId>,
        axis: AxisId,
        answered: bool,
    },
    /// The controller answered a request with an exception.
    Exception {
        id: Option<RequestId>,
        function: u8,
        code: ExceptionCode,
    },
    /// The core sent Stop (6) of its own to these axes.
    SafetyStop { why: SafetyStop, axes: Vec<AxisId> },
    /// A held jog ended by itself (the axis halted); no more moves go out for it.
    JogEnded { axis: AxisId, why: String },
    /// A reply that answered nothing in flight (late, or unreadable), left out.
    Ignored { why: String },
    /// A request's bytes went out (for the frame log).
    FrameSent { bytes: Vec<u8>, at: Instant },
    /// A whole frame came in.
    FrameReceived { bytes: Vec<u8>, at: Instant },
    /// Bytes that are not Modbus/TCP, and why (the connection is dropped after them).
    Garbage {
        bytes: Vec<u8>,
        error: String,
        at: Instant,
    },
    /// No reply in time to the request in flight.
    Timeout { what: String, at: Instant },
    /// Traffic events left out while the reader was behind.
    Dropped(u64),
    /// The core has finished.
    Closed,
}

impl RmcEvent {
    /// When it happened, for the events that carry a time (the frame log files traffic
    /// under it).
    pub fn at(&self) -> Option<Instant> {
        match self {
            RmcEvent::Controller { at, .. }
            | RmcEvent::Status { at, .. }
            | RmcEvent::Sent { at, .. }
            | RmcEvent::Acknowledged { at, .. }
            | RmcEvent::FrameSent { at, .. }
            | RmcEvent::FrameReceived { at, .. }
            | RmcEvent::Garbage { at, .. }
            | RmcEvent::Timeout { at, .. } => Some(*at),
            _ => None,
        }
    }
}

impl CoreEvent for RmcEvent {
    fn is_traffic(&self) -> bool {
        matches!(
            self,
            RmcEvent::Status { .. }
                | RmcEvent::Controller { .. }
                | RmcEvent::Ignored { .. }
                | RmcEvent::FrameSent { .. }
                | RmcEvent::FrameReceived { .. }
                | RmcEvent::Garbage { .. }
        )
    }

    fn dropped(frames: u64) -> Option<Self> {
        Some(RmcEvent::Dropped(frames))
    }
}
