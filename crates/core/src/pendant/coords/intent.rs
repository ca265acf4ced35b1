//! What the coordinate tables pane asks of the editor, and the answers it shows: a
//! refused cell entry (kept with its text) and the result of the last file read or write.

use std::time::Instant;

use super::cell::Column;
use super::file::TableFormat;
use super::{CoordEditor, CoordsCx};
use crate::pendant::{Level, Out};
use crate::protocol::CoordKind;
use crate::robot::{FrameKind, RobotModel};

/// One thing asked of the coordinate-table editor.
#[derive(Clone, Debug, PartialEq)]
pub enum CoordsIntent {
    /// Read a whole table again with 2A4H.
    Reload(CoordKind),
    /// Read again only the records a read missed.
    RetryUnread(CoordKind),
    /// Stop the read in progress.
    CancelRead,
    Undo(FrameKind),
    Redo(FrameKind),
    /// The draft becomes the controller's table.
    DraftFromController(FrameKind),
    /// A typed cell entry, checked when it ends (Enter or leaving the cell).
    SetCell(CellEntry),
    /// Forget the refusal shown in a cell (Esc).
    DismissRefusal,
    /// One cell back to the controller's value.
    ResetCell {
        kind: FrameKind,
        number: usize,
        column: Column,
    },
    /// Draw a row's frame over the arm, or not.
    OverArm {
        kind: FrameKind,
        number: u8,
        on: bool,
    },
    /// A file's bytes (or the sentence saying why they could not be read) to import into
    /// the drafts.
    Import {
        path: String,
        format: TableFormat,
        bytes: Result<Vec<u8>, String>,
    },
    /// How writing the drafts to a file went.
    Exported {
        path: String,
        result: Result<(), String>,
    },
    /// Import or Export with a path that names no format the editor knows.
    FileNotNamed,
    /// A file could not be asked for (nothing typed, a dialog that failed, a job
    /// cancelled or given up): the sentence says why, and nothing changed.
    FileRefused(String),
    /// The built-in simulator answers 2A4H with the drafts from now on.
    TryOnSimulator,
}

/// A cell entry as typed.
#[derive(Clone, Debug, PartialEq)]
pub struct CellEntry {
    pub kind: FrameKind,
    pub number: usize,
    pub column: Column,
    pub text: String,
}

/// An entry the draft refused: the text stays in its cell, in red, with the reason.
#[derive(Clone, Debug, PartialEq)]
pub struct CellRefusal {
    pub entry: CellEntry,
    pub why: String,
}

impl CellRefusal {
    /// Whether it belongs to this cell.
    pub fn is_at(&self, kind: FrameKind, number: usize, column: Column) -> bool {
        let e = &self.entry;
        e.kind == kind && e.number == number && e.column == column
    }

    /// The sentence shown above the table.
    pub fn sentence(&self) -> String {
        let e = &self.entry;
        format!(
            "Refused, the draft is unchanged: {} No. {}, {}: {}",
            e.kind,
            e.number,
            e.column.heading(),
            self.why
        )
    }
}

/// The result of the last import or export, as shown under the file row.
#[derive(Clone, Debug, PartialEq)]
pub struct FileOutcome {
    pub ok: bool,
    pub text: String,
}

/// What the file row says when the path names no format it knows.
pub const NAME_A_FILE: &str = "name a file ending .csv, .json or .toml (the simulator's file)";

impl CoordEditor {
    /// Applies one of the coordinate pane's intents.
    pub fn apply(&mut self, intent: CoordsIntent, cx: &CoordsCx, out: &mut Out, now: Instant) {
        // Any change but a new refusal takes the old one away.
        if !matches!(
            intent,
            CoordsIntent::SetCell(_) | CoordsIntent::OverArm { .. }
        ) {
            self.refused = None;
        }
        match intent {
            CoordsIntent::Reload(kind) => self.reload(cx.line_up, out, kind, now),
            CoordsIntent::RetryUnread(kind) => self.retry_unread(cx, out, kind, now),
            CoordsIntent::CancelRead => self.cancel_read(out),
            CoordsIntent::Undo(kind) => {
                self.draft_mut(kind).undo();
            }
            CoordsIntent::Redo(kind) => {
                self.draft_mut(kind).redo();
            }
            CoordsIntent::DraftFromController(kind) => {
                self.draft_from_controller(cx.controller, kind)
            }
            CoordsIntent::SetCell(entry) => self.set_cell(entry),
            CoordsIntent::DismissRefusal => {}
            CoordsIntent::ResetCell {
                kind,
                number,
                column,
            } => {
                let controller = super::read_table(cx.controller, kind)
                    .map(|t| t.records.clone())
                    .unwrap_or_default();
                let _ = self.draft_mut(kind).reset_cell(number, column, &controller);
            }
            CoordsIntent::OverArm { kind, number, on } => {
                self.set_over_arm(kind, number, on);
            }
            CoordsIntent::Import {
                path,
                format,
                bytes,
            } => {
                let outcome = self.import_file(&path, format, bytes, cx.model);
                self.file_said(outcome, out, now);
            }
            CoordsIntent::Exported { path, result } => {
                let outcome = match result {
                    Ok(()) => FileOutcome {
                        ok: true,
                        text: format!("exported the work and tool drafts to {path}"),
                    },
                    // The writer's sentence names the file.
                    Err(e) => FileOutcome { ok: false, text: e },
                };
                self.file_said(outcome, out, now);
            }
            CoordsIntent::FileRefused(text) => {
                self.file_said(FileOutcome { ok: false, text }, out, now);
            }
            CoordsIntent::FileNotNamed => {
                let text = NAME_A_FILE.to_owned();
                self.file_said(FileOutcome { ok: false, text }, out, now);
            }
            CoordsIntent::TryOnSimulator => self.give_to_simulator(out),
        }
    }

