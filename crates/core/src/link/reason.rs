//! Why the line went down, why a request was not sent, and what was wrong with bad input:
//! typed, so the window can choose icons and colours and tests can match variants.

use std::fmt;
use std::io;

use crate::protocol::{DecodeError, EncodeError, FrameErrorKind, MessageError, MessageId, Station};

/// An operating-system error: its kind, and its text for the user.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct IoFailure {
    pub kind: io::ErrorKind,
    pub detail: String,
}

impl From<&io::Error> for IoFailure {
    fn from(e: &io::Error) -> Self {
        Self {
            kind: e.kind(),
            detail: e.to_string(),
        }
    }
}

impl fmt::Display for IoFailure {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.detail)
    }
}

/// Why the line is down ([`LinkEvent::Disconnected`](super::LinkEvent::Disconnected)).
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum LineDownReason {
    /// The port, socket or simulator could not be opened.
    OpenFailed(IoFailure),
    /// The other end closed the line (a read gave end of file).
    Closed,
    /// Reading failed (port unplugged, socket reset...).
    ReadFailed(IoFailure),
    /// Writing failed.
    WriteFailed(IoFailure),
    /// The application asked to close and reopen the line.
    ReconnectRequested,
}

impl fmt::Display for LineDownReason {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::OpenFailed(e) => write!(f, "cannot open the line: {e}"),
            Self::Closed => f.write_str("the line was closed"),
            Self::ReadFailed(e) => write!(f, "read failed: {e}"),
            Self::WriteFailed(e) => write!(f, "write failed: {e}"),
            Self::ReconnectRequested => f.write_str("closed to reconnect on request"),
        }
    }
}

/// Why a request never reached the line ([`LinkEvent::NotSent`](super::LinkEvent::NotSent)).
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum NotSentReason {
    /// The line was down when it was submitted or its turn came.
    LineDown,
    /// The line was lost while it waited in the queue.
    LineLost,
    /// The write failed; part of the frame may have gone out.
    WriteFailed(IoFailure),
    /// A value does not fit the message.
    Unencodable(EncodeError),
    /// Motion: the line could not be proven in step (a late reply may still come).
    OutOfStep,
    /// A continuous jog whose lease lapsed before its turn came.
    LeaseLapsed,
    /// The link shut down before its turn came.
    ShuttingDown,
    /// Motion submitted before a STOP of all axes: the STOP ended it before it went out.
    StopCameFirst,
}

impl fmt::Display for NotSentReason {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::LineDown => f.write_str("the line is down"),
            Self::LineLost => f.write_str("the line was lost before it could be sent"),
            Self::WriteFailed(e) => {
                write!(f, "write failed: {e} (part of the frame may have gone out)")
            }
            Self::Unencodable(e) => e.fmt(f),
            Self::OutOfStep => f.write_str(
                "the controller's replies are out of step (a late reply may still come), \
                 so the move was not sent",
            ),
            Self::LeaseLapsed => f.write_str(
                "the jog's lease lapsed (its button was no longer held) before it went out",
            ),
            Self::ShuttingDown => f.write_str("the link shut down before it could be sent"),
            Self::StopCameFirst => f.write_str("STOP came first"),
        }
    }
}

/// What was wrong with bytes that arrived ([`LinkEvent::Garbage`](super::LinkEvent::Garbage)).
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum BadInput {
    /// Not a valid frame: noise, a bad checksum, a missing line end...
    Malformed(DecodeError),
    /// A frame was cut short: no line end came before the time-out (or while idle).
    CutOff,
    /// A valid frame that answers nothing outstanding (a late reply).
    Late,
    /// A reply from another station.
    WrongStation { got: Station, expected: Station },
    /// A command frame (`!`) came back: the line may be looped back.
    Echo,
    /// A reply to another message than the one outstanding.
    OtherReply {
        got: Option<MessageId>,
        expected: MessageId,
    },
    /// A well-formed frame whose message is not valid.
    BadMessage(MessageError),
}

impl BadInput {
    /// Whether this is a checksum mismatch.
    pub fn is_checksum(&self) -> bool {
        matches!(self, Self::Malformed(DecodeError::Frame(e))
            if matches!(e.kind, FrameErrorKind::Checksum { .. }))
    }
}

impl fmt::Display for BadInput {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Malformed(e) => e.fmt(f),
            Self::CutOff => f.write_str("incomplete frame: no line end"),
            Self::Late => f.write_str("late frame: not the answer to anything outstanding"),
            Self::WrongStation { got, expected } => {
                write!(
                    f,
                    "reply from station {got} while talking to station {expected}"
                )
            }
            Self::Echo => f.write_str("a command frame ('!') came back: is the line looped back?"),
            Self::OtherReply { got, expected } => {
                let got = got.map_or_else(|| "?".into(), |id| id.to_string());
                write!(
                    f,
                    "reply to {got} while waiting for the reply to {expected}"
                )
            }
            Self::BadMessage(e) => e.fmt(f),
        }
    }
}
