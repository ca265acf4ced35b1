//! Helpers shared by the window tests (egui_kittest driving the real app): wait for a
//! condition with a deadline, click a button, type into a field.
#![allow(dead_code)] // each test binary uses its own subset

use std::time::{Duration, Instant};

use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use xsel_pendant::ui::PendantApp;

// The window binary's waits (and the benches', which include this module alone).
#[path = "../wait/mod.rs"]
pub mod wait;
use wait::eventually;

/// How long a wait may take before the test fails (only a failing test waits this long).
pub const DEADLINE: Duration = Duration::from_secs(40);

/// Steps the window until `done` holds, or fails naming `what` and the pendant's last
/// messages after the deadline.
pub fn step_until(h: &mut Harness<'_, PendantApp>, what: &str, done: impl Fn(&PendantApp) -> bool) {
    let held = eventually(DEADLINE, || {
        done(h.state()) || {
            h.step();
            false
        }
    });
    assert!(
        held,
        "timed out waiting for: {what}; last jog message: {:?}; messages: {:?}",
        h.state().pendant().jog.feedback,
        h.state()
            .pendant()
            .messages
            .iter()
            .rev()
            .take(5)
            .collect::<Vec<_>>()
    );
    h.step();
}

/// Steps the window until some widget's label contains `text`, or fails after the
/// deadline.
pub fn step_until_shown(h: &mut Harness<'_, PendantApp>, text: &str) {
    let end = Instant::now() + DEADLINE;
    while h.query_all_by_label_contains(text).next().is_none() {
        assert!(
            Instant::now() < end,
            "timed out waiting for '{text}' in the window"
        );
        h.step();
    }
}

/// Clicks the button with this label (the first, where the window has it twice: Servo
/// ON beside the pad and in the Status tab do the same), then lets the layout settle (two
/// frames).
pub fn click(h: &mut Harness<'_, PendantApp>, label: &str) {
    h.get_all_by_role_and_label(egui::accesskit::Role::Button, label)
        .next()
        .unwrap_or_else(|| panic!("no button labelled {label:?}"))
        .click();
    h.step();
    h.step();
}

/// Clicks the first button with this label through its accessible action, wherever the
/// layout has put it this frame (a pane whose content moves as data arrives cannot shift
/// it from under the pointer), then lets the layout settle (two frames).
pub fn click_button(h: &mut Harness<'_, PendantApp>, label: &str) {
    h.get_all_by_role_and_label(egui::accesskit::Role::Button, label)
        .next()
        .unwrap_or_else(|| panic!("no button labelled {label:?}"))
        .click_accesskit();
    h.step();
    h.step();
}

/// Brings the centre tab with this title to the front (as assistive technology does: in
/// a narrow tab bar the title may be partly scrolled out of sight).
pub fn show_tab(h: &mut Harness<'_, PendantApp>, title: &str) {
    h.get_by_label(title).click_accesskit();
    h.step();
    h.step();
}

/// The text field with this label (a column header may have the same words).
fn field<'h>(h: &'h Harness<'_, PendantApp>, label: &'h str) -> egui_kittest::Node<'h> {
    h.get_by_role_and_label(egui::accesskit::Role::TextInput, label)
}

/// Focuses the field with this label and types `text` after what it holds.
pub fn type_into(h: &mut Harness<'_, PendantApp>, label: &str, text: &str) {
    field(h, label).focus();
    h.step();
    field(h, label).type_text(text);
    h.step();
    h.step();
}

/// Selects all of a field's text and types `text` over it.
pub fn replace_text(h: &mut Harness<'_, PendantApp>, label: &str, text: &str) {
    field(h, label).focus();
    h.step();
    h.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::A);
    h.step();
    field(h, label).type_text(text);
    h.step();
    h.step();
}

/// The critical-level error the pendant last read with 215H (0: none).
pub fn alarm_code(app: &PendantApp) -> Option<u16> {
    app.pendant()
        .controller
        .system
        .map(|s| s.value.critical_error.0)
}

/// A pointer press and release at `pos`, as a mouse gives them.
pub fn press(h: &mut Harness<'_, PendantApp>, pos: egui::Pos2) {
    h.event(egui::Event::PointerMoved(pos));
    h.step();
    for pressed in [true, false] {
        h.event(egui::Event::PointerButton {
            pos,
            button: egui::PointerButton::Primary,
            pressed,
            modifiers: egui::Modifiers::NONE,
        });
    }
    h.step();
    h.step();
}

/// The mouse wheel over `at`, moving the content by `delta` points, then the frames its
/// eased scrolling takes.
pub fn wheel(h: &mut Harness<'_, PendantApp>, at: egui::Pos2, delta: egui::Vec2) {
    h.event(egui::Event::PointerMoved(at));
    h.event(egui::Event::MouseWheel {
        unit: egui::MouseWheelUnit::Point,
        delta,
        phase: egui::TouchPhase::Move,
        source: egui::MouseWheelSource::Wheel,
        modifiers: egui::Modifiers::NONE,
    });
    h.run_steps(20);
}
