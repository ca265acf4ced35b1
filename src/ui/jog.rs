//! The jog panel: Servo ON/OFF, Home and Reset alarm, the "ready to jog" lamp, step or
//! continuous, the step ladder, PTP or CP, the arm system, speeds under the jog speed cap,
//! the frame and "relative to", the pad, and the target from the arm view ("Step here")
//! with its "Go to target". It draws `&Pendant` and pushes intents; rows are disabled,
//! never removed, and the reason and result lines keep their space.

use std::time::Instant;

use egui::{Button, ComboBox, DragValue, RichText, Ui};

use super::pad::{self, PadOutput};
use super::widgets::{AMBER, GREEN, RED, lamp, reserved_line};
use crate::pendant::jog::speed_cap::{self, MAX_CAP_MM_S, REDUCED_SPEED_MM_S};
use crate::pendant::jog::{MAX_STEP, STEP_LADDER};
use crate::pendant::{Intent, Interpolation, JogMode, JogSettings, Pendant};
use crate::protocol::ArmPolicy;
use crate::robot::{JogFrame, RelativeTo};

/// The panel's own state: the speed cap being raised.
#[derive(Default)]
pub struct JogPanel {
    /// The "raise the cap" dialog is open with this value.
    raising: Option<f64>,
}

impl JogPanel {
    /// Draws the panel; answers what the pad saw.
    pub fn show(
        &mut self,
        ui: &mut Ui,
        pendant: &Pendant,
        now: Instant,
        intents: &mut Vec<Intent>,
    ) -> PadOutput {
        controller_row(ui, pendant, now, intents);
        let ready = pendant.motion_ready(now);
        let why = ready
            .as_ref()
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        // The lamp an operator looks at: ready to jog, or what is missing.
        let ready_text = match &ready {
            Ok(()) => "Ready to jog".to_owned(),
            Err(why) => format!("Not ready: {why}"),
        };
        ui.horizontal(|ui| lamp(ui, ready.is_ok(), GREEN, &ready_text));
        ui.separator();
        let mut jog = pendant.settings.jog.clone();
        settings(ui, pendant, &mut jog);
        self.speed_cap(ui, pendant, intents);
        if jog != pendant.settings.jog {
            intents.push(Intent::JogSettings(jog));
        }
        ui.separator();
        ui.label(
            RichText::new(format!(
                "Cartesian ({} frame)  \u{2022}  Joints below",
                pendant.settings.jog.frame.name()
            ))
            .strong(),
        );
        // The latch, or else the reason motion is off: one reserved line.
        let latch = pendant.stop_latch();
        let line = match (&latch, &ready) {
            (Some(text), _) => Some((RED, text.clone())),
            (None, Err(why)) => Some((AMBER, format!("Not available: {why}"))),
            (None, Ok(())) => None,
        };
        reserved_line(ui, line.as_ref().map(|(c, t)| (*c, t.as_str())), None);
        let out = pad::show(ui, pendant, ready.is_ok() && latch.is_none(), &why);
        // The last word on a jog: one reserved line, cut to fit, the whole on hover.
        let feedback = pendant.jog.feedback.as_ref();
        reserved_line(
            ui,
            feedback.map(|m| (super::widgets::level_color(m.level), m.text.as_str())),
            feedback.map(|m| m.detail.as_deref().unwrap_or(&m.text)),
        );
        target(ui, pendant, ready.is_ok(), &why, intents);
        out
    }

