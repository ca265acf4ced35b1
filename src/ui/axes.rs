//! The RMC151's axis panel: the connection, the jog choices, and per axis its lamps
//! (Enabled, In Position, TG Done, the phase, Halted, errors), its Command, Target and
//! Actual positions, Enable, Clear faults and the − / + buttons; the command log below.

use egui::{Button, ComboBox, DragValue, Pos2, RichText, Ui};

use super::pane::{Pane, PaneCx};
use super::widgets::{AMBER, GREEN, GREY, RED, level_color, reserved_line};
use crate::pendant::axes::lamps::{Lamp, LampKind, Lit};
use crate::pendant::axes::{AxisIntent, AxisJog, AxisView};
use crate::pendant::{Intent, JogInput, JogMode, LineState, Pendant};
use crate::protocol::Direction;
use crate::rmc::AxisId;
use crate::robot::RelativeTo;

/// What the axis buttons saw this frame (as the arm's pad reports its own).
#[derive(Clone, Copy, Debug, Default)]
pub struct AxesPadOutput {
    /// The button the primary pointer button is held on (pressed on it, still over it).
    pub held_on: Option<AxisJog>,
    /// A button pressed and released within this one frame.
    pub tapped: Option<AxisJog>,
}

/// The step distances offered as buttons (any other is typed).
const STEP_LADDER: [f32; 4] = [0.1, 1.0, 10.0, 100.0];

/// Size of a − / + button: the same in every state, so nothing moves under the pointer.
const JOG_BUTTON: [f32; 2] = [46.0, 30.0];

/// Width of the Relative to choice, whichever is chosen.
const RELATIVE_TO_WIDTH: f32 = 90.0;

/// Draws the panel; intents go to `intents`, the buttons' pointer state to `pad`.
pub fn show(ui: &mut Ui, pendant: &Pendant, intents: &mut Vec<Intent>, pad: &mut AxesPadOutput) {
    let rmc = &pendant.axes;
    connection(ui, pendant, intents);
    ui.separator();
    jog_choices(ui, pendant, intents);
    // The latch, the running jog or the last word: one line whatever it says.
    let line = rmc.jog_line();
    let line = line.as_ref().map(|(l, t)| (level_color(*l), t.as_str()));
    reserved_line(ui, line, line.map(|(_, t)| t));
    // While the line is not up every lamp below is stale: said here, room always kept.
    let stale = rmc.stale_text();
    reserved_line(ui, stale.as_deref().map(|t| (GREY, t)), stale.as_deref());
    ui.separator();
    let mut row = Row {
        pendant,
        up: rmc.line.is_up(),
        intents,
        pad,
    };
    for (index, view) in rmc.axes.iter().enumerate() {
        let Some(axis) = AxisId::new(index) else {
            continue;
        };
        row.show(ui, axis, view);
        ui.separator();
    }
    egui::CollapsingHeader::new("Command log")
        .default_open(false)
        .show(ui, |ui| {
            for line in rmc.log.iter().rev().take(40) {
                let axis = line.axis.map(|a| format!("{a}: ")).unwrap_or_default();
                ui.label(
                    RichText::new(format!("{axis}{}", line.text))
                        .monospace()
                        .size(11.0),
                );
            }
        });
}

