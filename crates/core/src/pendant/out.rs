//! What the model hands out, a leaf every sub-model writes into: the requests for the
//! lines (in the order they must reach them) and the messages for the operator.

use std::collections::VecDeque;
use std::time::Instant;

use crate::protocol::{Command, CoordKind};

/// Messages kept for the operator.
const KEEP_MESSAGES: usize = 200;

/// What the pendant asks of the link. The window runs these after drawing a frame;
/// [`Request::Stop`] it runs at once.
#[derive(Clone, Debug, PartialEq)]
pub enum Request {
    /// A command at the user's priority.
    Submit(Command),
    /// A command that gives way to the status polls (position table reads).
    Background(Command),
    /// A command sent only in the line time the status polls leave (signal reads).
    Spare(Command),
    /// 238H for all axes, at the head of the queue.
    Stop,
    /// Keep the continuous jog alive (the link stops it when renewals stop).
    RenewJogLease,
    /// Read a whole coordinate table with 2A4H.
    ReadTable(CoordKind),
    /// Read these records of a coordinate table with 2A4H (a retry of what a read missed).
    ReadRecords(CoordKind, std::ops::Range<u16>),
    /// Stop the table read in progress.
    CancelTableRead,
    /// Give the embedded simulator these tables (the draft, to try it).
    SimulatorTables(crate::robot::CoordTables),
    /// Close the line (if open) and open the one in the settings.
    Connect,
    /// Close the line.
    Disconnect,
    /// A call for the RMC151's link.
    Axes(crate::pendant::axes::AxisCall),
}

/// How a message to the operator is shown.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Level {
    Info,
    Warning,
    Error,
}

/// One line for the operator: what happened, where they are looking.
#[derive(Clone, Debug, PartialEq)]
pub struct Message {
    pub level: Level,
    pub text: String,
    pub at: Instant,
    /// The whole story where `text` is the short form (a refusal's check point and
    /// distances): shown on hover.
    pub detail: Option<String>,
}

/// Adds a message for the operator, the oldest going once [`KEEP_MESSAGES`] are kept.
pub fn say(messages: &mut VecDeque<Message>, level: Level, text: impl Into<String>, now: Instant) {
    if messages.len() >= KEEP_MESSAGES {
        messages.pop_front();
    }
    messages.push_back(Message {
        level,
        text: text.into(),
        at: now,
        detail: None,
    });
}

/// Where a sub-model puts what it decided: the pendant's requests, in order, and its
/// messages. Borrowed from the pendant for one call.
pub struct Out<'a> {
    pub requests: &'a mut Vec<Request>,
    pub messages: &'a mut VecDeque<Message>,
}

impl Out<'_> {
    /// A word for the operator.
    pub fn say(&mut self, level: Level, text: impl Into<String>, now: Instant) {
        say(self.messages, level, text, now);
    }

    /// A request for the lines, after those asked for before it.
    pub fn push(&mut self, request: Request) {
        self.requests.push(request);
    }
}
