//! The Positions view: the controller's position table read in the background, taught
//! ("Teach here"), edited in place into a draft with undo, written after a preview, gone
//! to (2D6H), and imported from or exported to CSV and JSON files.

use std::path::Path;
use std::time::Instant;

use egui::{Button, Color32, Key, ProgressBar, RichText, Sense, TextEdit, Ui};
use egui_extras::{Column as Col, TableBuilder};

use super::file_field::{Browse, FieldSpec, FileAsk, Purpose};
use super::file_work::{Done, FileButton, FileWork, is_json, read_job, write_job};
use super::pane::{Pane, PaneCx};
use super::widgets::{AMBER, GREEN, GREY, RED, said_line};
use crate::files::job::Job;
use crate::pendant::positions::write::Outcome;
use crate::pendant::positions::{Column, Filter, Positions, PositionsIntent, Preview, Row, file};
use crate::pendant::{Intent, Interpolation, Pendant};
use crate::protocol::PositionRecord;

const ROW_HEIGHT: f32 = 22.0;
/// A value column's width (px).
const VALUE_WIDTH: f32 = 74.0;

/// What the file field is for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum PositionsFile {
    Import,
    Export,
}

static FILE_FIELD: FieldSpec<PositionsFile> = FieldSpec {
    label: "File",
    hint: "positions.csv or .json",
    width: 170.0,
    browse: &[
        Browse {
            label: "Import into the draft...",
            action: PositionsFile::Import,
            purpose: Purpose::Open,
        },
        Browse {
            label: "Export the rows shown as...",
            action: PositionsFile::Export,
            purpose: Purpose::Save,
        },
    ],
    filters: &[("Position table", &["csv", "json"])],
};

static FILE_BUTTONS: [FileButton<PositionsFile>; 2] = [
    (
        "Import",
        Some(
            "Read a CSV or JSON file into the draft (never the controller); a file with an \
             error anywhere changes nothing",
        ),
        PositionsFile::Import,
    ),
    (
        "Export",
        Some("Write the used rows the filter shows, as .csv or .json"),
        PositionsFile::Export,
    ),
];

/// A finished file job: the rows read, or the rows written.
type PositionsDone = Done<Vec<(PositionRecord, Option<String>)>>;

/// The cell being typed: a value of row `number`, or its name.
#[derive(Clone, Debug, PartialEq)]
struct CellEdit {
    number: u16,
    /// `None`: the name.
    column: Option<Column>,
    text: String,
    /// Focus was asked for (on the frame the edit began).
    focused: bool,
}

/// The view's own state: what the operator typed and chose; the table's data is the
/// pendant's.
pub struct PositionsPanel {
    read_from: String,
    /// Empty: up to the controller's last number.
    read_to: String,
    filter: Filter,
    /// The number Teach here and Go to No. N use.
    number: String,
    name: String,
    edit: Option<CellEdit>,
    /// "I take the risk: write while a program runs", for the preview shown.
    take_the_risk: bool,
    file: FileWork<PositionsFile, PositionsDone>,
    /// The record whose move is under the pointer this frame (a Go, a preview row): the
    /// arm view draws its ghost.
    pub hovered: Option<PositionRecord>,
    /// The numbers shown, and what they were filtered from (revision, filter, capacity).
    visible: Option<VisibleRows>,
    /// A row to bring into sight once (the arm view's "Select in the table").
    scroll_to: Option<u16>,
}

type VisibleRows = ((u64, Filter, u16), Vec<u16>);

impl PositionsPanel {
    /// The number in the No. field (Teach here and Go to No. use it): the selected row.
    pub fn selected(&self) -> Option<u16> {
        self.number.trim().parse().ok()
    }

    /// Selects No. `n` (the arm view's "Select in the table"): the No. field takes it and
    /// the table scrolls to its row.
    pub fn select(&mut self, n: u16) {
        self.number = n.to_string();
        self.scroll_to = Some(n);
    }
}

