//! What the link is asked to send: request ids, priorities and where a request came from.

use std::fmt;
use std::sync::atomic::{AtomicU64, Ordering};

use crate::protocol::{Command, CoordKind};

/// Identifies one submitted request in the events that answer it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct RequestId(pub u64);

impl RequestId {
    /// The next id from a counter shared by the handle and the link thread.
    pub fn next(counter: &AtomicU64) -> RequestId {
        RequestId(counter.fetch_add(1, Ordering::Relaxed))
    }
}

impl fmt::Display for RequestId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "#{}", self.0)
    }
}

/// Queue order. 238H STOP always travels as [`Priority::Stop`], whatever it was given.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Priority {
    /// Head of the queue: sent as soon as the transaction in flight ends.
    Stop,
    /// The user's own commands (jog steps, servo, home, queries from the UI).
    User,
    /// Bulk work that may wait for the user: coordinate-table chunks.
    Background,
    /// Watching that takes only the line time the status polls leave (signal reads):
    /// sent when it ends before the next poll is due, or from a small share of the line
    /// while polls run back to back ([`crate::link::schedule::SPARE_SHARE`]).
    Spare,
}

/// Why a request is on the line.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Origin {
    /// Submitted by the application.
    User,
    /// The link's own status poll.
    Poll,
    /// One chunk of a coordinate-table download (`generation` tells downloads apart).
    Table {
        kind: CoordKind,
        first: u8,
        count: u8,
        generation: u32,
    },
    /// A status read after a motion command timed out (motion is never re-sent).
    Recheck { after: RequestId },
    /// A query proving no late reply is on its way, sent before a motion command.
    Proof { before: RequestId },
    /// Sent by the link itself to stop a jog or move that may still be running after the
    /// line stalled or was lost, or as the link shuts down.
    SafetyStop,
    /// Sent by the link itself because a continuous jog's lease was not renewed in time.
    LeaseLapsed,
}

/// A request waiting for, or on, the line.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Pending {
    pub id: RequestId,
    pub command: Command,
    pub origin: Origin,
    pub priority: Priority,
    /// Times it has been sent already.
    pub attempts: u8,
    /// Proving queries sent for it (motion only) without putting the line in step.
    pub proofs: u8,
}

impl Pending {
    pub fn new(id: RequestId, command: Command, origin: Origin, priority: Priority) -> Self {
        let priority = if command.is_stop() {
            Priority::Stop
        } else {
            priority
        };
        Self {
            id,
            command,
            origin,
            priority,
            attempts: 0,
            proofs: 0,
        }
    }

    /// Whether a time-out may be answered by sending it again: never motion; never a
    /// write to the controller's data (it is sent once; the writer reads back what the
    /// controller holds); never a
    /// poll (the next poll is the retry) or a proving query (the next motion sends
    /// another); never 25BH software reset (the controller may be rebooting without a
    /// reply, PROTOCOL.md 3.13); queries and STOP (stopping twice is harmless).
    pub fn may_retry(&self, retries: u8) -> bool {
        !self.command.is_motion()
            && !self.command.writes_data()
            && self.command != Command::SoftwareReset
            && !matches!(self.origin, Origin::Poll | Origin::Proof { .. })
            && self.attempts <= retries
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::protocol::{PositionWrite, PositionWriteKind};

    #[test]
    fn a_write_to_the_controller_is_never_sent_again_after_a_time_out() {
        let p = |command| Pending::new(RequestId(1), command, Origin::User, Priority::User);
        assert!(p(Command::SystemStatus).may_retry(2));
        let write = Command::PositionWrite(PositionWrite {
            kind: PositionWriteKind::Range3,
            records: Vec::new(),
        });
        assert!(!p(write).may_retry(2));
    }
}
