//! The connection the operator chose (persisted) and the state of the line (live).

use std::fmt;
use std::time::Instant;

pub use crate::line::{ConnectionSettings, LineKind};

/// The state of the line, as the link reported it.
#[derive(Clone, Debug, Default, PartialEq)]
pub enum LineState {
    /// Not connected, and not trying.
    #[default]
    Closed,
    /// Opening the line.
    Opening,
    /// Open.
    Up { line: String, since: Instant },
    /// Lost or could not be opened; the link may be retrying.
    Down { reason: String, since: Instant },
}

impl LineState {
    /// The guardian process that owns the open line, if one does.
    pub fn guardian_pid(&self) -> Option<u32> {
        match self {
            LineState::Up { line, .. } => crate::link::transport::guardian_of(line),
            _ => None,
        }
    }

    pub fn is_up(&self) -> bool {
        matches!(self, LineState::Up { .. })
    }
}

impl fmt::Display for LineState {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            LineState::Closed => f.write_str("disconnected"),
            LineState::Opening => f.write_str("connecting..."),
            LineState::Up { line, .. } => write!(f, "connected: {line}"),
            LineState::Down { reason, .. } => write!(f, "line down: {reason}"),
        }
    }
}

/// What to do about a line that could not be opened, when the reason says (missing port,
/// busy port, permission), for the message beside the connection.
pub fn open_hint(reason: &crate::link::LineDownReason) -> Option<&'static str> {
    use std::io::ErrorKind;
    let crate::link::LineDownReason::OpenFailed(e) = reason else {
        return None;
    };
    let detail = e.detail.to_ascii_lowercase();
    if e.kind == ErrorKind::PermissionDenied || detail.contains("permission denied") {
        return Some(if cfg!(target_os = "linux") {
            "no permission to use the port: add your user to the dialout group \
             (sudo usermod -aG dialout $USER), then log in again"
        } else {
            "no permission to use the port: check who may open it"
        });
    }
    if detail.contains("busy") || detail.contains("access is denied") || detail.contains("lock") {
        return Some("another program holds the port: close it (or its terminal) and reconnect");
    }
    if e.kind == ErrorKind::NotFound
        || detail.contains("no such file")
        || detail.contains("not found")
        || detail.contains("cannot find the file")
    {
        return Some(if cfg!(windows) {
            "the port does not exist: check the cable, and the port's COM number in Device \
             Manager under Ports (COM & LPT) (Refresh lists the ports)"
        } else {
            "the port does not exist: check the cable and the name (Refresh lists the ports)"
        });
    }
    if e.kind == ErrorKind::ConnectionRefused || e.kind == ErrorKind::TimedOut {
        return Some(
            "nothing answers at that address: check the bridge's address and that it is on",
        );
    }
    None
}
