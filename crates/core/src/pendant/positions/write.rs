//! Writing the draft's changed rows: frames sized to the command buffer, one on the line
//! at a time, each row's outcome kept until the read-back says what the controller holds.

use std::collections::{BTreeMap, VecDeque};
use std::fmt;

use crate::protocol::{PositionRecord, PositionWrite, PositionWriteKind};

/// What became of one row of a write.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Outcome {
    /// Not sent yet.
    Waiting,
    /// In the frame on the line.
    Sending,
    /// The controller said it wrote it; the read-back has not come yet.
    Written,
    /// Read back: the controller holds exactly what was written.
    Holds,
    /// Read back: the controller holds something else (what differs).
    Differs(String),
    /// Never reached the controller (why): it holds what it held before.
    NotWritten(String),
    /// Sent, but no answer came (why): read back to know.
    Unknown(String),
}

impl Outcome {
    /// Whether the row's story is over (nothing more will come for it).
    pub fn is_final(&self) -> bool {
        matches!(
            self,
            Outcome::Holds | Outcome::Differs(_) | Outcome::NotWritten(_)
        )
    }
}

impl fmt::Display for Outcome {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Outcome::Waiting => f.write_str("waiting"),
            Outcome::Sending => f.write_str("sending"),
            Outcome::Written => f.write_str("written, reading back"),
            Outcome::Holds => f.write_str("the controller holds it"),
            Outcome::Differs(what) => write!(f, "read back different: {what}"),
            Outcome::NotWritten(why) => write!(f, "not written: {why}"),
            Outcome::Unknown(why) => write!(f, "unknown: {why}"),
        }
    }
}

/// Splits `records` (ascending numbers) into write commands of `kind` no longer than
/// `command_buffer` bytes: range writes (244H, 290H) one run of consecutive numbers per
/// frame, change writes (245H, 26DH, 291H) any numbers.
pub fn frames(
    kind: PositionWriteKind,
    records: &[PositionRecord],
    command_buffer: usize,
) -> Vec<PositionWrite> {
    let mut out: Vec<PositionWrite> = Vec::new();
    let mut current: Vec<PositionRecord> = Vec::new();
    let max = usize::from(kind.max_number());
    for rec in records {
        let breaks_run = kind.is_range()
            && current
                .last()
                .is_some_and(|last| u32::from(last.number) + 1 != u32::from(rec.number));
        let too_long = !current.is_empty()
            && (kind.frame_len(current.iter().chain(std::iter::once(rec))) > command_buffer
                || current.len() >= max);
        if breaks_run || too_long {
            out.push(PositionWrite {
                kind,
                records: std::mem::take(&mut current),
            });
        }
        current.push(*rec);
    }
    if !current.is_empty() {
        out.push(PositionWrite {
            kind,
            records: current,
        });
    }
    out
}

/// One write of the draft's changed rows.
#[derive(Clone, Debug, PartialEq)]
pub struct WriteJob {
    pub kind: PositionWriteKind,
    /// Frames not sent yet, in order.
    queued: VecDeque<PositionWrite>,
    /// The frame on the line.
    pub sent: Option<PositionWrite>,
    /// Every row's outcome, by number.
    pub outcomes: BTreeMap<u16, Outcome>,
    /// What was written, by number (to compare with the read-back).
    pub written: BTreeMap<u16, PositionRecord>,
    /// The read-back has been asked for.
    pub read_back: bool,
}

impl WriteJob {
    pub fn new(kind: PositionWriteKind, records: &[PositionRecord], command_buffer: usize) -> Self {
        WriteJob {
            kind,
            queued: frames(kind, records, command_buffer).into(),
            sent: None,
            outcomes: records
                .iter()
                .map(|r| (r.number, Outcome::Waiting))
                .collect(),
            written: records.iter().map(|r| (r.number, *r)).collect(),
            read_back: false,
        }
    }

    /// Frames in the whole write (sent, on the line and queued).
    pub fn frames_left(&self) -> usize {
        self.queued.len() + usize::from(self.sent.is_some())
    }

    /// The next frame to send, if none is on the line.
    pub fn next_frame(&mut self) -> Option<PositionWrite> {
        if self.sent.is_some() {
            return None;
        }
        let frame = self.queued.pop_front()?;
        for r in &frame.records {
            self.outcomes.insert(r.number, Outcome::Sending);
        }
        self.sent = Some(frame.clone());
        Some(frame)
    }

    /// Whether `w` is the frame on the line.
    pub fn is_sent(&self, w: &PositionWrite) -> bool {
        self.sent.as_ref() == Some(w)
    }

