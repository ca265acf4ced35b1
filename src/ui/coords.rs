//! The coordinate tables pane: work and tool tabs, reading from the controller (progress,
//! cancel, retry of unread records), the draft's undo, redo and diff, files, the
//! simulator, and the plain word on writing. The table itself is in `coords_table.rs`.

use std::path::{Path, PathBuf};
use std::time::{Instant, SystemTime};

use egui::{Button, ProgressBar, RichText, Ui};

use super::coords_table::{CellEdit, table};
use super::file_field::{Browse, FieldSpec, FileAsk, Purpose};
use super::file_work::FileWork;
use super::pane::{Pane, PaneCx};
use super::widgets::{AMBER, GREEN, RED, clock_utc, reserved_line};
use crate::files::job::Job;
use crate::files::{DOCUMENT_LIMIT, WriteError, read_bounded_in, write_file};
use crate::pendant::coords::file::TableFormat;
use crate::pendant::coords::{CoordsIntent, FileOutcome, diff};
use crate::pendant::{Intent, Pendant};
use crate::robot::FrameKind;

/// What the file field is for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum TablesFile {
    Import,
    Export,
}

static FILE_FIELD: FieldSpec<TablesFile> = FieldSpec {
    label: "File",
    hint: "tables.csv, .json or .toml",
    width: 200.0,
    browse: &[
        Browse {
            label: "Import a file...",
            action: TablesFile::Import,
            purpose: Purpose::Open,
        },
        Browse {
            label: "Export the drafts as...",
            action: TablesFile::Export,
            purpose: Purpose::Save,
        },
    ],
    filters: &[("Coordinate tables", &["csv", "json", "toml"])],
};

/// A finished file job.
enum TablesDone {
    Read {
        path: PathBuf,
        format: TableFormat,
        bytes: Result<Vec<u8>, String>,
    },
    Written {
        path: PathBuf,
        result: Result<(), WriteError>,
    },
}

/// What the pane keeps between frames: the tab, the cell being typed, the file and its
/// job.
pub struct CoordsPanel {
    pub(super) kind: FrameKind,
    pub(super) edit: Option<CellEdit>,
    pub(super) show_diff: bool,
    pub(super) only_differences: bool,
    /// How far each table (work, tool) is scrolled down, shared by its frozen No. column
    /// and its values.
    pub(super) rows_offset: [f32; 2],
    file: FileWork<TablesFile, TablesDone>,
    write_note: bool,
    /// The files rows: as the user chose, else shown only when the pane has room for
    /// them and the table (the default layout at 1280x800 has not).
    files_open: Option<bool>,
}

/// A pane at least this tall shows the files rows until the user hides them (px).
const ROOMY_PANE: f32 = 520.0;

impl Default for CoordsPanel {
    fn default() -> Self {
        Self {
            kind: FrameKind::Work,
            edit: None,
            show_diff: false,
            only_differences: false,
            rows_offset: [0.0; 2],
            file: FileWork::new(&FILE_FIELD),
            write_note: false,
            files_open: None,
        }
    }
}

/// `HH:MM:SS UTC` of an instant in the past.
fn wall_clock(at: Instant, now: Instant) -> String {
    let ago = now.saturating_duration_since(at);
    let at = SystemTime::now()
        .checked_sub(ago)
        .unwrap_or(SystemTime::UNIX_EPOCH);
    super::widgets::utc_time(at)
}

impl CoordsPanel {
    pub fn show(
        &mut self,
        ui: &mut Ui,
        pendant: &Pendant,
        folder: &Path,
        now: Instant,
        out: &mut Vec<Intent>,
    ) {
        let mut from_files = Vec::new();
        let files_shown = self
            .files_open
            .unwrap_or(ui.available_height() >= ROOMY_PANE);
        {
            let mut ask = |i: CoordsIntent| out.push(Intent::Coords(i));
            self.tabs_and_reading(ui, pendant, now, files_shown, &mut ask);
            self.draft_bar(ui, pendant, &mut ask);
        }
        // A file job finishes (and says so) even while its rows are hidden.
        self.poll_job(now, &mut |i| from_files.push(i));
        if files_shown {
            self.files(ui, pendant, folder, now, &mut |i| from_files.push(i));
        }
        out.append(&mut from_files);
        let mut ask = |i: CoordsIntent| out.push(Intent::Coords(i));
        // The refusal and the file result in lines that are always there: the table
        // below never jumps when one appears.
        let refused = pendant.coords.refused.as_ref().map(|r| r.sentence());
        reserved_line(ui, refused.as_deref().map(|t| (RED, t)), refused.as_deref());
        ui.separator();
        table(ui, self, pendant, &mut ask);
    }

