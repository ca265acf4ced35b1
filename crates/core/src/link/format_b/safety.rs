//! The Format B rules a STOP rests on, in one place for the link core and the guardian:
//! one command outstanding with its reply deadline, which frame is its answer, whether
//! motion may run, and a STOP owed until the line is free for it (PROTOCOL.md 1.2, 2).

use std::time::Instant;

use crate::link::timing::Timing;
use crate::protocol::{
    AxisPattern, Command, ErrorCode, Frame, Header, MessageId, ProgramCall, Reply, ScMode, Station,
    Stop,
};

/// A STOP of every axis (238H, pattern `FF`).
pub fn stop_all() -> Stop {
    Stop {
        axes: AxisPattern::ALL,
        cancel_held_outputs: false,
    }
}

/// Whether `command` is a STOP of every axis: its `#` answer ends all motion.
pub fn is_stop_all(command: &Command) -> bool {
    matches!(command, Command::Stop(s) if s.axes == AxisPattern::ALL)
}

/// What a command on the line is to the rules.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// 238H for every axis: a `#` answer means nothing runs any more.
    StopAll,
    /// It may start motion (a move, a jog, servo, homing, a speed change).
    Motion,
    /// A query or a setting.
    Other,
}

impl Kind {
    /// The kind of a command the codec read.
    pub fn of(command: &Command) -> Kind {
        if is_stop_all(command) {
            Kind::StopAll
        } else if command.is_motion() {
            Kind::Motion
        } else {
            Kind::Other
        }
    }
}

/// How a frame ended the transaction on the line.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Answer {
    /// `#` with the command's message ID.
    Reply,
    /// `&`: the controller refused the command (its code, when readable).
    Error(Option<ErrorCode>),
}

/// What a whole frame from the line is to the command outstanding.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Verdict {
    /// It is the command's answer.
    Answers(Answer),
    /// Another station's frame.
    WrongStation(Station),
    /// A command frame (an echo of what was sent, or another host).
    Echo,
    /// A `#` reply to another message (a late reply).
    OtherReply(Option<MessageId>),
}

/// Whether `frame` answers a command of `station` whose `#` answer carries `expected`
/// (`None`: the command could not be read, so any `#` of the station answers it). An
/// `&` frame answers whatever is outstanding: it has no message ID, and only one command
/// is ever outstanding (PROTOCOL.md 2).
pub fn judge(frame: &Frame<'_>, station: Station, expected: Option<MessageId>) -> Verdict {
    if frame.station() != station {
        return Verdict::WrongStation(frame.station());
    }
    match frame.header() {
        Header::Command => Verdict::Echo,
        Header::Error => {
            let code = match Reply::decode(frame) {
                Ok(Reply::Error(code)) => Some(code),
                _ => None,
            };
            Verdict::Answers(Answer::Error(code))
        }
        Header::Reply if expected.is_none_or(|id| frame.id() == Some(id)) => {
            Verdict::Answers(Answer::Reply)
        }
        Header::Reply => Verdict::OtherReply(frame.id()),
    }
}

/// What the rules read in a frame a host sends.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Classified {
    /// The ID its `#` answer carries (`None`: unreadable, any `#` answers it).
    pub expected: Option<MessageId>,
    pub kind: Kind,
    /// Its longest answer, for the reply deadline.
    pub max_reply_len: usize,
    /// What it does to programs.
    pub programs: Programs,
}

/// What a command does to the controller's programs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Programs {
    /// A run, one step or resume (253H, 256H, 257H): a program may move the arm.
    Start,
    /// 254H with `00`: its `#` answer ends every program.
    EndAll,
    /// 215H: its `#` answer says whether a program runs.
    Status,
    /// Nothing.
    Untouched,
}