impl Default for PositionsPanel {
    fn default() -> Self {
        Self {
            read_from: "1".into(),
            read_to: String::new(),
            filter: Filter::default(),
            number: "1".into(),
            name: String::new(),
            edit: None,
            take_the_risk: false,
            scroll_to: None,
            file: FileWork::new(&FILE_FIELD),
            hovered: None,
            visible: None,
        }
    }
}

/// A position number typed in a field, within the controller's table.
fn number_in(text: &str, positions: &Positions) -> Result<u16, String> {
    let cap = positions.capacity();
    match text.trim().parse::<u16>() {
        Ok(n) if (1..=cap).contains(&n) => Ok(n),
        _ => Err(format!("type a position number from 1 to {cap}")),
    }
}

/// `X 1.000 mm, Y ...`: a record in words (its empty values left out).
pub fn record_words(rec: &PositionRecord) -> String {
    let parts: Vec<String> = Column::ALL
        .iter()
        .filter_map(|&c| {
            let text = c.text(rec);
            if text.is_empty() {
                return None;
            }
            Some(match (c, c.heading().rsplit_once(' ')) {
                (Column::Arm, _) | (_, None) => format!("{} {text}", c.heading()),
                (_, Some((name, unit))) => format!("{name} {text} {unit}"),
            })
        })
        .collect();
    if parts.is_empty() {
        "no data".into()
    } else {
        parts.join(", ")
    }
}

/// What the controller holds at a row, in words (for the preview's "old").
fn row_words(row: &Row) -> String {
    match row {
        Row::Unread => "not read".into(),
        Row::Failed(why) => format!("not read: {why}"),
        Row::Empty => "empty".into(),
        Row::Held(rec) => record_words(rec),
    }
}

fn outcome_color(o: &Outcome, normal: Color32) -> Color32 {
    match o {
        Outcome::Holds => GREEN,
        Outcome::Differs(_) | Outcome::Unknown(_) => AMBER,
        Outcome::NotWritten(_) => RED,
        Outcome::Waiting | Outcome::Sending | Outcome::Written => normal,
    }
}

/// How a Go moves, said before it is pressed: 2D6H, PTP or CP and the speed, all from
/// the jog panel.
fn go_words(pendant: &Pendant) -> String {
    let sent = pendant.jog_sent();
    match sent.interpolation {
        Interpolation::Ptp => format!(
            "2D6H PTP at {} % (PTP/CP and speeds come from the jog panel)",
            sent.ptp_speed_pct
        ),
        Interpolation::Cp => format!(
            "2D6H CP at {} mm/s (PTP/CP and speeds come from the jog panel)",
            sent.cp_speed_mm_s
        ),
    }
}

/// Starts an import (read and parsed off the UI thread) or an export (the used rows
/// `filter` shows, written off the UI thread).
fn start_job(
    ask: FileAsk<PositionsFile>,
    pendant: &Pendant,
    filter: &Filter,
    now: Instant,
) -> Result<Job<PositionsDone>, String> {
    match ask.action {
        PositionsFile::Import => {
            read_job(ask.path, file::MAX_FILE_BYTES, now, |_, b| file::parse(b))
        }
        PositionsFile::Export => {
            let positions = &pendant.positions;
            let rows: Vec<(PositionRecord, Option<String>)> = positions
                .visible(filter)
                .into_iter()
                .filter_map(|n| {
                    positions
                        .shown(n)
                        .map(|rec| (rec, positions.names.get(&n).cloned()))
                })
                .collect();
            let json = is_json(&ask.path);
            write_job("writing", ask, rows.len(), now, move || {
                if json {
                    file::to_json(&rows)
                } else {
                    file::to_csv(&rows)
                }
            })
        }
    }
}

