//! One axis as the RMC link core sees it on the current connection: REQ and ACK, whether
//! its positions have been read, a held jog's chain of moves, a STOP owed.

use std::time::Instant;

use super::event::HoldJog;
use crate::link::RequestId;
use crate::rmc::{AxisId, AxisStatus};

/// A command written whose ACK has not been seen yet.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Awaiting {
    pub id: Option<RequestId>,
    /// The REQ it was written with.
    pub req: bool,
    /// Its write got no reply in time: the next status read decides whether it arrived.
    pub timed_out: bool,
    /// After this, an ACK still not equal to REQ means the command was not taken.
    pub until: Instant,
}

/// A held jog's chain of Move Relative moves relative to the Target (RMC.md section 6).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Chain {
    pub id: RequestId,
    pub jog: HoldJog,
    /// The distance of one move: speed × lease plus the distance to stop at the jog's
    /// deceleration, so the axis stops within it after the last move went out.
    pub chunk: f32,
    /// Whether the first move went out.
    pub started: bool,
}

impl Chain {
    pub fn new(id: RequestId, jog: HoldJog, lease_secs: f32) -> Self {
        let stopping = jog.speed * jog.speed / (2.0 * jog.decel);
        Self {
            id,
            jog,
            chunk: jog.speed * lease_secs + stopping,
            started: false,
        }
    }

    /// Whether the next move is due: the first, or the Command Position is less than
    /// half a move ahead of the Target.
    pub fn due(&self, last: Option<&AxisStatus>) -> bool {
        if !self.started {
            return true;
        }
        last.is_some_and(|s| {
            (s.command_position - s.target_position) * self.jog.direction < self.chunk / 2.0
        })
    }
}

/// The link's state of one axis.
#[derive(Clone, Debug)]
pub(super) struct AxisLink {
    pub id: AxisId,
    /// The REQ of the last command written on this connection.
    pub req: bool,
    /// ACK as last read; unknown after a reconnect until read.
    pub ack: Option<bool>,
    /// Zeros written on this connection (ACK reset to 0, RMC.md section 5).
    pub zeroed: bool,
    /// Positions read on this connection: relative moves may go out.
    pub fresh: bool,
    /// A status read is wanted before anything else is written (after a time-out).
    pub read_wanted: bool,
    pub last: Option<AxisStatus>,
    pub awaiting: Option<Awaiting>,
    pub chain: Option<Chain>,
    /// Stop (Closed Loop) (6) to send.
    pub stop_owed: bool,
    /// Motion was sent and no trusted status has shown the axis still since.
    pub may_move: bool,
}

impl AxisLink {
    pub fn new(id: AxisId) -> Self {
        Self {
            id,
            req: false,
            ack: None,
            zeroed: false,
            fresh: false,
            read_wanted: false,
            last: None,
            awaiting: None,
            chain: None,
            stop_owed: false,
            may_move: false,
        }
    }

    /// A new connection: nothing known of ACK, positions to be read again.
    pub fn reconnected(&mut self) {
        self.req = false;
        self.ack = None;
        self.zeroed = false;
        self.fresh = false;
        self.read_wanted = false;
        self.awaiting = None;
    }

    /// Whether STOP goes to it: enabled, or not known to be disabled.
    pub fn stoppable(&self) -> bool {
        self.last.is_none_or(|s| s.bits.enabled())
    }
}
