//! The Alarms view: controller snapshots (taken, saved, compared) above the controller's
//! alarm history as read (216H types 3 and 5) with the pendant's words for each code,
//! exported as CSV, and the alarms seen arriving, each with the frames just before and
//! after it.

use std::path::Path;
use std::time::Instant;

use egui::{ComboBox, RichText, Ui};
use egui_extras::{Column as Col, TableBuilder};

use super::file_field::{Browse, FieldSpec, FileAsk, Purpose};
use super::file_work::{Done, FileButton, FileWork, write_job};
use super::pane::{Pane, PaneCx};
use super::snapshots::SnapshotsSection;
use super::widgets::{GREY, RED, said_line};
use crate::files::job::Job;
use crate::pendant::alarms::{Alarms, AlarmsIntent, ListKind, LiveAlarm, to_csv};
use crate::pendant::frame_log::{Dir, FrameLog};
use crate::pendant::{Intent, Pendant};

const ROW_HEIGHT: f32 = 20.0;
/// Frames shown before and after a live alarm's.
const AROUND: u64 = 4;

/// What the file field is for: the export.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum AlarmsFile {
    Export,
}

static FILE_FIELD: FieldSpec<AlarmsFile> = FieldSpec {
    label: "File",
    hint: "alarms.csv",
    width: 170.0,
    browse: &[Browse {
        label: "Export the history as...",
        action: AlarmsFile::Export,
        purpose: Purpose::Save,
    }],
    filters: &[("Alarm history", &["csv"])],
};

static FILE_BUTTONS: [FileButton<AlarmsFile>; 1] = [(
    "Export CSV",
    Some(
        "Write the history as read: record, code, text, program, step, axis, point, details 5-8, message",
    ),
    AlarmsFile::Export,
)];

/// The view's own state: the live alarm opened, the export file, the snapshots.
pub struct AlarmsPanel {
    file: FileWork<AlarmsFile, Done<()>>,
    snapshots: SnapshotsSection,
    /// The live alarm whose frames are shown (its frame log row).
    opened: Option<u64>,
}

impl Default for AlarmsPanel {
    fn default() -> Self {
        Self {
            file: FileWork::new(&FILE_FIELD),
            snapshots: SnapshotsSection::default(),
            opened: None,
        }
    }
}

fn start_job(
    mut ask: FileAsk<AlarmsFile>,
    alarms: &Alarms,
    now: Instant,
) -> Result<Job<Done<()>>, String> {
    if ask.path.extension().is_none() {
        ask.path.set_extension("csv");
    }
    let records = alarms.records().to_vec();
    write_job("writing", ask, records.len(), now, move || to_csv(&records))
}

impl AlarmsPanel {
    /// Draws the view; what is asked for goes to `out`.
    pub fn show(
        &mut self,
        ui: &mut Ui,
        pendant: &Pendant,
        folder: &Path,
        now: Instant,
        out: &mut Vec<Intent>,
    ) {
        self.snapshots.show(ui, pendant, folder, now, out);
        ui.separator();
        let alarms = &pendant.alarms;
        let mut ask = Vec::new();
        ui.horizontal_wrapped(|ui| {
            if ui
                .button("Read history")
                .on_hover_text("Read the controller's error list again from record 1 (216H)")
                .clicked()
            {
                ask.push(AlarmsIntent::Read);
            }
            if let Some(n) = alarms.reading() {
                ui.spinner();
                ui.label(format!("record {n}"));
                if ui.button("Cancel").clicked() {
                    ask.push(AlarmsIntent::Cancel);
                }
            }
            let l = ui.label("List");
            let mut kind = alarms.kind;
            ComboBox::from_id_salt("alarms-kind")
                .selected_text(kind_label(kind))
                .show_ui(ui, |ui| {
                    for k in [ListKind::Type3, ListKind::Type5] {
                        ui.selectable_value(&mut kind, k, kind_label(k));
                    }
                })
                .response
                .labelled_by(l.id)
                .on_hover_text(
                    "Type 3 works on every model (records 1-255); type 5 on X-SEL \
                     R/S/RX/SX/RXD/SXD and TTA (records 1-4095), PROTOCOL.md 3.47",
                );
            if kind != alarms.kind {
                ask.push(AlarmsIntent::Kind(kind));
            }
        });
        said_line(ui, &alarms.outcome);
        self.poll_job(now, out);
        self.file.row(ui, folder, now, &FILE_BUTTONS, |ask| {
            start_job(ask, alarms, now)
        });
        ui.separator();
        self.live(ui, pendant, now);
        ui.separator();
        history(ui, alarms);
        out.extend(ask.into_iter().map(Intent::Alarms));
    }

    fn poll_job(&mut self, now: Instant, out: &mut Vec<Intent>) {
        let words = |rows| format!("exported {rows} records");
        let _ = self.file.poll(now, out, words, |_| AlarmsFile::Export);
    }