impl PositionsPanel {
    /// Draws the view; what is asked for goes to `out`.
    pub fn show(
        &mut self,
        ui: &mut Ui,
        pendant: &Pendant,
        folder: &Path,
        now: Instant,
        out: &mut Vec<Intent>,
    ) {
        let positions = &pendant.positions;
        let mut ask = Vec::new();
        self.toolbar(ui, positions, &mut ask);
        self.filter_bar(ui, positions);
        self.teach_row(ui, pendant, now, &mut ask);
        self.files(ui, pendant, folder, now, out);
        said_line(ui, &positions.feedback);
        ui.separator();
        // Filtered again only when the table, the draft or the filter changed.
        let key = (
            positions.revision(),
            self.filter.clone(),
            positions.capacity(),
        );
        if self.visible.as_ref().is_none_or(|(k, _)| *k != key) {
            self.visible = Some((key, positions.visible(&self.filter)));
        }
        let visible = self.visible.take().unwrap_or_default();
        self.table(ui, pendant, &visible.1, now, &mut ask);
        self.visible = Some(visible);
        out.extend(ask.into_iter().map(Intent::Positions));
    }

    /// The write's preview, whichever tab is in front, in a window kept inside `centre`
    /// (the panes: never over the top bar's STOP or the jog column's pad). Called once a
    /// frame after the panes.
    pub fn preview_window(
        &mut self,
        ctx: &egui::Context,
        centre: egui::Rect,
        pendant: &Pendant,
        out: &mut Vec<Intent>,
    ) {
        let Some(preview) = &pendant.positions.preview else {
            self.take_the_risk = false;
            return;
        };
        let mut ask = Vec::new();
        self.preview(ctx, centre, preview, &mut ask);
        out.extend(ask.into_iter().map(Intent::Positions));
    }

    fn toolbar(&mut self, ui: &mut Ui, positions: &Positions, ask: &mut Vec<PositionsIntent>) {
        ui.horizontal_wrapped(|ui| {
            if let Some(read) = &positions.read {
                let total = read.total().max(1);
                ui.add(
                    ProgressBar::new(read.done as f32 / total as f32)
                        .desired_width(160.0)
                        .text(format!("read {}/{}", read.done, read.total())),
                );
                if ui.button("Cancel read").clicked() {
                    ask.push(PositionsIntent::CancelRead);
                }
            } else {
                let cap = positions.capacity();
                let label = ui.label("Read No.");
                ui.add(TextEdit::singleline(&mut self.read_from).desired_width(44.0))
                    .labelled_by(label.id)
                    .on_hover_text("The first number to read");
                let to = ui.label("to No.");
                ui.add(
                    TextEdit::singleline(&mut self.read_to)
                        .desired_width(44.0)
                        .hint_text(cap.to_string()),
                )
                .labelled_by(to.id)
                .on_hover_text("The last number to read (empty: the controller's last)");
                let range = number_in(&self.read_from, positions).and_then(|from| {
                    let to = if self.read_to.trim().is_empty() {
                        Ok(cap)
                    } else {
                        number_in(&self.read_to, positions)
                    }?;
                    if from > to {
                        return Err(format!("{from} is after {to}"));
                    }
                    Ok((from, to))
                });
                let why = range.as_ref().err().cloned().unwrap_or_default();
                if ui
                    .add_enabled(
                        range.is_ok() && positions.write.is_none(),
                        Button::new("Read"),
                    )
                    .on_hover_text(
                        "Read these numbers from the controller (22DH, in the background); \
                         the draft stays as edited",
                    )
                    .on_disabled_hover_text(if positions.write.is_some() {
                        "a write is in progress"
                    } else {
                        why.as_str()
                    })
                    .clicked()
                    && let Ok((from, to)) = range
                {
                    ask.push(PositionsIntent::Read { from, to });
                }
            }
            ui.separator();
            if ui
                .add_enabled(positions.can_undo(), Button::new("Undo"))
                .clicked()
            {
                ask.push(PositionsIntent::Undo);
                self.edit = None;
            }
            if ui
                .add_enabled(positions.can_redo(), Button::new("Redo"))
                .clicked()
            {
                ask.push(PositionsIntent::Redo);
                self.edit = None;
            }
            ui.separator();
            let changed = positions.changed().len();
            let can_write = changed > 0 && !positions.busy() && positions.preview.is_none();
            let why = if positions.busy() {
                "a read or write is in progress"
            } else if positions.preview.is_some() {
                "the preview is open"
            } else {
                "no row of the draft differs from the controller"
            };
            if ui
                .add_enabled(can_write, Button::new("Write..."))
                .on_hover_text("Preview the changed rows, then write them to the controller")
                .on_disabled_hover_text(why)
                .clicked()
            {
                ask.push(PositionsIntent::PreviewWrite);
            }
            match changed {
                0 => ui.label(RichText::new("Draft = controller").color(GREEN)),
                1 => ui.label(RichText::new("1 row differs").color(AMBER)),
                n => ui.label(RichText::new(format!("{n} rows differ")).color(AMBER)),
            };
        });
    }