    /// The cap on the tool's speed: shown beside the speed, raised only through a dialog
    /// that asks for the new value, never saved.
    fn speed_cap(&mut self, ui: &mut Ui, pendant: &Pendant, intents: &mut Vec<Intent>) {
        let cap = pendant.speed_cap();
        let reduced = (cap - REDUCED_SPEED_MM_S).abs() < 0.5;
        let s = &pendant.settings.jog;
        let ptp = speed_cap::ptp_speed(s, &pendant.model, cap);
        let cp = speed_cap::cp_speed(s, &pendant.model, cap);
        let sent = match s.interpolation {
            Interpolation::Ptp if ptp.lowered => format!(": sends {} %", ptp.sent),
            Interpolation::Cp if cp.lowered => format!(": sends {} mm/s", cp.sent),
            _ => String::new(),
        };
        ui.horizontal(|ui| {
            let text = format!("Speed cap {cap:.0} mm/s at the tool{sent}");
            let color = if reduced {
                ui.visuals().text_color()
            } else {
                AMBER
            };
            ui.label(RichText::new(text).color(color))
                .on_hover_text(format!(
                    "Every step, jog and Go is capped at this tool speed (PTP % through the \
                 model's maximum joint speeds: {} % at most). Format B runs in AUTO, where \
                 the controller applies no reduced speed of its own.",
                    speed_cap::ptp_percent_cap(&pendant.model, cap)
                ));
            if reduced {
                if ui.small_button("Raise...").clicked() {
                    self.raising = Some(cap.max(500.0));
                }
            } else if ui.small_button("Back to reduced").clicked() {
                intents.push(Intent::ResetSpeedCap);
            }
        });
        if let Some(value) = self.raising.as_mut() {
            let mut close = false;
            egui::Window::new("Raise the jog speed cap")
                .collapsible(false)
                .resizable(false)
                .show(ui.ctx(), |ui| {
                    ui.label(
                        "Above the reduced speed, a person in the cell has less time to react. \
                         The raise lasts until the window closes.",
                    );
                    ui.horizontal(|ui| {
                        let l = ui.label("New cap");
                        ui.add(
                            DragValue::new(value)
                                .range(REDUCED_SPEED_MM_S..=MAX_CAP_MM_S)
                                .suffix(" mm/s"),
                        )
                        .labelled_by(l.id);
                    });
                    ui.horizontal(|ui| {
                        if ui.button("Raise the cap").clicked() {
                            intents.push(Intent::RaiseSpeedCap(*value));
                            close = true;
                        }
                        if ui.button("Cancel").clicked() {
                            close = true;
                        }
                    });
                });
            if close {
                self.raising = None;
            }
        }
    }
}

/// Servo ON/OFF, Home and Reset alarm, beside the pad.
fn controller_row(ui: &mut Ui, pendant: &Pendant, now: Instant, intents: &mut Vec<Intent>) {
    let ready = pendant.controller_ready(now);
    let why = ready
        .as_ref()
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default();
    ui.horizontal(|ui| {
        super::status::servo_home_buttons(ui, &ready, &why, intents);
        let alarm = pendant
            .controller
            .system
            .is_some_and(|s| s.value.critical_error.0 != 0);
        let reset = ui.add_enabled(
            alarm && pendant.line.is_up(),
            Button::new("Reset alarm").min_size(egui::vec2(72.0, 26.0)),
        );
        if reset
            .on_hover_text("252H alarm reset")
            .on_disabled_hover_text("no alarm pending")
            .clicked()
        {
            intents.push(Intent::ResetAlarm);
        }
    });
}

/// The target from the arm view's "Step here": editable, moved to only on "Go to target".
fn target(ui: &mut Ui, pendant: &Pendant, enabled: bool, why: &str, intents: &mut Vec<Intent>) {
    let Some(t) = pendant.step_target().cloned() else {
        return;
    };
    ui.separator();
    ui.label(RichText::new(format!("Target (work {}, tool {})", t.work, t.tool)).strong());
    let mut pose = t.pose;
    egui::Grid::new("jog-target").num_columns(4).show(ui, |ui| {
        for (i, (name, value)) in [
            ("X", &mut pose.x),
            ("Y", &mut pose.y),
            ("Z", &mut pose.z),
            ("R", &mut pose.r),
        ]
        .into_iter()
        .enumerate()
        {
            let l = ui.label(name);
            ui.add(DragValue::new(value).speed(0.1).max_decimals(3))
                .labelled_by(l.id);
            if i % 2 == 1 {
                ui.end_row();
            }
        }
    });
    if pose != t.pose {
        intents.push(Intent::EditTarget(pose));
    }
    ui.horizontal(|ui| {
        let go = ui
            .add_enabled(enabled, Button::new("Go to target"))
            .on_disabled_hover_text(why)
            .on_hover_text(
                "2D4H to the target after the same checks as a step (its ghost shows them)",
            );
        if go.clicked() {
            intents.push(Intent::GoToTarget);
        }
        if ui.button("Clear target").clicked() {
            intents.push(Intent::ClearTarget);
        }
    });
}

