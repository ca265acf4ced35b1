//! The connection panel's "First-contact report": the read-only run on the line in the
//! panel's settings, on a thread of its own with progress and Cancel, written as a new
//! file in the files folder and shown in a window of its own.

use std::path::Path;
use std::time::{Instant, SystemTime};

use egui::{RichText, Ui};

use super::widgets::GREY;
use crate::files::job::Job;
use crate::first_contact::{self, Answer};
use crate::pendant::{LineKind, LineState, Pendant};
use crate::protocol::Station;
use crate::session::{Connection, load_model};

/// A finished run: where the report went, its summary and its text.
struct Done {
    path: String,
    summary: String,
    text: String,
    answered: bool,
}

/// The row's own state.
#[derive(Default)]
pub struct FirstContactRow {
    job: Option<Job<Result<Done, String>>>,
    said: Option<(bool, String)>,
    /// The last report's text, and whether its window is open.
    report: Option<(String, bool)>,
}

impl FirstContactRow {
    /// The button (refused with the reason while the window's line holds a port or
    /// bridge), progress and Cancel, and what became of the last run.
    pub fn show(&mut self, ui: &mut Ui, pendant: &Pendant, folder: &Path, now: Instant) {
        if let Some(done) = Job::take(&mut self.job, now) {
            self.said = Some(match done {
                Ok(Ok(done)) => {
                    self.report = Some((done.text, false));
                    let first = done.summary.lines().nth(2).unwrap_or("").to_owned();
                    (
                        done.answered,
                        format!("report written: {}\n{first}", done.path),
                    )
                }
                Ok(Err(why)) => (false, why),
                Err(lost) => (false, format!("first-contact report: {lost}")),
            });
        }
        let settings = &pendant.settings.connection;
        let busy = !matches!(pendant.line, LineState::Closed | LineState::Down { .. });
        let window_holds_a_port = busy && pendant.line_kind != Some(LineKind::Simulator);
        let refused = (window_holds_a_port && settings.kind != LineKind::Simulator)
            .then_some("disconnect first: the report needs the line to itself");
        ui.horizontal_wrapped(|ui| {
            if let Some(job) = &self.job {
                if ui.button("Cancel report").clicked() {
                    job.cancel();
                }
                let p = job.progress();
                let total = p.total.unwrap_or(first_contact::QUESTIONS.len() as u64);
                ui.add(
                    egui::ProgressBar::new(p.done as f32 / total.max(1) as f32)
                        .desired_width(120.0)
                        .text(format!("question {} of {total}", p.done)),
                );
                ui.ctx()
                    .request_repaint_after(std::time::Duration::from_millis(100));
            } else {
                let button = ui
                    .add_enabled(refused.is_none(), egui::Button::new("First-contact report"))
                    .on_hover_text(format!(
                        "For a controller nobody here has tried: {} read-only queries (no \
                         motion, no writes), one at a time, on the line set above, that settle \
                         what the pendant's protocol reference could only infer. The report, \
                         with every frame and its time, goes to a new file in {}.",
                        first_contact::QUESTIONS.len(),
                        folder.display()
                    ));
                if button.clicked() {
                    self.start(pendant, folder, now);
                }
                if let Some((_, open)) = &mut self.report {
                    ui.toggle_value(open, "Show report");
                }
            }
        });
        if let Some(why) = refused.filter(|_| self.job.is_none()) {
            ui.label(RichText::new(why).color(GREY).small());
        }
        if let Some((ok, said)) = &self.said
            && self.job.is_none()
        {
            let color = if *ok {
                GREY
            } else {
                ui.visuals().error_fg_color
            };
            ui.label(RichText::new(said).color(color));
        }
        if let Some((text, open)) = &mut self.report {
            egui::Window::new("First-contact report")
                .open(open)
                .default_size([720.0, 520.0])
                // Clear of the STOP button and the jog pad at the left.
                .default_pos([390.0, 90.0])
                .show(ui.ctx(), |ui| {
                    egui::ScrollArea::both().show(ui, |ui| {
                        ui.add(egui::Label::new(RichText::new(text.as_str()).monospace()).extend());
                    });
                });
        }
    }

    fn start(&mut self, pendant: &Pendant, folder: &Path, now: Instant) {
        let settings = pendant.settings.connection.clone();
        let model = match load_model(&settings.robot) {
            Ok(m) => m,
            Err(e) => {
                self.said = Some((false, e));
                return;
            }
        };
        let folder = folder.to_path_buf();
        let job = Job::spawn("take the first-contact report", now, move |ctl| {
            let mut conn = Connection::prepare_in_process(&settings, model);
            let station = Station(settings.station);
            ctl.set_total(first_contact::QUESTIONS.len() as u64);
            let (header, exchanges) = first_contact::report_on(
                &mut conn,
                station,
                || ctl.cancelled(),
                |_| ctl.advance(1),
            )
            .map_err(|e| e.to_string())?;
            drop(conn);
            let text = first_contact::render(&header, &exchanges);
            let path = folder.join(first_contact::file_name(SystemTime::now()));
            first_contact::write_new(&path, &text).map_err(|e| e.to_string())?;
            Ok(Done {
                path: path.display().to_string(),
                summary: first_contact::summary_text(&exchanges),
                text,
                answered: exchanges
                    .iter()
                    .any(|e| matches!(e.answer, Answer::Reply(_) | Answer::Refused(_))),
            })
        });
        match job {
            Ok(job) => {
                self.job = Some(job);
                self.said = None;
            }
            Err(why) => self.said = Some((false, why)),
        }
    }
}