    fn filter_bar(&mut self, ui: &mut Ui, positions: &Positions) {
        let cap = positions.capacity();
        ui.horizontal_wrapped(|ui| {
            ui.label("Show No.");
            ui.add(egui::DragValue::new(&mut self.filter.from).range(1..=cap))
                .on_hover_text("The first number shown");
            ui.label("to");
            ui.add(egui::DragValue::new(&mut self.filter.to).range(1..=cap.max(1)))
                .on_hover_text("The last number shown");
            ui.checkbox(&mut self.filter.used_only, "Used only")
                .on_hover_text("Only rows the controller or the draft holds data in");
            ui.checkbox(&mut self.filter.differ_only, "Only rows that differ");
        });
    }

    fn teach_row(
        &mut self,
        ui: &mut Ui,
        pendant: &Pendant,
        now: Instant,
        ask: &mut Vec<PositionsIntent>,
    ) {
        let positions = &pendant.positions;
        let number = number_in(&self.number, positions);
        ui.horizontal_wrapped(|ui| {
            let label = ui.label("No.");
            ui.add(TextEdit::singleline(&mut self.number).desired_width(44.0))
                .labelled_by(label.id)
                .on_hover_text("The number Teach here and Go to No. use");
            let label = ui.label("Name");
            ui.add(
                TextEdit::singleline(&mut self.name)
                    .desired_width(110.0)
                    .hint_text("optional"),
            )
            .labelled_by(label.id);
            let shown_n = number
                .as_ref()
                .map_or_else(|_| "N".to_owned(), |n| n.to_string());
            let known = pendant.line.is_up() && pendant.controller.work.is_some();
            let teach_why = match &number {
                Err(why) => why.clone(),
                Ok(_) if !pendant.line.is_up() => "not connected".into(),
                Ok(_) => "no position read from the controller yet".into(),
            };
            if ui
                .add_enabled(
                    known && number.is_ok(),
                    Button::new(format!("Teach current pose into No. {shown_n}")),
                )
                .on_hover_text(
                    "Store the current work position (selected work and tool frame) and arm \
                     system into the draft; Write stores it in the controller",
                )
                .on_disabled_hover_text(teach_why)
                .clicked()
                && let Ok(n) = number
            {
                ask.push(PositionsIntent::TeachHere {
                    number: n,
                    name: std::mem::take(&mut self.name),
                });
            }
            let ready = pendant.motion_ready(now);
            let go_why = match (&number, &ready) {
                (Err(why), _) => why.clone(),
                (_, Err(e)) => e.to_string(),
                _ => String::new(),
            };
            let go = ui
                .add_enabled(
                    ready.is_ok() && number.is_ok(),
                    Button::new(format!("Go to No. {shown_n}")),
                )
                .on_hover_text(format!(
                    "Move to the controller's record (not the draft's): {}",
                    go_words(pendant)
                ))
                .on_disabled_hover_text(go_why);
            if let Ok(n) = number {
                if go.hovered()
                    && let Row::Held(r) = pendant.positions.row(n)
                {
                    self.hovered = Some(*r);
                }
                if go.clicked() {
                    ask.push(PositionsIntent::Go(n));
                }
            }
            ui.label(RichText::new(go_words(pendant)).small().color(GREY));
        });
    }

    fn files(
        &mut self,
        ui: &mut Ui,
        pendant: &Pendant,
        folder: &Path,
        now: Instant,
        out: &mut Vec<Intent>,
    ) {
        self.poll_job(now, out);
        let (filter, edit) = (&self.filter, &mut self.edit);
        self.file.row(ui, folder, now, &FILE_BUTTONS, |ask| {
            if ask.action == PositionsFile::Import {
                *edit = None;
            }
            start_job(ask, pendant, filter, now)
        });
    }

