//! One row of the frame log as handed to readers (its protocol, kind, verdict, bytes and
//! note), read from the stored entry (`entry.rs`).

use std::borrow::Cow;

use super::entry::Entry;
use super::packed;
use crate::protocol::describe::FrameDescription;
use crate::protocol::{ChecksumVerdict, MessageId};
use crate::rmc::describe as modbus;

/// Which line a row was on.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Protocol {
    /// The X-SEL's Format B (serial or its TCP bridge).
    FormatB,
    /// The RMC151's Modbus/TCP.
    Modbus,
}

impl Protocol {
    pub(super) fn index(self) -> usize {
        match self {
            Protocol::FormatB => 0,
            Protocol::Modbus => 1,
        }
    }
}

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
            ChecksumVerdict::Absent | ChecksumVerdict::NotUsed => Verdict::None,
        }
    }
}

/// A row of the log, borrowed.
#[derive(Clone, Copy, Debug)]
pub struct Row<'a> {
    seq: u64,
    entry: &'a Entry,
    buf: &'a [u8],
    /// The request this row answers, when still kept: its entry and its chunk's bytes.
    request: Option<(&'a Entry, &'a [u8])>,
}

impl<'a> Row<'a> {
    /// The row `entry` with its bytes in `buf`; `request` finds the request it answers,
    /// looked up only when it answers one.
    pub(super) fn new(
        seq: u64,
        entry: &'a Entry,
        buf: &'a [u8],
        request: impl FnOnce() -> Option<(&'a Entry, &'a [u8])>,
    ) -> Self {
        let request = entry.answers().then(request).flatten();
        Row {
            seq,
            entry,
            buf,
            request,
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

    /// Which line the row was on.
    pub fn protocol(&self) -> Protocol {
        self.entry.protocol()
    }

    /// The Format B message ID (an `&` reply or a time-out takes its request's); none
    /// for a Modbus row.
    pub fn id(&self) -> Option<u16> {
        match self.protocol() {
            Protocol::FormatB => self.entry.id(),
            Protocol::Modbus => None,
        }
    }

    /// A Modbus row's function code (with 0x80 on an exception).
    pub fn function(&self) -> Option<u8> {
        match self.protocol() {
            Protocol::FormatB => None,
            Protocol::Modbus => self.entry.id().map(|f| f as u8),
        }
    }

    pub fn verdict(&self) -> Verdict {
        self.entry.verdict()
    }

    /// Request-to-reply time, for answers.
    pub fn latency_us(&self) -> Option<u32> {
        let (request, _) = self.request.filter(|_| self.dir() != Dir::Timeout)?;
        let us = self.entry.t_ns().saturating_sub(request.t_ns()) / 1000;
        Some(us.min(u64::from(u32::MAX)) as u32)
    }

    /// The row answers a request (the last of its protocol before it).
    pub(super) fn answers(&self) -> bool {
        self.entry.answers()
    }

    /// The bytes of the request this row answers, when still kept.
    pub fn request_bytes(&self) -> Option<Cow<'a, [u8]>> {
        let (e, buf) = self.request?;
        Some(packed::original(buf, e.stored(), e.packed()))
    }

    /// An `&` error reply, or a Modbus exception.
    pub fn is_error_reply(&self) -> bool {
        if self.dir() != Dir::Received {
            return false;
        }
        match self.protocol() {
            Protocol::FormatB => {
                packed::first_byte(self.buf, self.entry.stored(), self.entry.packed()) == Some(b'&')
            }
            Protocol::Modbus => self.function().is_some_and(|f| f & 0x80 != 0),
        }
    }

    /// Error replies, garbage, bad checksums and time-outs: the rows to highlight.
    pub fn is_problem(&self) -> bool {
        self.is_error_reply()
            || matches!(self.dir(), Dir::Garbage | Dir::Timeout)
            || self.verdict() == Verdict::Bad
    }

    /// The message's name: `212H axis status query`, `error reply 232H ...`, `FC3 read
    /// Status Bits..Command Velocity, Axis 1`.
    pub fn name(&self) -> String {
        if self.protocol() == Protocol::Modbus {
            return self.modbus_name();
        }
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

    fn modbus_name(&self) -> String {
        let request = self.request_bytes();
        let asked = || {
            request.as_deref().map_or(String::new(), |r| {
                format!(" to {}", modbus::request_title(r))
            })
        };
        match self.dir() {
            Dir::Sent => modbus::request_title(&self.bytes()),
            Dir::Received => modbus::reply_title(&self.bytes(), request.as_deref()),
            Dir::Garbage => format!("Modbus garbage{}", asked()),
            Dir::Timeout => format!("Modbus time-out{}", asked()),
        }
    }

    /// The bytes as text: a Format B frame with CR, LF and other control bytes visible
    /// (`\r`, `\n`, `\x02`); Modbus bytes as spaced hex pairs.
    pub fn ascii(&self) -> String {
        match self.protocol() {
            Protocol::FormatB => self.bytes().escape_ascii().to_string(),
            Protocol::Modbus => hex_pairs(&self.bytes()),
        }
    }

    /// The bytes described field by field, as the protocol reads them.
    pub fn describe(&self) -> FrameDescription {
        let bytes = self.bytes();
        match (self.protocol(), self.dir()) {
            (Protocol::FormatB, _) => crate::protocol::describe::describe(&bytes),
            (Protocol::Modbus, Dir::Sent) => modbus::describe(&bytes, modbus::Role::Request),
            (Protocol::Modbus, _) => {
                let request = self.request_bytes();
                modbus::describe(
                    &bytes,
                    modbus::Role::Reply {
                        request: request.as_deref(),
                    },
                )
            }
        }
    }
}

/// `00 07 00 00`: bytes as spaced upper-case hex pairs.
pub fn hex_pairs(bytes: &[u8]) -> String {
    use std::fmt::Write as _;
    let mut s = String::with_capacity(bytes.len() * 3);
    for (i, b) in bytes.iter().enumerate() {
        if i > 0 {
            s.push(' ');
        }
        let _ = write!(s, "{b:02X}");
    }
    s
}
