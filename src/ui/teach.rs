//! The teach list: record the current pose under a name, go there (2D4H), rename,
//! reorder, delete, and save or load the list as CSV or JSON.

use std::path::Path;
use std::time::Instant;

use egui::{Button, RichText, TextEdit, Ui};
use egui_extras::{Column as Col, TableBuilder};

use super::file_field::{Browse, FieldSpec, FileAsk, Purpose};
use super::file_work::{Done, FileWork, is_json, read_job, write_job};
use super::pane::{Pane, PaneCx};
use super::widgets::{AMBER, RED, reserved_line};
use crate::files::DOCUMENT_LIMIT;
use crate::files::job::Job;
use crate::pendant::teach::{TeachList, arm_word};
use crate::pendant::{Intent, Level, Pendant};

const ROW_HEIGHT: f32 = 22.0;

/// What the file field is for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum TeachFile {
    Save,
    Load,
}

static FILE_FIELD: FieldSpec<TeachFile> = FieldSpec {
    label: "File",
    hint: "points.csv or .json",
    width: 170.0,
    browse: &[
        Browse {
            label: "Load a list...",
            action: TeachFile::Load,
            purpose: Purpose::Open,
        },
        Browse {
            label: "Save the list as...",
            action: TeachFile::Save,
            purpose: Purpose::Save,
        },
    ],
    filters: &[("Teach list", &["csv", "json"])],
};

/// A finished file job: the list read, or the points saved.
type TeachDone = Done<TeachList>;

/// The panel's own state: the name being typed, the selected row, the file and its job.
pub struct TeachPanel {
    name: String,
    selected: Option<usize>,
    rename: String,
    file: FileWork<TeachFile, TeachDone>,
    /// The row whose Go is under the pointer (the arm view shows its ghost).
    pub hovered_go: Option<usize>,
}

impl TeachPanel {
    /// The selected row.
    pub fn selected(&self) -> Option<usize> {
        self.selected
    }

    /// Selects row `i` (the arm view's "Select in the table").
    pub fn select(&mut self, i: usize, name: &str) {
        self.selected = Some(i);
        self.rename = name.to_owned();
    }
}

impl Default for TeachPanel {
    fn default() -> Self {
        Self {
            name: String::new(),
            selected: None,
            rename: String::new(),
            file: FileWork::new(&FILE_FIELD),
            hovered_go: None,
        }
    }
}

impl TeachPanel {
    /// Draws the list; what is asked for goes to `intents` (a changed list as a whole).
    pub fn show(
        &mut self,
        ui: &mut Ui,
        pendant: &Pendant,
        folder: &Path,
        now: Instant,
        intents: &mut Vec<Intent>,
    ) {
        ui.horizontal(|ui| {
            let label = ui.label("Name");
            ui.add(
                TextEdit::singleline(&mut self.name)
                    .desired_width(120.0)
                    .hint_text("P1, P2..."),
            )
            .labelled_by(label.id);
            let can_record = pendant.controller.work.is_some() && pendant.line.is_up();
            if ui
                .add_enabled(can_record, Button::new("Record"))
                .on_hover_text("Store the current work position, arm system, work and tool numbers")
                .on_disabled_hover_text("No position read from the controller")
                .clicked()
            {
                intents.push(Intent::TeachRecord(std::mem::take(&mut self.name)));
            }
            let mut rmc = pendant.settings.rmc.clone();
            if ui
                .checkbox(&mut rmc.teach_axes, "with RMC axes")
                .on_hover_text("Record takes the RMC axes' Command Positions too; Go moves them with Move Absolute (20)")
                .changed()
            {
                intents.push(Intent::Axes(crate::pendant::axes::AxisIntent::Connection(rmc)));
            }
        });
        self.rows(ui, pendant, now, intents);
        self.actions(ui, pendant, intents);
        ui.separator();
        self.files(ui, pendant, folder, now, intents);
    }

