//! The first-contact report, sans-IO: a read-only run of queries that settle what
//! PROTOCOL.md could only infer, one on the line at a time, every byte kept with its time.
//!
//! [`FirstContact`] is driven like the link's core: [`poll_transmit`](FirstContact::poll_transmit)
//! hands out the next command's bytes, [`handle_input`](FirstContact::handle_input) takes
//! what arrived, [`poll_timeout`](FirstContact::poll_timeout) /
//! [`handle_timeout`](FirstContact::handle_timeout) end a wait. Nothing it sends moves an
//! axis or writes the controller's data: every question is a query (checked by a test).

pub mod command_line;
mod probes;
mod report;
mod run;
#[cfg(test)]
mod tests;

use std::time::{Duration, Instant};

use crate::protocol::{ErrorCode, Header, OwnedFrame, Reply, Station, StreamDecoder};

pub use probes::{Ask, QUESTIONS, Question};
pub use report::{ReportHeader, render, summary_text};
pub use run::{Progress, RunError, file_name, report_on, run_on, write_new};

/// How long a reply may take to begin, beyond the wire time of the longest reply
/// `[inferred]`: the spec's time-out section was not retrieved (PROTOCOL.md 5 row 20);
/// the link's own reply time-out is shorter, but a first contact should rather wait.
pub const REPLY_WAIT: Duration = Duration::from_secs(1);
/// The pause between a reply and the next command (PROTOCOL.md's client rule 2 asks
/// for at least 1 ms `[inferred]`; 20 ms leaves a slow controller room).
pub const GAP: Duration = Duration::from_millis(20);
/// After a wait ended without a reply, this long more is listened to before the next
/// command, so a late reply is kept with its own question and not taken for the next.
pub const QUIET: Duration = Duration::from_millis(300);
/// At most this many bytes kept per exchange (a flood is counted, not kept).
pub const KEEP_BYTES: usize = 8 * 1024;
/// When the controller has not answered this many status queries, the run ends: nothing
/// else can be learned on this line.
const SILENT_STATUS_LIMIT: usize = 3;

/// What one question got in the end.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Answer {
    /// A `#` reply from the station asked.
    Reply(OwnedFrame),
    /// An `&` error reply.
    Refused(ErrorCode),
    /// Nothing usable within the wait (what did arrive is in the exchange's log).
    Silent,
    /// Not sent: the run ended first (why).
    NotAsked(String),
}

/// Something that arrived while a question was out (or in the quiet after it).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Received {
    /// Since the run began.
    pub at: Duration,
    /// The bytes (a frame, or a run of bytes that are not one).
    pub bytes: Vec<u8>,
    /// What the pendant makes of them.
    pub kind: ReceivedKind,
}

/// How the bytes received were read.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum ReceivedKind {
    /// A valid frame answering the question.
    Answer,
    /// Our own command coming back (a line that echoes what it is sent).
    Echo,
    /// A valid frame that does not answer it (another station, another message ID).
    Other(String),
    /// Arrived after the wait had ended.
    Late,
    /// Not a valid frame (why).
    Bad(String),
}

/// One question as asked and answered.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Exchange {
    /// Index into [`QUESTIONS`].
    pub question: usize,
    /// The bytes sent (empty when not asked).
    pub sent: Vec<u8>,
    /// When the bytes were handed to the line, since the run began.
    pub sent_at: Duration,
    /// Everything received for it, in order.
    pub received: Vec<Received>,
    /// Bytes received beyond [`KEEP_BYTES`] (counted, not kept).
    pub dropped: usize,
    pub answer: Answer,
}

impl Exchange {
    /// How long after sending the first byte of the answer arrived.
    pub fn delay(&self) -> Option<Duration> {
        self.received
            .iter()
            .find(|r| r.kind == ReceivedKind::Answer)
            .map(|r| r.at.saturating_sub(self.sent_at))
    }

    /// The question asked.
    pub fn question(&self) -> &'static Question {
        &QUESTIONS[self.question]
    }
}

/// Where the run is.
#[derive(Clone, Debug)]
enum State {
    /// Next question may go at this time.
    Ready(Instant),
    /// A question is out; its wait ends at this time.
    Waiting(Instant),
    /// The wait ended without a reply; listening until this time.
    Quiet(Instant),
    Done,
}

/// A first-contact run on one line.
pub struct FirstContact {
    station: Station,
    /// How long the longest reply (a 2048-byte buffer) takes on this line.
    reply_wire: Duration,
    start: Instant,
    next: usize,
    state: State,
    decoder: StreamDecoder,
    exchanges: Vec<Exchange>,
    silent_status: usize,
}

impl FirstContact {
    /// A run for `station`, whose line carries a byte in `byte_time`, starting at `now`.
    pub fn new(station: Station, byte_time: Duration, now: Instant) -> Self {
        FirstContact {
            station,
            reply_wire: byte_time * crate::protocol::REPLY_BUFFER as u32,
            start: now,
            next: 0,
            state: State::Ready(now),
            decoder: StreamDecoder::new(),
            exchanges: Vec::new(),
            silent_status: 0,
        }
    }

    /// The bytes of the next question, when one is due at `now`.
    pub fn poll_transmit(&mut self, now: Instant) -> Option<Vec<u8>> {
        let State::Ready(at) = self.state else {
            return None;
        };
        if now < at {
            return None;
        }
        let Some(question) = QUESTIONS.get(self.next) else {
            self.state = State::Done;
            return None;
        };
        let sent = question.ask.bytes(self.station);
        self.exchanges.push(Exchange {
            question: self.next,
            sent: sent.clone(),
            sent_at: now - self.start,
            received: Vec::new(),
            dropped: 0,
            answer: Answer::Silent,
        });
        self.next += 1;
        self.state = State::Waiting(now + REPLY_WAIT + self.reply_wire);
        Some(sent)
    }