    /// A finished job: a read handed to the pendant, a write said (or asked to replace).
    fn poll_job(&mut self, now: Instant, out: &mut Vec<Intent>) {
        let Some((path, read)) = self.file.poll(
            now,
            out,
            |rows| format!("exported {rows} rows"),
            |_| PositionsFile::Export,
        ) else {
            return;
        };
        self.file.message = None;
        out.push(Intent::Positions(PositionsIntent::Import {
            path: path.display().to_string(),
            read,
        }));
    }

    /// The table: only the rows in sight are laid out.
    fn table(
        &mut self,
        ui: &mut Ui,
        pendant: &Pendant,
        visible: &[u16],
        now: Instant,
        ask: &mut Vec<PositionsIntent>,
    ) {
        let positions = &pendant.positions;
        if visible.is_empty() {
            ui.label("No rows under this filter.");
            return;
        }
        let ready = pendant.motion_ready(now);
        let go_why = ready
            .as_ref()
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        let go_how = go_words(pendant);
        let selected = self.selected();
        let scroll = ui.spacing().scroll;
        ui.spacing_mut().scroll = egui::style::ScrollStyle::solid();
        let height = ui.available_height();
        egui::ScrollArea::horizontal()
            .id_salt("positions-x")
            .show(ui, |ui| {
                let mut table = TableBuilder::new(ui);
                if let Some(i) = self
                    .scroll_to
                    .take()
                    .and_then(|n| visible.iter().position(|&m| m == n))
                {
                    table = table.scroll_to_row(i, Some(egui::Align::Center));
                }
                table
                    .id_salt("positions-table")
                    .striped(true)
                    .auto_shrink([false, false])
                    .max_scroll_height(height)
                    .cell_layout(egui::Layout::left_to_right(egui::Align::Center))
                    .column(Col::exact(44.0))
                    .column(Col::exact(96.0))
                    .columns(Col::exact(VALUE_WIDTH), Column::ALL.len())
                    .column(Col::remainder().at_least(220.0))
                    .header(ROW_HEIGHT, |mut h| {
                        h.col(|ui| {
                            ui.strong("No.");
                        });
                        h.col(|ui| {
                            ui.strong("Name");
                        });
                        for c in Column::ALL {
                            h.col(|ui| {
                                ui.strong(c.heading());
                            });
                        }
                        h.col(|ui| {
                            ui.strong("Write / Go");
                        });
                    })
                    .body(|body| {
                        body.rows(ROW_HEIGHT, visible.len(), |mut row| {
                            let n = visible[row.index()];
                            let differs = positions.differs(n);
                            row.col(|ui| {
                                let t = RichText::new(n.to_string());
                                let t = if differs { t.color(AMBER) } else { t };
                                if selected == Some(n) {
                                    ui.label(t.strong().underline());
                                } else {
                                    ui.label(t);
                                }
                            });
                            row.col(|ui| self.name_cell(ui, positions, n, ask));
                            for c in Column::ALL {
                                row.col(|ui| self.value_cell(ui, positions, n, c, ask));
                            }
                            row.col(|ui| {
                                if let Some(o) = positions.outcome(n) {
                                    let color = outcome_color(o, ui.visuals().text_color());
                                    let text = o.to_string();
                                    ui.add(
                                        egui::Label::new(RichText::new(&text).color(color))
                                            .truncate(),
                                    )
                                    .on_hover_text(format!("No. {n}: {text}"));
                                }
                                if differs
                                    && ui
                                        .small_button("Revert")
                                        .on_hover_text("Back to the controller's")
                                        .clicked()
                                {
                                    ask.push(PositionsIntent::Revert(n));
                                    self.edit = None;
                                }
                                if let Row::Held(held) = positions.row(n) {
                                    let go = ui
                                        .add_enabled(ready.is_ok(), Button::new("Go").small())
                                        .on_hover_text(format!(
                                            "Go to No. {n} (the controller's record): {go_how}"
                                        ))
                                        .on_disabled_hover_text(&go_why);
                                    if go.hovered() {
                                        self.hovered = Some(*held);
                                    }
                                    if go.clicked() {
                                        ask.push(PositionsIntent::Go(n));
                                    }
                                }
                            });
                        });
                    });
            });
        ui.spacing_mut().scroll = scroll;
    }

