//! The connection the operator chose (persisted) and the state of the line (live).

use std::fmt;
use std::time::Instant;

use serde::{Deserialize, Serialize};

use crate::link::{LineSettings, Parity};
use crate::protocol::Station;

/// Where the controller is.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum LineKind {
    /// The built-in simulated controller.
    #[default]
    Simulator,
    /// A serial port (RS-232C or USB adapter).
    Serial,
    /// A serial-to-Ethernet bridge, or `xsel-sim --tcp`.
    Tcp,
}

impl LineKind {
    pub fn name(self) -> &'static str {
        match self {
            LineKind::Simulator => "Built-in simulator",
            LineKind::Serial => "Serial port",
            LineKind::Tcp => "TCP bridge",
        }
    }
}

/// The line the operator chose, persisted between runs.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(default)]
pub struct ConnectionSettings {
    pub kind: LineKind,
    /// Serial port name, e.g. `/dev/ttyUSB0` or `COM3`.
    pub port: String,
    /// `HOST:PORT` of a TCP bridge.
    pub tcp: String,
    pub baud: u32,
    pub data_bits: u8,
    pub parity: Parity,
    pub stop_bits: u8,
    /// Station number (2 hex digits on the wire).
    pub station: u8,
    /// Robot model for checks and the simulator: a built-in name or a TOML file.
    pub robot: String,
    /// Send `@@` instead of computed checksums (a debug setting; the controller accepts
    /// both [spec: PROTOCOL.md 1.4]). Applies when the line is next opened.
    pub send_at_at: bool,
}

impl Default for ConnectionSettings {
    fn default() -> Self {
        let line = LineSettings::default();
        Self {
            kind: LineKind::Simulator,
            port: String::new(),
            tcp: "127.0.0.1:5099".into(),
            baud: line.baud,
            data_bits: line.data_bits,
            parity: line.parity,
            stop_bits: line.stop_bits,
            station: Station::DEFAULT.0,
            robot: "scara-500".into(),
            send_at_at: false,
        }
    }
}

impl ConnectionSettings {
    pub fn line(&self) -> LineSettings {
        LineSettings {
            baud: self.baud,
            data_bits: self.data_bits,
            parity: self.parity,
            stop_bits: self.stop_bits,
        }
    }

    pub fn station(&self) -> Station {
        Station(self.station)
    }

    /// What the settings name, for the top bar: "built-in simulator", "/dev/ttyUSB0"...
    pub fn target(&self) -> String {
        match self.kind {
            LineKind::Simulator => "built-in simulator".into(),
            LineKind::Serial => self.port.clone(),
            LineKind::Tcp => self.tcp.clone(),
        }
    }
}

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
    {
        return Some(
            "the port does not exist: check the cable and the name (Refresh lists the ports)",
        );
    }
    if e.kind == ErrorKind::ConnectionRefused || e.kind == ErrorKind::TimedOut {
        return Some(
            "nothing answers at that address: check the bridge's address and that it is on",
        );
    }
    None
}
