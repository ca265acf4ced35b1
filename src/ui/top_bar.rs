//! The top bar: line state, controller version, mode, E-stop, ready, alarm with reset,
//! the theme switch, and the big STOP that is always visible and always enabled.

use std::time::{Duration, Instant};

use egui::{Button, Color32, RichText, Ui, vec2};

use super::pane::{Pane, PaneCx};
use super::widgets::{AMBER, GREEN, RED};
use crate::pendant::{Intent, LineState, Pendant, StopCause};
use crate::protocol::SystemMode;

/// How often a window showing stale lamps draws again.
const STALE_REDRAW: Duration = Duration::from_millis(250);

/// Draws the bar; STOP pushes [`Intent::Stop`], which the app runs before anything else.
pub fn show(ui: &mut Ui, pendant: &Pendant, now: Instant, intents: &mut Vec<Intent>) {
    ui.horizontal(|ui| {
        let stop = Button::new(
            RichText::new("STOP")
                .size(26.0)
                .strong()
                .color(Color32::WHITE),
        )
        .fill(RED)
        .min_size(vec2(130.0, 46.0));
        if ui
            .add(stop)
            .on_hover_text("238H to all axes, ahead of everything (Esc)")
            .clicked()
        {
            intents.push(Intent::Stop(StopCause::Button));
        }
        ui.separator();
        ui.vertical(|ui| {
            let (color, text) = match &pendant.line {
                LineState::Up { line, .. } => (GREEN, format!("Connected: {line}")),
                LineState::Opening => (AMBER, "Connecting...".to_owned()),
                LineState::Down { reason, .. } => (RED, format!("Line down: {reason}")),
                LineState::Closed => (AMBER, "Disconnected".to_owned()),
            };
            ui.label(RichText::new(text).color(color).strong());
            let version = pendant.controller.version.map_or_else(
                || "controller version: -".to_owned(),
                |v| {
                    format!(
                        "controller version {:X}, model {:02X}, {}-{:02}-{:02}",
                        v.version, v.model, v.year, v.month, v.day
                    )
                },
            );
            ui.label(version);
        });
        ui.separator();
        system_lamps(ui, pendant, now, intents);
        ui.with_layout(egui::Layout::right_to_left(egui::Align::Center), |ui| {
            let light = pendant.settings.light_theme;
            if ui
                .button(if light { "Dark theme" } else { "Light theme" })
                .on_hover_text("Switch between the dark and light themes")
                .clicked()
            {
                intents.push(Intent::LightTheme(!light));
            }
            rmc_lamp(ui, pendant);
        });
    });
}

fn system_lamps(ui: &mut Ui, pendant: &Pendant, now: Instant, intents: &mut Vec<Intent>) {
    let system = pendant.controller.system.map(|s| s.value);
    // Lamps from a 215H that is old, or from a line that is down, are grey: "stale".
    let at = pendant.controller.system.map(|s| s.at);
    let stale = super::status::is_stale(pendant, at, now)
        || (at.is_some() && pendant.controller.is_stale(now));
    if stale {
        // Nothing may wake the window when the answers come back unchanged: look again
        // soon, so the lamps turn back from grey once the status is fresh.
        ui.ctx().request_repaint_after(STALE_REDRAW);
    }
    let lamp = |ui: &mut Ui, on: bool, color: Color32, label: &str| {
        super::status::status_lamp(ui, on, color, label, stale);
    };
    ui.vertical(|ui| {
        ui.horizontal(|ui| {
            let mode = system.map_or("-", |s| s.mode.name().unwrap_or("unknown"));
            let auto = system.is_some_and(|s| s.mode == SystemMode::AUTO);
            lamp(ui, auto, GREEN, &format!("Mode {mode}"));
            let estop = system.is_some_and(|s| s.status1.emergency_stop());
            lamp(
                ui,
                estop,
                RED,
                if estop { "E-STOP ACTIVE" } else { "E-stop off" },
            );
            let ready = system.is_some_and(|s| s.status3.ready());
            ui.horizontal(|ui| lamp(ui, ready, GREEN, "Controller ready"))
                .response
                .on_hover_text(
                    "215H's ready bit: the controller's own state, not whether a jog may go",
                );
            if stale {
                ui.label(RichText::new("status stale").color(AMBER))
                    .on_hover_text(super::status::stale_text(pendant, at, now));
            }
        });
        ui.horizontal(|ui| {
            // 215H carries two codes [spec p.30]: the critical-level error, which holds
            // motion until 252H, and the latest error, which the simulator keeps after a
            // reset as history (whether a controller clears it on 252H is not known). Only
            // the first is an alarm; the second is shown as the last error.
            let pending = system.map(|s| (s.critical_error, s.latest_error));
            match pending {
                Some((critical, latest)) if critical.0 != 0 || latest.0 != 0 => {
                    if critical.0 != 0 {
                        lamp(ui, true, RED, &format!("Alarm {critical}"));
                    } else {
                        lamp(ui, false, RED, "No alarm");
                        ui.label(RichText::new(format!("last error {latest}")).color(AMBER))
                            .on_hover_text("215H latest system error: history, not holding motion");
                    }
                    if ui
                        .add_enabled(pendant.line.is_up(), Button::new("Reset alarm"))
                        .on_hover_text("252H alarm reset")
                        .clicked()
                    {
                        intents.push(Intent::ResetAlarm);
                    }
                }
                _ => lamp(ui, false, RED, "No alarm"),
            }
        });
    });
}

/// The RMC151's line at a glance (its axes are in the RMC axes tab).
fn rmc_lamp(ui: &mut Ui, pendant: &Pendant) {
    let (color, hover) = match &pendant.axes.line {
        LineState::Closed => return,
        LineState::Opening => (AMBER, "RMC151: connecting".to_owned()),
        LineState::Up { line, .. } => (GREEN, format!("RMC151 connected: {line}")),
        LineState::Down { reason, .. } => (RED, format!("RMC151 line down: {reason}")),
    };
    ui.scope(|ui| super::widgets::lamp(ui, true, color, "RMC"))
        .response
        .on_hover_text(hover);
}

/// The top bar.
#[derive(Default)]
pub struct TopBar;

impl Pane for TopBar {
    fn ui(&mut self, ui: &mut Ui, cx: &mut PaneCx<'_>) {
        show(ui, cx.pendant, cx.now, cx.intents);
    }
}
