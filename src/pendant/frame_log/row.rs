//! One row of the frame log as handed to readers (its kind, verdict, bytes and note),
//! read from the stored entry (`entry.rs`).

use std::borrow::Cow;

use super::entry::Entry;
use super::packed;
use crate::protocol::{ChecksumVerdict, MessageId};

/// Which way a row went, or what it is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Dir {
    /// A frame the pendant wrote.
    Sent,
    /// A well-formed frame that came in.
    Received,
    /// Bytes that made no valid frame (with the link's reason).
    Garbage,
    /// No reply in time (a note, no bytes).
    Timeout,
}

impl Dir {
    pub fn code(self) -> u8 {
        match self {
            Dir::Sent => 0,
            Dir::Received => 1,
            Dir::Garbage => 2,
            Dir::Timeout => 3,
        }
    }

    pub(super) fn from_code(c: u8) -> Dir {
        match c {
            0 => Dir::Sent,
            1 => Dir::Received,
            2 => Dir::Garbage,
            _ => Dir::Timeout,
        }
    }

    /// Short label for the table: `>>` out, `<<` in.
    pub fn arrow(self) -> &'static str {
        match self {
            Dir::Sent => ">>",
            Dir::Received => "<<",
            Dir::Garbage => "<< ??",
            Dir::Timeout => "--",
        }
    }

    /// The name used in saved files.
    pub fn key(self) -> &'static str {
        match self {
            Dir::Sent => "sent",
            Dir::Received => "received",
            Dir::Garbage => "garbage",
            Dir::Timeout => "timeout",
        }
    }

    pub fn from_key(key: &str) -> Option<Dir> {
        [Dir::Sent, Dir::Received, Dir::Garbage, Dir::Timeout]
            .into_iter()
            .find(|d| d.key() == key)
    }
}

/// The SC field's verdict, as the table shows it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Verdict {
    /// The sum matches.
    Ok,
    /// `@@` instead of a sum (accepted, flagged) [spec: PROTOCOL.md 1.4].
    AtAt,
    /// The sum does not match, or the SC is unreadable.
    Bad,
    /// No SC to judge (too short, a time-out row).
    None,
}

impl Verdict {
    pub(super) fn code(self) -> u8 {
        match self {
            Verdict::Ok => 0,
            Verdict::AtAt => 1,
            Verdict::Bad => 2,
            Verdict::None => 3,
        }
    }

    pub(super) fn from_code(c: u8) -> Verdict {
        match c {
            0 => Verdict::Ok,
            1 => Verdict::AtAt,
            2 => Verdict::Bad,
            _ => Verdict::None,
        }
    }

    pub fn label(self) -> &'static str {
        match self {
            Verdict::Ok => "ok",
            Verdict::AtAt => "@@",
            Verdict::Bad => "bad",
            Verdict::None => "",
        }
    }

    /// The verdict of a frame's SC [spec: PROTOCOL.md 1.4], as the protocol reads it.
    pub fn of(bytes: &[u8]) -> Verdict {
        match crate::protocol::peek::checksum_verdict(bytes) {
            ChecksumVerdict::Valid(_) => Verdict::Ok,
            ChecksumVerdict::AtAt { .. } => Verdict::AtAt,
            ChecksumVerdict::Wrong { .. } | ChecksumVerdict::Unreadable { .. } => Verdict::Bad,
            ChecksumVerdict::Absent => Verdict::None,
        }
    }
}

/// A row of the log, borrowed.
#[derive(Clone, Copy, Debug)]
pub struct Row<'a> {
    seq: u64,
    entry: &'a Entry,
    buf: &'a [u8],
    /// The time of the request this row answers, when still kept.
    request_t: Option<u64>,
}

impl<'a> Row<'a> {
    /// The row `entry` with its bytes in `buf`; `previous` finds the row before it, looked
    /// up only when this row answers it (for the latency).
    pub(super) fn new(
        seq: u64,
        entry: &'a Entry,
        buf: &'a [u8],
        previous: impl FnOnce() -> Option<&'a Entry>,
    ) -> Self {
        let request_t = entry
            .answers_previous()
            .then(previous)
            .flatten()
            .map(Entry::t_ns);
        Row {
            seq,
            entry,
            buf,
            request_t,
        }
    }

    /// The row's sequence number (stable while the row is kept).
    pub fn seq(&self) -> u64 {
        self.seq
    }

    pub fn dir(&self) -> Dir {
        self.entry.dir()
    }

    /// Nanoseconds after the log's start.
    pub fn t_ns(&self) -> u64 {
        self.entry.t_ns()
    }

    /// The exact bytes on the line (rebuilt from the packed form when stored packed).
    pub fn bytes(&self) -> Cow<'a, [u8]> {
        packed::original(self.buf, self.entry.stored(), self.entry.packed())
    }

    /// Appends the exact bytes to `out` (for loops over many rows: one buffer serves).
    pub fn write_bytes(&self, out: &mut Vec<u8>) {
        packed::write_original(self.buf, self.entry.stored(), self.entry.packed(), out);
    }

    /// The link's reason for garbage, or the time-out text.
    pub fn note(&self) -> &'a str {
        if !self.entry.has_note() {
            return "";
        }
        let at = self.entry.stored().end;
        let len = self
            .buf
            .get(at..at + 2)
            .map_or(0, |l| u16::from_le_bytes([l[0], l[1]]));
        let text = self
            .buf
            .get(at + 2..at + 2 + usize::from(len))
            .unwrap_or_default();
        std::str::from_utf8(text).unwrap_or("")
    }

    /// The message ID (an `&` reply or a time-out takes its request's).
    pub fn id(&self) -> Option<u16> {
        self.entry.id()
    }

    pub fn verdict(&self) -> Verdict {
        self.entry.verdict()
    }

    /// Request-to-reply time, for answers.
    pub fn latency_us(&self) -> Option<u32> {
        let sent = self.request_t.filter(|_| self.dir() != Dir::Timeout)?;
        let us = self.entry.t_ns().saturating_sub(sent) / 1000;
        Some(us.min(u64::from(u32::MAX)) as u32)
    }

    /// The row answers the row just before it (its request).
    pub(super) fn answers_previous(&self) -> bool {
        self.entry.answers_previous()
    }

    /// An `&` error reply.
    pub fn is_error_reply(&self) -> bool {
        self.dir() == Dir::Received
            && packed::first_byte(self.buf, self.entry.stored(), self.entry.packed()) == Some(b'&')
    }

    /// Error replies, garbage, bad checksums and time-outs: the rows to highlight.
    pub fn is_problem(&self) -> bool {
        self.is_error_reply()
            || matches!(self.dir(), Dir::Garbage | Dir::Timeout)
            || self.verdict() == Verdict::Bad
    }

    /// The message's name: `212H axis status query`, `error reply to 232H ...`.
    pub fn name(&self) -> String {
        let id = match self.id() {
            Some(id) => {
                let name = MessageId(id).name().unwrap_or("unknown message");
                format!("{id:03X}H {name}")
            }
            None => String::new(),
        };
        match self.dir() {
            Dir::Timeout => format!("time-out {id}"),
            Dir::Garbage => format!("garbage {id}"),
            _ if self.is_error_reply() => format!("error reply {id}"),
            _ => id,
        }
        .trim_end()
        .to_string()
    }

    /// The bytes as text with CR, LF and other control bytes visible (`\r`, `\n`, `\x02`).
    pub fn ascii(&self) -> String {
        self.bytes().escape_ascii().to_string()
    }
}
