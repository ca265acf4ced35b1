//! The guardian's rules as a sans-IO state machine (quinn-proto's shape, time passed in):
//! it relays the window's frames to the line and the line's bytes back, keeps track of
//! whether motion may run, and owes a 238H STOP when the window closes or falls silent
//! for longer than the lease while it may. The line's bytes are split with the protocol's
//! deframer, and the Format B safety component decides which frame answers the command on
//! the line: its STOP waits for the transaction in flight (one outstanding command,
//! PROTOCOL.md 1.5), holds the window's next frames back until it is answered, and is
//! answered only by a `#` 238 or an `&` of its station. Every buffer is bounded: line bytes
//! for a window that does not read them are dropped and counted, never its answers.

use std::collections::VecDeque;
use std::time::{Duration, Instant};

use super::guard::{ToWindow, WindowGone};
use super::wire::FromGuardian;
use crate::link::format_b::safety::{Answer, Kind, Safety, classify};
use crate::link::timing::Timing;
use crate::protocol::{Frame, MAX_FRAME_LEN, Station, StreamDecoder};

/// Tries of the guardian's own STOP when it gets no reply or a refusal ([inferred] 238H
/// is harmless to repeat: it stops what is already stopped).
const STOP_TRIES: u8 = 2;
/// Line bytes nobody waits for that the core holds for the window at most (the loop
/// takes them after every event, so only a loop that falls behind reaches it).
pub const WINDOW_BYTES_MAX: usize = 64 * 1024;
/// Line bytes gathered into one message for the window at most.
const CHUNK: usize = 4096;
/// The window's frames held back at most (its link sends one command at a time).
const HELD_MAX: usize = 16;
/// Log lines kept between two polls at most.
const LOG_MAX: usize = 256;

/// Whose command is on the line.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Sender {
    Window,
    /// The guardian's 238H.
    Guardian,
    /// The guardian's 254H `00`, ending every program between its two 238H.
    GuardianPrograms,
}

/// What the guardian knows and owes.
#[derive(Debug)]
pub struct GuardianCore {
    lease: Duration,
    /// One outstanding command, motion may run, the STOP owed, the reply deadline.
    safety: Safety<Sender>,
    /// The window's bytes not yet ending in CR LF (its frames are relayed whole).
    window_partial: Vec<u8>,
    /// The line's bytes, split into frames and noise.
    decoder: StreamDecoder,
    /// Frames from the window for the line (held while a command or a STOP is out).
    held: VecDeque<Vec<u8>>,
    to_window: VecDeque<ToWindow>,
    /// Droppable line bytes in `to_window`.
    window_bytes: usize,
    /// Line bytes the window did not get because it did not read them in time.
    dropped_for_window: u64,
    /// Bytes dropped since the window last got some (0: it keeps up).
    dropping: u64,
    log: VecDeque<String>,
    /// How many times the owed STOP went out.
    stop_tries: u8,
    /// The guardian's STOP is owed or on the line: the window's motion is not sent.
    stopping: bool,
    /// After the guardian's 238H, a 254H `00` is owed: a program may run.
    programs_owed: bool,
    /// This STOP's 254H went out already (one per STOP, whatever its answer).
    programs_tried: bool,
    last_heard: Instant,
    /// This silence already cost a STOP (one per silence).
    silence_stopped: bool,
    window_closed: bool,
}

impl GuardianCore {
    pub fn new(now: Instant, station: Station, lease: Duration, timing: Timing) -> Self {
        Self {
            lease,
            safety: Safety::new(station, timing),
            window_partial: Vec::new(),
            decoder: StreamDecoder::new(),
            held: VecDeque::new(),
            to_window: VecDeque::new(),
            window_bytes: 0,
            dropped_for_window: 0,
            dropping: 0,
            log: VecDeque::new(),
            stop_tries: 0,
            stopping: false,
            programs_owed: false,
            programs_tried: false,
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
            self.window_frame(frame);
        }
        // Bytes that never end a frame are still the window's to send (the line judges).
        if self.window_partial.len() > MAX_FRAME_LEN {
            let rest = std::mem::take(&mut self.window_partial);
            self.window_frame(rest);
        }
    }

