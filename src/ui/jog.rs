//! The jog panel: Servo ON/OFF, Home and Reset alarm, the "ready to jog" lamp, step or
//! continuous, the step ladder, PTP or CP, the arm system, speeds under the jog speed cap,
//! the frame and "relative to", the pad, and the target from the arm view ("Step here")
//! with its "Go to target". It draws `&Pendant` and pushes intents; rows are disabled,
//! never removed, and the reason and result lines keep their space.

use std::time::Instant;

use egui::{
    Align, Button, Color32, ComboBox, DragValue, Layout, Rect, RichText, Sense, TextStyle,
    TextWrapMode, Ui, UiBuilder, vec2,
};

use super::pad::{self, PadOutput};
use super::pane::{Pane, PaneCx};
use super::widgets::{AMBER, GREEN, GREY, RED, reserved_line};
use crate::pendant::jog::speed_cap::{self, MAX_CAP_MM_S, REDUCED_SPEED_MM_S};
use crate::pendant::jog::{MAX_STEP, STEP_LADDER};
use crate::pendant::{Intent, Interpolation, JogMode, JogSettings, NotReady, Pendant};
use crate::protocol::ArmPolicy;
use crate::robot::{JogFrame, RelativeTo};

/// The panel's own state: the speed cap being raised.
#[derive(Default)]
pub struct JogPanel {
    /// The "raise the cap" dialog is open with this value.
    raising: Option<f64>,
    /// What the pad saw this frame (taken after drawing, for the pointer's jog input).
    pub pad: PadOutput,
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
        let latch = pendant.stop_latch();
        // The lamp an operator looks at: ready to jog, latched by a STOP, or what is
        // missing. One line of its own, cut to the column: its words never widen it.
        let (on, color, ready_text) = ready_lamp(&ready, latch.as_deref());
        lamp_line(ui, on, color, &ready_text);
        ui.separator();
        let mut jog = pendant.settings.jog.clone();
        settings(ui, pendant, &mut jog);
        self.speed_cap(ui, pendant, intents);
        // What each kind of jog sends, in its unit, from the settings as set now.
        let cap = pendant.speed_cap();
        for joint in [false, true] {
            let text = speed_cap::speed_line(&jog, &pendant.model, cap, joint);
            let lowered = speed_cap::sent_speed(&jog, &pendant.model, cap, joint)
                .capped
                .lowered;
            let color = if lowered {
                AMBER
            } else {
                ui.visuals().text_color()
            };
            reserved_line(ui, Some((color, &text)), Some(&text));
        }
        if jog != pendant.settings.jog {
            intents.push(Intent::JogSettings(jog));
        }
        ui.separator();
        // Above the pad, one reserved line: the latch, else the reason motion is off, else
        // what the pad's two blocks are.
        let heading = format!(
            "Cartesian ({} frame)  \u{2022}  Joints below",
            pendant.settings.jog.frame.name()
        );
        let (color, line) = match (&latch, &ready) {
            (Some(text), _) => (RED, text.clone()),
            (None, Err(why)) => (AMBER, format!("Not available: {why}")),
            (None, Ok(())) => (ui.visuals().strong_text_color(), heading),
        };
        reserved_line(ui, Some((color, &line)), Some(&line));
        // A disabled pad says why on hover: the latch, else what is missing.
        let pad_why = latch.clone().unwrap_or_else(|| why.clone());
        let out = pad::show(ui, pendant, ready.is_ok() && latch.is_none(), &pad_why);
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