    fn tabs_and_reading(
        &mut self,
        ui: &mut Ui,
        pendant: &Pendant,
        now: Instant,
        files_shown: bool,
        ask: &mut impl FnMut(CoordsIntent),
    ) {
        let kind = self.kind;
        ui.horizontal_wrapped(|ui| {
            for (k, title) in [
                (FrameKind::Work, "Work table"),
                (FrameKind::Tool, "Tool table"),
            ] {
                if ui.selectable_label(self.kind == k, title).clicked() && self.kind != k {
                    self.kind = k;
                    self.edit = None;
                }
            }
            // Before the read controls, so it never moves when they change.
            if ui
                .selectable_label(files_shown, "Files")
                .on_hover_text("Show or hide the import, export and simulator rows")
                .clicked()
            {
                self.files_open = Some(!files_shown);
            }
            ui.separator();
            let reading = pendant.coords.reading();
            if let Some(r) = reading {
                let share = f32::from(r.received) / f32::from(r.total.max(1));
                ui.add(
                    ProgressBar::new(share)
                        .desired_width(140.0)
                        .text(format!("{:?} {}/{}", r.kind, r.received, r.total)),
                );
                if ui.button("Cancel read").clicked() {
                    ask(CoordsIntent::CancelRead);
                }
            } else {
                let up = pendant.line.is_up();
                if ui
                    .add_enabled(up, Button::new("Read from controller"))
                    .on_hover_text(
                        "Read the whole table again with 2A4H; edited rows stay as edited",
                    )
                    .on_disabled_hover_text("The line is down")
                    .clicked()
                {
                    ask(CoordsIntent::Reload(kind.into()));
                }
                let unread: u16 = pendant
                    .unread_ranges(kind)
                    .iter()
                    .map(|r| r.len() as u16)
                    .sum();
                if unread > 0
                    && ui
                        .add_enabled(up, Button::new(format!("Retry unread ({unread})")))
                        .on_hover_text("Read again only the records that could not be read")
                        .clicked()
                {
                    ask(CoordsIntent::RetryUnread(kind.into()));
                }
            }
        });
        ui.horizontal_wrapped(|ui| {
            match pendant.read_table(kind) {
                Some(t) => {
                    let unread = t.records.iter().filter(|r| r.is_none()).count();
                    let axes = pendant
                        .coords
                        .answered_axes(kind)
                        .map_or(String::new(), |a| format!(", axes {a}"));
                    ui.label(format!(
                        "Read from the controller at {}{axes}",
                        wall_clock(t.at, now)
                    ));
                    if unread > 0 {
                        ui.label(RichText::new(format!("{unread} records unread")).color(AMBER));
                    }
                }
                None => {
                    ui.label(RichText::new("Not read from the controller yet").color(AMBER));
                }
            }
            if let Some((work, tool)) = pendant.controller.frame_numbers() {
                ui.label(format!("In use: work {work}, tool {tool}"));
            }
        });
    }

    fn draft_bar(&mut self, ui: &mut Ui, pendant: &Pendant, ask: &mut impl FnMut(CoordsIntent)) {
        let kind = self.kind;
        let controller = pendant
            .read_table(kind)
            .map(|t| t.records.clone())
            .unwrap_or_default();
        let differ = diff(pendant.coords.draft(kind).rows(), &controller);
        ui.horizontal_wrapped(|ui| {
            let d = pendant.coords.draft(kind);
            let (can_undo, can_redo) = (d.can_undo(), d.can_redo());
            if ui.add_enabled(can_undo, Button::new("Undo")).clicked() {
                ask(CoordsIntent::Undo(kind));
                self.edit = None;
            }
            if ui.add_enabled(can_redo, Button::new("Redo")).clicked() {
                ask(CoordsIntent::Redo(kind));
                self.edit = None;
            }
            if ui
                .add_enabled(
                    pendant.read_table(kind).is_some(),
                    Button::new("Draft = controller"),
                )
                .on_hover_text("Every row read from the controller replaces the draft's (undoable)")
                .clicked()
            {
                ask(CoordsIntent::DraftFromController(kind));
                self.edit = None;
            }
            ui.checkbox(&mut self.show_diff, "Diff with controller");
            ui.checkbox(&mut self.only_differences, "Only rows that differ");
            let summary = if differ.is_empty() {
                RichText::new("Draft = controller").color(GREEN)
            } else {
                let list: Vec<String> = differ
                    .iter()
                    .take(12)
                    .map(|r| r.number.to_string())
                    .collect();
                let more = if differ.len() > 12 { ", ..." } else { "" };
                let rows = match differ.len() {
                    1 => "1 row differs".to_owned(),
                    n => format!("{n} rows differ"),
                };
                RichText::new(format!("{rows}: No. {}{more}", list.join(", "))).color(AMBER)
            };
            ui.label(summary);
        });
    }