impl Programs {
    /// What `command` does to programs.
    pub fn of(command: &Command) -> Programs {
        match command {
            c if c.is_program_start() => Programs::Start,
            Command::Program(c) if *c == ProgramCall::END_ALL => Programs::EndAll,
            Command::SystemStatus => Programs::Status,
            _ => Programs::Untouched,
        }
    }
}

/// Reads the bytes a host sends as a command. Bytes the codec cannot read may still move
/// the arm on the controller and be answered at any length ([inferred]): motion, with
/// the longest reply.
pub fn classify(frame: &[u8]) -> Classified {
    let parsed = Frame::parse(frame)
        .ok()
        .filter(|f| f.header() == Header::Command);
    match parsed.as_ref().map(|f| (f.id(), Command::decode(f))) {
        Some((_, Ok(c))) => Classified {
            expected: Some(c.id()),
            kind: Kind::of(&c),
            max_reply_len: c.max_reply_len(),
            programs: Programs::of(&c),
        },
        // Unreadable: it may start anything, a program too.
        Some((id, Err(_))) => Classified {
            expected: id,
            kind: Kind::Motion,
            max_reply_len: crate::protocol::MAX_FRAME_LEN,
            programs: Programs::Start,
        },
        None => Classified {
            expected: None,
            kind: Kind::Motion,
            max_reply_len: crate::protocol::MAX_FRAME_LEN,
            programs: Programs::Start,
        },
    }
}

/// The command on the line, awaiting its answer.
#[derive(Debug, Clone)]
pub struct InFlight<T> {
    /// Whose it is (the caller's note).
    pub tag: T,
    /// The message ID its `#` answer carries (`None`: unreadable, any `#` answers it).
    pub expected: Option<MessageId>,
    pub kind: Kind,
    pub programs: Programs,
    pub sent_at: Instant,
    /// Its answer is complete by then, or it will not come.
    pub deadline: Instant,
}

/// One Format B line's safety state: at most one command outstanding, whether motion may
/// run, and the STOP owed. Sans-IO: time comes in, frames go out as bytes.
#[derive(Debug)]
pub struct Safety<T> {
    station: Station,
    timing: Timing,
    in_flight: Option<InFlight<T>>,
    motion_may_run: bool,
    /// A program was started (or 215H said one runs) and no `#` to 254H `00` came since.
    program_may_run: bool,
    /// A STOP of every axis owed as soon as the line is free, and why.
    stop_owed: Option<String>,
}

impl<T> Safety<T> {
    pub fn new(station: Station, timing: Timing) -> Self {
        Self {
            station,
            timing,
            in_flight: None,
            motion_may_run: false,
            program_may_run: false,
            stop_owed: None,
        }
    }

    pub fn station(&self) -> Station {
        self.station
    }

    /// The command on the line, if any.
    pub fn in_flight(&self) -> Option<&InFlight<T>> {
        self.in_flight.as_ref()
    }

    /// No command is outstanding: the next may go out.
    pub fn is_free(&self) -> bool {
        self.in_flight.is_none()
    }

    /// A motion command went out and no `#` answer to a STOP of every axis came since.
    pub fn motion_may_run(&self) -> bool {
        self.motion_may_run
    }

    /// A program may run: a run, step or resume went out (or 215H said a program runs)
    /// and no `#` answer to 254H `00` came since.
    pub fn program_may_run(&self) -> bool {
        self.program_may_run
    }

    /// Why a STOP is owed, if one is.
    pub fn stop_owed(&self) -> Option<&str> {
        self.stop_owed.as_deref()
    }

    /// When the outstanding command's answer can no longer come.
    pub fn deadline(&self) -> Option<Instant> {
        self.in_flight.as_ref().map(|f| f.deadline)
    }

    /// `frame` (any bytes) went on the line at `now`: it is outstanding until its answer
    /// or its deadline (see [`classify`]).
    pub fn sent_bytes(&mut self, now: Instant, frame: &[u8], tag: T) -> &InFlight<T> {
        let c = classify(frame);
        let wait = self.timing.reply_timeout(frame.len(), c.max_reply_len);
        self.start(now, c.expected, (c.kind, c.programs), wait, tag)
    }