fn connection(ui: &mut Ui, pendant: &Pendant, intents: &mut Vec<Intent>) {
    let rmc = &pendant.axes;
    // Buttons first, the state's words on a line of their own and the controller's lamps
    // always drawn: a state that changes moves nothing below it.
    ui.horizontal(|ui| {
        ui.label(RichText::new("RMC151").strong());
        let up = !matches!(rmc.line, LineState::Closed);
        if ui
            .add(Button::new(if up { "Reconnect" } else { "Connect" }).min_size([84.0, 0.0].into()))
            .clicked()
        {
            intents.push(Intent::Axes(AxisIntent::Connect));
        }
        if ui.add_enabled(up, Button::new("Disconnect")).clicked() {
            intents.push(Intent::Axes(AxisIntent::Disconnect));
        }
    });
    let (color, text) = match &rmc.line {
        LineState::Closed => (GREY, "not connected".to_string()),
        LineState::Opening => (AMBER, "connecting...".to_string()),
        LineState::Up { line, .. } => (GREEN, format!("connected: {line}")),
        LineState::Down { reason, .. } => (RED, format!("down: {reason}")),
    };
    let hover = format!(
        "{text}\n\nAddress, unit ID, axes, units and soft limits: the left column's \
         \"Delta RMC151 (Modbus/TCP)\" section"
    );
    reserved_line(ui, Some((color, &text)), Some(&hover));
    ui.horizontal(|ui| {
        for l in rmc.controller_lamps() {
            model_lamp(ui, &l);
        }
        if let Some(id) = rmc.module {
            let name = match id {
                17 => "RMC151E",
                16 => "RMC150E",
                _ => "unknown module",
            };
            ui.label(format!("CPU Module ID {id} ({name})"));
        }
    });
}

/// A lamp as the model derives it: its kind's colour when lit, dim when not, grey and
/// said so when stale.
fn model_lamp(ui: &mut Ui, l: &Lamp) {
    let color = match l.kind {
        LampKind::Good => GREEN,
        LampKind::Bad => RED,
        LampKind::Phase => AMBER,
    };
    let (fill, hover) = match l.lit {
        Lit::On => (color, l.hover.clone()),
        Lit::Off => (GREY.gamma_multiply(0.4), l.hover.clone()),
        Lit::Stale { was_on } => (
            GREY.gamma_multiply(0.4),
            format!(
                "{}\n\nstale: read {} before the line went down",
                l.hover,
                if was_on { "lit" } else { "dark" }
            ),
        ),
    };
    ui.horizontal(|ui| {
        let (rect, _) = ui.allocate_exact_size(egui::vec2(12.0, 12.0), egui::Sense::hover());
        if matches!(l.lit, Lit::Stale { .. }) {
            ui.painter()
                .circle_stroke(rect.center(), 5.0, egui::Stroke::new(1.0, GREY));
        } else {
            ui.painter().circle_filled(rect.center(), 5.5, fill);
        }
        let text = match l.lit {
            Lit::Stale { .. } => RichText::new(l.name).color(GREY),
            _ => RichText::new(l.name),
        };
        ui.label(text);
    })
    .response
    .on_hover_text(hover);
}