    /// The alarms seen arriving, newest first; a click shows the frames around each.
    fn live(&mut self, ui: &mut Ui, pendant: &Pendant, now: Instant) {
        let live = pendant.alarms.live();
        ui.label(RichText::new(format!("Seen arriving ({})", live.len())).strong());
        if live.is_empty() {
            ui.label(RichText::new("No alarm came in since the window opened.").color(GREY));
            return;
        }
        egui::ScrollArea::vertical()
            .id_salt("alarms-live")
            .max_height(180.0)
            .show(ui, |ui| {
                for alarm in live.iter().rev() {
                    let open = self.opened == Some(alarm.row);
                    let text = format!(
                        "{}  {:03X}  {}  ({:.1} s ago)",
                        clock(alarm),
                        alarm.code.0,
                        alarm.code.describe(),
                        now.saturating_duration_since(alarm.at).as_secs_f64()
                    );
                    let r = ui
                        .selectable_label(open, RichText::new(text).color(RED))
                        .on_hover_text("Show the frames just before and after it");
                    if r.clicked() {
                        self.opened = if open { None } else { Some(alarm.row) };
                    }
                    if open {
                        frames_around(ui, &pendant.frame_log, alarm.row);
                    }
                }
            });
    }
}

fn kind_label(kind: ListKind) -> &'static str {
    match kind {
        ListKind::Type3 => "type 3 (all models)",
        ListKind::Type5 => "type 5 (R/S/RX/SX/RXD/SXD, TTA)",
    }
}

/// "14:03:12.482" in UTC, the frame log's clock.
fn clock(alarm: &LiveAlarm) -> String {
    let t = alarm
        .wall
        .duration_since(std::time::UNIX_EPOCH)
        .unwrap_or_default();
    let s = t.as_secs() % 86_400;
    format!(
        "{:02}:{:02}:{:02}.{:03}",
        s / 3600,
        s / 60 % 60,
        s % 60,
        t.subsec_millis()
    )
}

/// The frame log's rows from `AROUND` before `row` to `AROUND` after, `row` in bold.
fn frames_around(ui: &mut Ui, log: &FrameLog, row: u64) {
    let first = row.saturating_sub(AROUND);
    let mut any = false;
    ui.indent("alarm-frames", |ui| {
        for seq in first..=row + AROUND {
            let Some(r) = log.row(seq) else {
                continue;
            };
            any = true;
            let arrow = match r.dir() {
                Dir::Sent => "->",
                Dir::Received => "<-",
                _ => "!!",
            };
            let bytes = r.bytes();
            let text = format!(
                "{arrow} {}",
                String::from_utf8_lossy(bytes.trim_ascii_end()).escape_debug()
            );
            let line = RichText::new(text).monospace();
            ui.label(if seq == row {
                line.strong()
            } else {
                line.color(GREY)
            });
        }
        if !any {
            ui.label(
                RichText::new("Those frames are no longer in the frame log (its cap or budget).")
                    .color(GREY),
            );
        }
    });
}

/// The history as read: one row per record.
fn history(ui: &mut Ui, alarms: &Alarms) {
    let records = alarms.records();
    ui.label(RichText::new(format!("History ({} records, newest first)", records.len())).strong());
    ui.push_id("alarms-history", |ui| {
        TableBuilder::new(ui)
            .striped(true)
            .column(Col::exact(50.0))
            .column(Col::exact(44.0))
            .column(Col::initial(220.0).at_least(120.0))
            .columns(Col::exact(56.0), 4)
            .column(Col::remainder().at_least(120.0))
            .header(ROW_HEIGHT, |mut h| {
                for title in [
                    "Record",
                    "Code",
                    "Text",
                    "Program",
                    "Step",
                    "Axis",
                    "Point",
                    "Details 5-8, message",
                ] {
                    h.col(|ui| {
                        ui.strong(title);
                    });
                }
            })
            .body(|body| {
                body.rows(ROW_HEIGHT, records.len(), |mut row| {
                    let r = &records[row.index()];
                    row.col(|ui| {
                        ui.label(r.record.to_string());
                    });
                    match &r.detail {
                        Ok(d) => {
                            row.col(|ui| {
                                ui.label(format!("{:03X}", d.error.0));
                            });
                            row.col(|ui| {
                                ui.label(d.error.describe());
                            });
                            for v in [d.details[0], d.details[1], d.details[2]] {
                                row.col(|ui| {
                                    ui.label(v.to_string());
                                });
                            }
                            row.col(|ui| {
                                ui.label((d.details[3] as i32).to_string());
                            });
                            row.col(|ui| {
                                let raw = format!(
                                    "{:08X} {:08X} {:08X} {:08X} {}",
                                    d.details[4],
                                    d.details[5],
                                    d.details[6],
                                    d.details[7],
                                    d.message_text()
                                );
                                ui.label(RichText::new(raw).monospace().color(GREY))
                                    .on_hover_text("Unnamed on the spec's pages: shown raw");
                            });
                        }
                        Err(why) => {
                            row.col(|_| {});
                            row.col(|ui| {
                                ui.label(RichText::new(why).color(RED));
                            });
                        }
                    }
                });
            });
    });
}

impl Pane for AlarmsPanel {
    fn ui(&mut self, ui: &mut Ui, cx: &mut PaneCx<'_>) {
        self.show(ui, cx.pendant, cx.folder, cx.now, cx.intents);
    }
}
