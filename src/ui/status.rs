//! The status panel: per-axis servo, home, in use, completed and error; the arm system,
//! work and tool numbers; in-position and motion-phase lamps; Servo ON/OFF and Home.

use std::time::Instant;

use egui::{Button, RichText, Ui};

use super::widgets::{AMBER, GREEN, RED, lamp, reason};
use crate::pendant::{Intent, MotionPhase, Pendant};
use crate::protocol::HomeState;

const AXIS_NAMES: [&str; 4] = ["1 (J1 / X)", "2 (J2 / Y)", "3 (Z)", "4 (R)"];
const SHORT_AXIS_NAMES: [&str; 4] = ["1 J1", "2 J2", "3 Z", "4 R"];
/// Below this width the axis grid is drawn narrow.
const WIDE_GRID: f32 = 360.0;

pub fn show(ui: &mut Ui, pendant: &Pendant, now: Instant, intents: &mut Vec<Intent>) {
    let ready = pendant.controller_ready(now);
    let why = ready
        .as_ref()
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default();
    ui.horizontal(|ui| servo_home_buttons(ui, &ready, &why, intents));
    if let Err(why) = &ready {
        reason(ui, why);
    }
    if let Some(s) = pendant.controller.system.map(|s| s.value) {
        ui.horizontal_wrapped(|ui| {
            lamp(ui, !s.status3.drive_cut_off(), GREEN, "Drive source");
            lamp(ui, s.status1.manual_switch(), AMBER, "MANUAL switch");
            lamp(ui, s.status2.program_running(), AMBER, "Program running");
        });
    }
    if let Some(w) = pendant.controller.work.map(|s| s.value) {
        ui.label(format!(
            "{}, work No. {}, tool No. {}",
            w.common.arm, w.work, w.tool
        ));
    }
    axis_grid(ui, pendant);
    let phase = pendant.motion_phase(now);
    let inpos = pendant.in_position().unwrap_or(false);
    let lamps = |ui: &mut Ui, set: &[(MotionPhase, &str)]| {
        ui.horizontal(|ui| {
            for &(p, label) in set {
                let color = if p == MotionPhase::Stopped {
                    RED
                } else {
                    GREEN
                };
                lamp(ui, phase == p, color, label);
            }
        });
    };
    ui.vertical(|ui| {
        ui.horizontal(|ui| {
            lamp(ui, inpos, GREEN, "In position");
            lamps(
                ui,
                &[
                    (MotionPhase::Done, "Done"),
                    (MotionPhase::Stopped, "Stopped"),
                ],
            );
        });
        lamps(
            ui,
            &[
                (MotionPhase::Accelerating, "Accel"),
                (MotionPhase::Constant, "Constant"),
                (MotionPhase::Decelerating, "Decel"),
                (MotionPhase::Jogging, "Jogging"),
            ],
        );
    })
    .response
    .on_hover_text(
        "The controller reports no motion phase: the pendant follows the profile of the \
         move it sent (inferred), and compares the polled joints with the move's end.",
    );
}

fn axis_grid(ui: &mut Ui, pendant: &Pendant) {
    let Some(axes) = pendant.controller.axes() else {
        ui.label("no axis status yet");
        return;
    };
    // A narrow pane (a small window) gets short axis names and tight columns.
    let narrow = ui.available_width() < WIDE_GRID;
    let names = if narrow { SHORT_AXIS_NAMES } else { AXIS_NAMES };
    egui::Grid::new("axis-status")
        .striped(true)
        .num_columns(6)
        .spacing(if narrow { [5.0, 3.0] } else { [8.0, 3.0] })
        .min_col_width(if narrow {
            0.0
        } else {
            ui.spacing().interact_size.x
        })
        .show(ui, |ui| {
            let completed = if narrow { "Done" } else { "Completed" };
            for h in ["Axis", "Servo", "Home", "In use", completed, "Error"] {
                ui.label(RichText::new(h).strong())
                    .on_hover_text(if h == "Done" {
                        "Completed normally"
                    } else {
                        ""
                    });
            }
            ui.end_row();
            for (i, (_, a)) in axes.iter().enumerate() {
                let st = a.status;
                ui.label(names.get(i).copied().unwrap_or("?"));
                yes_no(ui, st.servo_on(), "on", "off");
                let home = match st.home_state() {
                    HomeState::Done => RichText::new("homed").color(GREEN),
                    HomeState::Homing => RichText::new("homing").color(AMBER),
                    _ => RichText::new("not homed").color(AMBER),
                };
                ui.label(home);
                ui.label(if st.in_use() { "in use" } else { "-" });
                ui.label(if st.completed_normally() { "yes" } else { "-" });
                if a.error.0 == 0 {
                    ui.label("-");
                } else {
                    ui.label(RichText::new(a.error.to_string()).color(RED));
                }
                ui.end_row();
            }
        });
}

fn yes_no(ui: &mut Ui, v: bool, yes: &str, no: &str) {
    if v {
        ui.label(RichText::new(yes).color(GREEN));
    } else {
        ui.label(no);
    }
}

/// Servo ON, Servo OFF and Home: enabled while the controller takes commands, else the
/// reason on hover (here and beside the pad).
pub fn servo_home_buttons(
    ui: &mut Ui,
    ready: &Result<(), crate::pendant::NotReady>,
    why: &str,
    intents: &mut Vec<Intent>,
) {
    let buttons = [
        ("Servo ON", "232H servo on, SCARA axes", Intent::Servo(true)),
        (
            "Servo OFF",
            "232H servo off, SCARA axes",
            Intent::Servo(false),
        ),
        ("Home", "233H home return, SCARA axes", Intent::Home),
    ];
    for (label, hover, intent) in buttons {
        let b = ui.add_enabled(
            ready.is_ok(),
            Button::new(label).min_size(egui::vec2(72.0, 26.0)),
        );
        if b.on_hover_text(hover).on_disabled_hover_text(why).clicked() {
            intents.push(intent);
        }
    }
}