fn jog_choices(ui: &mut Ui, pendant: &Pendant, intents: &mut Vec<Intent>) {
    let units = pendant.settings.rmc.units.clone();
    let mut jog = pendant.settings.rmc.jog;
    // Rows of their own, none wrapping: a choice whose words change width (Relative
    // to, a typed step) moves nothing below it.
    ui.horizontal(|ui| {
        ui.selectable_value(&mut jog.mode, JogMode::Step, "Step")
            .on_hover_text("one Move Relative (21) per press");
        ui.selectable_value(&mut jog.mode, JogMode::Continuous, "Hold")
            .on_hover_text("moves while held: short Move Relative moves relative to the Target, renewed while the button is down; Stop (6) on release");
    });
    // A held jog always moves relative to the Target, by its own distances: the step's
    // choices are disabled, not removed, so nothing moves under the pointer.
    ui.add_enabled_ui(jog.mode == JogMode::Step, |ui| {
        ui.horizontal(|ui| {
            ui.label("Step");
            for d in STEP_LADDER {
                ui.selectable_value(&mut jog.step, d, format!("{d}"));
            }
            ui.add(
                DragValue::new(&mut jog.step)
                    .speed(0.1)
                    .range(0.001..=10_000.0)
                    .max_decimals(3)
                    .suffix(format!(" {units}")),
            );
        });
        ui.horizontal(|ui| {
            ui.label("Relative to");
            ComboBox::from_id_salt("rmc-relative-to")
                .width(RELATIVE_TO_WIDTH)
                .selected_text(jog.relative_to.name())
                .show_ui(ui, |ui| {
                    for r in RelativeTo::ALL {
                        ui.selectable_value(&mut jog.relative_to, r, r.name());
                    }
                });
        });
    });
    ui.horizontal(|ui| {
        ui.label("Speed");
        ui.add(
            DragValue::new(&mut jog.speed)
                .range(0.001..=100_000.0)
                .suffix(format!(" {units}/s")),
        );
    });
    ui.horizontal(|ui| {
        ui.label("Accel");
        ui.add(
            DragValue::new(&mut jog.accel)
                .range(0.001..=1_000_000.0)
                .suffix(format!(" {units}/s²")),
        );
        ui.label("Decel");
        ui.add(
            DragValue::new(&mut jog.decel)
                .range(0.001..=1_000_000.0)
                .suffix(format!(" {units}/s²")),
        );
    });
    let meaning = match jog.relative_to {
        RelativeTo::Command => {
            "relative to command: added to where the last move ends (steps never drift)"
        }
        RelativeTo::Actual => {
            "relative to actual: added to the measured position when the RMC takes it"
        }
        RelativeTo::Target => {
            "relative to target: added to where the target generator is when the RMC takes it"
        }
    };
    let meaning = if jog.mode == JogMode::Step {
        meaning
    } else {
        "hold: moves relative to the target while held, Stop (6) on release"
    };
    // One line whatever it says (the whole of it on hover).
    reserved_line(ui, Some((GREY, meaning)), Some(meaning));
    if jog != pendant.settings.rmc.jog {
        intents.push(Intent::Axes(AxisIntent::Settings(jog)));
    }
}

/// What every axis row draws with.
struct Row<'a> {
    pendant: &'a Pendant,
    /// The RMC's line is up.
    up: bool,
    intents: &'a mut Vec<Intent>,
    pad: &'a mut AxesPadOutput,
}

impl Row<'_> {
    fn show(&mut self, ui: &mut Ui, axis: AxisId, view: &AxisView) {
        let (pendant, up) = (self.pendant, self.up);
        axis_row(ui, pendant, axis, view, up, self.intents, self.pad);
    }
}