    /// The cap on the tool's speed: one line of the column's width whatever its value,
    /// raised only through a dialog that asks for the new value, never saved.
    fn speed_cap(&mut self, ui: &mut Ui, pendant: &Pendant, intents: &mut Vec<Intent>) {
        let cap = pendant.speed_cap();
        let reduced = (cap - REDUCED_SPEED_MM_S).abs() < 0.5;
        let text = format!("Speed cap {cap:.0} mm/s at the tool");
        let color = if reduced {
            ui.visuals().text_color()
        } else {
            AMBER
        };
        let hover = format!(
            "Every step, jog and Go is capped at this tool speed (PTP % through the model's \
             maximum joint speeds: {} % at most). Format B runs in AUTO, where the \
             controller applies no reduced speed of its own.",
            speed_cap::ptp_percent_cap(&pendant.model, cap)
        );
        // The button keeps the width of the wider of its two words, the text the rest.
        let button_width = [RAISE, BACK_TO_REDUCED]
            .map(|t| {
                egui::WidgetText::from(t)
                    .into_galley(
                        ui,
                        Some(TextWrapMode::Extend),
                        f32::INFINITY,
                        TextStyle::Small,
                    )
                    .size()
                    .x
            })
            .into_iter()
            .fold(0.0, f32::max)
            + 2.0 * ui.spacing().button_padding.x;
        let height = ui.spacing().interact_size.y;
        let (rect, _) = ui.allocate_exact_size(vec2(ui.available_width(), height), Sense::hover());
        // The words on the left, cut to their room; the button on the right.
        let split = rect.right() - button_width;
        let words = Rect::from_min_max(rect.min, egui::pos2(split - 4.0, rect.bottom()));
        let layout = Layout::left_to_right(Align::Center);
        ui.scope_builder(UiBuilder::new().max_rect(words).layout(layout), |ui| {
            ui.add(egui::Label::new(RichText::new(text).color(color)).truncate())
                .on_hover_text(hover);
        });
        let (word, tip) = if reduced {
            (RAISE, "Raise the cap until the window closes")
        } else {
            (BACK_TO_REDUCED, "Back to the reduced speed")
        };
        let button_rect = Rect::from_min_max(egui::pos2(split, rect.top()), rect.max);
        let button = egui::Button::new(RichText::new(word).small());
        let resp = ui.put(button_rect, button).on_hover_text(tip);
        if resp.clicked() {
            if reduced {
                self.raising = Some(cap.max(500.0));
            } else {
                intents.push(Intent::ResetSpeedCap);
            }
        }
        let raise_at = Some(resp.rect);
        if let Some(value) = self.raising.as_mut() {
            let mut close = false;
            // Away from STOP (the top bar's left) and the safety band: below the band,
            // in the middle of the window, right of the column.
            // The column's visible part starts below the band.
            let column = ui.clip_rect();
            let screen = ui.ctx().content_rect();
            let left = raise_at.map_or(column.right(), |r| r.right()) + DIALOG_GAP;
            let at = egui::pos2(
                left.max(screen.center().x - DIALOG_WIDTH / 2.0),
                column.top() + DIALOG_GAP,
            );
            egui::Window::new("Raise the jog speed cap")
                .collapsible(false)
                .resizable(false)
                .default_width(DIALOG_WIDTH)
                .fixed_pos(at)
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

/// The cap button's two words.
const RAISE: &str = "Raise...";
const BACK_TO_REDUCED: &str = "Back to reduced";
/// The raise dialog's width, and its distance from what it must not cover, px.
const DIALOG_WIDTH: f32 = 320.0;
const DIALOG_GAP: f32 = 24.0;

/// The jog lamp: ready, latched by a STOP (with its words), or not ready and why.
fn ready_lamp(ready: &Result<(), NotReady>, latch: Option<&str>) -> (bool, Color32, String) {
    match (latch, ready) {
        (Some(latch), _) => (true, AMBER, format!("Latched: {latch}")),
        (None, Ok(())) => (true, GREEN, "Ready to jog".to_owned()),
        (None, Err(why)) => (false, GREEN, format!("Not ready: {why}")),
    }
}

/// A lamp and its words in one line of the column's width: cut to fit (the whole on
/// hover), so no state's words widen the column.
fn lamp_line(ui: &mut Ui, on: bool, color: Color32, text: &str) {
    let height = ui.spacing().interact_size.y;
    let (rect, _) = ui.allocate_exact_size(vec2(ui.available_width(), height), Sense::hover());
    let fill = if on { color } else { GREY.gamma_multiply(0.4) };
    let dot = egui::pos2(rect.left() + 6.0, rect.center().y);
    ui.painter().circle_filled(dot, 5.5, fill);
    let words = Rect::from_min_max(egui::pos2(rect.left() + 18.0, rect.top()), rect.max);
    let layout = Layout::left_to_right(Align::Center);
    ui.scope_builder(UiBuilder::new().max_rect(words).layout(layout), |ui| {
        ui.add(egui::Label::new(text).truncate())
    })
    .inner
    .on_hover_text(text);
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

/// Why a row is disabled, or what it shows, after its controls: weak, cut to the room
/// left (the whole on hover), so it never widens the column.
fn beside(ui: &mut Ui, text: &str) {
    ui.add(egui::Label::new(RichText::new(text).weak().small()).truncate())
        .on_hover_text(text);
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
    // A continuous jog is a 236H, which has neither PTP nor CP (nor an arm policy):
    // these rows keep their place, disabled with the reason beside them. Go to a target
    // or a taught point still uses them.
    let continuous = j.mode == JogMode::Continuous;
    ui.add_enabled_ui(!continuous, |ui| {
        ui.horizontal(|ui| {
            ui.label("Motion");
            ui.selectable_value(&mut j.interpolation, Interpolation::Ptp, "PTP");
            ui.selectable_value(&mut j.interpolation, Interpolation::Cp, "CP")
                .on_hover_text("A straight line of the tool tip, checked along its whole length");
            if continuous {
                beside(ui, "a jog (236H) has neither; Go uses it");
            }
        });
    })
    .response
    .on_disabled_hover_text(
        "A continuous jog is a 236H: X Y Z R at the mm/s speed, joints at the % speed. \
         Steps and Go use PTP or CP.",
    );
    let arm_applies = !continuous && j.interpolation == Interpolation::Ptp;
    ui.add_enabled_ui(arm_applies, |ui| {
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
            let why = if arm_applies {
                String::new()
            } else if continuous {
                " (a jog keeps it)".to_owned()
            } else {
                " (CP keeps it)".to_owned()
            };
            beside(ui, &format!("{now}{why}"));
        });
    })
    .response
    .on_disabled_hover_text("CP moves and continuous jogs keep the arm system");
    // Both rates, always in place: each row enabled while a jog of this mode uses it.
    let cp_used = continuous || j.interpolation == Interpolation::Cp;
    egui::Grid::new("jog-speeds")
        .num_columns(3)
        .show(ui, |ui| {
            let l = ui.label("%");
            ui.add(
                DragValue::new(&mut j.ptp_speed_pct)
                    .range(0..=100)
                    .suffix(" %"),
            )
            .labelled_by(l.id)
            .on_hover_text("Speed: PTP steps, joint steps and joint jogs");
            ui.horizontal(|ui| {
                for v in [&mut j.ptp_accel_pct, &mut j.ptp_decel_pct] {
                    ui.add(DragValue::new(v).range(0..=100).suffix(" %"))
                        .labelled_by(l.id)
                        .on_hover_text("Acceleration, deceleration");
                }
            });
            ui.end_row();
            let l = ui.label("mm/s");
            ui.add_enabled_ui(cp_used, |ui| {
                ui.add(
                    DragValue::new(&mut j.cp_speed_mm_s)
                        .range(0..=cp_max)
                        .suffix(" mm/s"),
                )
                .labelled_by(l.id)
                .on_hover_text("Speed: CP steps and X Y Z R jogs");
            })
            .response
            .on_disabled_hover_text("used by CP steps and continuous X Y Z R jogs");
            ui.add_enabled_ui(cp_used, |ui| {
                ui.horizontal(|ui| {
                    for v in [&mut j.cp_accel_cg, &mut j.cp_decel_cg] {
                        ui.add(DragValue::new(v).range(0..=999).suffix(" cG"))
                            .labelled_by(l.id)
                            .on_hover_text("Acceleration, deceleration");
                    }
                    if !cp_used {
                        beside(ui, "PTP steps: unused");
                    }
                });
            });
            ui.end_row();
        })
        .response
        .on_hover_text(
            "0 = the controller's parameter value; cG = 0.01 G. The lines below say which \
             speed each jog sends.",
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

impl Pane for JogPanel {
    fn ui(&mut self, ui: &mut Ui, cx: &mut PaneCx<'_>) {
        self.pad = self.show(ui, cx.pendant, cx.now, cx.intents);
    }
}