    /// An edit of this cell in progress: the field, and what ends it (Enter or leaving:
    /// the text goes to the pendant; Esc: forgotten).
    fn editing(
        &mut self,
        ui: &mut Ui,
        n: u16,
        column: Option<Column>,
        ask: &mut Vec<PositionsIntent>,
    ) -> bool {
        let Some(edit) = self
            .edit
            .as_mut()
            .filter(|e| e.number == n && e.column == column)
        else {
            return false;
        };
        let salt = column.map_or(usize::MAX, |c| {
            Column::ALL.iter().position(|&k| k == c).unwrap_or(0)
        });
        let r = ui.add(
            TextEdit::singleline(&mut edit.text)
                .id_salt(("position-cell", n, salt))
                .desired_width(f32::INFINITY)
                .margin(egui::vec2(2.0, 1.0)),
        );
        if !edit.focused {
            r.request_focus();
            edit.focused = true;
        } else if r.lost_focus() {
            let text = std::mem::take(&mut edit.text);
            self.edit = None;
            if !ui.input(|i| i.key_pressed(Key::Escape)) {
                ask.push(match column {
                    Some(column) => PositionsIntent::SetCell {
                        number: n,
                        column,
                        text,
                    },
                    None => PositionsIntent::SetName {
                        number: n,
                        name: text,
                    },
                });
            }
        } else if !r.has_focus() {
            // Focus went elsewhere before this field had it: the edit ends unchanged.
            self.edit = None;
        }
        true
    }

    fn begin_edit(&mut self, n: u16, column: Option<Column>, text: String) {
        self.edit = Some(CellEdit {
            number: n,
            column,
            text,
            focused: false,
        });
    }

    fn name_cell(
        &mut self,
        ui: &mut Ui,
        positions: &Positions,
        n: u16,
        ask: &mut Vec<PositionsIntent>,
    ) {
        if self.editing(ui, n, None, ask) {
            return;
        }
        let name = positions.names.get(&n).map_or("", String::as_str);
        let r = ui
            .add(egui::Label::new(name).truncate().sense(Sense::click()))
            .on_hover_text(format!("No. {n} name (the pendant's own): click to edit"));
        if r.clicked() || r.double_clicked() {
            self.begin_edit(n, None, name.to_owned());
        }
    }

    fn value_cell(
        &mut self,
        ui: &mut Ui,
        positions: &Positions,
        n: u16,
        column: Column,
        ask: &mut Vec<PositionsIntent>,
    ) {
        if self.editing(ui, n, Some(column), ask) {
            return;
        }
        let row = positions.row(n);
        let shown = positions.shown(n);
        let text = shown.as_ref().map(|r| column.text(r)).unwrap_or_default();
        let first = column == Column::ALL[0];
        // What the cell says, its colour and what its hover adds.
        let (words, color, hover) = match (&shown, row) {
            (None, Row::Unread) if first => ("not read".to_owned(), GREY, None),
            (None, Row::Failed(why)) if first => {
                (format!("not read: {why}"), AMBER, Some(why.clone()))
            }
            (None, _) => (String::new(), ui.visuals().text_color(), None),
            (Some(_), _) if positions.draft(n).is_some() => {
                let theirs = match row {
                    Row::Held(h) => Some(column.text(h)),
                    _ => None,
                };
                if theirs.as_ref() == Some(&text) {
                    (text.clone(), ui.visuals().text_color(), None)
                } else {
                    let was = match (theirs, row) {
                        (Some(t), _) if t.is_empty() => "empty".to_owned(),
                        (Some(t), _) => t,
                        (None, r) => row_words(r),
                    };
                    (
                        text.clone(),
                        AMBER,
                        Some(format!("the controller's: {was}")),
                    )
                }
            }
            (Some(_), _) => (text.clone(), ui.visuals().text_color(), None),
        };
        let label = format!("No. {n} {}", column.heading());
        let mut r = ui.add(
            egui::Label::new(RichText::new(words).color(color))
                .truncate()
                .sense(Sense::click()),
        );
        // Its accessible name says which cell it is (screen readers, tests).
        r.widget_info(|| {
            egui::WidgetInfo::labeled(egui::Role::Label, true, format!("{label}: {text}"))
        });
        r = match hover {
            Some(h) => r.on_hover_text(format!("{label}: {h}")),
            None => r.on_hover_text(format!("{label}: click to edit")),
        };
        if r.clicked() || r.double_clicked() {
            self.begin_edit(n, Some(column), text);
        }
        if positions.draft(n).is_some() {
            r.context_menu(|ui| {
                if ui.button("Back to the controller's").clicked() {
                    ask.push(PositionsIntent::Revert(n));
                    self.edit = None;
                    ui.close();
                }
            });
        }
    }

