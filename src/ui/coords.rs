//! The coordinate tables pane: work and tool tabs, reading from the controller (progress,
//! cancel, retry of unread records), the draft's undo, redo and diff, files, the
//! simulator, and the plain word on writing. The table itself is in `coords_table.rs`.

use std::time::{Instant, SystemTime};

use egui::{Button, ProgressBar, RichText, TextEdit, Ui};

use super::coords_table::{CellEdit, table};
use super::widgets::{AMBER, GREEN, RED, reserved_line};
use crate::pendant::Pendant;
use crate::pendant::coords::diff;
use crate::pendant::coords::file::TableFormat;
use crate::protocol::CoordKind;
use crate::robot::FrameKind;

/// What the pane keeps between frames: the tab, the cell being typed, the file path.
pub struct CoordsPanel {
    pub(super) kind: FrameKind,
    pub(super) edit: Option<CellEdit>,
    pub(super) show_diff: bool,
    pub(super) only_differences: bool,
    path: String,
    file_message: Option<(bool, String)>,
    write_note: bool,
}

impl Default for CoordsPanel {
    fn default() -> Self {
        Self {
            kind: FrameKind::Work,
            edit: None,
            show_diff: false,
            only_differences: false,
            path: String::new(),
            file_message: None,
            write_note: false,
        }
    }
}

fn coord_kind(kind: FrameKind) -> CoordKind {
    match kind {
        FrameKind::Work => CoordKind::Work,
        FrameKind::Tool => CoordKind::Tool,
    }
}

/// `HH:MM:SS UTC` of an instant in the past.
fn wall_clock(at: Instant, now: Instant) -> String {
    let ago = now.saturating_duration_since(at);
    let secs = SystemTime::now()
        .checked_sub(ago)
        .and_then(|t| t.duration_since(SystemTime::UNIX_EPOCH).ok())
        .map_or(0, |d| d.as_secs());
    let day = secs % 86_400;
    format!(
        "{:02}:{:02}:{:02} UTC",
        day / 3600,
        day % 3600 / 60,
        day % 60
    )
}

impl CoordsPanel {
    pub fn show(&mut self, ui: &mut Ui, pendant: &mut Pendant, now: Instant) {
        self.tabs_and_reading(ui, pendant, now);
        self.draft_bar(ui, pendant);
        self.files(ui, pendant, now);
        // The refusal and the file result in lines that are always there: the table
        // below never jumps when one appears.
        let refused = self
            .edit
            .as_ref()
            .and_then(|e| e.refused.as_ref())
            .map(|e| format!("Refused, the draft is unchanged: {e}"));
        reserved_line(ui, refused.as_deref().map(|t| (RED, t)), refused.as_deref());
        ui.separator();
        table(ui, self, pendant);
    }

    fn tabs_and_reading(&mut self, ui: &mut Ui, pendant: &mut Pendant, now: Instant) {
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
                    pendant.cancel_table_read();
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
                    pendant.reload_table(coord_kind(kind), now);
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
                    pendant.retry_unread(coord_kind(kind), now);
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

    fn draft_bar(&mut self, ui: &mut Ui, pendant: &mut Pendant) {
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
                pendant.coords.draft_mut(kind).undo();
                self.edit = None;
            }
            if ui.add_enabled(can_redo, Button::new("Redo")).clicked() {
                pendant.coords.draft_mut(kind).redo();
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
                pendant.draft_from_controller(kind);
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

    fn files(&mut self, ui: &mut Ui, pendant: &mut Pendant, now: Instant) {
        ui.horizontal_wrapped(|ui| {
            let label = ui.label("File");
            ui.add(
                TextEdit::singleline(&mut self.path)
                    .desired_width(200.0)
                    .hint_text("tables.csv, .json or .toml"),
            )
            .labelled_by(label.id)
            .on_hover_text(
                ".csv, .json, or .toml: the simulator's coordinate file (xsel-sim --coords)",
            );
            if ui.button("Import").clicked() {
                self.file_message = Some(import(&self.path, pendant));
                self.edit = None;
            }
            if ui.button("Export").clicked() {
                self.file_message = Some(export(&self.path, pendant));
            }
            if ui
                .button("Try on simulator")
                .on_hover_text("The built-in simulator answers 2A4H with the draft from now on")
                .clicked()
            {
                pendant.give_draft_to_simulator(now);
            }
            if ui.button("Write to controller?").clicked() {
                self.write_note = !self.write_note;
            }
        });
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
        let file = self
            .file_message
            .as_ref()
            .map(|(ok, text)| (if *ok { GREEN } else { RED }, text.as_str()));
        reserved_line(ui, file, file.map(|(_, t)| t));
    }
}

const NAME_A_FILE: &str = "name a file ending .csv, .json or .toml (the simulator's file)";

fn export(path: &str, pendant: &Pendant) -> (bool, String) {
    let path = path.trim();
    let Some(format) = TableFormat::of_path(path) else {
        return (false, NAME_A_FILE.to_owned());
    };
    match std::fs::write(path, pendant.export_tables(format)) {
        Ok(()) => (true, format!("exported the work and tool drafts to {path}")),
        Err(e) => (false, format!("cannot write {path}: {e}")),
    }
}

fn import(path: &str, pendant: &mut Pendant) -> (bool, String) {
    let path = path.trim();
    let Some(format) = TableFormat::of_path(path) else {
        return (false, NAME_A_FILE.to_owned());
    };
    let bytes = match std::fs::read(path) {
        Ok(b) => b,
        Err(e) => return (false, format!("cannot read {path}: {e}")),
    };
    match pendant.import_tables(&bytes, format) {
        Ok(n) => (
            true,
            format!("imported {n} rows from {path} (Undo takes them back)"),
        ),
        Err(e) => (false, format!("{path}: {e} (nothing changed)")),
    }
}
