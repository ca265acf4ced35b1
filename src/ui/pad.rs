//! The jog pad: X/Y as a cross, Z up/down and R ccw/cw beside it, the joints below, each
//! button in a fixed place and size (at least 56x40 px, growing with the panel). It only
//! reports where the pointer is held; the pendant decides what a press does.

use egui::{Button, Pos2, Rect, RichText, Sense, Ui, vec2};

use super::axes::AxesPadOutput;
use crate::pendant::axes::AxisIntent;
use crate::pendant::{Intent, JogAxis, JogInput, JogTarget, Pendant, PhysicalJog, Press};
use crate::protocol::Direction;

/// Smallest button, px (the floor at 1280x800).
const MIN_BUTTON: egui::Vec2 = vec2(56.0, 40.0);
const GAP: f32 = 4.0;

/// What the pad saw this frame.
#[derive(Clone, Copy, Debug, Default)]
pub struct PadOutput {
    /// The button under the pointer (the arm view draws its step as the ghost).
    pub hovered: Option<JogTarget>,
    /// The button the primary pointer button is held on (pressed on it, still over it).
    pub held_on: Option<JogTarget>,
    /// A button pressed and released within this one frame.
    pub tapped: Option<JogTarget>,
}

/// What a pad button stands for: a physical jog (Cartesian), or a joint.
#[derive(Clone, Copy)]
enum Slot {
    Physical(PhysicalJog),
    Joint,
}

/// The Cartesian cross, Z and R: (column, row, slot) in a 5x3 grid.
const CROSS: [(usize, usize, PhysicalJog); 8] = [
    (1, 0, PhysicalJog::YPlus),
    (0, 1, PhysicalJog::XMinus),
    (2, 1, PhysicalJog::XPlus),
    (1, 2, PhysicalJog::YMinus),
    (3, 0, PhysicalJog::ZUp),
    (3, 2, PhysicalJog::ZDown),
    (4, 0, PhysicalJog::RCcw),
    (4, 2, PhysicalJog::RCw),
];

/// Draws the pad where `ui` is; the same rectangles whatever the state.
pub fn show(ui: &mut Ui, pendant: &Pendant, enabled: bool, why: &str) -> PadOutput {
    // Within what is visible: a scroll bar may take the panel's last pixels.
    let visible = ui.clip_rect().right() - ui.cursor().left();
    let width = (ui.available_width().min(visible) - 6.0).max(5.0 * MIN_BUTTON.x + 4.0 * GAP + 8.0);
    let w = ((width - 4.0 * GAP - 8.0) / 5.0).clamp(MIN_BUTTON.x, 120.0);
    let h = (w * 0.72).clamp(MIN_BUTTON.y, 70.0);
    let size = vec2(w, h);
    let mut out = PadOutput::default();
    // The cross and Z/R block: 3 rows.
    let (block, _) = ui.allocate_exact_size(vec2(width, 3.0 * h + 2.0 * GAP), Sense::hover());
    for (col, row, physical) in CROSS {
        // A wider gap before the Z and R columns.
        let extra = if col >= 3 { 8.0 } else { 0.0 };
        let min = block.min + vec2(col as f32 * (w + GAP) + extra, row as f32 * (h + GAP));
        let rect = Rect::from_min_size(min, size);
        let target = pendant.physical_jog(physical);
        button(
            ui,
            pendant,
            rect,
            Slot::Physical(physical),
            target,
            enabled,
            why,
            &mut out,
        );
    }
    // Labels in the middle row of the Z and R columns.
    for (col, text) in [(3, "Z"), (4, "R")] {
        let center = block.min + vec2(col as f32 * (w + GAP) + 8.0 + w / 2.0, h + GAP + h / 2.0);
        ui.painter().text(
            center,
            egui::Align2::CENTER_CENTER,
            text,
            egui::FontId::proportional(14.0),
            ui.visuals().weak_text_color(),
        );
    }
    ui.add_space(GAP);
    // The joints: two rows of four.
    let jw = ((width - 3.0 * GAP) / 4.0).max(MIN_BUTTON.x);
    let (joints, _) = ui.allocate_exact_size(vec2(width, 2.0 * h + GAP), Sense::hover());
    for (i, axis) in JogAxis::JOINTS.into_iter().enumerate() {
        for (k, dir) in [Direction::Negative, Direction::Positive]
            .into_iter()
            .enumerate()
        {
            let col = (i % 2) * 2 + k;
            let row = i / 2;
            let min = joints.min + vec2(col as f32 * (jw + GAP), row as f32 * (h + GAP));
            let rect = Rect::from_min_size(min, vec2(jw, h));
            let target = JogTarget::new(axis, dir);
            button(
                ui,
                pendant,
                rect,
                Slot::Joint,
                target,
                enabled,
                why,
                &mut out,
            );
        }
    }
    out
}

