//! What a guardian core shows the guardian's loop: the window's bytes, heartbeats and
//! end in, the line's bytes in, frames for the line and messages for the window out.
//! Format B's rules (`core`) and the RMC151's (`rmc_core`) have this one face.

use std::time::Instant;

use super::core::GuardianCore;
use super::wire::FromGuardian;

/// How the window let go of its pipe.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum WindowGone {
    /// It said it lets go of the line (its link closed it: a reconnect, a disconnect, a
    /// stalled link dropped, an orderly exit), then closed the pipe: its process may run on.
    LetGo,
    /// The pipe closed or failed without a word: the window's process ended (a crash, a
    /// kill, an exit that skipped closing its links).
    Ended,
}

impl WindowGone {
    /// What happened, for the log.
    pub fn describe(self) -> &'static str {
        match self {
            WindowGone::LetGo => "the window let go of the line (its link closed it)",
            WindowGone::Ended => {
                "the window's pipe closed without a word: its process ended (crash, kill or exit)"
            }
        }
    }
}

/// A message for the window and whether it may be dropped when the window does not read
/// (line bytes nobody waits for) or must be kept (an answer the window's link waits for,
/// the guardian's own news).
#[derive(Debug, Clone, PartialEq)]
pub struct ToWindow {
    pub message: FromGuardian,
    pub droppable: bool,
}

pub trait Guard {
    /// The window's process is alive.
    fn handle_heartbeat(&mut self, now: Instant);
    /// Bytes the window's link writes to the line.
    fn handle_window_bytes(&mut self, now: Instant, bytes: &[u8]);
    /// The window's pipe closed: its process is gone.
    fn handle_window_closed(&mut self, now: Instant);
    /// The window's pipe closed, and how; a STOP is owed at once if motion may run.
    fn handle_window_gone(&mut self, now: Instant, _gone: WindowGone) {
        self.handle_window_closed(now);
    }
    /// Bytes the line delivered.
    fn handle_line_bytes(&mut self, bytes: &[u8]);
    fn handle_timeout(&mut self, now: Instant);
    /// The next bytes for the line.
    fn poll_transmit(&mut self, now: Instant) -> Option<Vec<u8>>;
    fn poll_to_window(&mut self) -> Option<FromGuardian>;
    /// The next message for the window, marked droppable or not (by default line bytes
    /// may be dropped, the guardian's own messages not).
    fn poll_for_window(&mut self) -> Option<ToWindow> {
        self.poll_to_window().map(|message| ToWindow {
            droppable: matches!(message, FromGuardian::Bytes(_)),
            message,
        })
    }
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
        GuardianCore::handle_window_gone(self, now, WindowGone::Ended);
    }
    fn handle_window_gone(&mut self, now: Instant, gone: WindowGone) {
        GuardianCore::handle_window_gone(self, now, gone);
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
        GuardianCore::poll_for_window(self).map(|m| m.message)
    }
    fn poll_for_window(&mut self) -> Option<ToWindow> {
        GuardianCore::poll_for_window(self)
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