    /// The window's end of the pipe closed (exit, crash or kill; see [`WindowGone`]).
    pub fn handle_window_closed(&mut self, now: Instant) {
        self.handle_window_gone(now, WindowGone::Ended);
    }

    /// The window's end of the pipe closed, and how: a STOP is owed at once if motion may
    /// run (sent as soon as the transaction on the line has ended).
    pub fn handle_window_gone(&mut self, _now: Instant, gone: WindowGone) {
        if self.window_closed {
            return;
        }
        self.window_closed = true;
        self.held.clear();
        if self.safety.motion_may_run() {
            self.owe_stop(&format!("{} while motion may run", gone.describe()));
        } else {
            self.say(&format!("{}, with no motion running", gone.describe()));
        }
    }

    /// Bytes from the line.
    pub fn handle_line_bytes(&mut self, bytes: &[u8]) {
        self.decoder.push(bytes);
        while let Some(item) = self.decoder.pull() {
            match item {
                Ok(frame) => self.line_frame(&frame),
                // Noise, a damaged or cut frame: it answers nothing.
                Err(e) => self.relay(e.raw(), true),
            }
        }
    }

    /// Deadlines: a reply that did not come, the guardian's STOP unanswered, the window's
    /// silence while motion may run.
    pub fn handle_timeout(&mut self, now: Instant) {
        if let Some(done) = self.safety.timed_out(now) {
            match done.tag {
                Sender::Guardian => self.own_stop_failed(
                    "no reply to the guardian's 238H",
                    "238H sent again after no reply",
                ),
                Sender::GuardianPrograms => {
                    self.programs_answered("no reply to the guardian's 254H 00")
                }
                Sender::Window => {}
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
        if !self.safety.is_free() {
            return None; // its reply first: one outstanding command
        }
        if self.safety.stop_owed().is_some() && !self.safety.motion_may_run() {
            // The window's own 238H for all axes was answered meanwhile.
            if let Some(why) = self.safety.forgive_stop() {
                self.say(&format!(
                    "no 238H needed after all ({why}): the window's own 238H was answered"
                ));
            }
            self.stopping = false;
        }
        // Bytes before the guardian's 238H cannot be its answer.
        if self.safety.stop_owed().is_some() {
            let before = self.decoder.take_pending();
            self.relay(&before, true);
        }
        if let Some((frame, why)) = self.safety.take_owed_stop(now, Sender::Guardian) {
            self.stop_tries += 1;
            self.push_to_window(FromGuardian::Stopped(why));
            return Some(frame);
        }
        if self.programs_owed
            && let Some(frame) = self.safety.take_program_end(now, Sender::GuardianPrograms)
        {
            self.programs_owed = false;
            self.programs_tried = true;
            self.say("a program may run: sending 254H 00 (end every program), then 238H again");
            return Some(frame);
        }
        let frame = self.held.pop_front()?;
        self.safety.sent_bytes(now, &frame, Sender::Window);
        Some(frame)
    }

    /// The next message for the window.
    pub fn poll_to_window(&mut self) -> Option<FromGuardian> {
        self.poll_for_window().map(|m| m.message)
    }

    /// The next message for the window, and whether it may be dropped if the window does
    /// not read it (line bytes no command of the window waits for).
    pub fn poll_for_window(&mut self) -> Option<ToWindow> {
        let next = self.to_window.pop_front()?;
        if next.droppable
            && let FromGuardian::Bytes(b) = &next.message
        {
            self.window_bytes -= b.len().min(self.window_bytes);
        }
        Some(next)
    }

    /// The next line for the guardian's log (stderr).
    pub fn poll_log(&mut self) -> Option<String> {
        self.log.pop_front()
    }

    /// When [`GuardianCore::handle_timeout`] wants to run next.
    pub fn poll_timeout(&self) -> Option<Instant> {
        [self.safety.deadline(), self.silence_deadline()]
            .into_iter()
            .flatten()
            .min()
    }

    /// The window is gone and no STOP is owed or waiting for its reply: the guardian may
    /// close the line and exit.
    pub fn is_done(&self) -> bool {
        self.window_closed && self.safety.stop_owed().is_none() && !self.own_stop_out()
    }

    /// Whether a motion command went out with no 238H for all axes answered since.
    pub fn motion_may_run(&self) -> bool {
        self.safety.motion_may_run()
    }

    /// Line bytes the window did not get because it did not read them in time.
    pub fn dropped_for_window(&self) -> u64 {
        self.dropped_for_window
    }

    /// Every byte the core holds (its buffers and queues): bounded whatever the line sends.
    pub fn buffered(&self) -> usize {
        let messages: usize = self
            .to_window
            .iter()
            .map(|m| match &m.message {
                FromGuardian::Bytes(b) => b.len(),
                FromGuardian::Stopped(s) | FromGuardian::Failed(s) => s.len(),
                FromGuardian::Opened { line, .. } => line.len(),
            })
            .sum();
        self.window_partial.len()
            + self.decoder.pending()
            + self.held.iter().map(Vec::len).sum::<usize>()
            + messages
            + self.log.iter().map(String::len).sum::<usize>()
    }

    fn heard(&mut self, now: Instant) {
        self.last_heard = now;
        self.silence_stopped = false;
    }

    fn silence_deadline(&self) -> Option<Instant> {
        (self.safety.motion_may_run() && !self.silence_stopped && !self.window_closed)
            .then(|| self.last_heard + self.lease)
    }

    fn own_stop_out(&self) -> bool {
        self.programs_owed
            || self
                .safety
                .in_flight()
                .is_some_and(|f| f.tag != Sender::Window)
    }

    fn say(&mut self, text: &str) {
        if self.log.len() < LOG_MAX {
            self.log.push_back(text.to_owned());
        }
    }

    fn push_to_window(&mut self, message: FromGuardian) {
        self.to_window.push_back(ToWindow {
            message,
            droppable: false,
        });
    }

    fn owe_stop(&mut self, why: &str) {
        self.say(&format!("{why}: sending 238H"));
        self.safety.owe_stop(why);
        self.stop_tries = 0;
        self.programs_tried = false;
        self.stopping = true;
        let before = self.held.len();
        self.held.retain(|f| classify(f).kind != Kind::Motion);
        let refused = before - self.held.len();
        if refused > 0 {
            self.say(&format!(
                "{refused} motion frame(s) of the window held back: not sent (STOP came first)"
            ));
        }
    }

    /// A frame from the window for the line: held until the line is free. Motion that
    /// reaches the guardian while its STOP is owed or out is not sent (STOP came first;
    /// the window's link times it out and re-reads the status).
    fn window_frame(&mut self, frame: Vec<u8>) {
        if self.stopping && classify(&frame).kind == Kind::Motion {
            self.say(&format!(
                "the window's {} came while the guardian's 238H was owed: not sent (STOP came first)",
                frame.trim_ascii_end().escape_ascii()
            ));
            return;
        }
        if self.held.len() >= HELD_MAX {
            self.say(&format!(
                "the window sent more than {HELD_MAX} frames ahead: {} not sent",
                frame.trim_ascii_end().escape_ascii()
            ));
            return;
        }
        self.held.push_back(frame);
    }

    /// A whole frame from the line: the answer of the command on the line, or not.
    fn line_frame(&mut self, frame: &Frame<'_>) {
        match self.safety.frame(frame) {
            Ok((done, answer)) => match done.tag {
                Sender::Guardian => self.own_stop_answered(answer),
                Sender::GuardianPrograms => self.programs_answered(&match answer {
                    Answer::Reply => "254H 00 answered: every program ended".to_owned(),
                    Answer::Error(code) => format!(
                        "the controller refused 254H 00 (error {})",
                        code.map_or_else(|| "unreadable".to_owned(), |c| c.to_string())
                    ),
                }),
                // The window's link waits for it: never dropped.
                Sender::Window => self.relay(frame.raw(), false),
            },
            // A late reply, an echo, another station: the window's link reports it.
            Err(_) => self.relay(frame.raw(), true),
        }
    }

    fn own_stop_answered(&mut self, answer: Answer) {
        match answer {
            Answer::Reply => {
                self.say("238H answered: the controller stopped");
                self.end_programs_or_rest();
            }
            Answer::Error(code) => {
                let code = code.map_or_else(|| "unreadable".to_owned(), |c| c.to_string());
                self.own_stop_failed(
                    &format!("the controller refused the guardian's 238H (error {code})"),
                    "238H sent again after a refusal",
                );
            }
        }
    }

    /// The guardian's 238H is done: while a program may run, 254H `00` follows (once per
    /// STOP), then a second 238H halts a move the program commanded in between (README:
    /// "STOP ends programs"); otherwise the guardian's stop is over.
    fn end_programs_or_rest(&mut self) {
        if self.safety.program_may_run() && !self.programs_tried {
            self.programs_owed = true;
        } else {
            self.stopping = false;
        }
    }

    /// The guardian's 254H `00` was answered, refused or timed out: the second 238H.
    fn programs_answered(&mut self, what: &str) {
        self.say(&format!("{what}: sending 238H again"));
        // The program may have commanded a move after the first 238H.
        self.safety.assume_motion();
        self.safety.owe_stop("after ending the programs");
        self.stop_tries = 0;
    }

    /// The guardian's STOP failed: sent once more, or given up on (the window hears it).
    fn own_stop_failed(&mut self, what: &str, again: &str) {
        if self.stop_tries < STOP_TRIES {
            self.say(&format!("{what}: sending it again"));
            self.safety.owe_stop(again);
        } else {
            self.say(&format!("{what}: motion may still run"));
            self.end_programs_or_rest();
            self.push_to_window(FromGuardian::Stopped(format!(
                "{what}: motion may still run"
            )));
        }
    }

    /// Line bytes for the window. Bytes no command of the window waits for are dropped
    /// and counted when the window does not read them; none go to a closed window, nor
    /// while the guardian's own STOP is out (the window's held frames are not on the line).
    fn relay(&mut self, bytes: &[u8], droppable: bool) {
        if bytes.is_empty() || self.window_closed || self.own_stop_out() {
            return;
        }
        if !droppable {
            self.push_to_window(FromGuardian::Bytes(bytes.to_vec()));
            return;
        }
        if self.window_bytes + bytes.len() > WINDOW_BYTES_MAX {
            if self.dropping == 0 {
                self.say("the window does not read the line's bytes: dropping them");
            }
            self.dropping += bytes.len() as u64;
            self.dropped_for_window += bytes.len() as u64;
            return;
        }
        if self.dropping > 0 {
            let dropped = std::mem::take(&mut self.dropping);
            self.say(&format!(
                "the window reads again: {dropped} line bytes were dropped for it"
            ));
        }
        self.window_bytes += bytes.len();
        if let Some(last) = self.to_window.back_mut()
            && last.droppable
            && let FromGuardian::Bytes(b) = &mut last.message
            && b.len() + bytes.len() <= CHUNK
        {
            b.extend_from_slice(bytes);
            return;
        }
        self.to_window.push_back(ToWindow {
            message: FromGuardian::Bytes(bytes.to_vec()),
            droppable: true,
        });
    }
}

/// The length of the first frame in `bytes` (up to and including LF after CR).
fn frame_end(bytes: &[u8]) -> Option<usize> {
    bytes.windows(2).position(|w| w == b"\r\n").map(|i| i + 2)
}

#[cfg(test)]
#[path = "core_tests.rs"]
mod tests;
