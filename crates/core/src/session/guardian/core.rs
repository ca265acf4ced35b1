//! The guardian's rules as a sans-IO state machine (quinn-proto's shape, time passed in):
//! it relays the window's frames to the line and the line's bytes back, keeps track of
//! whether motion may run, and owes a 238H STOP when the window closes or falls silent
//! for longer than the lease while it may. Its STOP waits for the transaction in flight
//! (one outstanding command, PROTOCOL.md 1.5) and holds the window's next frames back
//! until it is answered.

use std::collections::VecDeque;
use std::time::{Duration, Instant};

use super::wire::FromGuardian;
use crate::link::timing::Timing;
use crate::protocol::{AxisPattern, Command, Frame, Header, MAX_FRAME_LEN, ScMode, Station, Stop};

/// Tries of the guardian's own STOP when it gets no reply ([inferred] 238H is harmless
/// to repeat: it stops what is already stopped).
const STOP_TRIES: u8 = 2;

/// What the guardian knows and owes.
#[derive(Debug)]
pub struct GuardianCore {
    station: Station,
    lease: Duration,
    timing: Timing,
    /// The window's bytes not yet ending in CR LF (frames are checked whole).
    window_partial: Vec<u8>,
    /// The line's bytes not yet ending in CR LF (a reply ends a transaction).
    line_partial: Vec<u8>,
    /// Frames from the window for the line (held while the guardian's STOP is out).
    to_line: VecDeque<Vec<u8>>,
    to_window: VecDeque<FromGuardian>,
    log: VecDeque<String>,
    /// A window frame is on the line and its reply may still come until then.
    window_outstanding: Option<Instant>,
    /// The window's last frame on the line was a 238H for all axes.
    window_stop_out: bool,
    /// The guardian's own 238H is on the line, answered by then at the latest.
    own_stop: Option<Instant>,
    /// How many times the owed STOP went out.
    stop_tries: u8,
    /// A STOP the guardian must send as soon as the line is free, and why.
    stop_owed: Option<String>,
    /// A motion command went out and no 238H for all axes was answered since.
    motion_may_run: bool,
    last_heard: Instant,
    /// This silence already cost a STOP (one per silence).
    silence_stopped: bool,
    window_closed: bool,
}

impl GuardianCore {
    pub fn new(now: Instant, station: Station, lease: Duration, timing: Timing) -> Self {
        Self {
            station,
            lease,
            timing,
            window_partial: Vec::new(),
            line_partial: Vec::new(),
            to_line: VecDeque::new(),
            to_window: VecDeque::new(),
            log: VecDeque::new(),
            window_outstanding: None,
            window_stop_out: false,
            own_stop: None,
            stop_tries: 0,
            stop_owed: None,
            motion_may_run: false,
            last_heard: now,
            silence_stopped: false,
            window_closed: false,
        }
    }

    /// A heartbeat from the window: its process runs.
    pub fn handle_heartbeat(&mut self, now: Instant) {
        self.heard(now);
    }

    /// Bytes the window's link writes to the line.
    pub fn handle_window_bytes(&mut self, now: Instant, bytes: &[u8]) {
        self.heard(now);
        if self.window_closed {
            return;
        }
        self.window_partial.extend_from_slice(bytes);
        while let Some(end) = frame_end(&self.window_partial) {
            let frame: Vec<u8> = self.window_partial.drain(..end).collect();
            self.to_line.push_back(frame);
        }
        // Bytes that never end a frame are still the window's to send (the line judges).
        if self.window_partial.len() > MAX_FRAME_LEN {
            let rest = std::mem::take(&mut self.window_partial);
            self.to_line.push_back(rest);
        }
    }

    /// The window's end of the pipe closed: its process exited, crashed or was killed.
    pub fn handle_window_closed(&mut self, _now: Instant) {
        if self.window_closed {
            return;
        }
        self.window_closed = true;
        self.to_line.clear();
        if self.motion_may_run {
            self.owe_stop("the window closed (exit, crash or kill) while motion may run");
        } else {
            self.say("the window closed with no motion running");
        }
    }

    /// Bytes from the line.
    pub fn handle_line_bytes(&mut self, bytes: &[u8]) {
        if self.own_stop.is_none() && !self.window_closed {
            self.to_window
                .push_back(FromGuardian::Bytes(bytes.to_vec()));
        }
        self.line_partial.extend_from_slice(bytes);
        while let Some(end) = frame_end(&self.line_partial) {
            let frame: Vec<u8> = self.line_partial.drain(..end).collect();
            self.reply_seen(&frame);
        }
        if self.line_partial.len() > MAX_FRAME_LEN {
            self.line_partial.clear();
        }
    }

    /// Deadlines: a reply that did not come, the guardian's STOP unanswered, the window's
    /// silence while motion may run.
    pub fn handle_timeout(&mut self, now: Instant) {
        if self.window_outstanding.is_some_and(|d| now >= d) {
            self.window_outstanding = None;
            self.window_stop_out = false;
        }
        if self.own_stop.is_some_and(|d| now >= d) {
            self.own_stop = None;
            if self.stop_tries < STOP_TRIES {
                self.say("no reply to the guardian's 238H: sending it again");
                self.stop_owed = Some("238H sent again after no reply".into());
            } else {
                self.say("no reply to the guardian's 238H: motion may still run");
                self.to_window.push_back(FromGuardian::Stopped(
                    "the guardian's 238H STOP got no reply".into(),
                ));
            }
        }
        if let Some(silent_until) = self.silence_deadline()
            && now >= silent_until
        {
            self.silence_stopped = true;
            let silent = now.saturating_duration_since(self.last_heard).as_millis();
            self.owe_stop(&format!(
                "the window was silent for {silent} ms while motion may run (frozen or stopped process)"
            ));
        }
    }

