//! The line the operator names and the window saves: where the controller is (the
//! built-in simulator, a serial port, a TCP bridge), the line settings, the station and
//! the robot model. Plain data, read by the pendant (which saves it) and the session
//! (which opens it).

use serde::{Deserialize, Serialize};

use super::{LineSettings, Parity};

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
            // The usual station, PROTOCOL.md 1.3.
            station: 0x99,
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

    /// What the settings name, for the top bar: "built-in simulator", "/dev/ttyUSB0"...
    pub fn target(&self) -> String {
        match self.kind {
            LineKind::Simulator => "built-in simulator".into(),
            LineKind::Serial => self.port.clone(),
            LineKind::Tcp => self.tcp.clone(),
        }
    }
}
