//! Auto-detect in the connection panel: probes the chosen serial port at the usual baud
//! rates (and, if asked, every station) with 215H on a worker thread, shows progress,
//! and fills in the settings that answered.

use egui::{RichText, Ui};

use super::widgets::{AMBER, RED};
use crate::pendant::ConnectionSettings;
use crate::session::probe::{ProbeEvent, ProbeHandle, ProbePlan, spawn_probe};

/// A probe in progress, and what the last one found.
#[derive(Default)]
pub struct Detect {
    running: Option<ProbeHandle>,
    progress: Option<(usize, usize, String)>,
    result: Option<(bool, String)>,
    sweep_stations: bool,
}

impl Detect {
    /// The button, the options and the progress; `allowed` is `Err(reason)` while the
    /// port is in use by the connection.
    pub fn show(
        &mut self,
        ui: &mut Ui,
        settings: &mut ConnectionSettings,
        allowed: Result<(), &str>,
    ) -> bool {
        let found = self.poll(settings);
        let plan = self.plan();
        ui.horizontal(|ui| {
            if let Some(handle) = &self.running {
                if ui.button("Cancel detect").clicked() {
                    handle.cancel();
                }
                ui.spinner();
            } else {
                let start = ui
                    .add_enabled(
                        allowed.is_ok() && !settings.port.trim().is_empty(),
                        egui::Button::new("Auto-detect"),
                    )
                    .on_hover_text(format!(
                        "Ask 215H at the usual baud rates{}: about {:.0} s at most",
                        if self.sweep_stations {
                            " and every station"
                        } else {
                            " at station 99"
                        },
                        plan.estimate().as_secs_f64().ceil()
                    ));
                if start.clicked() {
                    let ctx = ui.ctx().clone();
                    self.start(settings, plan, move || ctx.request_repaint());
                }
                ui.checkbox(&mut self.sweep_stations, "all stations");
            }
        });
        if let Err(why) = allowed {
            ui.label(RichText::new(why).color(AMBER).small());
        }
        if let Some((tried, total, candidate)) = &self.progress
            && self.running.is_some()
        {
            ui.add(
                egui::ProgressBar::new(*tried as f32 / (*total).max(1) as f32)
                    .text(format!("{tried}/{total}: {candidate}")),
            );
        }
        if let Some((found, text)) = &self.result {
            let color = if *found {
                ui.visuals().text_color()
            } else {
                RED
            };
            ui.label(RichText::new(text).color(color));
        }
        found
    }

    fn plan(&self) -> ProbePlan {
        let plan = ProbePlan::default();
        if self.sweep_stations {
            plan.with_station_sweep()
        } else {
            plan
        }
    }

    fn start(
        &mut self,
        settings: &ConnectionSettings,
        plan: ProbePlan,
        wake: impl Fn() + Send + Sync + 'static,
    ) {
        match spawn_probe(
            settings.port.trim().to_owned(),
            plan,
            std::sync::Arc::new(wake),
        ) {
            Ok(handle) => {
                self.running = Some(handle);
                self.result = None;
                self.progress = None;
            }
            Err(e) => self.result = Some((false, format!("cannot start the probe: {e}"))),
        }
    }

    /// Takes the probe's events; on success the settings take what answered (and the
    /// result is `true`).
    fn poll(&mut self, settings: &mut ConnectionSettings) -> bool {
        let Some(handle) = &self.running else {
            return false;
        };
        while let Ok(event) = handle.events.try_recv() {
            match event {
                ProbeEvent::Trying {
                    tried,
                    total,
                    candidate,
                } => self.progress = Some((tried, total, candidate.to_string())),
                ProbeEvent::Tried { .. } => {}
                ProbeEvent::Finished(report) => {
                    if let Some(found) = report.found() {
                        let c = found.candidate;
                        settings.baud = c.line.baud;
                        settings.data_bits = c.line.data_bits;
                        settings.parity = c.line.parity;
                        settings.stop_bits = c.line.stop_bits;
                        settings.station = c.station.0;
                    }
                    let found = report.found().is_some();
                    self.result = Some((found, report.summary()));
                    self.running = None;
                    return found;
                }
            }
        }
        false
    }
}
