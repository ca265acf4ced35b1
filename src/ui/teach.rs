//! The teach list: record the current pose under a name, go there (2D4H), rename,
//! reorder, delete, and save or load the list as CSV or JSON.

use std::path::Path;
use std::time::Instant;

use egui::{Button, RichText, TextEdit, Ui};

use super::widgets::{AMBER, RED, reserved_line};
use crate::pendant::teach::{TeachList, arm_word};
use crate::pendant::{Intent, Level, Pendant};

/// The panel's own state: the name being typed, the selected row, the file path.
#[derive(Default)]
pub struct TeachPanel {
    name: String,
    selected: Option<usize>,
    rename: String,
    path: String,
    file_message: Option<(bool, String)>,
    /// The row whose Go is under the pointer (the arm view shows its ghost).
    pub hovered_go: Option<usize>,
}

impl TeachPanel {
    /// Draws the list; what is asked for goes to `intents` (a changed list as a whole).
    pub fn show(
        &mut self,
        ui: &mut Ui,
        pendant: &Pendant,
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
        });
        self.rows(ui, pendant, now, intents);
        self.actions(ui, pendant, intents);
        ui.separator();
        self.files(ui, pendant, intents);
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
        egui::ScrollArea::vertical()
            .max_height(220.0)
            .show(ui, |ui| {
                egui::Grid::new("teach-list")
                    .striped(true)
                    .num_columns(5)
                    .show(ui, |ui| {
                        for h in ["", "Name", "X / Y / Z / R (work)", "Arm", "Work / Tool"] {
                            ui.label(RichText::new(h).strong());
                        }
                        ui.end_row();
                        for (i, p) in list.iter().enumerate() {
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
                            let selected = self.selected == Some(i);
                            if ui.selectable_label(selected, &p.name).clicked() {
                                self.selected = Some(i);
                                self.rename = p.name.clone();
                            }
                            let [x, y, z, r] = p.pose.map(|v| f64::from(v) / 1000.0);
                            ui.monospace(format!("{x:.3} / {y:.3} / {z:.3} / {r:.3}"));
                            ui.label(arm_word(p.arm));
                            ui.label(format!("{} / {}", p.work, p.tool));
                            ui.end_row();
                        }
                    });
            });
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
                    Err(e) => self.file_message = Some((false, e.to_string())),
                }
            }
        });
    }

    fn files(&mut self, ui: &mut Ui, pendant: &Pendant, intents: &mut Vec<Intent>) {
        ui.horizontal(|ui| {
            let label = ui.label("File");
            ui.add(
                TextEdit::singleline(&mut self.path)
                    .desired_width(170.0)
                    .hint_text("points.csv or .json"),
            )
            .labelled_by(label.id);
        });
        ui.horizontal(|ui| {
            if ui.button("Save").clicked() {
                self.file_message = Some(save(&self.path, pendant));
            }
            let waiting = pendant.teach.pending().is_some();
            if ui
                .add_enabled(!waiting, Button::new("Load"))
                .on_hover_text(
                    "Reads a list; it replaces this one only when you say so. A file with \
                     an error or no points changes nothing",
                )
                .clicked()
            {
                self.file_message = None;
                intents.push(load(&self.path));
            }
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
        let said = match (&self.file_message, &pendant.teach_feedback) {
            (Some((ok, text)), _) => Some((*ok, text.as_str())),
            (None, Some((level, text))) => Some((*level == Level::Info, text.as_str())),
            (None, None) => None,
        };
        let said = said.map(|(ok, t)| (if ok { ui.visuals().text_color() } else { RED }, t));
        reserved_line(ui, said, said.map(|(_, t)| t));
    }
}

fn is_json(path: &str) -> bool {
    Path::new(path)
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("json"))
}

/// Writes the list; the message says where, or why not.
fn save(path: &str, pendant: &Pendant) -> (bool, String) {
    let path = path.trim();
    if path.is_empty() {
        return (false, "enter a file name first".into());
    }
    let list = pendant.teach.list();
    let text = if is_json(path) {
        list.to_json()
    } else {
        list.to_csv()
    };
    match crate::files::write_whole(Path::new(path), text.as_bytes()) {
        Ok(()) => (true, format!("saved {} points to {path}", list.len())),
        Err(e) => (false, e),
    }
}

/// Reads a list (a regular file, bounded in size; still on the UI thread, bounded) and
/// hands the pendant its points or why not.
fn load(path: &str) -> Intent {
    let path = path.trim().to_owned();
    let read = if path.is_empty() {
        Err("enter a file name first".to_owned())
    } else {
        crate::files::read_bounded(Path::new(&path), crate::files::DOCUMENT_LIMIT).and_then(
            |bytes| {
                let list = if is_json(&path) {
                    TeachList::from_json_bytes(&bytes)
                } else {
                    TeachList::from_csv_bytes(&bytes)
                };
                list.map_err(|e| format!("{path}: {e}"))
            },
        )
    };
    Intent::TeachLoaded { path, read }
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
