//! What the link thread reports: traffic, answers, faults and the state of the line.

use std::ops::Range;
use std::time::{Duration, Instant};

use super::format_b::ShutdownReport;
use super::health::LinkHealth;
use super::reason::{BadInput, LineDownReason, NotSentReason};
use super::request::{Origin, RequestId};
use crate::protocol::{
    AxisPattern, Command, CoordKind, DecodeError, ErrorCode, Milli, PerAxis, Reply,
};

/// One event from the link thread, in the order things happened on the line.
#[derive(Debug, Clone, PartialEq)]
pub enum LinkEvent {
    /// The line is open (first time).
    Connected { line: String },
    /// The line was lost (port vanished, socket closed, read/write error), or could not
    /// be opened.
    Disconnected { reason: LineDownReason },
    /// The line is open again after a loss.
    Reconnected { line: String },
    /// A frame went out: the exact bytes, when the write returned.
    FrameSent {
        id: RequestId,
        bytes: Vec<u8>,
        at: Instant,
    },
    /// A well-formed frame came in.
    FrameReceived {
        bytes: Vec<u8>,
        first_byte: Instant,
        last_byte: Instant,
    },
    /// Bytes that did not make a valid frame (garbage, bad checksum, missing LF, cut-off
    /// reply), or a valid frame nobody asked for.
    Garbage {
        /// The first [`GARBAGE_KEEP`] bytes of the run.
        bytes: Vec<u8>,
        /// Bytes of the run beyond those (counted, not carried: a flood of junk without
        /// CR LF would otherwise fill the event queue with 16 KB runs).
        more: usize,
        error: BadInput,
        at: Instant,
    },
    /// The reader fell behind: this many traffic events (`FrameSent`, `FrameReceived`,
    /// `Garbage`) were left out just before this point. Nothing else is ever left out.
    Dropped { frames: u64 },
    /// The reply to a request.
    Reply {
        id: RequestId,
        origin: Origin,
        command: Command,
        reply: Reply,
        round_trip: Duration,
    },
    /// The controller refused a request with an `&` error code.
    ErrorReply {
        id: RequestId,
        origin: Origin,
        command: Command,
        code: ErrorCode,
    },
    /// No valid reply in time. `retrying` says whether the request goes out again; for
    /// motion it never does, and `recheck` names the status read sent instead.
    Timeout {
        id: RequestId,
        origin: Origin,
        command: Command,
        retrying: bool,
        recheck: Option<RequestId>,
        /// When the reply's time ran out (the frame log puts the row there).
        at: Instant,
    },
    /// The line was lost while the request waited for its reply: it may or may not have
    /// been carried out. A `Disconnected` follows.
    Interrupted {
        id: RequestId,
        origin: Origin,
        command: Command,
    },
    /// A request that never reached the line.
    NotSent {
        id: RequestId,
        command: Command,
        reason: NotSentReason,
    },
    /// Progress of a coordinate-table download.
    TableProgress {
        kind: CoordKind,
        received: u16,
        total: u16,
    },
    /// A coordinate-table download ended; `missing` lists record ranges that could not
    /// be read after the retries (empty when complete).
    TableDone {
        kind: CoordKind,
        axes: AxisPattern,
        /// The definition number of `records[0]` (0 for a whole table).
        first: u16,
        records: Vec<Option<PerAxis<Milli>>>,
        missing: Vec<Range<u16>>,
    },
    /// Figures of the line, about twice a second while connected (fewer while the
    /// reader is behind: each one says it all).
    Health(LinkHealth),
    /// The link thread has ended: the last event. What was done to stop motion.
    ShutDown(ShutdownReport),
    /// The guardian process that owns the line sent 238H of its own, and why (the
    /// window's process was silent longer than the lease while motion may run).
    GuardianStopped(String),
}

impl LinkEvent {
    /// When it happened on the line, for the events that carry a time: the time the
    /// frame log files it under (a received frame's first byte).
    pub fn at(&self) -> Option<Instant> {
        match self {
            LinkEvent::FrameSent { at, .. }
            | LinkEvent::Garbage { at, .. }
            | LinkEvent::Timeout { at, .. } => Some(*at),
            LinkEvent::FrameReceived { first_byte, .. } => Some(*first_byte),
            _ => None,
        }
    }

    /// Traffic events may be left out when the reader falls behind (counted in
    /// [`LinkEvent::Dropped`]); all others always arrive.
    pub fn is_traffic(&self) -> bool {
        matches!(
            self,
            LinkEvent::FrameSent { .. }
                | LinkEvent::FrameReceived { .. }
                | LinkEvent::Garbage { .. }
        )
    }

