//! The controller's alarm history (216H types 3 and 5, PROTOCOL.md 3.47 with 3.5) read
//! record by record on connect and on demand, and each alarm seen arriving live (215H)
//! stamped with its time and the frame log row it came in.

#[cfg(test)]
mod tests;

use std::collections::VecDeque;
use std::fmt::Write as _;
use std::time::{Instant, SystemTime};

use crate::link::LinkEvent;
use crate::pendant::Level;
use crate::protocol::{Command, ErrorCode, ErrorDetail, ErrorDetailQuery, Reply};

/// The highest record of a type 3 list: its record number is 2 hex digits `[spec p.32]`.
pub const MAX_TYPE_3: u16 = 0xFF;
/// The highest record of a type 5 list: 3 hex digits `[spec p.32]`.
pub const MAX_TYPE_5: u16 = 0xFFF;
/// Records in a row without a valid reply before a read gives up (a dead line must not
/// take 255 time-outs).
pub const MAX_FAILURES: u8 = 3;
/// Live alarms kept at most (the oldest go first).
pub const MAX_LIVE: usize = 1_000;

/// Which form of the error list the controller answers (PROTOCOL.md 3.47).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ListKind {
    /// Type 3: every model, records 1-255.
    #[default]
    Type3,
    /// Type 5: X-SEL R/S/RX/SX/RXD/SXD and TTA, records 1-4095.
    Type5,
}

impl ListKind {
    /// The query for record `n`.
    pub fn query(self, n: u16) -> ErrorDetailQuery {
        match self {
            ListKind::Type3 => ErrorDetailQuery::ListRecord {
                record: n.min(MAX_TYPE_3) as u8,
            },
            ListKind::Type5 => ErrorDetailQuery::ExtendedListRecord { record: n },
        }
    }

    /// The last record it can name.
    pub const fn bound(self) -> u16 {
        match self {
            ListKind::Type3 => MAX_TYPE_3,
            ListKind::Type5 => MAX_TYPE_5,
        }
    }

    fn record_of(query: &ErrorDetailQuery) -> Option<u16> {
        match *query {
            ErrorDetailQuery::ListRecord { record } => Some(u16::from(record)),
            ErrorDetailQuery::ExtendedListRecord { record } => Some(record),
            _ => None,
        }
    }
}

/// One record of the history: what the controller said, or why it could not be read.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct AlarmRecord {
    /// Record number, from 1 (newest first, the simulator's order `[inferred]`).
    pub record: u16,
    pub detail: Result<ErrorDetail, String>,
}

impl AlarmRecord {
    /// The code's words from the pendant's one table.
    pub fn text(&self) -> String {
        match &self.detail {
            Ok(d) => d.error.describe(),
            Err(why) => why.clone(),
        }
    }
}

/// An alarm seen arriving in a 215H poll.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct LiveAlarm {
    pub code: ErrorCode,
    pub at: Instant,
    pub wall: SystemTime,
    /// The frame log row of the reply that brought it (`FrameLog::row`).
    pub row: u64,
}

/// What the operator asked of the Alarms view.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AlarmsIntent {
    /// Read the history again from record 1.
    Read,
    Cancel,
    Kind(ListKind),
}

/// Why a read runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Cause {
    Connected,
    Asked,
    NewAlarm,
}

#[derive(Clone, Copy, Debug)]
struct Reading {
    next: u16,
    failures: u8,
    cause: Cause,
}

/// The history as last read, the read going on, and the alarms seen live.
#[derive(Debug, Default)]
pub struct Alarms {
    pub kind: ListKind,
    records: Vec<AlarmRecord>,
    reading: Option<Reading>,
    /// How the last read ended, for the view.
    pub outcome: Option<(Level, String)>,
    live: VecDeque<LiveAlarm>,
    commands: Vec<Command>,
    revision: u64,
}

impl Alarms {
    pub fn records(&self) -> &[AlarmRecord] {
        &self.records
    }

    pub fn live(&self) -> &VecDeque<LiveAlarm> {
        &self.live
    }

    /// The record being read, when a read runs.
    pub fn reading(&self) -> Option<u16> {
        self.reading.map(|r| r.next)
    }

    /// Changes whenever the records or the live alarms change.
    pub fn revision(&self) -> u64 {
        self.revision
    }

    /// Queries for the link, each in the line time the polls leave.
    pub fn take_commands(&mut self) -> Vec<Command> {
        std::mem::take(&mut self.commands)
    }

    /// Whether this model sent `command`.
    pub fn owns(command: &Command) -> bool {
        matches!(command, Command::ErrorDetail(q) if ListKind::record_of(q).is_some())
    }

    /// Applies one intent; the words for the operator come back.
    pub fn apply(&mut self, intent: AlarmsIntent, line_up: bool) -> Option<(Level, String)> {
        match intent {
            AlarmsIntent::Read if !line_up => {
                let said = (
                    Level::Warning,
                    "alarm history not read: the line is down".to_owned(),
                );
                self.outcome = Some(said.clone());
                Some(said)
            }
            AlarmsIntent::Read => {
                self.start(Cause::Asked);
                None
            }
            AlarmsIntent::Cancel => self.reading.take().map(|r| {
                let said = (
                    Level::Info,
                    format!("alarm history read cancelled at record {}", r.next),
                );
                self.outcome = Some(said.clone());
                said
            }),
            AlarmsIntent::Kind(kind) => {
                self.kind = kind;
                None
            }
        }
    }

    /// The line came up: the history is read.
    pub fn connected(&mut self) {
        self.start(Cause::Connected);
    }

