//! What a guardian core shows the guardian's loop: the window's bytes, heartbeats and
//! end in, the line's bytes in, frames for the line and messages for the window out.
//! Format B's rules (`core`) and the RMC151's (`rmc_core`) have this one face.

use std::time::Instant;

use super::core::GuardianCore;
use super::wire::FromGuardian;

pub trait Guard {
    /// The window's process is alive.
    fn handle_heartbeat(&mut self, now: Instant);
    /// Bytes the window's link writes to the line.
    fn handle_window_bytes(&mut self, now: Instant, bytes: &[u8]);
    /// The window's pipe closed: its process is gone.
    fn handle_window_closed(&mut self, now: Instant);
    /// Bytes the line delivered.
    fn handle_line_bytes(&mut self, bytes: &[u8]);
    fn handle_timeout(&mut self, now: Instant);
    /// The next bytes for the line.
    fn poll_transmit(&mut self, now: Instant) -> Option<Vec<u8>>;
    fn poll_to_window(&mut self) -> Option<FromGuardian>;
    fn poll_log(&mut self) -> Option<String>;
    fn poll_timeout(&self) -> Option<Instant>;
    /// The window is gone and nothing more is owed: the guardian may exit.
    fn is_done(&self) -> bool;
}

impl Guard for GuardianCore {
    fn handle_heartbeat(&mut self, now: Instant) {
        GuardianCore::handle_heartbeat(self, now);
    }
    fn handle_window_bytes(&mut self, now: Instant, bytes: &[u8]) {
        GuardianCore::handle_window_bytes(self, now, bytes);
    }
    fn handle_window_closed(&mut self, now: Instant) {
        GuardianCore::handle_window_closed(self, now);
    }
    fn handle_line_bytes(&mut self, bytes: &[u8]) {
        GuardianCore::handle_line_bytes(self, bytes);
    }
    fn handle_timeout(&mut self, now: Instant) {
        GuardianCore::handle_timeout(self, now);
    }
    fn poll_transmit(&mut self, now: Instant) -> Option<Vec<u8>> {
        GuardianCore::poll_transmit(self, now)
    }
    fn poll_to_window(&mut self) -> Option<FromGuardian> {
        GuardianCore::poll_to_window(self)
    }
    fn poll_log(&mut self) -> Option<String> {
        GuardianCore::poll_log(self)
    }
    fn poll_timeout(&self) -> Option<Instant> {
        GuardianCore::poll_timeout(self)
    }
    fn is_done(&self) -> bool {
        GuardianCore::is_done(self)
    }
}