    /// A one-line description for logs and the status bar.
    pub fn summary(&self) -> String {
        match self {
            LinkEvent::Connected { line } => format!("connected to {line}"),
            LinkEvent::Disconnected { reason } => format!("line down: {reason}"),
            LinkEvent::Reconnected { line } => format!("reconnected to {line}"),
            LinkEvent::FrameSent { bytes, .. } => format!("sent {}", printable(bytes)),
            LinkEvent::FrameReceived { bytes, .. } => format!("received {}", printable(bytes)),
            LinkEvent::Garbage { bytes, error, .. } => {
                format!("bad input {}: {error}", printable(bytes))
            }
            LinkEvent::Dropped { frames } => {
                format!("{frames} traffic events left out (the reader fell behind)")
            }
            LinkEvent::Interrupted { command, .. } => {
                format!("line lost while waiting for the reply to {}", command.id())
            }
            LinkEvent::Reply { command, .. } => format!("reply to {}", command.id()),
            LinkEvent::ErrorReply { command, code, .. } => {
                format!("{} refused with error {code}", command.id())
            }
            LinkEvent::Timeout {
                command, retrying, ..
            } => format!(
                "no reply to {}{}",
                command.id(),
                if *retrying { ", retrying" } else { "" }
            ),
            LinkEvent::NotSent {
                command, reason, ..
            } => format!("{} not sent: {reason}", command.id()),
            LinkEvent::TableProgress {
                kind,
                received,
                total,
            } => format!("{kind:?} table: {received}/{total} records"),
            LinkEvent::TableDone { kind, missing, .. } if missing.is_empty() => {
                format!("{kind:?} table read")
            }
            LinkEvent::TableDone { kind, missing, .. } => {
                format!("{kind:?} table read with records missing: {missing:?}")
            }
            LinkEvent::Health(h) => {
                format!("{} transactions, {} timeouts", h.transactions, h.timeouts)
            }
            LinkEvent::ShutDown(report) => format!("link shut down: {report}"),
            LinkEvent::GuardianStopped(why) => format!("the guardian sent 238H STOP: {why}"),
        }
    }
}

/// Frame bytes as text, with CR, LF and other control bytes escaped.
pub fn printable(bytes: &[u8]) -> String {
    bytes.escape_ascii().to_string()
}

/// The most of one run of bad bytes a [`LinkEvent::Garbage`] carries.
pub const GARBAGE_KEEP: usize = 1024;

/// Internal: bad bytes as the link reports them, the run cut to [`GARBAGE_KEEP`].
pub(crate) fn garbage(bytes: &[u8], error: BadInput, at: Instant) -> LinkEvent {
    let keep = bytes.len().min(GARBAGE_KEEP);
    LinkEvent::Garbage {
        bytes: bytes[..keep].to_vec(),
        more: bytes.len() - keep,
        error,
        at,
    }
}

/// Internal: a decode error with its raw bytes, as the link reports it (the error's own
/// copy of the bytes cut as the event's).
pub(crate) fn garbage_event(error: &DecodeError, at: Instant) -> LinkEvent {
    let mut kept = error.clone();
    match &mut kept {
        DecodeError::Garbage { raw } | DecodeError::Overlong { raw } => raw.truncate(GARBAGE_KEEP),
        DecodeError::Frame(e) => e.raw.truncate(GARBAGE_KEEP),
    }
    garbage(error.raw(), BadInput::Malformed(kept), at)
}

#[cfg(test)]
mod garbage_tests {
    use super::*;

    /// A long run of junk crosses the event queue cut to its first bytes and a count,
    /// the decode error's own copy of the bytes cut too.
    #[test]
    fn a_long_run_of_junk_is_carried_cut_and_counted() {
        let mut d = crate::protocol::StreamDecoder::new();
        // A header, then more than a frame's length without LF: dropped as overlong.
        let mut junk = b"#".to_vec();
        junk.extend(std::iter::repeat_n(b'x', 40_000));
        d.push(&junk);
        let error = std::iter::from_fn(|| d.pull())
            .find_map(Result::err)
            .expect("junk is an error");
        let raw_len = error.raw().len();
        assert!(raw_len > GARBAGE_KEEP, "{raw_len}");
        let LinkEvent::Garbage {
            bytes, more, error, ..
        } = garbage_event(&error, Instant::now())
        else {
            panic!("not garbage")
        };
        assert_eq!(bytes.len(), GARBAGE_KEEP);
        assert_eq!(more, raw_len - GARBAGE_KEEP);
        let BadInput::Malformed(e) = error else {
            panic!("{error:?}")
        };
        assert_eq!(e.raw().len(), GARBAGE_KEEP);
    }
}