/// The choices, edited in a copy: every row always there, disabled when the mode does
/// not use it.
fn settings(ui: &mut Ui, pendant: &Pendant, j: &mut JogSettings) {
    let current_arm = pendant.controller.work.map(|s| s.value.common.arm);
    let cp_max = pendant.model.cp_max_speed_mm_s.min(f64::from(u16::MAX)) as u16;
    ui.horizontal(|ui| {
        ui.label("Mode");
        ui.selectable_value(&mut j.mode, JogMode::Step, "Step");
        ui.selectable_value(&mut j.mode, JogMode::Continuous, "Continuous")
            .on_hover_text("236H while the button or key is held; 238H on release");
    });
    let stepping = j.mode == JogMode::Step;
    ui.add_enabled_ui(stepping, |ui| {
        ui.horizontal(|ui| {
            let label = ui.label("Step");
            for s in STEP_LADDER {
                let selected = (j.step - s).abs() < 1e-9;
                if ui.selectable_label(selected, format!("{s}")).clicked() {
                    j.step = s;
                }
            }
            ui.add(
                DragValue::new(&mut j.step)
                    .range(0.001..=MAX_STEP)
                    .speed(0.1)
                    .max_decimals(3),
            )
            .labelled_by(label.id)
            .on_hover_text("A custom step: 0.001 to 1000 mm (deg for R and the rotary joints)");
            if ui
                .small_button("-")
                .on_hover_text("Smaller step (-)")
                .clicked()
            {
                j.step_ladder(false);
            }
            if ui
                .small_button("+")
                .on_hover_text("Larger step (+)")
                .clicked()
            {
                j.step_ladder(true);
            }
        });
    })
    .response
    .on_disabled_hover_text("continuous jogs have no step");
    ui.horizontal(|ui| {
        ui.label("Motion");
        ui.selectable_value(&mut j.interpolation, Interpolation::Ptp, "PTP");
        ui.selectable_value(&mut j.interpolation, Interpolation::Cp, "CP")
            .on_hover_text("A straight line of the tool tip, checked along its whole length");
    });
    ui.add_enabled_ui(j.interpolation == Interpolation::Ptp, |ui| {
        ui.horizontal(|ui| {
            let label = ui.label("Arm");
            ComboBox::from_id_salt("arm-policy")
                .selected_text(j.arm.to_string())
                .show_ui(ui, |ui| {
                    for a in ArmPolicy::ALL {
                        ui.selectable_value(&mut j.arm, a, a.to_string());
                    }
                })
                .response
                .labelled_by(label.id);
            let now = current_arm.map_or_else(|| "now: -".to_owned(), |arm| format!("now: {arm}"));
            ui.label(now);
        });
    })
    .response
    .on_disabled_hover_text("CP keeps the arm system");
    egui::Grid::new("jog-speeds")
        .num_columns(4)
        .show(ui, |ui| {
            match j.interpolation {
                Interpolation::Ptp => {
                    let l = ui.label("Speed");
                    let v = DragValue::new(&mut j.ptp_speed_pct)
                        .range(0..=100)
                        .suffix(" %");
                    ui.add(v).labelled_by(l.id);
                    let l = ui.label("Acc/Dec");
                    ui.horizontal(|ui| {
                        let v = DragValue::new(&mut j.ptp_accel_pct)
                            .range(0..=100)
                            .suffix(" %");
                        ui.add(v).labelled_by(l.id);
                        let v = DragValue::new(&mut j.ptp_decel_pct)
                            .range(0..=100)
                            .suffix(" %");
                        ui.add(v).labelled_by(l.id);
                    });
                }
                Interpolation::Cp => {
                    let l = ui.label("Speed");
                    let v = DragValue::new(&mut j.cp_speed_mm_s)
                        .range(0..=cp_max)
                        .suffix(" mm/s");
                    ui.add(v).labelled_by(l.id);
                    let l = ui.label("Acc/Dec");
                    ui.horizontal(|ui| {
                        let v = DragValue::new(&mut j.cp_accel_cg)
                            .range(0..=999)
                            .suffix(" cG");
                        ui.add(v).labelled_by(l.id);
                        let v = DragValue::new(&mut j.cp_decel_cg)
                            .range(0..=999)
                            .suffix(" cG");
                        ui.add(v).labelled_by(l.id);
                    });
                }
            }
            ui.end_row();
        })
        .response
        .on_hover_text(
            "0 = the controller's parameter value; cG = 0.01 G. Joint steps and jogs use \
             the % rates, Cartesian jogs the mm/s rates.",
        );
    ui.horizontal(|ui| {
        ui.label("Frame");
        for f in JogFrame::ALL {
            ui.selectable_value(&mut j.frame, f, f.name());
        }
    });
    ui.add_enabled_ui(stepping, |ui| {
        ui.horizontal(|ui| {
            ui.label("Relative to");
            for b in RelativeTo::ALL {
                ui.selectable_value(&mut j.relative_to, b, b.name());
            }
        })
        .response
        .on_hover_text(
            "command: where the last move ends (chained steps never drift); actual: the \
             polled position; target: where the profile is now",
        );
    });
}
