//! Connections open and close off the UI thread: the window keeps drawing while an old
//! line closes, and the new one opens once it has.

use std::time::Instant;

use egui_kittest::Harness;
use xsel_pendant::pendant::LineState;
use xsel_pendant::ui::{PendantApp, StartOptions};

use xsel_pendant::pendant::Intent;

use crate::kittest_common::step_until;

fn app<'a>() -> Harness<'a, PendantApp> {
    Harness::builder()
        .with_size([1280.0, 800.0])
        .build_eframe(|cc| PendantApp::new(cc, StartOptions::fresh_simulator()))
}

/// What the connection panel's Reconnect and Disconnect buttons push, applied as the
/// window applies them (the panel sits below the fold of a 1280x800 window's column).
fn connect(h: &mut Harness<'_, PendantApp>, intent: Intent) {
    h.state_mut().pendant_mut().apply(intent, Instant::now());
    h.step();
}

fn up_and_polled(a: &PendantApp) -> bool {
    a.pendant().line.is_up()
        && a.sim().is_some()
        && a.pendant().controller_ready(Instant::now()).is_ok()
}

#[test]
fn reconnect_twice_in_a_row_then_disconnect_leaves_one_line_then_none() {
    let mut h = app();
    step_until(&mut h, "the line up", up_and_polled);
    // Reconnect (the connection panel's button), and again in the same frame, while the
    // old line is still closing: it opens once, after it has closed. (A second press a
    // frame later may find the new line already open, and rightly reconnects it.)
    let now = Instant::now();
    let pendant = h.state_mut().pendant_mut();
    pendant.apply(Intent::Connect, now);
    pendant.apply(Intent::Connect, now);
    h.step();
    step_until(&mut h, "the line up again, every old line closed", |a| {
        up_and_polled(a) && a.lines_closing() == 0
    });
    let opened = |a: &PendantApp| {
        a.pendant()
            .messages
            .iter()
            .filter(|m| m.text.starts_with("connected: built-in"))
            .count()
    };
    assert_eq!(opened(h.state()), 2, "the first line, then one more");
    connect(&mut h, Intent::Disconnect);
    step_until(&mut h, "no line, none closing", |a| {
        a.pendant().line == LineState::Closed && a.sim().is_none() && a.lines_closing() == 0
    });
    assert!(
        !h.state()
            .pendant()
            .messages
            .iter()
            .any(|m| m.text.contains("closed:")),
        "the closes were clean: {:?}",
        h.state().pendant().messages
    );
}