    fn rows(&mut self, ui: &mut Ui, pendant: &Pendant, now: Instant, intents: &mut Vec<Intent>) {
        self.hovered_go = None;
        let ready = pendant.motion_ready(now);
        let why = ready
            .as_ref()
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        let how = go_words(pendant);
        let mut go = None;
        let list = pendant.teach.list();
        if list.is_empty() {
            ui.label("No points taught yet.");
            return;
        }
        // Only the rows in sight are laid out: 10,000 points cost what 10 do. A pane too
        // narrow for every column scrolls sideways, header and rows together.
        // Solid scroll bars here: a floating one would lie over the last row.
        let scroll = ui.spacing().scroll;
        ui.spacing_mut().scroll = egui::style::ScrollStyle::solid();
        egui::ScrollArea::horizontal()
            .id_salt("teach-list-x")
            .show(ui, |ui| {
                TableBuilder::new(ui)
                    .id_salt("teach-list")
                    .striped(true)
                    .max_scroll_height(220.0)
                    .cell_layout(egui::Layout::left_to_right(egui::Align::Center))
                    .column(Col::exact(34.0))
                    .column(Col::initial(90.0).at_least(60.0))
                    .column(Col::initial(190.0).at_least(150.0))
                    .column(Col::initial(44.0))
                    .column(Col::remainder().at_least(60.0))
                    .header(ROW_HEIGHT, |mut h| {
                        for title in ["", "Name", "X / Y / Z / R (work)", "Arm", "Work / Tool"] {
                            h.col(|ui| {
                                ui.strong(title);
                            });
                        }
                    })
                    .body(|body| {
                        body.rows(ROW_HEIGHT, list.len(), |mut row| {
                            let i = row.index();
                            let Some(p) = list.get(i) else { return };
                            row.col(|ui| {
                                let b = ui
                                    .add_enabled(ready.is_ok(), Button::new("Go"))
                                    .on_hover_text(format!("Go to \"{}\": {how}", p.name))
                                    .on_disabled_hover_text(&why);
                                if b.hovered() {
                                    self.hovered_go = Some(i);
                                }
                                if b.clicked() {
                                    go = Some(i);
                                }
                            });
                            row.col(|ui| {
                                let selected = self.selected == Some(i);
                                if ui.selectable_label(selected, &p.name).clicked() {
                                    self.selected = Some(i);
                                    self.rename = p.name.clone();
                                }
                            });
                            row.col(|ui| {
                                let [x, y, z, r] =
                                    p.pose.map(|v| crate::protocol::Milli(v).units());
                                ui.monospace(format!("{x:.3} / {y:.3} / {z:.3} / {r:.3}"));
                            });
                            row.col(|ui| {
                                ui.label(arm_word(p.arm));
                            });
                            row.col(|ui| {
                                let frames = format!("{} / {}", p.work, p.tool);
                                if p.axes.is_empty() {
                                    ui.label(frames);
                                } else {
                                    let axes: Vec<String> = p
                                        .axes
                                        .iter()
                                        .map(|v| format!("{:.3}", crate::protocol::Milli(*v).units()))
                                        .collect();
                                    ui.label(format!("{frames}  RMC {}", axes.join(" / ")))
                                        .on_hover_text("the RMC axes' positions, axis 1 first (Go moves them with Move Absolute)");
                                }
                            });
                        });
                    });
            });
        ui.spacing_mut().scroll = scroll;
        if let Some(i) = go {
            intents.push(Intent::TeachGo(i));
        }
    }

    /// Up, Down, Delete and Rename, each on a copy of the list pushed whole.
    fn actions(&mut self, ui: &mut Ui, pendant: &Pendant, intents: &mut Vec<Intent>) {
        let Some(i) = self.selected.filter(|&i| i < pendant.teach.list().len()) else {
            return;
        };
        let edit = |f: &mut dyn FnMut(&mut TeachList)| {
            let mut list = pendant.teach.list().clone();
            f(&mut list);
            list
        };
        ui.horizontal_wrapped(|ui| {
            if ui.button("Up").clicked() {
                intents.push(Intent::TeachList(edit(&mut |l| {
                    self.selected = l.move_up(i).ok();
                })));
            }
            if ui.button("Down").clicked() {
                intents.push(Intent::TeachList(edit(&mut |l| {
                    self.selected = l.move_down(i).ok();
                })));
            }
            if ui.button("Delete").clicked() {
                intents.push(Intent::TeachList(edit(&mut |l| {
                    let _ = l.remove(i);
                })));
                self.selected = None;
            }
        });
        ui.horizontal(|ui| {
            let label = ui.label("Rename");
            ui.add(TextEdit::singleline(&mut self.rename).desired_width(120.0))
                .labelled_by(label.id);
            if ui.button("Apply").clicked() {
                let mut list = pendant.teach.list().clone();
                match list.rename(i, &self.rename) {
                    Ok(()) => intents.push(Intent::TeachList(list)),
                    Err(e) => self.file.message = Some((false, e.to_string())),
                }
            }
        });
    }

