//! The draft of one coordinate table: rows the user edits, each change undoable, and the
//! comparison with the table read from the controller.

use crate::robot::{CoordSystem, FrameKind};

use super::cell::{self, Column};

/// A table's rows by definition number; `None` = not read and not set (never zeros).
pub type Rows = Vec<Option<CoordSystem>>;

/// Most edits kept for undo.
const KEEP_UNDO: usize = 500;

/// One row's change: what it was and what it became.
#[derive(Clone, Debug, PartialEq)]
struct Change {
    number: usize,
    before: Option<CoordSystem>,
    after: Option<CoordSystem>,
}

/// Where a draft row and the controller's row differ.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RowDiff {
    pub number: usize,
    /// X, Y, Z, R: true where the cell differs.
    pub cells: [bool; 4],
    pub draft: Option<CoordSystem>,
    pub controller: Option<CoordSystem>,
}

/// The draft of one table, with its undo and redo history.
#[derive(Clone, Debug)]
pub struct DraftTable {
    kind: FrameKind,
    rows: Rows,
    undo: Vec<Vec<Change>>,
    redo: Vec<Vec<Change>>,
}

impl DraftTable {
    /// `size` unread rows.
    pub fn new(kind: FrameKind, size: usize) -> Self {
        Self {
            kind,
            rows: vec![None; size.max(1)],
            undo: Vec::new(),
            redo: Vec::new(),
        }
    }

    pub fn kind(&self) -> FrameKind {
        self.kind
    }

    pub fn rows(&self) -> &Rows {
        &self.rows
    }

    pub fn get(&self, number: usize) -> Option<CoordSystem> {
        self.rows.get(number).copied().flatten()
    }

    pub fn can_undo(&self) -> bool {
        !self.undo.is_empty()
    }

    pub fn can_redo(&self) -> bool {
        !self.redo.is_empty()
    }

    /// Checks a typed entry and, if it passes, puts it in the draft (one undo step).
    /// Nothing changes when it is refused.
    pub fn set_cell(&mut self, number: usize, column: Column, text: &str) -> Result<bool, String> {
        self.check_row(number)?;
        let value = cell::parse_entry(column, text)?;
        let row = self.get(number).unwrap_or(CoordSystem::ZERO);
        if cell::read_only(self.kind, number) && value != 0 {
            return Err(cell::READ_ONLY.to_owned());
        }
        Ok(self.apply(vec![(number, Some(column.with(&row, value)))]))
    }

    /// Puts one cell back to the controller's value (one undo step).
    pub fn reset_cell(
        &mut self,
        number: usize,
        column: Column,
        controller: &Rows,
    ) -> Result<bool, String> {
        self.check_row(number)?;
        let Some(theirs) = controller.get(number).copied().flatten() else {
            return Err(format!(
                "{} No. {number} was not read from the controller: nothing to reset to",
                self.kind
            ));
        };
        let row = self.get(number).unwrap_or(CoordSystem::ZERO);
        let value = column.get(&theirs);
        Ok(self.apply(vec![(number, Some(column.with(&row, value)))]))
    }

    /// The whole draft becomes the controller's table (one undo step); rows the
    /// controller could not give keep the draft's values.
    pub fn reset_all(&mut self, controller: &Rows) -> bool {
        let changes = controller
            .iter()
            .enumerate()
            .filter_map(|(n, r)| r.map(|cs| (n, Some(cs))))
            .collect();
        self.apply(changes)
    }

    /// Replaces the rows a file lists (one undo step); `rows[n] == None` leaves row `n`.
    pub fn import(&mut self, rows: &Rows) -> bool {
        let changes = rows
            .iter()
            .enumerate()
            .filter(|(n, _)| *n < self.rows.len())
            .filter_map(|(n, r)| r.map(|cs| (n, Some(cs))))
            .collect();
        self.apply(changes)
    }

    /// Rows just read from the controller, `first` onwards: each row not edited (equal to
    /// what the controller held before, or never set) takes the new value. Not an edit:
    /// no undo step.
    pub fn adopt(&mut self, before: Option<&Rows>, first: usize, read: &[Option<CoordSystem>]) {
        for (i, new) in read.iter().enumerate() {
            let n = first + i;
            let (Some(slot), Some(new)) = (self.rows.get_mut(n), new) else {
                continue;
            };
            let old = before.and_then(|b| b.get(n).copied().flatten());
            if slot.is_none() || *slot == old {
                *slot = Some(*new);
            }
        }
    }

    /// Undoes the last edit; false when there is none.
    pub fn undo(&mut self) -> bool {
        let Some(edit) = self.undo.pop() else {
            return false;
        };
        for c in edit.iter().rev() {
            self.rows[c.number] = c.before;
        }
        self.redo.push(edit);
        true
    }

    /// Redoes the last undone edit; false when there is none.
    pub fn redo(&mut self) -> bool {
        let Some(edit) = self.redo.pop() else {
            return false;
        };
        for c in &edit {
            self.rows[c.number] = c.after;
        }
        self.undo.push(edit);
        true
    }

    /// Rows as restored from an autosave (no undo step, history cleared); the size
    /// stays, work No. 0 stays the base frame.
    pub fn restore(&mut self, rows: Rows) {
        for (slot, row) in self.rows.iter_mut().zip(rows) {
            *slot = row;
        }
        if self.kind == FrameKind::Work {
            self.rows[0] = self.rows[0].map(|_| CoordSystem::ZERO);
        }
        self.undo.clear();
        self.redo.clear();
    }

    fn check_row(&self, number: usize) -> Result<(), String> {
        if number >= self.rows.len() {
            return Err(format!(
                "there is no {} No. {number} (0 to {})",
                self.kind,
                self.rows.len() - 1
            ));
        }
        Ok(())
    }

    /// Applies the changes that change something as one undo step.
    fn apply(&mut self, changes: Vec<(usize, Option<CoordSystem>)>) -> bool {
        let mut edit = Vec::new();
        for (number, after) in changes {
            let Some(slot) = self.rows.get_mut(number) else {
                continue;
            };
            let after = if cell::read_only(self.kind, number) {
                after.map(|_| CoordSystem::ZERO)
            } else {
                after
            };
            if *slot != after {
                edit.push(Change {
                    number,
                    before: *slot,
                    after,
                });
                *slot = after;
            }
        }
        if edit.is_empty() {
            return false;
        }
        if self.undo.len() >= KEEP_UNDO {
            self.undo.remove(0);
        }
        self.undo.push(edit);
        self.redo.clear();
        true
    }
}

/// Whether one cell of a draft row differs from the controller's row.
pub fn cell_differs(
    draft: Option<CoordSystem>,
    controller: Option<CoordSystem>,
    column: Column,
) -> bool {
    match (draft, controller) {
        (Some(d), Some(c)) => column.get(&d) != column.get(&c),
        (None, None) => false,
        _ => true,
    }
}

/// The rows where the draft and the controller's table differ, in order. A row read on
/// one side only differs in every cell.
pub fn diff(draft: &Rows, controller: &Rows) -> Vec<RowDiff> {
    let len = draft.len().max(controller.len());
    (0..len)
        .filter_map(|number| {
            let d = draft.get(number).copied().flatten();
            let c = controller.get(number).copied().flatten();
            if d == c {
                return None;
            }
            Some(RowDiff {
                number,
                cells: Column::ALL.map(|col| cell_differs(d, c, col)),
                draft: d,
                controller: c,
            })
        })
        .collect()
}
