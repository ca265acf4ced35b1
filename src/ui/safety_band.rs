//! The safety band under the top bar: E-stop, drive cut off, alarm, MANUAL mode and the
//! STOP latch, full width in their colour with the reason and what to do. Its height is
//! always taken, so nothing below moves when a state comes or goes.

use std::time::Instant;

use egui::{Color32, RichText, Ui};

use super::pane::{Pane, PaneCx};
use super::widgets::{AMBER, RED};
use crate::pendant::Pendant;
use crate::protocol::SystemMode;

/// One state an operator must not miss: how severe, and the words.
pub struct Alert {
    pub color: Color32,
    pub text: String,
}

/// Every alert that holds now, the most severe first.
pub fn alerts(pendant: &Pendant) -> Vec<Alert> {
    let mut out = Vec::new();
    let red = |text: String| Alert { color: RED, text };
    let amber = |text: String| Alert { color: AMBER, text };
    if let Some(s) = pendant.controller.system.map(|s| s.value) {
        if s.status1.emergency_stop() {
            out.push(red(
                "EMERGENCY STOP: motion is held. Release the E-stop, then Reset alarm and \
                 Servo ON."
                    .into(),
            ));
        }
        if s.status3.drive_cut_off() {
            out.push(red(
                "DRIVE SOURCE CUT OFF: restore the drive source (safety circuit) before any \
                 motion."
                    .into(),
            ));
        }
        if s.critical_error.0 != 0 {
            out.push(red(format!(
                "ALARM {:03X}: {}. Remove the cause, then Reset alarm.",
                s.critical_error.0,
                s.critical_error.describe()
            )));
        }
        if s.mode == SystemMode::MANUAL {
            out.push(amber(
                "MANUAL mode: the controller's own teach pendant has control; switch the \
                 MODE to AUTO to jog from here."
                    .into(),
            ));
        }
    }
    out.extend(rmc_alerts(pendant).into_iter().map(
        |(red_, text)| {
            if red_ { red(text) } else { amber(text) }
        },
    ));
    if let Some(latch) = pendant
        .stop_latch()
        .or_else(|| pendant.axes.hold.latch_text())
    {
        out.push(amber(latch));
    }
    out
}

/// The RMC151's states an operator must not miss: an axis halted, PROGRAM mode, a
/// disabled controller (red or amber, and the words).
fn rmc_alerts(pendant: &Pendant) -> Vec<(bool, String)> {
    let rmc = &pendant.axes;
    if !rmc.line.is_up() {
        return Vec::new();
    }
    let mut out = Vec::new();
    for (i, view) in rmc.axes.iter().enumerate() {
        let Some(s) = view.status.filter(|s| s.bits.halted()) else {
            continue;
        };
        let errors = s.errors.names();
        let why = if errors.is_empty() {
            String::new()
        } else {
            format!(" ({})", errors.join(", "))
        };
        out.push((
            true,
            format!(
                "RMC AXIS {} HALTED{why}: remove the cause, then Clear faults.",
                i + 1
            ),
        ));
    }
    if let Some(c) = rmc.controller {
        if !c.run_mode() {
            out.push((false, "RMC in PROGRAM mode: its axes take no motion from here; switch it to RUN in RMCTools.".into()));
        } else if !c.enabled() {
            out.push((
                false,
                "RMC controller disabled: its axes take no motion.".into(),
            ));
        }
    }
    out
}

/// Draws the band: the first alert filled in its colour, the others after it; the whole
/// list on hover.
pub fn show(ui: &mut Ui, pendant: &Pendant, _now: Instant) {
    let alerts = alerts(pendant);
    let height = ui.text_style_height(&egui::TextStyle::Heading) + 6.0;
    let (rect, resp) = ui.allocate_exact_size(
        egui::vec2(ui.available_width(), height),
        egui::Sense::hover(),
    );
    let Some(first) = alerts.first() else {
        let quiet = "No E-stop, alarm or STOP latch";
        ui.painter().text(
            rect.left_center() + egui::vec2(8.0, 0.0),
            egui::Align2::LEFT_CENTER,
            quiet,
            egui::FontId::proportional(13.0),
            ui.visuals().weak_text_color(),
        );
        return;
    };
    ui.painter().rect_filled(rect, 3.0, first.color);
    let mut text = first.text.clone();
    if alerts.len() > 1 {
        text.push_str(&format!("   (+{} more)", alerts.len() - 1));
    }
    let label = egui::Label::new(
        RichText::new(text)
            .strong()
            .size(16.0)
            .color(Color32::WHITE),
    )
    .truncate();
    let layout = egui::Layout::left_to_right(egui::Align::Center);
    ui.scope_builder(
        egui::UiBuilder::new()
            .max_rect(rect.shrink2(egui::vec2(8.0, 0.0)))
            .layout(layout),
        |ui| ui.add(label),
    );
    let all: Vec<String> = alerts.iter().map(|a| a.text.clone()).collect();
    resp.on_hover_text(all.join("\n"));
}

/// The safety band under the top bar.
#[derive(Default)]
pub struct SafetyBand;

impl Pane for SafetyBand {
    fn ui(&mut self, ui: &mut Ui, cx: &mut PaneCx<'_>) {
        show(ui, cx.pendant, cx.now);
    }
}