    fn files(
        &mut self,
        ui: &mut Ui,
        pendant: &Pendant,
        folder: &Path,
        now: Instant,
        intents: &mut Vec<Intent>,
    ) {
        self.poll_job(now, intents);
        ui.horizontal_wrapped(|ui| {
            self.file.field(ui, folder, now);
        });
        ui.horizontal(|ui| {
            self.file
                .button(ui, ("Save", None, TeachFile::Save), true, folder);
            let waiting = pendant.teach.pending().is_some();
            let load = (
                "Load",
                Some(
                    "Reads a list; it replaces this one only when you say so. A file with \
                     an error or no points changes nothing",
                ),
                TeachFile::Load,
            );
            self.file.button(ui, load, !waiting, folder);
            if let Some((path, n)) = pendant.teach.undoable_load()
                && ui
                    .button("Undo load")
                    .on_hover_text(format!(
                        "Back to the {n} points the load of {path} replaced"
                    ))
                    .clicked()
            {
                intents.push(Intent::TeachUndoLoad);
                self.selected = None;
            }
        });
        self.file.start(|ask| start_job(ask, pendant, now));
        self.file.lines(ui);
        if let Some(p) = pendant.teach.pending() {
            ui.label(
                RichText::new(format!(
                    "Replace the {} points of the list with the {} points of {}?",
                    pendant.teach.list().len(),
                    p.list.len(),
                    p.path
                ))
                .color(AMBER),
            );
            ui.horizontal(|ui| {
                if ui.button("Replace").clicked() {
                    intents.push(Intent::TeachConfirmLoad);
                    self.selected = None;
                }
                if ui.button("Cancel").clicked() {
                    intents.push(Intent::TeachCancelLoad);
                }
            });
        }
        // The panel's own word (a save) or the pendant's (a load): one reserved line.
        let said = match (&self.file.message, pendant.teach.feedback()) {
            (Some((ok, text)), _) => Some((*ok, text.as_str())),
            (None, Some((level, text))) => Some((*level == Level::Info, text.as_str())),
            (None, None) => None,
        };
        let said = said.map(|(ok, t)| (if ok { ui.visuals().text_color() } else { RED }, t));
        reserved_line(ui, said, said.map(|(_, t)| t));
    }
}

impl TeachPanel {
    /// Takes a finished job's result: a save said (or asked to replace), a read handed
    /// to the pendant.
    fn poll_job(&mut self, now: Instant, intents: &mut Vec<Intent>) {
        let words = |points| match points {
            1 => "saved 1 point".to_owned(),
            n => format!("saved {n} points"),
        };
        let Some((path, read)) = self.file.poll(now, intents, words, |_| TeachFile::Save) else {
            return;
        };
        intents.push(Intent::TeachLoaded {
            path: path.display().to_string(),
            read,
        });
    }
}

/// Starts the job a file action asks for: the list written (as CSV or JSON by the name's
/// extension) or a file read and parsed, off the UI thread.
fn start_job(
    ask: FileAsk<TeachFile>,
    pendant: &Pendant,
    now: Instant,
) -> Result<Job<TeachDone>, String> {
    match ask.action {
        TeachFile::Save => {
            let list = pendant.teach.list().clone();
            let json = is_json(&ask.path);
            write_job("saving", ask, list.len(), now, move || {
                if json { list.to_json() } else { list.to_csv() }
            })
        }
        TeachFile::Load => read_job(ask.path, DOCUMENT_LIMIT, now, |path, bytes| {
            if is_json(path) {
                TeachList::from_json_bytes(bytes)
            } else {
                TeachList::from_csv_bytes(bytes)
            }
        }),
    }
}

/// How a Go moves, said before it is pressed: 2D4H, PTP or CP, the speed sent.
fn go_words(pendant: &Pendant) -> String {
    let sent = pendant.jog_sent();
    match sent.interpolation {
        crate::pendant::Interpolation::Ptp => format!(
            "2D4H PTP at {} % with the point's arm system (the ghost shows the end)",
            sent.ptp_speed_pct
        ),
        crate::pendant::Interpolation::Cp => format!(
            "2D4H CP (straight line) at {} mm/s (the ghost shows the line)",
            sent.cp_speed_mm_s
        ),
    }
}

impl Pane for TeachPanel {
    fn ui(&mut self, ui: &mut Ui, cx: &mut PaneCx<'_>) {
        egui::ScrollArea::vertical().show(ui, |ui| {
            self.show(ui, cx.pendant, cx.folder, cx.now, cx.intents);
        });
    }
}