    /// The write's preview, in a window that stays inside the centre (the top bar's
    /// STOP is never covered).
    fn preview(
        &mut self,
        ctx: &egui::Context,
        area: egui::Rect,
        preview: &Preview,
        ask: &mut Vec<PositionsIntent>,
    ) {
        let mut open = true;
        egui::Window::new("Write positions to the controller")
            .collapsible(false)
            .resizable(true)
            .constrain_to(area)
            .default_pos(area.left_top() + egui::vec2(20.0, 20.0))
            .default_width(560.0)
            .open(&mut open)
            .show(ctx, |ui| {
                let n = preview.rows.len();
                ui.label(format!(
                    "{n} {} ({}):",
                    if n == 1 { "row changes" } else { "rows change" },
                    preview.kind.id()
                ));
                egui::ScrollArea::vertical()
                    .max_height(280.0)
                    .id_salt("positions-preview-rows")
                    .show(ui, |ui| {
                        for row in &preview.rows {
                            let line = ui.label(format!(
                                "No. {}: {} -> {}",
                                row.number,
                                row_words(&row.old),
                                record_words(&row.new)
                            ));
                            if line.hovered() {
                                // Its ghost in the arm view: where the new row would take the arm.
                                self.hovered = Some(row.new);
                            }
                            match &row.check {
                                Ok(()) => {
                                    ui.label(RichText::new("    the arm can go there").color(GREEN))
                                }
                                Err(why) => ui.label(
                                    RichText::new(format!("    the arm could not go there: {why}"))
                                        .color(AMBER),
                                ),
                            };
                        }
                    });
                ui.separator();
                if preview.program_running {
                    ui.label(
                        RichText::new("215H reports a program running")
                            .color(RED)
                            .strong(),
                    );
                    ui.checkbox(
                        &mut self.take_the_risk,
                        "I take the risk: write while a program runs",
                    );
                }
                ui.label(
                    "Whether the controller keeps these after power-off is not known from the \
                     protocol (PROTOCOL.md 3.48): save to flash with the controller's own \
                     tools (IAI's PC software or the teaching pendant).",
                );
                ui.horizontal(|ui| {
                    let can = !preview.program_running || self.take_the_risk;
                    if ui
                        .add_enabled(can, Button::new("Write"))
                        .on_disabled_hover_text("a program is running: tick the risk first")
                        .clicked()
                    {
                        ask.push(PositionsIntent::ConfirmWrite {
                            take_the_risk: self.take_the_risk,
                        });
                    }
                    if ui.button("Cancel").clicked() {
                        ask.push(PositionsIntent::CancelPreview);
                    }
                });
            });
        if !open {
            ask.push(PositionsIntent::CancelPreview);
        }
    }
}

impl Pane for PositionsPanel {
    fn ui(&mut self, ui: &mut Ui, cx: &mut PaneCx<'_>) {
        self.show(ui, cx.pendant, cx.folder, cx.now, cx.intents);
    }
}