#[allow(clippy::too_many_arguments)]
fn button(
    ui: &mut Ui,
    pendant: &Pendant,
    rect: Rect,
    slot: Slot,
    target: JogTarget,
    enabled: bool,
    why: &str,
    out: &mut PadOutput,
) {
    let text = match slot {
        // The physical direction, and the sign it sends.
        Slot::Physical(
            p @ (PhysicalJog::ZUp | PhysicalJog::ZDown | PhysicalJog::RCcw | PhysicalJog::RCw),
        ) => {
            format!("{}\n{}", p.name(), target.label())
        }
        Slot::Physical(p) => p.name().to_owned(),
        Slot::Joint => target.label(),
    };
    let running = pendant.held_jog().is_some_and(|j| j.target == target);
    let held = pendant.held_on(JogInput::Pointer) == Some(target) || running;
    // Two-line labels (direction and sign) a little smaller, never wrapped further; all
    // grow with the button (a wide window's pad).
    let grow = (rect.height() / MIN_BUTTON.y).clamp(1.0, 1.6);
    let size = grow * if text.contains('\n') { 13.0 } else { 15.0 };
    let widget = Button::new(RichText::new(text).size(size))
        .wrap_mode(egui::TextWrapMode::Extend)
        .selected(held);
    let resp = ui.put(rect, |ui: &mut Ui| ui.add_enabled(enabled, widget));
    // No empty tooltip: a reason, or none.
    let resp = if why.is_empty() {
        resp
    } else {
        resp.on_disabled_hover_text(why)
    };
    if resp.hovered() || resp.contains_pointer() {
        out.hovered = Some(target);
    }
    let (down, origin, pos, pressed_now) = ui.input(|i| {
        (
            i.pointer.primary_down(),
            i.pointer.press_origin(),
            i.pointer.latest_pos(),
            i.pointer.primary_pressed(),
        )
    });
    let inside = |p: Option<Pos2>| p.is_some_and(|p| rect.contains(p));
    if down && inside(origin) && inside(pos) {
        out.held_on = Some(target);
    }
    if !down && pressed_now && resp.clicked() {
        out.tapped = Some(target);
    }
}

/// The pointer's state on a pad: on the button it was pressed on, aside, or up.
fn pointer_press<T>(ctx: &egui::Context, held_on: Option<T>) -> Press<T> {
    match (ctx.input(|i| i.pointer.primary_down()), held_on) {
        (false, _) => Press::Up,
        (true, Some(target)) => Press::On(target),
        (true, None) => Press::Aside,
    }
}

/// The pointer's jog input this frame, on the arm's pad and the same pointer on the RMC
/// axis buttons (one hold machine each, one STOP): a tap first, then where it is.
pub fn pointer_intents(
    ctx: &egui::Context,
    pad: &PadOutput,
    axes: &AxesPadOutput,
    intents: &mut Vec<Intent>,
) {
    if let Some(target) = pad.tapped {
        intents.push(Intent::Jog(JogInput::Pointer, Press::On(target)));
    }
    intents.push(Intent::Jog(
        JogInput::Pointer,
        pointer_press(ctx, pad.held_on),
    ));
    if let Some(target) = axes.tapped {
        let tap = AxisIntent::Jog(JogInput::Pointer, Press::On(target));
        intents.push(Intent::Axes(tap));
    }
    let press = pointer_press(ctx, axes.held_on);
    intents.push(Intent::Axes(AxisIntent::Jog(JogInput::Pointer, press)));
}
