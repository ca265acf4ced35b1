//! The coordinate-table editor's model: drafts of the work and tool tables, the reading
//! of the controller's tables with 2A4H (progress, cancel, retry of what was missed),
//! the "over the arm" choices, and the autosaved form of the drafts.

pub mod cell;
pub mod draft;
pub mod file;
pub mod intent;

use std::collections::{BTreeSet, VecDeque};
use std::ops::Range;
use std::time::Instant;

use serde::{Deserialize, Serialize};

use super::controller::{ControllerState, ReadTable};
use super::{Level, Out, Request};
use crate::protocol::{AxisPattern, CoordKind};
use crate::robot::{CoordSystem, FrameKind, RobotModel};
pub use cell::Column;
pub use draft::{DraftTable, RowDiff, Rows, diff};
pub use file::TablePair;
pub use intent::{CellEntry, CellRefusal, CoordsIntent, FileOutcome};

/// The `format` of the autosaved drafts.
const SAVED_FORMAT: &str = "xsel-pendant drafts 1";

/// A table read in progress.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Reading {
    pub kind: CoordKind,
    pub received: u16,
    pub total: u16,
}

/// The drafts and the state of the reads.
#[derive(Clone, Debug)]
pub struct CoordEditor {
    pub work: DraftTable,
    pub tool: DraftTable,
    over_work: BTreeSet<u8>,
    over_tool: BTreeSet<u8>,
    reading: Option<Reading>,
    /// Record ranges still to read again, one download after another.
    retries: VecDeque<(CoordKind, Range<u16>)>,
    /// The axis pattern each table was last answered with (work, tool).
    answered: [Option<AxisPattern>; 2],
    /// Counts every change of a draft or a choice: the autosave writes when it moves.
    revision: u64,
    /// The last cell entry refused, shown in its cell until the next change.
    pub refused: Option<CellRefusal>,
    /// The result of the last import or export.
    pub file_result: Option<FileOutcome>,
}

/// The drafts as autosaved (wire units).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct SavedDrafts {
    pub format: String,
    pub work: Vec<Option<[i32; 4]>>,
    pub tool: Vec<Option<[i32; 4]>>,
    pub over_work: Vec<u8>,
    pub over_tool: Vec<u8>,
}

impl CoordEditor {
    pub fn new(work: usize, tool: usize) -> Self {
        Self {
            work: DraftTable::new(FrameKind::Work, work),
            tool: DraftTable::new(FrameKind::Tool, tool),
            over_work: BTreeSet::new(),
            over_tool: BTreeSet::new(),
            reading: None,
            retries: VecDeque::new(),
            answered: [None; 2],
            revision: 0,
            refused: None,
            file_result: None,
        }
    }

    pub fn draft(&self, kind: FrameKind) -> &DraftTable {
        match kind {
            FrameKind::Work => &self.work,
            FrameKind::Tool => &self.tool,
        }
    }

    /// A draft to change; the autosave sees the change.
    pub fn draft_mut(&mut self, kind: FrameKind) -> &mut DraftTable {
        self.revision += 1;
        match kind {
            FrameKind::Work => &mut self.work,
            FrameKind::Tool => &mut self.tool,
        }
    }

    /// Moves on every change worth saving.
    pub fn revision(&self) -> u64 {
        self.revision
    }

    pub fn reading(&self) -> Option<Reading> {
        self.reading
    }

    /// The axis pattern the controller answered the table's last read with.
    pub fn answered_axes(&self, kind: FrameKind) -> Option<AxisPattern> {
        self.answered[usize::from(kind == FrameKind::Tool)]
    }

    fn over(&self, kind: FrameKind) -> &BTreeSet<u8> {
        match kind {
            FrameKind::Work => &self.over_work,
            FrameKind::Tool => &self.over_tool,
        }
    }

    /// Whether row `number` is drawn over the arm.
    pub fn is_over_arm(&self, kind: FrameKind, number: u8) -> bool {
        self.over(kind).contains(&number)
    }

    /// Shows or hides row `number` over the arm.
    pub fn set_over_arm(&mut self, kind: FrameKind, number: u8, on: bool) {
        self.revision += 1;
        let set = match kind {
            FrameKind::Work => &mut self.over_work,
            FrameKind::Tool => &mut self.over_tool,
        };
        if on {
            set.insert(number);
        } else {
            set.remove(&number);
        }
    }

    /// The line is gone: no read is running any more (the link reports none).
    pub(super) fn line_gone(&mut self) {
        self.reading = None;
        self.retries.clear();
    }