    /// The line went down: a read in progress ends where it was.
    pub fn line_gone(&mut self) {
        if let Some(r) = self.reading.take() {
            self.outcome = Some((
                Level::Warning,
                format!(
                    "alarm history read stopped at record {}: the line went down",
                    r.next
                ),
            ));
        }
    }

    /// A 215H poll brought alarm `code` (was none or another): stamped with its time and
    /// frame log row, and the history read again so it holds it.
    pub fn alarm_arrived(&mut self, code: ErrorCode, at: Instant, wall: SystemTime, row: u64) {
        if self.live.len() == MAX_LIVE {
            self.live.pop_front();
        }
        self.live.push_back(LiveAlarm {
            code,
            at,
            wall,
            row,
        });
        self.revision += 1;
        if self.reading.is_none() {
            self.start(Cause::NewAlarm);
        }
    }

    fn start(&mut self, cause: Cause) {
        self.reading = Some(Reading {
            next: 1,
            failures: 0,
            cause,
        });
        self.records.clear();
        self.revision += 1;
        self.outcome = Some((Level::Info, "reading the alarm history...".to_owned()));
        self.ask(1);
    }

    fn ask(&mut self, n: u16) {
        self.commands.push(Command::ErrorDetail(self.kind.query(n)));
    }

    /// Ends the read with `said` (for Messages when the operator asked or it went wrong).
    fn finish(&mut self, level: Level, text: String) -> Option<(Level, String)> {
        let cause = self.reading.take()?.cause;
        self.outcome = Some((level, text.clone()));
        (cause == Cause::Asked || level != Level::Info).then_some((level, text))
    }

    /// The next record, or the end at the bound.
    fn next(&mut self, failed: bool) -> Option<(Level, String)> {
        let r = self.reading.as_mut()?;
        r.failures = if failed { r.failures + 1 } else { 0 };
        if r.failures >= MAX_FAILURES {
            let n = r.next;
            return self.finish(
                Level::Warning,
                format!(
                    "alarm history read stopped at record {n}: {MAX_FAILURES} records in a row without a valid reply ({} read)",
                    self.count()
                ),
            );
        }
        if r.next >= self.kind.bound() {
            let bound = self.kind.bound();
            return self.finish(
                Level::Warning,
                format!("alarm history: {bound} records read, the most this list type can name; older ones are not read"),
            );
        }
        r.next += 1;
        let n = r.next;
        self.ask(n);
        None
    }

    fn count(&self) -> usize {
        self.records.iter().filter(|r| r.detail.is_ok()).count()
    }

    /// Applies an event answering one of this model's queries.
    pub fn handle_event(&mut self, event: &LinkEvent) -> Option<(Level, String)> {
        let (command, n) = match event {
            LinkEvent::Reply { command, .. }
            | LinkEvent::ErrorReply { command, .. }
            | LinkEvent::Timeout { command, .. }
            | LinkEvent::Interrupted { command, .. }
            | LinkEvent::NotSent { command, .. } => match command {
                Command::ErrorDetail(q) => (command, ListKind::record_of(q)?),
                _ => return None,
            },
            _ => return None,
        };
        let _ = command;
        // An answer to a read that was cancelled or begun again is not this read's.
        if self.reading.is_none_or(|r| r.next != n) {
            return None;
        }
        match event {
            LinkEvent::Reply {
                reply: Reply::ErrorDetail(d),
                ..
            } if d.error == ErrorCode::NONE => {
                let count = self.count();
                self.finish(Level::Info, format!("alarm history: {count} record(s)"))
            }
            LinkEvent::Reply {
                reply: Reply::ErrorDetail(d),
                ..
            } => {
                self.records.push(AlarmRecord {
                    record: n,
                    detail: Ok(d.clone()),
                });
                self.revision += 1;
                self.next(false)
            }
            LinkEvent::ErrorReply { code, .. } => {
                let count = self.count();
                let text = if n == 1 {
                    format!(
                        "the controller refused to read its error list (error {code}): try the other list type"
                    )
                } else {
                    format!(
                        "alarm history: {count} record(s); record {n} was refused (error {code}), taken as the end"
                    )
                };
                let level = if n == 1 { Level::Warning } else { Level::Info };
                self.finish(level, text)
            }
            LinkEvent::Timeout { retrying: true, .. } => None,
            LinkEvent::Timeout { .. } | LinkEvent::Interrupted { .. } => {
                self.records.push(AlarmRecord {
                    record: n,
                    detail: Err("no valid reply (the frame log shows what came)".to_owned()),
                });
                self.revision += 1;
                self.next(true)
            }
            LinkEvent::NotSent { reason, .. } => self.finish(
                Level::Warning,
                format!("alarm history read stopped at record {n}: not sent: {reason}"),
            ),
            _ => None,
        }
    }
}

/// The history as CSV: record, code, text, program, step, axis, point, details 5-8 (hex,
/// unnamed on the pages), message.
pub fn to_csv(records: &[AlarmRecord]) -> String {
    use crate::files::csv_style::{BOM, EOL, field};
    let mut s = format!(
        "{BOM}record,code,text,program,step,axis,point,detail5,detail6,detail7,detail8,message{EOL}"
    );
    for r in records {
        let _ = match &r.detail {
            Ok(d) => write!(
                s,
                "{},{:03X},{},{},{},{},{},{:08X},{:08X},{:08X},{:08X},{}{EOL}",
                r.record,
                d.error.0,
                field(&d.error.describe()),
                d.details[0],
                d.details[1],
                d.details[2],
                d.details[3] as i32,
                d.details[4],
                d.details[5],
                d.details[6],
                d.details[7],
                field(&d.message_text()),
            ),
            Err(why) => write!(s, "{},,{},,,,,,,,,{EOL}", r.record, field(why)),
        };
    }
    s
}
