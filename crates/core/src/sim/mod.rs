//! The simulated X-SEL SCARA controller: a Format B slave built on protocol and robot.
//!
//! - [`Controller`]: sans-IO, a frame and the time in, the reply (or silence) out.
//! - [`start_embedded`]: the simulator on its own thread behind an in-memory pipe.
//! - [`runner::start_pty`] / [`runner::start_tcp`]: serving a pseudo-terminal or TCP port.
//! - [`errors::CODE_TABLE`]: the error codes of `&` replies.
//! - [`console`]: operator states (E-stop, mode, cut-off, alarms) from outside the protocol.
//! - [`signals`]: inputs, outputs, flags and variables (PROTOCOL.md 3.34-3.43).
//! - [`programs`]: SEL programs run by an interpreter of a subset (PROTOCOL.md 3.44-3.45).
//! - [`rmc`]: a simulated Delta RMC151E axis controller over Modbus/TCP.

pub mod console;
mod control;
pub mod controller;
pub mod errors;
pub mod faults;
pub mod framing;
mod handlers;
pub mod log_limit;
pub mod motion;
pub mod panel;
pub mod pipe;
pub mod programs;
pub mod rmc;
pub mod runner;
mod servers;
pub mod signals;
pub mod state;

#[cfg(test)]
mod rules_tests;

use crate::protocol::{Frame, Reply};

pub use controller::{Controller, SimSetup, Snapshot};
pub use errors::{CODE_TABLE, SimError};
pub use faults::{Fault, FaultCounts, FaultSpec};
pub use handlers::{MAX_POSITIONS_3_DIGIT, MAX_POSITIONS_4_DIGIT};
pub use runner::{EmbeddedOptions, SimHandle, SimWatch, start_embedded};
pub use signals::Signals;
pub use state::{Counters, Mode, SimConfig};

/// A short decoded summary of a frame for logs: the protocol describer's title, the
/// first problem it finds, and the simulator's text for an error code.
pub fn describe_frame(frame: &[u8]) -> String {
    let d = crate::protocol::describe(frame);
    let mut s = d.title;
    if let Some(Reply::Error(code)) = Frame::parse(frame)
        .ok()
        .and_then(|f| Reply::decode(&f).ok())
    {
        let code = code.0;
        s.push_str(&format!(" — {:03X}: {}", code, errors::describe_code(code)));
    }
    if let Some(p) = d.problems.first() {
        s.push_str(&format!(" [{}]", p.message));
    }
    s
}
