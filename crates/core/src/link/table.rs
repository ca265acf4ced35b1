//! Reading a whole work or tool coordinate table with 2A4H, in chunks that fit the
//! controller's reply buffer, with retries and a list of what could not be read.

use std::ops::Range;

use crate::protocol::{AxisPattern, Command, CoordKind, CoordQuery2, CoordTable2, Milli, PerAxis};

/// What to download.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TableRequest {
    pub kind: CoordKind,
    /// `0F`, `F0` or `FF` (PROTOCOL.md 3.16).
    pub axes: AxisPattern,
    /// The first definition number to read (0 for a whole table; a retry of the records
    /// a read missed starts where they start).
    pub first: u16,
    /// Number of definitions to read from `first` (32 work / 128 tool for a whole table;
    /// `first + records` at most 256).
    pub records: u16,
    /// The controller's reply buffer in bytes: 2048, or 1024 on J/K/KE/KT/KET/JX/KX/KTX
    /// and TT (PROTOCOL.md 1.7).
    pub reply_buffer: usize,
}

impl TableRequest {
    /// Records one reply can carry.
    pub fn records_per_chunk(&self) -> u16 {
        let fit = CoordTable2::records_fitting(self.axes, self.reply_buffer);
        fit.clamp(1, 255) as u16
    }
}

/// The state of one download.
#[derive(Debug)]
pub struct TableJob {
    pub request: TableRequest,
    /// Tells this download's chunks from those of one it replaced.
    pub generation: u32,
    next_first: u16,
    /// Records `request.first ..`, `None` where not (yet) read.
    pub records: Vec<Option<PerAxis<Milli>>>,
    pub answered_axes: AxisPattern,
}

impl TableJob {
    pub fn new(request: TableRequest, generation: u32) -> Self {
        let first = request.first.min(255);
        let total = request.records.min(256 - first);
        Self {
            generation,
            request: TableRequest {
                first,
                records: total,
                ..request
            },
            next_first: first,
            records: vec![None; usize::from(total)],
            answered_axes: AxisPattern::NONE,
        }
    }

    /// The next chunk's query, if any remain.
    pub fn next_query(&mut self) -> Option<Command> {
        let end = self.end();
        if self.next_first >= end {
            return None;
        }
        let first = self.next_first;
        let count = self.request.records_per_chunk().min(end - first);
        self.next_first += count;
        Some(Command::CoordQuery2(CoordQuery2 {
            axes: self.request.axes,
            kind: self.request.kind,
            first: first as u8,
            count: count as u8,
        }))
    }

    /// Stores a chunk's records; returns how many landed.
    pub fn accept(&mut self, axes: AxisPattern, first: u8, records: &[PerAxis<Milli>]) -> usize {
        self.answered_axes = axes;
        let mut stored = 0;
        let Some(offset) = usize::from(first).checked_sub(usize::from(self.request.first)) else {
            return 0;
        };
        for (i, rec) in records.iter().enumerate() {
            if let Some(slot) = self.records.get_mut(offset + i) {
                *slot = Some(*rec);
                stored += 1;
            }
        }
        stored
    }

    /// One past the last definition number asked for.
    fn end(&self) -> u16 {
        self.request.first + self.request.records
    }

    /// The record ranges (definition numbers) not (yet) read: chunks that failed after
    /// their retries, came back short, or were never asked for because the download
    /// ended early.
    pub fn missing(&self) -> Vec<Range<u16>> {
        let mut holes: Vec<Range<u16>> = Vec::new();
        for (i, rec) in self.records.iter().enumerate() {
            let i = self.request.first + i as u16;
            if rec.is_none() {
                match holes.last_mut() {
                    Some(h) if h.end == i => h.end = i + 1,
                    _ => holes.push(i..i + 1),
                }
            }
        }
        holes
    }

    pub fn received(&self) -> u16 {
        self.records.iter().filter(|r| r.is_some()).count() as u16
    }

    pub fn is_finished(&self) -> bool {
        self.next_first >= self.end()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn request(axes: u8, records: u16, buffer: usize) -> TableRequest {
        TableRequest {
            kind: CoordKind::Tool,
            axes: AxisPattern(axes),
            first: 0,
            records,
            reply_buffer: buffer,
        }
    }

    #[test]
    fn chunks_fit_the_reply_buffer_as_protocol_section_1_7_counts() {
        assert_eq!(request(0x0F, 128, 2048).records_per_chunk(), 63);
        assert_eq!(request(0x0F, 128, 1024).records_per_chunk(), 31);
        assert_eq!(request(0xFF, 128, 2048).records_per_chunk(), 31);
        assert_eq!(request(0xFF, 128, 1024).records_per_chunk(), 15);
    }

    #[test]
    fn a_tool_table_of_128_takes_three_chunks_and_reports_gaps() {
        let mut job = TableJob::new(request(0x0F, 128, 2048), 1);
        let mut queries = Vec::new();
        while let Some(Command::CoordQuery2(q)) = job.next_query() {
            queries.push((q.first, q.count));
        }
        assert_eq!(queries, [(0, 63), (63, 63), (126, 2)]);
        let rec = PerAxis::new();
        assert_eq!(job.accept(AxisPattern(0x0F), 0, &vec![rec; 63]), 63);
        // The second chunk came back two records short; the third failed.
        assert_eq!(job.accept(AxisPattern(0x0F), 63, &vec![rec; 61]), 61);
        assert_eq!(job.received(), 124);
        assert_eq!(job.missing(), vec![124..128]);
        assert!(job.is_finished());
    }

    #[test]
    fn a_retry_reads_only_the_records_asked_for() {
        let mut job = TableJob::new(
            TableRequest {
                first: 124,
                records: 4,
                ..request(0x0F, 0, 2048)
            },
            2,
        );
        let Some(Command::CoordQuery2(q)) = job.next_query() else {
            panic!("no query")
        };
        assert_eq!((q.first, q.count), (124, 4));
        assert!(job.next_query().is_none());
        assert_eq!(job.missing(), vec![124..128]);
        assert_eq!(job.accept(AxisPattern(0x0F), 124, &[PerAxis::new(); 3]), 3);
        assert_eq!(job.missing(), vec![127..128]);
        // A stray chunk from before the range lands nowhere.
        assert_eq!(job.accept(AxisPattern(0x0F), 0, &[PerAxis::new(); 2]), 0);
    }
}