    /// `command`, `frame_len` bytes of it, went on the line at `now`.
    pub fn sent_command(
        &mut self,
        now: Instant,
        command: &Command,
        frame_len: usize,
        tag: T,
    ) -> &InFlight<T> {
        let wait = self
            .timing
            .reply_timeout(frame_len, command.max_reply_len());
        let what = (Kind::of(command), Programs::of(command));
        self.start(now, Some(command.id()), what, wait, tag)
    }

    fn start(
        &mut self,
        now: Instant,
        expected: Option<MessageId>,
        (kind, programs): (Kind, Programs),
        wait: std::time::Duration,
        tag: T,
    ) -> &InFlight<T> {
        if kind == Kind::Motion {
            self.motion_may_run = true;
        }
        if programs == Programs::Start {
            self.program_may_run = true;
        }
        self.in_flight.insert(InFlight {
            tag,
            expected,
            kind,
            programs,
            sent_at: now,
            deadline: now.checked_add(wait).unwrap_or(now),
        })
    }

    /// A whole frame from the line. When it answers the outstanding command, the
    /// transaction ends and that command comes back with the answer (a `#` to a STOP of
    /// every axis ends all motion); otherwise what the frame is, and the wait goes on.
    pub fn frame(&mut self, frame: &Frame<'_>) -> Result<(InFlight<T>, Answer), Verdict> {
        let expected = match &self.in_flight {
            Some(f) => f.expected,
            // Nothing outstanding: no frame answers anything (a late reply).
            None => return Err(Verdict::OtherReply(frame.id())),
        };
        match judge(frame, self.station, expected) {
            Verdict::Answers(answer) => {
                let done = self.in_flight.take().ok_or(Verdict::OtherReply(None))?;
                if answer == Answer::Reply {
                    match (done.kind, done.programs) {
                        (Kind::StopAll, _) => self.motion_may_run = false,
                        (_, Programs::EndAll) => self.program_may_run = false,
                        (_, Programs::Status) => {
                            if let Ok(Reply::SystemStatus(s)) = Reply::decode(frame) {
                                self.program_may_run = s.status2.program_running();
                            }
                        }
                        _ => {}
                    }
                }
                Ok((done, answer))
            }
            other => Err(other),
        }
    }

    /// The outstanding command whose deadline has passed at `now` (the line is free).
    pub fn timed_out(&mut self, now: Instant) -> Option<InFlight<T>> {
        if self.in_flight.as_ref().is_some_and(|f| now >= f.deadline) {
            return self.in_flight.take();
        }
        None
    }

    /// The line was lost or reopened: nothing is outstanding on it any more.
    pub fn abandon(&mut self) -> Option<InFlight<T>> {
        self.in_flight.take()
    }

    /// Motion may run from now (a command counted elsewhere, a reopened line).
    pub fn assume_motion(&mut self) {
        self.motion_may_run = true;
    }

    /// A STOP of every axis is owed, for `why`, as soon as the line is free.
    pub fn owe_stop(&mut self, why: impl Into<String>) {
        self.stop_owed = Some(why.into());
    }

    /// The owed STOP is no longer wanted.
    pub fn forgive_stop(&mut self) -> Option<String> {
        self.stop_owed.take()
    }

    /// 254H `00`, ending every program, when the line is free for it (it is then the
    /// outstanding command, tagged `tag`).
    pub fn take_program_end(&mut self, now: Instant, tag: T) -> Option<Vec<u8>> {
        if self.in_flight.is_some() {
            return None;
        }
        let command = Command::Program(ProgramCall::END_ALL);
        let frame = command
            .to_bytes(self.station, ScMode::Computed)
            .unwrap_or_default();
        self.sent_command(now, &command, frame.len(), tag);
        Some(frame)
    }

