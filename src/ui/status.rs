//! The status panel: per-axis servo, home, in use, completed and error; the arm system,
//! work and tool numbers; in-position and motion-phase lamps; Servo ON/OFF and Home. Every
//! lamp from a status that is old or from a line that is down is grey, marked stale.

use std::time::Instant;

use egui::{Button, Color32, RichText, Ui};

use super::pane::{Pane, PaneCx};
use super::widgets::{AMBER, GREEN, GREY, RED, reason};
use crate::pendant::controller::STALE_AFTER;
use crate::pendant::{Intent, MotionPhase, Pendant};
use crate::protocol::HomeState;

const AXIS_NAMES: [&str; 4] = ["1 (J1 / X)", "2 (J2 / Y)", "3 (Z)", "4 (R)"];
const SHORT_AXIS_NAMES: [&str; 4] = ["1 J1", "2 J2", "3 Z", "4 R"];
/// Below this width the axis grid is drawn narrow.
const WIDE_GRID: f32 = 360.0;

/// Whether lamps drawn from a status read at `at` no longer show the controller: the
/// line is down, or the read is older than [`STALE_AFTER`] (polls failing).
pub(super) fn is_stale(pendant: &Pendant, at: Option<Instant>, now: Instant) -> bool {
    at.is_some_and(|t| !pendant.line.is_up() || now.saturating_duration_since(t) > STALE_AFTER)
}

/// The words for a stale status: how old, or that the line is down.
pub(super) fn stale_text(pendant: &Pendant, at: Option<Instant>, now: Instant) -> String {
    match at {
        _ if !pendant.line.is_up() => "stale: the line is down".to_owned(),
        Some(t) => format!(
            "stale: read {:.1} s ago",
            now.saturating_duration_since(t).as_secs_f64()
        ),
        None => "stale".to_owned(),
    }
}

/// A lamp from a status: in its colour while the status is fresh, grey (and its words
/// weak) when `stale`, so an old green is never taken for the controller's state; its
/// accessible name then says so ("Drive source lamp: stale").
pub(super) fn status_lamp(ui: &mut Ui, on: bool, color: Color32, label: &str, stale: bool) {
    ui.horizontal(|ui| {
        let (rect, dot) = ui.allocate_exact_size(egui::vec2(12.0, 12.0), egui::Sense::hover());
        let fill = match (stale, on) {
            (false, true) => color,
            (true, true) => GREY,
            (_, false) => GREY.gamma_multiply(0.4),
        };
        ui.painter().circle_filled(rect.center(), 5.5, fill);
        if stale && on {
            ui.painter().circle_stroke(
                rect.center(),
                5.5,
                egui::Stroke::new(1.0, ui.visuals().weak_text_color()),
            );
        }
        if stale {
            let name = format!("{label} lamp: stale");
            dot.widget_info(|| egui::WidgetInfo::labeled(egui::Role::Label, true, &name));
        }
        let text = RichText::new(label);
        ui.label(if stale { text.weak() } else { text });
    });
}

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
    // Every lamp and word below is from a poll: grey with "stale" once it is old.
    let c = &pendant.controller;
    let at = [
        c.system.map(|s| s.at),
        c.work.map(|s| s.at),
        c.joints.map(|s| s.at),
    ]
    .into_iter()
    .flatten()
    .min();
    let stale = is_stale(pendant, at, now);
    if stale {
        ui.label(RichText::new(stale_text(pendant, at, now)).color(AMBER))
            .on_hover_text("The lamps show the last status read; the controller may differ now.");
    }
    if let Some(s) = pendant.controller.system.map(|s| s.value) {
        ui.horizontal_wrapped(|ui| {
            status_lamp(ui, !s.status3.drive_cut_off(), GREEN, "Drive source", stale);
            status_lamp(ui, s.status1.manual_switch(), AMBER, "MANUAL switch", stale);
            status_lamp(
                ui,
                s.status2.program_running(),
                AMBER,
                "Program running",
                stale,
            );
        });
    }
    if let Some(w) = pendant.controller.work.map(|s| s.value) {
        ui.label(format!(
            "{}, work No. {}, tool No. {}",
            w.common.arm, w.work, w.tool
        ));
    }
    axis_grid(ui, pendant, stale);
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
                status_lamp(ui, phase == p, color, label, stale);
            }
        });
    };
    ui.vertical(|ui| {
        ui.horizontal(|ui| {
            status_lamp(ui, inpos, GREEN, "In position", stale);
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

fn axis_grid(ui: &mut Ui, pendant: &Pendant, stale: bool) {
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
                let header = ui.label(RichText::new(h).strong());
                // No empty tooltips: only the short header has one.
                if h == "Done" {
                    header.on_hover_text("Completed normally");
                }
            }
            ui.end_row();
            for (i, (_, a)) in axes.iter().enumerate() {
                let st = a.status;
                ui.label(names.get(i).copied().unwrap_or("?"));
                yes_no(ui, st.servo_on(), "on", "off", stale);
                let (home, color) = match st.home_state() {
                    HomeState::Done => ("homed", GREEN),
                    HomeState::Homing => ("homing", AMBER),
                    _ => ("not homed", AMBER),
                };
                ui.label(colored(home, color, stale));
                ui.label(if st.in_use() { "in use" } else { "-" });
                ui.label(if st.completed_normally() { "yes" } else { "-" });
                if a.error.0 == 0 {
                    ui.label("-");
                } else {
                    ui.label(colored(&a.error.to_string(), RED, stale));
                }
                ui.end_row();
            }
        });
}

fn yes_no(ui: &mut Ui, v: bool, yes: &str, no: &str, stale: bool) {
    if v {
        ui.label(colored(yes, GREEN, stale));
    } else {
        ui.label(no);
    }
}

/// A word in its colour, or weak grey from a stale status.
fn colored(text: &str, color: Color32, stale: bool) -> RichText {
    let text = RichText::new(text);
    if stale {
        text.weak()
    } else {
        text.color(color)
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

/// The Status pane.
#[derive(Default)]
pub struct StatusPane;

impl Pane for StatusPane {
    fn ui(&mut self, ui: &mut Ui, cx: &mut PaneCx<'_>) {
        egui::ScrollArea::vertical().show(ui, |ui| show(ui, cx.pendant, cx.now, cx.intents));
    }
}