    /// The next bytes to write to the line.
    pub fn poll_transmit(&mut self, now: Instant) -> Option<Vec<u8>> {
        if self.own_stop.is_some() {
            return None;
        }
        if self.stop_owed.is_some() {
            if self.window_outstanding.is_some() {
                return None; // its reply first: one outstanding command
            }
            return Some(self.send_own_stop(now));
        }
        let frame = self.to_line.pop_front()?;
        self.forwarded(now, &frame);
        Some(frame)
    }

    /// The next message for the window.
    pub fn poll_to_window(&mut self) -> Option<FromGuardian> {
        self.to_window.pop_front()
    }

    /// The next line for the guardian's log (stderr).
    pub fn poll_log(&mut self) -> Option<String> {
        self.log.pop_front()
    }

    /// When [`GuardianCore::handle_timeout`] wants to run next.
    pub fn poll_timeout(&self) -> Option<Instant> {
        [
            self.window_outstanding,
            self.own_stop,
            self.silence_deadline(),
        ]
        .into_iter()
        .flatten()
        .min()
    }

    /// The window is gone and no STOP is owed or waiting for its reply: the guardian may
    /// close the line and exit.
    pub fn is_done(&self) -> bool {
        self.window_closed && self.stop_owed.is_none() && self.own_stop.is_none()
    }

    /// Whether a motion command went out with no 238H for all axes answered since.
    pub fn motion_may_run(&self) -> bool {
        self.motion_may_run
    }

    fn heard(&mut self, now: Instant) {
        self.last_heard = now;
        self.silence_stopped = false;
    }

    fn silence_deadline(&self) -> Option<Instant> {
        (self.motion_may_run && !self.silence_stopped && !self.window_closed)
            .then(|| self.last_heard + self.lease)
    }

    fn say(&mut self, text: &str) {
        self.log.push_back(text.to_owned());
    }

    fn owe_stop(&mut self, why: &str) {
        self.say(&format!("{why}: sending 238H"));
        self.stop_owed = Some(why.to_owned());
        self.stop_tries = 0;
    }

    fn send_own_stop(&mut self, now: Instant) -> Vec<u8> {
        self.stop_tries += 1;
        let command = Command::Stop(stop_all());
        let frame = command
            .to_bytes(self.station, ScMode::Computed)
            .unwrap_or_default();
        let wait = self
            .timing
            .reply_timeout(frame.len(), command.max_reply_len());
        self.own_stop = Some(now + wait);
        if let Some(why) = self.stop_owed.take() {
            self.to_window.push_back(FromGuardian::Stopped(why));
        }
        self.line_partial.clear();
        frame
    }

    /// A window frame went to the line: note what it may start or stop.
    fn forwarded(&mut self, now: Instant, frame: &[u8]) {
        let command = Frame::parse(frame)
            .ok()
            .filter(|f| f.header() == Header::Command)
            .map(|f| Command::decode(&f));
        let reply_len = match &command {
            Some(Ok(c)) => c.max_reply_len(),
            _ => MAX_FRAME_LEN,
        };
        self.window_outstanding = Some(now + self.timing.reply_timeout(frame.len(), reply_len));
        self.window_stop_out = false;
        match command {
            Some(Ok(Command::Stop(s))) => self.window_stop_out = s.axes == AxisPattern::ALL,
            Some(Ok(c)) if c.is_motion() => self.motion_may_run = true,
            Some(Ok(_)) => {}
            // [inferred] A command the codec cannot read may still move the arm on the
            // controller: assume it does.
            Some(Err(_)) | None => self.motion_may_run = true,
        }
    }

    /// A whole frame came from the line: it ends the transaction on the line.
    fn reply_seen(&mut self, frame: &[u8]) {
        let stop_answered = Frame::parse(frame).is_ok_and(|f| {
            f.header() == Header::Reply && f.id() == Some(Command::Stop(stop_all()).id())
        });
        if self.own_stop.take().is_some() {
            if stop_answered {
                self.motion_may_run = false;
                self.say("238H answered: the controller stopped");
            } else {
                let why = format!("the guardian's 238H was answered {}", frame.escape_ascii());
                self.say(&why);
                self.to_window.push_back(FromGuardian::Stopped(why));
            }
            return;
        }
        if self.window_outstanding.take().is_some() && self.window_stop_out && stop_answered {
            self.motion_may_run = false;
        }
        self.window_stop_out = false;
    }
}

fn stop_all() -> Stop {
    Stop {
        axes: AxisPattern::ALL,
        cancel_held_outputs: false,
    }
}

/// The length of the first frame in `bytes` (up to and including LF after CR).
fn frame_end(bytes: &[u8]) -> Option<usize> {
    bytes.windows(2).position(|w| w == b"\r\n").map(|i| i + 2)
}

#[cfg(test)]
#[path = "core_tests.rs"]
mod tests;