    /// Both drafts, as files take them.
    pub fn tables(&self) -> TablePair {
        TablePair {
            work: self.work.rows().clone(),
            tool: self.tool.rows().clone(),
        }
    }

    /// The drafts in their autosaved form.
    pub fn saved(&self) -> SavedDrafts {
        let wire = |rows: &Rows| rows.iter().map(|r| r.map(|cs| cs.to_wire())).collect();
        SavedDrafts {
            format: SAVED_FORMAT.to_owned(),
            work: wire(self.work.rows()),
            tool: wire(self.tool.rows()),
            over_work: self.over_work.iter().copied().collect(),
            over_tool: self.over_tool.iter().copied().collect(),
        }
    }

    /// Takes back autosaved drafts (a different format is ignored: false).
    pub fn restore(&mut self, saved: &SavedDrafts) -> bool {
        if saved.format != SAVED_FORMAT {
            return false;
        }
        let rows =
            |w: &[Option<[i32; 4]>]| w.iter().map(|r| r.map(CoordSystem::from_wire)).collect();
        self.work.restore(rows(&saved.work));
        self.tool.restore(rows(&saved.tool));
        self.over_work = saved.over_work.iter().copied().collect();
        self.over_tool = saved.over_tool.iter().copied().collect();
        true
    }
}

/// A finished read of a table, as the link reports it.
pub struct TableDone<'a> {
    pub kind: CoordKind,
    /// The axis pattern the table was answered with.
    pub axes: AxisPattern,
    /// The first record read.
    pub first: u16,
    pub records: &'a [Option<crate::protocol::PerAxis<crate::protocol::Milli>>],
    /// The record ranges that could not be read.
    pub missing: &'a [Range<u16>],
}

/// What the coordinate-table editor needs to know of the rest of the model.
pub struct CoordsCx<'a> {
    pub line_up: bool,
    /// The controller's tables as read.
    pub controller: &'a ControllerState,
    /// The robot (the simulator's file names its axes).
    pub model: &'a RobotModel,
}

/// The controller's table as read, if it was.
pub fn read_table(controller: &ControllerState, kind: FrameKind) -> Option<&ReadTable> {
    match kind {
        FrameKind::Work => controller.work_table.as_ref(),
        FrameKind::Tool => controller.tool_table.as_ref(),
    }
}

/// The record ranges of a table not read (empty when all were, or none was read).
pub fn unread_ranges(controller: &ControllerState, kind: FrameKind) -> Vec<Range<u16>> {
    let Some(t) = read_table(controller, kind) else {
        return Vec::new();
    };
    let mut holes: Vec<Range<u16>> = Vec::new();
    for (i, r) in t.records.iter().enumerate() {
        let i = i as u16;
        if r.is_none() {
            match holes.last_mut() {
                Some(h) if h.end == i => h.end = i + 1,
                _ => holes.push(i..i + 1),
            }
        }
    }
    holes
}

impl CoordEditor {
    /// Reads a whole table from the controller again (the draft keeps its edits).
    pub fn reload(&mut self, line_up: bool, out: &mut Out, kind: CoordKind, now: Instant) {
        if !line_up {
            return out.say(
                Level::Warning,
                format!("{kind:?} table not read: the line is down"),
                now,
            );
        }
        self.retries.clear();
        let total = self.draft(FrameKind::from(kind)).rows().len() as u16;
        self.reading = Some(Reading {
            kind,
            received: 0,
            total,
        });
        out.push(Request::ReadTable(kind));
    }

    /// Stops the read in progress; what was read so far is kept, the rest shown unread.
    pub fn cancel_read(&mut self, out: &mut Out) {
        self.retries.clear();
        if self.reading.is_some() {
            out.push(Request::CancelTableRead);
        }
    }

    /// Reads again only the records a read missed, range by range.
    pub fn retry_unread(&mut self, cx: &CoordsCx, out: &mut Out, kind: CoordKind, now: Instant) {
        if !cx.line_up {
            return out.say(Level::Warning, "records not read: the line is down", now);
        }
        let holes = unread_ranges(cx.controller, FrameKind::from(kind));
        self.retries.extend(holes.into_iter().map(|r| (kind, r)));
        if self.reading.is_none() {
            self.next_retry(out);
        }
    }

    fn next_retry(&mut self, out: &mut Out) {
        if let Some((kind, range)) = self.retries.pop_front() {
            self.reading = Some(Reading {
                kind,
                received: 0,
                total: range.len() as u16,
            });
            out.push(Request::ReadRecords(kind, range));
        }
    }