fn axis_row(
    ui: &mut Ui,
    pendant: &Pendant,
    axis: AxisId,
    view: &AxisView,
    up: bool,
    intents: &mut Vec<Intent>,
    pad: &mut AxesPadOutput,
) {
    let units = pendant.settings.rmc.units(axis);
    let enabled = view.enabled();
    ui.horizontal(|ui| {
        ui.label(RichText::new(axis.to_string()).strong().size(15.0));
        let (text, on) = if enabled {
            ("Disable", false)
        } else {
            ("Enable", true)
        };
        if ui
            .add_enabled(up, Button::new(text).min_size([70.0, 0.0].into()))
            .clicked()
        {
            intents.push(Intent::Axes(AxisIntent::Enable(axis, on)));
        }
        if ui.add_enabled(up, Button::new("Clear faults")).clicked() {
            intents.push(Intent::Axes(AxisIntent::ClearFaults(axis)));
        }
        if ui
            .add_enabled(up, Button::new(RichText::new("Stop").color(RED)))
            .on_hover_text("Stop (Closed Loop) (6) for this axis, at STOP's deceleration")
            .clicked()
        {
            intents.push(Intent::Axes(AxisIntent::Stop(axis)));
        }
        let why_not = pendant.axes.not_ready(axis);
        let can_move = up && why_not.is_none();
        for direction in [Direction::Negative, Direction::Positive] {
            jog_button(ui, pendant, AxisJog { axis, direction }, can_move, pad);
        }
    });
    let status = view.status;
    for row in pendant.axes.axis_lamps(axis) {
        ui.horizontal(|ui| {
            for l in &row {
                model_lamp(ui, l);
            }
        });
    }
    let errors = status.map(|s| s.errors.names()).unwrap_or_default();
    let last_error = status.map_or(0.0, |s| s.last_error);
    let line = if !errors.is_empty() {
        Some((RED, format!("Errors: {}", errors.join(", "))))
    } else if last_error != 0.0 {
        Some((AMBER, format!("Last Error Number {last_error}")))
    } else if view.awaiting {
        Some((AMBER, "ACK awaited: lamps as last acknowledged".to_string()))
    } else {
        None
    };
    reserved_line(ui, line.as_ref().map(|(c, t)| (*c, t.as_str())), None);
    // Positions from the latest read (valid while ACK is awaited), the lamps from the last
    // trusted one.
    let s = view.latest.or(status);
    let value = |v: Option<f32>| v.map_or("—".to_string(), |v| format!("{v:.3}"));
    egui::Grid::new(("rmc-axis-grid", axis.index()))
        .num_columns(3)
        .spacing([18.0, 1.0])
        .show(ui, |ui| {
            ui.label("");
            ui.label(
                RichText::new(format!("Position ({units})"))
                    .size(11.0)
                    .color(GREY),
            );
            ui.label(
                RichText::new(format!("Velocity ({units}/s)"))
                    .size(11.0)
                    .color(GREY),
            );
            ui.end_row();
            for (name, position, velocity) in [
                (
                    "Command",
                    s.map(|s| s.command_position),
                    s.map(|s| s.command_velocity),
                ),
                (
                    "Target",
                    s.map(|s| s.target_position),
                    s.map(|s| s.target_velocity),
                ),
                (
                    "Actual",
                    s.map(|s| s.actual_position),
                    s.map(|s| s.actual_velocity),
                ),
            ] {
                ui.label(name);
                ui.label(RichText::new(value(position)).monospace().size(15.0));
                ui.label(RichText::new(value(velocity)).monospace());
                ui.end_row();
            }
            ui.label("Following error");
            ui.label(RichText::new(value(s.map(|s| s.following_error()))).monospace());
            ui.end_row();
        });
}

fn jog_button(
    ui: &mut Ui,
    pendant: &Pendant,
    target: AxisJog,
    enabled: bool,
    pad: &mut AxesPadOutput,
) {
    let text = match target.direction {
        Direction::Negative => "−",
        Direction::Positive => "+",
    };
    let running = pendant.axes.hold.jog().is_some_and(|j| j.target == target);
    let held = pendant.axes.hold.on(JogInput::Pointer) == Some(target) || running;
    let resp = ui
        .add_enabled(
            enabled,
            Button::new(RichText::new(text).size(18.0))
                .min_size(JOG_BUTTON.into())
                .selected(held),
        )
        .on_hover_text(target.label())
        .on_disabled_hover_text(format!(
            "{}: connect and enable the axis first",
            target.label()
        ));
    // Named for what it does ("Axis 1+"), as screen readers and tests find it.
    let label = target.label();
    resp.widget_info(|| egui::WidgetInfo::labeled(egui::Role::Button, enabled, &label));
    let rect = resp.rect;
    let (down, origin, pos, pressed_now) = ui.input(|i| {
        (
            i.pointer.primary_down(),
            i.pointer.press_origin(),
            i.pointer.latest_pos(),
            i.pointer.primary_pressed(),
        )
    });
    if !enabled {
        return;
    }
    let inside = |p: Option<Pos2>| p.is_some_and(|p| rect.contains(p));
    if down && inside(origin) && inside(pos) {
        pad.held_on = Some(target);
    }
    if !down && pressed_now && resp.clicked() {
        pad.tapped = Some(target);
    }
}

/// The RMC axes pane: what its axis buttons saw this frame is kept for the window's
/// pointer (taken after drawing).
#[derive(Default)]
pub struct AxesPane {
    pub pad: AxesPadOutput,
}

impl Pane for AxesPane {
    fn ui(&mut self, ui: &mut Ui, cx: &mut PaneCx<'_>) {
        egui::ScrollArea::vertical().show(ui, |ui| show(ui, cx.pendant, cx.intents, &mut self.pad));
    }
}
