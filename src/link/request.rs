//! What the link is asked to send: request ids, priorities and where a request came from.

use std::fmt;

use crate::protocol::{Command, CoordKind};

/// Identifies one submitted request in the events that answer it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct RequestId(pub u64);

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
}

/// Why a request is on the line.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Origin {
    /// Submitted by the application.
    User,
    /// The link's own status poll.
    Poll,
    /// One chunk of a coordinate-table download.
    Table {
        kind: CoordKind,
        first: u8,
        count: u8,
    },
    /// A status read after a motion command timed out (motion is never re-sent).
    Recheck { after: RequestId },
}

/// A request waiting for, or on, the line.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Pending {
    pub id: RequestId,
    pub command: Command,
    pub origin: Origin,
    /// Times it has been sent already.
    pub attempts: u8,
}

impl Pending {
    /// Whether a time-out may be answered by sending it again: never motion; never a
    /// poll (the next poll is the retry); never 25BH software reset (the controller
    /// may be rebooting without a reply, PROTOCOL.md 3.13); queries and STOP (stopping
    /// twice is harmless).
    pub fn may_retry(&self, retries: u8) -> bool {
        !self.command.is_motion()
            && self.command != Command::SoftwareReset
            && self.origin != Origin::Poll
            && self.attempts <= retries
    }
}