    /// The draft becomes the controller's table (one undo step).
    pub fn draft_from_controller(&mut self, controller: &ControllerState, kind: FrameKind) {
        let Some(rows) = read_table(controller, kind).map(|t| t.records.clone()) else {
            return;
        };
        self.draft_mut(kind).reset_all(&rows);
    }

    /// Frames to draw over the arm, the rows whose "over the arm" toggle is on: the
    /// number and the definition. The draft's values are used (an edited row shows as
    /// edited; a row not edited holds the controller's values); a row neither read nor
    /// set is left out.
    pub fn frames_over_arm(
        &self,
        controller: &ControllerState,
    ) -> Vec<(FrameKind, u8, CoordSystem)> {
        let mut out = Vec::new();
        for kind in [FrameKind::Work, FrameKind::Tool] {
            for &n in self.over(kind) {
                let draft = self.draft(kind).get(usize::from(n));
                let read = read_table(controller, kind)
                    .and_then(|t| t.records.get(usize::from(n)).copied().flatten());
                if let Some(cs) = draft.or(read) {
                    out.push((kind, n, cs));
                }
            }
        }
        out
    }

    /// Both drafts in a file format.
    pub fn export(&self, format: file::TableFormat) -> String {
        let t = self.tables();
        match format {
            file::TableFormat::Csv => file::to_csv(&t),
            file::TableFormat::Json => file::to_json(&t),
            file::TableFormat::SimToml => file::to_sim_toml(&t),
        }
    }

    /// Reads a file into the drafts: the rows it lists replace the drafts' (one undo
    /// step per table); a file with an error anywhere, or listing no row, changes
    /// nothing. The number of rows the file lists.
    pub fn import(
        &mut self,
        bytes: &[u8],
        format: file::TableFormat,
        model: &RobotModel,
    ) -> Result<usize, crate::pendant::teach::file::FileError> {
        let (w, t) = (self.work.rows().len(), self.tool.rows().len());
        let pair = match format {
            file::TableFormat::Csv => file::from_csv(bytes, w, t)?,
            file::TableFormat::Json => file::from_json(bytes, w, t)?,
            file::TableFormat::SimToml => file::from_sim_toml(bytes, model)?,
        };
        let count = pair
            .work
            .iter()
            .chain(&pair.tool)
            .filter(|r| r.is_some())
            .count();
        if count == 0 {
            // Nothing to take: no undo step, no change.
            return Ok(0);
        }
        self.draft_mut(FrameKind::Work).import(&pair.work);
        self.draft_mut(FrameKind::Tool).import(&pair.tool);
        Ok(count)
    }

    /// Asks the window to give the drafts to the built-in simulator as its tables.
    pub fn give_to_simulator(&self, out: &mut Out) {
        out.push(Request::SimulatorTables(self.tables().to_coord_tables()));
    }

    /// A read's progress.
    pub fn table_progress(&mut self, kind: CoordKind, received: u16, total: u16) {
        self.reading = Some(Reading {
            kind,
            received,
            total,
        });
    }

    /// Files a finished read: the controller's table, the drafts' unedited rows, the
    /// next retry.
    pub fn table_done(
        &mut self,
        controller: &mut ControllerState,
        out: &mut Out,
        done: TableDone<'_>,
        now: Instant,
    ) {
        let TableDone {
            kind,
            axes,
            first,
            records,
            missing,
        } = done;
        let fk = FrameKind::from(kind);
        let before = read_table(controller, fk).map(|t| t.records.clone());
        let size = self.draft(fk).rows().len();
        controller.table(kind, first, size, records, now);
        let read: Rows = read_table(controller, fk)
            .map(|t| {
                t.records
                    .iter()
                    .skip(usize::from(first))
                    .take(records.len())
                    .copied()
                    .collect()
            })
            .unwrap_or_default();
        self.revision += 1;
        self.answered[usize::from(fk == FrameKind::Tool)] = Some(axes);
        let draft = match fk {
            FrameKind::Work => &mut self.work,
            FrameKind::Tool => &mut self.tool,
        };
        draft.adopt(before.as_ref(), usize::from(first), &read);
        self.reading = None;
        if !missing.is_empty() {
            let list: Vec<String> = missing
                .iter()
                .map(|r| match r.len() {
                    1 => format!("{}", r.start),
                    _ => format!("{}-{}", r.start, r.end - 1),
                })
                .collect();
            out.say(
                Level::Warning,
                format!(
                    "{fk} table: No. {} could not be read (shown as unread)",
                    list.join(", ")
                ),
                now,
            );
        }
        self.next_retry(out);
    }
}

#[cfg(test)]
mod tests;