    /// The frame on the line ended: its rows get `on_line`; with `stop` the frames still
    /// queued are never sent (their rows get `NotWritten(why)`).
    pub fn frame_ended(&mut self, on_line: Outcome, stop: Option<String>) {
        if let Some(frame) = self.sent.take() {
            for r in &frame.records {
                self.outcomes.insert(r.number, on_line.clone());
            }
        }
        if let Some(why) = stop {
            for frame in self.queued.drain(..) {
                for r in &frame.records {
                    self.outcomes
                        .insert(r.number, Outcome::NotWritten(why.clone()));
                }
            }
        }
    }

    /// The controller answered the frame on the line having written `count` records:
    /// the first `count` are written, any others not (a short count).
    pub fn frame_written(&mut self, count: u16) {
        let Some(frame) = self.sent.take() else {
            return;
        };
        for (i, r) in frame.records.iter().enumerate() {
            let outcome = if i < usize::from(count) {
                Outcome::Written
            } else {
                Outcome::NotWritten(format!(
                    "the controller wrote {count} of the frame's {} records",
                    frame.records.len()
                ))
            };
            self.outcomes.insert(r.number, outcome);
        }
    }

    /// Nothing on the line and nothing queued.
    pub fn is_sent_out(&self) -> bool {
        self.sent.is_none() && self.queued.is_empty()
    }

    /// Numbers to read back: every row the controller may have changed.
    pub fn to_read_back(&self) -> Vec<u16> {
        self.outcomes
            .iter()
            .filter(|(_, o)| matches!(o, Outcome::Written | Outcome::Unknown(_)))
            .map(|(n, _)| *n)
            .collect()
    }

    /// Counts of rows that the controller holds, that differ, that were not written and
    /// whose fate is unknown.
    pub fn tally(&self) -> Tally {
        let mut t = Tally::default();
        for o in self.outcomes.values() {
            match o {
                Outcome::Holds => t.holds += 1,
                Outcome::Differs(_) => t.differs += 1,
                Outcome::NotWritten(_) => t.not_written += 1,
                Outcome::Unknown(_) => t.unknown += 1,
                _ => t.pending += 1,
            }
        }
        t
    }
}

/// A write's rows by outcome.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Tally {
    pub holds: usize,
    pub differs: usize,
    pub not_written: usize,
    pub unknown: usize,
    pub pending: usize,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::protocol::{Axis, Milli, PerAxis};

    fn rec(n: u16) -> PositionRecord {
        PositionRecord {
            number: n,
            coords: PerAxis::from_pairs(
                [Axis::A1, Axis::A2, Axis::A3, Axis::A4].map(|a| (a, Milli(1))),
            ),
            ..PositionRecord::default()
        }
    }

    #[test]
    fn range_frames_break_at_gaps_and_at_the_command_buffer() {
        let recs: Vec<_> = (1..=100).chain([200, 201]).map(rec).collect();
        let f = frames(PositionWriteKind::Range3, &recs, 2051);
        // 42 four-axis records fit one 290H frame (PROTOCOL.md 3.24).
        let sizes: Vec<usize> = f.iter().map(|w| w.records.len()).collect();
        assert_eq!(sizes, vec![42, 42, 16, 2]);
        for w in &f {
            assert!(w.kind.frame_len(w.records.iter()) <= 2051);
        }
        let f = frames(PositionWriteKind::Change3, &recs, 2051);
        let sizes: Vec<usize> = f.iter().map(|w| w.records.len()).collect();
        assert_eq!(sizes, vec![39, 39, 24]);
    }

    #[test]
    fn an_error_half_way_says_which_rows_were_written() {
        let recs: Vec<_> = (1..=100).map(rec).collect();
        let mut job = WriteJob::new(PositionWriteKind::Range3, &recs, 2051);
        let first = job.next_frame().unwrap();
        assert!(
            job.next_frame().is_none(),
            "one frame on the line at a time"
        );
        assert_eq!(first.records.len(), 42);
        job.frame_written(42);
        job.next_frame().unwrap();
        job.frame_ended(
            Outcome::NotWritten("the controller answered & B0A".into()),
            Some("an earlier frame was refused".into()),
        );
        assert!(job.is_sent_out());
        assert_eq!(job.outcomes[&1], Outcome::Written);
        assert_eq!(job.outcomes[&42], Outcome::Written);
        assert!(matches!(job.outcomes[&43], Outcome::NotWritten(ref w) if w.contains("B0A")));
        assert!(matches!(job.outcomes[&100], Outcome::NotWritten(ref w) if w.contains("earlier")));
        assert_eq!(job.to_read_back(), (1..=42).collect::<Vec<_>>());
    }

    #[test]
    fn a_short_count_marks_the_rest_of_the_frame_not_written() {
        let recs: Vec<_> = (1..=3).map(rec).collect();
        let mut job = WriteJob::new(PositionWriteKind::Change3, &recs, 2051);
        job.next_frame();
        job.frame_written(2);
        assert_eq!(job.outcomes[&2], Outcome::Written);
        assert!(matches!(job.outcomes[&3], Outcome::NotWritten(_)));
    }
}
