//! The snapshots section of the Alarms view: take one (progress, Cancel), compare the
//! last two or a file with the latest, save the latest; the differences table by table;
//! a support bundle written to a new folder.

use std::path::Path;
use std::time::Instant;

use egui::{RichText, Ui};
use egui_extras::{Column as Col, TableBuilder};

use super::file_field::{Browse, FieldSpec, FileAsk, Purpose};
use super::file_work::{Done, FileButton, FileWork, read_job, write_job};
use super::widgets::{AMBER, GREY, said_line};
use crate::files::job::Job;
use crate::pendant::bundle;
use crate::pendant::snapshot::{MAX_FILE_BYTES, Part, Snapshot, SnapshotIntent, Snapshots};
use crate::pendant::{Intent, Pendant};

const ROW_HEIGHT: f32 = 20.0;

/// What the file field is for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum SnapshotFile {
    Save,
    Open,
}

static FILE_FIELD: FieldSpec<SnapshotFile> = FieldSpec {
    label: "Snapshot file",
    hint: "snapshot.json",
    width: 170.0,
    browse: &[
        Browse {
            label: "Save the latest snapshot as...",
            action: SnapshotFile::Save,
            purpose: Purpose::Save,
        },
        Browse {
            label: "Open a snapshot to compare...",
            action: SnapshotFile::Open,
            purpose: Purpose::Open,
        },
    ],
    filters: &[("Controller snapshot", &["json"])],
};

static FILE_BUTTONS: [FileButton<SnapshotFile>; 2] = [
    (
        "Save latest",
        Some("Write the latest snapshot to the file (JSON)"),
        SnapshotFile::Save,
    ),
    (
        "Open and compare",
        Some("Read a snapshot file and compare it with the latest snapshot"),
        SnapshotFile::Open,
    ),
];

/// The section's own state: its file field, and a support bundle being written and
/// the last word on it.
pub struct SnapshotsSection {
    file: FileWork<SnapshotFile, Done<Box<Snapshot>>>,
    bundle: Option<Job<Result<String, String>>>,
    bundle_said: Option<(bool, String)>,
}

impl Default for SnapshotsSection {
    fn default() -> Self {
        Self {
            file: FileWork::new(&FILE_FIELD),
            bundle: None,
            bundle_said: None,
        }
    }
}

fn start_job(
    mut ask: FileAsk<SnapshotFile>,
    snapshots: &Snapshots,
    now: Instant,
) -> Result<Job<Done<Box<Snapshot>>>, String> {
    if ask.path.extension().is_none() {
        ask.path.set_extension("json");
    }
    match ask.action {
        SnapshotFile::Open => read_job(ask.path, MAX_FILE_BYTES, now, |_, bytes| {
            Snapshot::from_json(bytes).map(Box::new)
        }),
        SnapshotFile::Save => {
            let latest = snapshots
                .latest
                .clone()
                .ok_or("no snapshot taken yet: Take snapshot first")?;
            write_job("writing", ask, 1, now, move || {
                String::from_utf8_lossy(&latest.to_json()).into_owned()
            })
        }
    }
}