    /// Takes bytes that arrived at `now`.
    pub fn handle_input(&mut self, now: Instant, bytes: &[u8]) {
        self.decoder.push(bytes);
        while let Some(item) = self.decoder.pull() {
            let at = now - self.start;
            match item {
                Ok(frame) => self.frame(now, at, frame),
                Err(e) => self.keep(at, e.raw().to_vec(), ReceivedKind::Bad(e.to_string())),
            }
        }
    }

    /// When [`handle_timeout`](Self::handle_timeout) is next due (or a question may go).
    pub fn poll_timeout(&self) -> Option<Instant> {
        match self.state {
            State::Ready(at) | State::Waiting(at) | State::Quiet(at) => Some(at),
            State::Done => None,
        }
    }

    /// Ends a wait or a quiet time that is over at `now`.
    pub fn handle_timeout(&mut self, now: Instant) {
        match self.state {
            State::Waiting(at) if now >= at => {
                // Bytes still held (a reply cut short) are kept as they are.
                let rest = self.decoder.take_pending();
                if !rest.is_empty() {
                    let kind = ReceivedKind::Bad("no line end before the wait ended".into());
                    self.keep(now - self.start, rest, kind);
                }
                self.state = State::Quiet(now + QUIET);
                if self.last().is_some_and(|e| e.question().is_status()) {
                    self.silent_status += 1;
                }
            }
            State::Quiet(at) if now >= at => {
                self.state = State::Ready(now);
                if self.silent_status >= SILENT_STATUS_LIMIT && !self.answered_any() {
                    self.end("the controller answered none of the first status queries");
                }
            }
            _ => {}
        }
    }

    /// Ends the run now (cancelled, or the line failed): what was not asked says why.
    pub fn end(&mut self, why: &str) {
        if let State::Waiting(_) = self.state
            && let Some(last) = self.exchanges.last_mut()
            && last.answer == Answer::Silent
            && last.received.is_empty()
        {
            last.answer = Answer::NotAsked(format!("{why} (before any reply)"));
        }
        while self.next < QUESTIONS.len() {
            self.exchanges.push(Exchange {
                question: self.next,
                sent: Vec::new(),
                sent_at: Duration::ZERO,
                received: Vec::new(),
                dropped: 0,
                answer: Answer::NotAsked(why.to_string()),
            });
            self.next += 1;
        }
        self.state = State::Done;
    }

    /// Whether every question has been asked and answered (or not).
    pub fn is_done(&self) -> bool {
        matches!(self.state, State::Done)
    }

    /// Questions asked so far, and how many there are.
    pub fn progress(&self) -> (usize, usize) {
        (self.exchanges.len(), QUESTIONS.len())
    }

    /// Every exchange so far, in order.
    pub fn exchanges(&self) -> &[Exchange] {
        &self.exchanges
    }

    fn answered_any(&self) -> bool {
        self.exchanges
            .iter()
            .any(|e| matches!(e.answer, Answer::Reply(_) | Answer::Refused(_)))
    }

    fn last(&self) -> Option<&Exchange> {
        self.exchanges.last()
    }

    /// A valid frame arrived: an answer ends the wait; an echo or a stranger is kept.
    fn frame(&mut self, now: Instant, at: Duration, frame: OwnedFrame) {
        let waiting = matches!(self.state, State::Waiting(_));
        let Some(last) = self.exchanges.last() else {
            return self.keep(at, frame.raw().to_vec(), ReceivedKind::Late);
        };
        let raw = frame.raw().to_vec();
        let parsed = &frame;
        let kind = if !waiting {
            ReceivedKind::Late
        } else if raw == last.sent {
            ReceivedKind::Echo
        } else if parsed.station() != self.station {
            ReceivedKind::Other(format!("from station {}", parsed.station()))
        } else {
            match parsed.header() {
                Header::Command => ReceivedKind::Other("a command, not a reply".into()),
                Header::Error => ReceivedKind::Answer,
                Header::Reply => {
                    let asked = last.question().ask.id();
                    if parsed.id() == Some(asked) {
                        ReceivedKind::Answer
                    } else {
                        ReceivedKind::Other(format!(
                            "a reply to {}, not to {asked}",
                            parsed.id().map_or("?".into(), |id| id.to_string())
                        ))
                    }
                }
            }
        };
        let answer = (kind == ReceivedKind::Answer).then(|| match parsed.header() {
            Header::Error => Answer::Refused(match Reply::decode(parsed) {
                Ok(Reply::Error(code)) => code,
                _ => ErrorCode::NONE,
            }),
            _ => Answer::Reply(frame.clone()),
        });
        self.keep(at, raw, kind);
        if let Some(answer) = answer
            && let Some(last) = self.exchanges.last_mut()
        {
            last.answer = answer;
            self.silent_status = 0;
            self.state = State::Ready(now + GAP);
        }
    }

    /// Keeps received bytes with the current exchange, within [`KEEP_BYTES`].
    fn keep(&mut self, at: Duration, bytes: Vec<u8>, kind: ReceivedKind) {
        let Some(last) = self.exchanges.last_mut() else {
            return;
        };
        let kept: usize = last.received.iter().map(|r| r.bytes.len()).sum();
        if kept + bytes.len() > KEEP_BYTES {
            last.dropped += bytes.len();
            return;
        }
        let kind = match (&self.state, kind) {
            (State::Quiet(_), ReceivedKind::Bad(_) | ReceivedKind::Other(_)) => ReceivedKind::Late,
            (_, kind) => kind,
        };
        last.received.push(Received { at, bytes, kind });
    }
}