    /// A file's outcome under the file row (one line) and, whole, in Messages.
    fn file_said(&mut self, outcome: FileOutcome, out: &mut Out, now: Instant) {
        let level = if outcome.ok {
            Level::Info
        } else {
            Level::Warning
        };
        out.say(level, format!("coordinate tables: {}", outcome.text), now);
        self.file_result = Some(outcome);
    }

    /// Puts a typed entry in the draft, or keeps it with the reason it was refused.
    fn set_cell(&mut self, entry: CellEntry) {
        self.refused = None;
        // Unchanged text (the value as shown, or an unread cell left empty) is no edit.
        let shown = self
            .draft(entry.kind)
            .get(entry.number)
            .map_or_else(String::new, |cs| super::cell::show(entry.column.get(&cs)));
        let typed = entry.text.trim();
        if typed == shown || (typed.is_empty() && shown.is_empty()) {
            return;
        }
        let result = self
            .draft_mut(entry.kind)
            .set_cell(entry.number, entry.column, &entry.text);
        if let Err(why) = result {
            self.refused = Some(CellRefusal { entry, why });
        }
    }

    fn import_file(
        &mut self,
        path: &str,
        format: TableFormat,
        bytes: Result<Vec<u8>, String>,
        model: &RobotModel,
    ) -> FileOutcome {
        let refused = |text: String| FileOutcome { ok: false, text };
        let bytes = match bytes {
            Ok(b) => b,
            // The reader's sentence names the file.
            Err(e) => return refused(e),
        };
        match self.import(&bytes, format, model) {
            // `import` changes nothing for a file that lists no rows.
            Ok(0) => refused(format!(
                "{path}: the file lists no rows of either table; the drafts are unchanged"
            )),
            Ok(n) => FileOutcome {
                ok: true,
                text: format!("imported {n} rows from {path} (Undo takes them back)"),
            },
            Err(e) => refused(format!("{path}: {e} (nothing changed)")),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pendant::{Pendant, Settings};
    use crate::robot::RobotModel;

    fn pendant() -> Pendant {
        Pendant::new(Settings::default(), RobotModel::default_model())
    }

    fn entry(number: usize, column: Column, text: &str) -> CellEntry {
        CellEntry {
            kind: FrameKind::Work,
            number,
            column,
            text: text.to_owned(),
        }
    }

    #[test]
    fn a_refused_entry_keeps_its_text_and_reason_and_the_next_change_clears_it() {
        let mut p = pendant();
        let now = Instant::now();
        p.apply_coords(CoordsIntent::SetCell(entry(2, Column::X, "12,5")), now);
        let refusal = p.coords.refused.clone().expect("refused");
        assert!(refusal.is_at(FrameKind::Work, 2, Column::X));
        assert_eq!(refusal.entry.text, "12,5");
        assert!(
            refusal
                .sentence()
                .starts_with("Refused, the draft is unchanged: work No. 2")
        );
        assert_eq!(
            p.coords.draft(FrameKind::Work).get(2),
            None,
            "draft changed"
        );
        p.apply_coords(CoordsIntent::SetCell(entry(2, Column::X, "12.5")), now);
        assert_eq!(p.coords.refused, None);
        let row = p.coords.draft(FrameKind::Work).get(2).expect("row set");
        assert_eq!(Column::X.get(&row), 12_500);
        p.apply_coords(CoordsIntent::SetCell(entry(3, Column::Y, "x")), now);
        p.apply_coords(CoordsIntent::Undo(FrameKind::Work), now);
        assert_eq!(p.coords.refused, None, "an undo leaves no stale refusal");
        assert_eq!(p.coords.draft(FrameKind::Work).get(2), None, "undone");
    }

    #[test]
    fn an_unreadable_or_bad_file_changes_nothing_and_says_why() {
        let mut p = pendant();
        let now = Instant::now();
        p.apply_coords(
            CoordsIntent::Import {
                path: "t.csv".into(),
                format: TableFormat::Csv,
                bytes: Err("cannot read t.csv: No such file or directory".into()),
            },
            now,
        );
        let out = p.coords.file_result.clone().expect("a result");
        assert!(!out.ok);
        assert_eq!(out.text, "cannot read t.csv: No such file or directory");
        p.apply_coords(
            CoordsIntent::Import {
                path: "t.csv".into(),
                format: TableFormat::Csv,
                bytes: Ok(b"\xff\xfe garbage".to_vec()),
            },
            now,
        );
        let out = p.coords.file_result.clone().expect("a result");
        assert!(
            !out.ok && out.text.ends_with("(nothing changed)"),
            "{}",
            out.text
        );
        assert!(!p.coords.draft(FrameKind::Work).can_undo(), "draft touched");
        // A file that lists no rows (`{}`) is no import of zero rows.
        p.apply_coords(
            CoordsIntent::Import {
                path: "empty.json".into(),
                format: TableFormat::Json,
                bytes: Ok(b"{}".to_vec()),
            },
            now,
        );
        let out = p.coords.file_result.clone().expect("a result");
        assert!(!out.ok, "{}", out.text);
        assert!(out.text.contains("lists no rows"), "{}", out.text);
        assert!(!p.coords.draft(FrameKind::Work).can_undo(), "draft touched");
        assert!(!p.coords.draft(FrameKind::Tool).can_undo(), "draft touched");
        // Each outcome is in Messages whole, not only on the file row's one line.
        assert!(
            p.messages
                .iter()
                .any(|m| m.text == format!("coordinate tables: {}", out.text)),
            "{:?}",
            p.messages
        );
    }
}