    fn files(
        &mut self,
        ui: &mut Ui,
        pendant: &Pendant,
        folder: &Path,
        now: Instant,
        ask: &mut impl FnMut(Intent),
    ) {
        ui.horizontal_wrapped(|ui| {
            self.file.field(ui, folder, now).on_hover_text(
                ".csv, .json, or .toml: the simulator's coordinate file (xsel-sim --coords)",
            );
            let import = ("Import", None, TablesFile::Import);
            self.file.button(ui, import, true, folder);
            let export = ("Export", None, TablesFile::Export);
            self.file.button(ui, export, true, folder);
            if ui
                .button("Try on simulator")
                .on_hover_text("The built-in simulator answers 2A4H with the draft from now on")
                .clicked()
            {
                ask(Intent::Coords(CoordsIntent::TryOnSimulator));
            }
            if ui.button("Write to controller?").clicked() {
                self.write_note = !self.write_note;
            }
        });
        if let Some(file) = self.file.take_ask() {
            self.start_job(file, pendant, now, ask);
        }
        self.refused(ask);
        self.file.lines(ui);
        self.refused(ask);
        if self.write_note {
            ui.label(
                RichText::new(
                    "The pendant cannot write these tables: Format B has no message that \
                     writes work or tool coordinate systems (PROTOCOL.md 3.23). Export the \
                     draft (CSV, JSON, or the simulator's .toml) and enter it with IAI's \
                     tools, or try it on the built-in simulator.",
                )
                .color(AMBER),
            );
        }
        let file = pendant
            .coords
            .file_result
            .as_ref()
            .map(|FileOutcome { ok, text }| (if *ok { GREEN } else { RED }, text.as_str()));
        reserved_line(ui, file, file.map(|(_, t)| t));
    }
}

impl CoordsPanel {
    /// Starts an Import (read off the UI thread, handed to the pendant) or an Export
    /// (the drafts as the name's format, written off the UI thread).
    fn start_job(
        &mut self,
        file: FileAsk<TablesFile>,
        pendant: &Pendant,
        now: Instant,
        ask: &mut impl FnMut(Intent),
    ) {
        let FileAsk {
            action,
            path,
            overwrite,
        } = file;
        let Some(format) = TableFormat::of_path(&path.to_string_lossy()) else {
            return ask(Intent::Coords(CoordsIntent::FileNotNamed));
        };
        let shown = path.display().to_string();
        let job = match action {
            TablesFile::Import => {
                self.edit = None;
                Job::spawn_opening(format!("reading {shown}"), now, move |ctl| {
                    let bytes = read_bounded_in(&path, DOCUMENT_LIMIT, ctl);
                    TablesDone::Read {
                        path,
                        format,
                        bytes,
                    }
                })
            }
            TablesFile::Export => {
                let text = pendant.export_tables(format);
                Job::spawn_opening(format!("writing {shown}"), now, move |ctl| {
                    let result = write_file(&path, text.as_bytes(), overwrite, ctl);
                    TablesDone::Written { path, result }
                })
            }
        };
        self.file.started(job);
    }

    /// What went wrong with a file (the field's word) handed to the pendant, whose line
    /// says it.
    fn refused(&mut self, ask: &mut impl FnMut(Intent)) {
        if let Some((_, why)) = self.file.message.take() {
            ask(Intent::Coords(CoordsIntent::FileRefused(why)));
        }
    }

    /// Hands a finished job to the pendant, or asks before replacing a file.
    fn poll_job(&mut self, now: Instant, ask: &mut impl FnMut(Intent)) {
        let done = self.file.finished(now);
        self.refused(ask);
        let Some(done) = done else {
            return;
        };
        match done {
            TablesDone::Read {
                path,
                format,
                bytes,
            } => {
                if bytes.is_ok() {
                    ask(Intent::FileUsed(path.clone()));
                }
                ask(Intent::Coords(CoordsIntent::Import {
                    path: path.display().to_string(),
                    format,
                    bytes,
                }));
            }
            TablesDone::Written { path, result } => {
                let result = match result {
                    Err(WriteError::Exists(what)) => {
                        return self.file.exists(TablesFile::Export, path, what);
                    }
                    Err(e) => Err(e.sentence(&path)),
                    Ok(()) => {
                        ask(Intent::FileUsed(path.clone()));
                        Ok(())
                    }
                };
                ask(Intent::Coords(CoordsIntent::Exported {
                    path: format!("{} at {}", path.display(), clock_utc()),
                    result,
                }));
            }
        }
    }
}

impl Pane for CoordsPanel {
    fn ui(&mut self, ui: &mut Ui, cx: &mut PaneCx<'_>) {
        self.show(ui, cx.pendant, cx.folder, cx.now, cx.intents);
    }
}