impl SnapshotsSection {
    /// Draws the section; what is asked for goes to `out`.
    pub fn show(
        &mut self,
        ui: &mut Ui,
        pendant: &Pendant,
        folder: &Path,
        now: Instant,
        out: &mut Vec<Intent>,
    ) {
        let snapshots = &pendant.snapshots;
        let mut ask = Vec::new();
        ui.horizontal_wrapped(|ui| {
            ui.label(RichText::new("Snapshots").strong());
            let taking = snapshots.part();
            if ui
                .add_enabled(taking.is_none(), egui::Button::new("Take snapshot"))
                .on_hover_text(
                    "Read versions, the position table, the coordinate tables, global flags \
                     and variables, the alarm history and the zones into one snapshot",
                )
                .clicked()
            {
                ask.push(SnapshotIntent::Take);
            }
            if let (Some(part), Some((done, all))) = (taking, snapshots.progress()) {
                ui.spinner();
                ui.label(format!("{} ({}/{all})", part.name(), done + 1));
                // The position table's own read: how far it is.
                if let (Part::Positions, Some(job)) = (part, pendant.positions.read.as_ref()) {
                    ui.label(format!("{} of {} numbers", job.done, job.total()));
                }
                if ui.button("Cancel").clicked() {
                    ask.push(SnapshotIntent::Cancel);
                }
            }
            if ui
                .add_enabled(
                    snapshots.previous.is_some() && snapshots.latest.is_some(),
                    egui::Button::new("Compare the last two"),
                )
                .clicked()
            {
                ask.push(SnapshotIntent::CompareLast);
            }
            let source = snapshots.restore_source();
            let restore = ui
                .add_enabled(
                    source.is_some() && taking.is_none(),
                    egui::Button::new("Restore positions to the draft"),
                )
                .on_hover_text(match source {
                    Some(s) => format!(
                        "Put the {} position(s) of the snapshot of {} into the Positions \
                         view's draft (one Undo step). Nothing is sent: Write there shows \
                         every changed row first.",
                        s.positions.len(),
                        s.taken
                    ),
                    None => "Take or open a snapshot first".to_owned(),
                });
            if restore.clicked() {
                ask.push(SnapshotIntent::RestorePositions);
            }
        });
        said_line(ui, &snapshots.feedback);
        self.poll_job(now, out);
        self.file.row(ui, folder, now, &FILE_BUTTONS, |ask| {
            start_job(ask, snapshots, now)
        });
        self.bundle_row(ui, pendant, folder, now);
        if let Some(latest) = &snapshots.latest {
            ui.label(RichText::new(format!("Latest: {}", latest.summary())).color(GREY));
        }
        if let Some(c) = &snapshots.comparison {
            if let Some(w) = &c.warning {
                ui.colored_label(AMBER, w);
            }
            ui.label(c.summary());
            if !c.differences.is_empty() {
                ui.push_id("snapshot-differences", |ui| {
                    TableBuilder::new(ui)
                        .striped(true)
                        .max_scroll_height(200.0)
                        .column(Col::initial(120.0).at_least(80.0))
                        .column(Col::initial(90.0).at_least(60.0))
                        .column(Col::initial(200.0).at_least(80.0).clip(true))
                        .column(Col::remainder().at_least(80.0).clip(true))
                        .header(ROW_HEIGHT, |mut h| {
                            for title in ["Table", "Row", "Was", "Now"] {
                                h.col(|ui| {
                                    ui.strong(title);
                                });
                            }
                        })
                        .body(|body| {
                            body.rows(ROW_HEIGHT, c.differences.len(), |mut row| {
                                let d = &c.differences[row.index()];
                                for text in [d.table, &d.row, &d.old, &d.new] {
                                    row.col(|ui| {
                                        ui.label(text).on_hover_text(text);
                                    });
                                }
                            });
                        });
                });
            }
        }
        out.extend(ask.into_iter().map(Intent::Snapshot));
    }

    /// "Write support bundle": a new folder in the files folder with the latest snapshot,
    /// the alarm history, the last frames, Messages, the settings and the versions; what
    /// became of it beside the button.
    fn bundle_row(&mut self, ui: &mut Ui, pendant: &Pendant, folder: &Path, now: Instant) {
        if let Some(done) = Job::take(&mut self.bundle, now) {
            self.bundle_said = Some(match done {
                Ok(Ok(said)) => (true, said),
                Ok(Err(why)) => (false, why),
                Err(lost) => (false, format!("support bundle: {lost}")),
            });
        }
        ui.horizontal_wrapped(|ui| {
            let idle = self.bundle.is_none();
            let r = ui
                .add_enabled(idle, egui::Button::new("Write support bundle"))
                .on_hover_text(format!(
                    "A new folder in {} with the latest snapshot, the alarm history, the \
                     last {} frames (JSON Lines), Messages, the settings and the versions, \
                     to keep or send with a support request",
                    folder.display(),
                    bundle::LAST_FRAMES
                ));
            if r.clicked() {
                let wall = std::time::SystemTime::now();
                let files = bundle::gather(pendant, now, wall);
                let target = folder.join(bundle::folder_name(wall));
                let job = Job::spawn_opening("writing the support bundle", now, move |ctl| {
                    let written = bundle::write(&target, &files);
                    ctl.opened();
                    written.map(|bytes| {
                        format!(
                            "support bundle written: {} ({} files, {:.1} kB)",
                            target.display(),
                            files.len(),
                            bytes as f64 / 1e3
                        )
                    })
                });
                match job {
                    Ok(job) => self.bundle = Some(job),
                    Err(why) => self.bundle_said = Some((false, why)),
                }
            }
            if !idle {
                ui.spinner();
            } else if let Some((ok, said)) = &self.bundle_said {
                let color = if *ok {
                    GREY
                } else {
                    ui.visuals().error_fg_color
                };
                ui.colored_label(color, said);
            }
        });
    }

    /// A finished file job: an opened snapshot goes to the model; a write's words stay
    /// beside the field.
    fn poll_job(&mut self, now: Instant, out: &mut Vec<Intent>) {
        let words = |_| "snapshot saved".to_owned();
        let Some((path, read)) = self.file.poll(now, out, words, |_| SnapshotFile::Save) else {
            return;
        };
        out.push(Intent::Snapshot(SnapshotIntent::Opened {
            path: path.display().to_string(),
            read,
        }));
    }
}
