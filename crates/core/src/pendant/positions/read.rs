//! Reading the controller's position table: ranges of numbers in queries sized to the
//! reply buffer, two in flight, each answered chunk marking its numbers.

use std::collections::VecDeque;
use std::ops::RangeInclusive;

use crate::protocol::{Command, PositionQuery, PositionQueryKind};

/// Queries kept on their way at once: the next is queued while one is on the line, so
/// the line never waits for the window between two chunks.
pub const IN_FLIGHT: usize = 2;

/// One read of ranges of position numbers.
#[derive(Clone, Debug, PartialEq)]
pub struct ReadJob {
    pub kind: PositionQueryKind,
    /// The numbers asked for, ascending ranges (a read-back reads only what was written).
    pub parts: Vec<RangeInclusive<u16>>,
    /// Numbers looked at per query (PROTOCOL.md 3.24: sized for the worst case).
    pub chunk: u16,
    part: usize,
    next: u32,
    /// Queries sent and not yet answered, oldest first.
    pub in_flight: VecDeque<PositionQuery>,
    /// Numbers answered (read, empty or failed).
    pub done: u32,
    /// Whether this read checks a write (its rows are compared when it ends).
    pub verifies: bool,
    /// Ranges to ask for before going on (the rest of a reply that was cut short).
    again: VecDeque<RangeInclusive<u16>>,
}

impl ReadJob {
    pub fn new(
        kind: PositionQueryKind,
        parts: Vec<RangeInclusive<u16>>,
        chunk: u16,
        verifies: bool,
    ) -> Self {
        ReadJob {
            kind,
            next: parts.first().map_or(1, |r| u32::from(*r.start())),
            part: 0,
            parts,
            chunk: chunk.max(1),
            in_flight: VecDeque::new(),
            done: 0,
            verifies,
            again: VecDeque::new(),
        }
    }

    /// Numbers in the whole read.
    pub fn total(&self) -> u32 {
        self.parts
            .iter()
            .map(|r| u32::from(*r.end()).saturating_sub(u32::from(*r.start())) + 1)
            .sum()
    }

    /// From the first number asked for to the last.
    pub fn span(&self) -> RangeInclusive<u16> {
        let first = self.parts.first().map_or(1, |r| *r.start());
        let last = self.parts.last().map_or(first, |r| *r.end());
        first..=last
    }

    /// The queries to send now to keep [`IN_FLIGHT`] on their way.
    pub fn next_queries(&mut self) -> Vec<Command> {
        let mut out = Vec::new();
        while self.in_flight.len() < IN_FLIGHT {
            if let Some(r) = self.again.pop_front() {
                let count = (u32::from(*r.end()) - u32::from(*r.start()) + 1)
                    .min(u32::from(self.chunk)) as u16;
                let q = PositionQuery {
                    kind: self.kind,
                    first: *r.start(),
                    count,
                };
                if let Some(rest) = r.start().checked_add(count).filter(|s| s <= r.end()) {
                    self.again.push_front(rest..=*r.end());
                }
                // The numbers asked again were counted done with the reply that was cut.
                self.done = self.done.saturating_sub(u32::from(count));
                self.in_flight.push_back(q);
                out.push(Command::PositionQuery(q));
                continue;
            }
            let Some(range) = self.parts.get(self.part) else {
                break;
            };
            let end = u32::from(*range.end());
            if self.next > end {
                self.part += 1;
                if let Some(r) = self.parts.get(self.part) {
                    self.next = u32::from(*r.start());
                }
                continue;
            }
            let count = (end - self.next + 1).min(u32::from(self.chunk));
            let q = PositionQuery {
                kind: self.kind,
                first: self.next as u16,
                count: count as u16,
            };
            self.next += count;
            self.in_flight.push_back(q);
            out.push(Command::PositionQuery(q));
        }
        out
    }

    /// Takes `q` off the in-flight list; false when it is not this job's.
    pub fn answered(&mut self, q: &PositionQuery) -> bool {
        let Some(i) = self.in_flight.iter().position(|f| f == q) else {
            return false;
        };
        self.in_flight.remove(i);
        self.done += u32::from(q.count);
        true
    }

    /// Every query sent and answered.
    pub fn is_finished(&self) -> bool {
        self.in_flight.is_empty() && self.again.is_empty() && self.part >= self.parts.len()
    }

    /// Stops asking; what is in flight is still taken in.
    pub fn stop_asking(&mut self) {
        self.part = self.parts.len();
        self.again.clear();
    }

    /// Asks for `range` again first (a reply cut short by the reply buffer).
    pub fn read_again(&mut self, range: RangeInclusive<u16>) {
        self.again.push_back(range);
    }
}

/// Numbers gathered into ascending ranges of consecutive numbers, with gaps of at most
/// `bridge` numbers bridged (one query reads them more cheaply than two).
pub fn ranges(numbers: &[u16], bridge: u16) -> Vec<RangeInclusive<u16>> {
    let mut out: Vec<RangeInclusive<u16>> = Vec::new();
    for &n in numbers {
        match out.last_mut() {
            Some(r) if u32::from(n) <= u32::from(*r.end()) + 1 + u32::from(bridge) => {
                *r = *r.start()..=n.max(*r.end());
            }
            _ => out.push(n..=n),
        }
    }
    out
}