    /// The owed STOP's frame and why, when the line is free for it (it is then the
    /// outstanding command, tagged `tag`); `None` while a command is on the line or
    /// nothing is owed.
    pub fn take_owed_stop(&mut self, now: Instant, tag: T) -> Option<(Vec<u8>, String)> {
        if self.in_flight.is_some() {
            return None;
        }
        let why = self.stop_owed.take()?;
        let command = Command::Stop(stop_all());
        let frame = command
            .to_bytes(self.station, ScMode::Computed)
            .unwrap_or_default();
        self.sent_command(now, &command, frame.len(), tag);
        Some((frame, why))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::protocol::checksum;
    use std::time::Duration;

    fn frame(text: &str) -> Vec<u8> {
        let sc = checksum(text.as_bytes());
        format!("{text}{sc:02X}\r\n").into_bytes()
    }

    fn parsed(bytes: &[u8]) -> Frame<'_> {
        Frame::parse(bytes).expect("a frame")
    }

    #[test]
    fn only_its_own_answer_or_an_error_ends_a_transaction() {
        let t0 = Instant::now();
        let mut s: Safety<u8> = Safety::new(Station::DEFAULT, Timing::default());
        let query = Command::SystemStatus
            .to_bytes(Station::DEFAULT, ScMode::Computed)
            .unwrap();
        s.sent_bytes(t0, &query, 1);
        assert!(!s.is_free());
        assert!(!s.motion_may_run(), "a query starts nothing");
        let late = frame("#99238");
        assert_eq!(
            s.frame(&parsed(&late)).unwrap_err(),
            Verdict::OtherReply(Some(MessageId(0x238)))
        );
        let other = frame("#98215000000000000000000000");
        assert!(matches!(
            s.frame(&parsed(&other)),
            Err(Verdict::WrongStation(_))
        ));
        assert_eq!(s.frame(&parsed(&query)).unwrap_err(), Verdict::Echo);
        assert!(!s.is_free());
        let refused = frame("&99C74");
        let (done, answer) = s.frame(&parsed(&refused)).unwrap();
        assert_eq!(done.tag, 1);
        assert!(matches!(answer, Answer::Error(Some(ErrorCode(0xC74)))));
        assert!(s.is_free());
    }

    #[test]
    fn a_stop_owed_waits_for_the_line_and_its_answer_ends_motion() {
        let t0 = Instant::now();
        let mut s: Safety<&str> = Safety::new(Station::DEFAULT, Timing::default());
        let jog = frame("!99236019901000A000A0005");
        s.sent_bytes(t0, &jog, "window");
        assert!(s.motion_may_run(), "unreadable or motion: may run");
        s.owe_stop("silence");
        assert_eq!(s.take_owed_stop(t0, "guardian"), None, "one outstanding");
        let deadline = s.deadline().unwrap();
        assert_eq!(
            s.timed_out(deadline - Duration::from_millis(1))
                .map(|f| f.tag),
            None
        );
        assert_eq!(s.timed_out(deadline).map(|f| f.tag), Some("window"));
        let (bytes, why) = s.take_owed_stop(t0, "guardian").unwrap();
        assert_eq!(why, "silence");
        assert_eq!(bytes, b"!99238FF001C\r\n".to_vec());
        // An error does not stop anything; a `#` 238 does.
        let (_, answer) = s.frame(&parsed(&frame("&99C74"))).unwrap();
        assert!(matches!(answer, Answer::Error(_)));
        assert!(s.motion_may_run());
        s.owe_stop("again");
        s.take_owed_stop(t0, "guardian").unwrap();
        let (done, answer) = s.frame(&parsed(&frame("#99238"))).unwrap();
        assert_eq!(
            (done.tag, done.kind, answer),
            ("guardian", Kind::StopAll, Answer::Reply)
        );
        assert!(!s.motion_may_run());
    }
}
