//! The jog panel: step or continuous, the step ladder, PTP or CP, the arm system, speeds,
//! the frame and "relative to", the +/- buttons of X, Y, Z, R and the joints, and the
//! target filled in from the arm view ("Step here") with its "Go to target".

use std::time::Instant;

use egui::{Button, ComboBox, DragValue, RichText, Ui, vec2};

use super::widgets::{message, reason};
use crate::pendant::jog::{MAX_STEP, STEP_LADDER};
use crate::pendant::{
    ArmChoice, HoldSource, Interpolation, JogAxis, JogMode, Pendant, StepBase, StepFrame,
};
use crate::protocol::Direction;

/// Draws the panel; answers the jog button under the pointer (the arm view shows its
/// step as a ghost).
pub fn show(ui: &mut Ui, pendant: &mut Pendant, now: Instant) -> Option<(JogAxis, Direction)> {
    settings(ui, pendant);
    ui.separator();
    let ready = pendant.motion_ready(now);
    if let Err(why) = &ready {
        reason(ui, why);
    }
    let enabled = ready.is_ok();
    let why = ready.err().map(|e| e.to_string()).unwrap_or_default();
    ui.label(
        RichText::new(format!(
            "Cartesian ({} frame)",
            pendant.settings.jog.frame.name()
        ))
        .strong(),
    );
    let mut hovered = buttons(ui, pendant, &JogAxis::CARTESIAN, enabled, &why, now);
    ui.label(RichText::new("Joints").strong());
    hovered = buttons(ui, pendant, &JogAxis::JOINTS, enabled, &why, now).or(hovered);
    target(ui, pendant, enabled, &why, now);
    if let Some(m) = &pendant.jog_feedback {
        message(ui, m.level, &m.text);
    }
    hovered
}

/// The target from the arm view's "Step here": editable, moved to only on "Go to target".
fn target(ui: &mut Ui, pendant: &mut Pendant, enabled: bool, why: &str, now: Instant) {
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
    pendant.edit_step_target(pose);
    ui.horizontal(|ui| {
        let go = ui
            .add_enabled(enabled, Button::new("Go to target"))
            .on_disabled_hover_text(why)
            .on_hover_text(
                "2D4H to the target after the same checks as a step (its ghost shows them)",
            );
        if go.clicked() {
            pendant.go_to_target(now);
        }
        if ui.button("Clear target").clicked() {
            pendant.clear_step_target();
        }
    });
}

fn settings(ui: &mut Ui, pendant: &mut Pendant) {
    let current_arm = pendant.controller.work.map(|s| s.value.common.arm);
    let cp_max = pendant.model.cp_max_speed_mm_s.min(f64::from(u16::MAX)) as u16;
    let j = &mut pendant.settings.jog;
    ui.horizontal(|ui| {
        ui.label("Mode");
        ui.selectable_value(&mut j.mode, JogMode::Step, "Step");
        ui.selectable_value(&mut j.mode, JogMode::Continuous, "Continuous")
            .on_hover_text("236H while the button or key is held; 238H on release");
    });
    if j.mode == JogMode::Step {
        ui.horizontal_wrapped(|ui| {
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
                    .max_decimals(3)
                    .suffix(" mm|deg"),
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
    }
    ui.horizontal(|ui| {
        ui.label("Motion");
        ui.selectable_value(&mut j.interpolation, Interpolation::Ptp, "PTP");
        ui.selectable_value(&mut j.interpolation, Interpolation::Cp, "CP")
            .on_hover_text("A straight line of the tool tip, checked along its whole length");
    });
    if j.interpolation == Interpolation::Ptp {
        ui.horizontal(|ui| {
            let label = ui.label("Arm");
            ComboBox::from_id_salt("arm-policy")
                .selected_text(j.arm.name())
                .show_ui(ui, |ui| {
                    for a in ArmChoice::ALL {
                        ui.selectable_value(&mut j.arm, a, a.name());
                    }
                })
                .response
                .labelled_by(label.id);
            if let Some(arm) = current_arm {
                ui.label(format!("now: {arm}"));
            }
        });
    }
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
                            .suffix(" x0.01 G");
                        ui.add(v).labelled_by(l.id);
                        let v = DragValue::new(&mut j.cp_decel_cg)
                            .range(0..=999)
                            .suffix(" x0.01 G");
                        ui.add(v).labelled_by(l.id);
                    });
                }
            }
            ui.end_row();
        })
        .response
        .on_hover_text(
            "0 = the controller's parameter value. Joint steps and jogs use the % rates.",
        );
    ui.horizontal(|ui| {
        ui.label("Frame");
        for f in [StepFrame::Work, StepFrame::Base, StepFrame::Tool] {
            ui.selectable_value(&mut j.frame, f, f.name());
        }
    });
    if j.mode == JogMode::Step {
        ui.horizontal(|ui| {
            ui.label("Relative to");
            for b in [StepBase::Command, StepBase::Actual, StepBase::Target] {
                ui.selectable_value(&mut j.relative_to, b, b.name());
            }
        })
        .response
        .on_hover_text(
            "command: where the last move ends (chained steps never drift); actual: the \
             polled position; target: where the profile is now",
        );
    }
}

fn buttons(
    ui: &mut Ui,
    pendant: &mut Pendant,
    axes: &[JogAxis],
    enabled: bool,
    why: &str,
    now: Instant,
) -> Option<(JogAxis, Direction)> {
    let mut hovered = None;
    ui.horizontal_wrapped(|ui| {
        for &axis in axes {
            for dir in [Direction::Negative, Direction::Positive] {
                let sign = if dir == Direction::Positive { "+" } else { "-" };
                let label = format!("{}{sign}", axis.name());
                let held = pendant.held_jog();
                let held_here = held.is_some_and(|h| h.axis == axis && h.direction == dir);
                let by_pointer = held.is_some_and(|h| h.source == HoldSource::Pointer);
                let button = Button::new(RichText::new(&label).size(16.0))
                    .min_size(vec2(44.0, 30.0))
                    .selected(held_here);
                let resp = ui
                    .add_enabled(enabled || held_here, button)
                    .on_disabled_hover_text(why);
                if resp.hovered() {
                    hovered = Some((axis, dir));
                }
                match pendant.settings.jog.mode {
                    JogMode::Step => {
                        if resp.clicked() {
                            pendant.jog_step(axis, dir, now);
                        }
                    }
                    JogMode::Continuous => {
                        let down = resp.is_pointer_button_down_on();
                        if down && held.is_none() {
                            pendant.jog_press(axis, dir, HoldSource::Pointer, now);
                        } else if down && held_here {
                            pendant.jog_held();
                        } else if !down && held_here && by_pointer {
                            pendant.jog_release(now);
                        }
                    }
                }
            }
            ui.add_space(6.0);
        }
    });
    hovered
}
