//! The jog panel says what the line carries and nothing in it moves: the speed a jog
//! sends as its lines show it, the cap raised and reset with the pad in place, the raise
//! dialog clear of STOP and the band, jog keys with a modifier, the latch and stale lamps.

use std::time::{Duration, Instant};

use egui_kittest::Harness;
use egui_kittest::kittest::{NodeT, Queryable};
use xsel_pendant::pendant::script::ready_controller;
use xsel_pendant::pendant::{Interpolation, JogMode};
use xsel_pendant::robot::Joints;
use xsel_pendant::ui::{PendantApp, StartOptions};

use crate::kittest_common::{click, step_until};
use crate::main_window::{
    PAD, app, button_rect, count_in, pad_rects, ready, sim_busy, sim_in_frames,
};

/// A window with no line, fed a ready controller's events read at `read_at` (now, or
/// long ago for a stale status), the line up.
fn scripted<'a>(read_at: impl Fn() -> Instant) -> Harness<'a, PendantApp> {
    let mut h = Harness::builder()
        .with_size([1280.0, 800.0])
        .build_eframe(|cc| PendantApp::new(cc, StartOptions::fresh_offline()));
    feed(&mut h, &read_at);
    h
}

/// The scripted controller's events once more, read at `read_at`, and two frames.
fn feed(h: &mut Harness<'_, PendantApp>, read_at: &dyn Fn() -> Instant) {
    for _ in 0..2 {
        let app = h.state_mut();
        let kin = *app.pendant().kinematics();
        let pendant = app.pendant_mut();
        for event in ready_controller(&kin, Joints::new(30.0, 60.0, 50.0, 0.0)) {
            pendant.handle_event(read_at(), event);
        }
        pendant.take_requests();
        h.step();
    }
}

/// The number after "send" in the panel's line that starts with `what`.
fn shown_speed(h: &Harness<'_, PendantApp>, what: &str) -> u16 {
    let node = h.get_by_label_contains(what);
    // A label's text is its value in AccessKit.
    let text = node
        .accesskit_node()
        .value()
        .or_else(|| node.accesskit_node().label())
        .unwrap_or_default();
    let (_, after) = text
        .split_once(" send ")
        .unwrap_or_else(|| panic!("no 'send' in {text:?}"));
    after
        .split_whitespace()
        .next()
        .and_then(|w| w.parse().ok())
        .unwrap_or_else(|| panic!("no number in {text:?}"))
}

/// The speed field (columns 17-20) of the last frame of message `id` the simulator got.
fn wire_speed(app: &PendantApp, id: &str) -> u16 {
    let frames = sim_in_frames(app, id);
    let last = frames.last().unwrap_or_else(|| panic!("no {id}H sent"));
    u16::from_str_radix(&last[16..20], 16).expect("a hex speed field")
}

#[test]
fn a_continuous_jog_in_ptp_carries_the_speed_its_line_shows() {
    let mut h = app();
    ready(&mut h);
    // The case: Motion PTP at 20 %, the mm/s field at 400 (above the cap).
    {
        let jog = &mut h.state_mut().pendant_mut().settings.jog;
        jog.interpolation = Interpolation::Ptp;
        jog.ptp_speed_pct = 20;
        jog.cp_speed_mm_s = 400;
    }
    click(&mut h, "Continuous");
    assert_eq!(h.state().pendant().settings.jog.mode, JogMode::Continuous);
    let shown = shown_speed(&h, "X Y Z R jogs (236H) send");
    h.key_down(egui::Key::ArrowRight);
    step_until(&mut h, "the jog to run", sim_busy);
    h.key_up(egui::Key::ArrowRight);
    step_until(&mut h, "the jog to stop", |a| !sim_busy(a));
    assert_eq!(wire_speed(h.state(), "236"), shown, "X+ in mm/s");
    assert_eq!(shown, 250, "400 mm/s capped at the reduced speed");
    // A joint jog from the pad: the % line.
    let shown = shown_speed(&h, "Joint jogs (236H) send");
    let at = button_rect(&h, "J1+").center();
    h.hover_at(at);
    h.drag_at(at);
    step_until(&mut h, "the joint jog to run", sim_busy);
    h.drop_at(at);
    step_until(&mut h, "the joint jog to stop", |a| !sim_busy(a));
    assert_eq!(count_in(h.state(), "236"), 2);
    assert_eq!(wire_speed(h.state(), "236"), shown, "J1+ in %");
}

#[test]
fn raising_and_resetting_the_cap_moves_no_pad_button() {
    let mut h = scripted(Instant::now);
    let base = pad_rects(&h);
    let same = |h: &mut Harness<'_, PendantApp>, after: &str| {
        h.run_steps(3);
        assert_eq!(pad_rects(h), base, "the pad moved after {after}");
    };
    click(&mut h, "Raise...");
    same(&mut h, "opening the raise dialog");
    click(&mut h, "Raise the cap");
    assert!(
        h.state().pendant().speed_cap() > 400.0,
        "the cap was raised"
    );
    same(&mut h, "raising the cap");
    // The fastest speeds the fields take, in every mode, under the raised cap.
    {
        let jog = &mut h.state_mut().pendant_mut().settings.jog;
        jog.cp_speed_mm_s = 2000;
        jog.ptp_speed_pct = 100;
        jog.interpolation = Interpolation::Cp;
    }
    same(&mut h, "a CP speed of 2000 mm/s");
    for label in ["Continuous", "Step", "PTP"] {
        click(&mut h, label);
        same(&mut h, label);
    }
    click(&mut h, "Back to reduced");
    same(&mut h, "Back to reduced");
    assert_eq!(h.state().pendant().speed_cap(), 250.0);
}

#[test]
fn the_raise_dialog_lies_clear_of_stop_and_the_safety_band() {
    let mut h = scripted(Instant::now);
    // Below the band: at or below the top of the left column's first row.
    let column_top = h.get_by_label("Jog").rect().top();
    let stop = button_rect(&h, "STOP");
    click(&mut h, "Raise...");
    h.run_steps(2);
    let dialog = h
        .get_by_role_and_label(egui::accesskit::Role::Window, "Raise the jog speed cap")
        .rect();
    assert!(!dialog.intersects(stop), "{dialog:?} covers STOP {stop:?}");
    assert!(
        dialog.top() >= column_top,
        "{dialog:?} covers the safety band (the column starts at {column_top})"
    );
    // Nor does it cover the pad.
    for label in PAD {
        let r = button_rect(&h, label);
        assert!(!dialog.intersects(r), "{dialog:?} covers {label} {r:?}");
    }
    click(&mut h, "Cancel");
    assert!(h.query_by_label("Raise the cap").is_none(), "closed");
}

#[test]
fn a_jog_key_with_shift_ctrl_or_alt_sends_nothing() {
    let mut h = app();
    ready(&mut h);
    click(&mut h, "10");
    let moves = |a: &PendantApp| count_in(a, "2D5") + count_in(a, "236");
    for modifiers in [
        egui::Modifiers::SHIFT,
        egui::Modifiers::CTRL,
        egui::Modifiers::ALT,
    ] {
        h.key_press_modifiers(modifiers, egui::Key::PageDown);
        h.run_steps(5);
        assert_eq!(moves(h.state()), 0, "{modifiers:?}+PgDn jogged");
    }
    // Held with Shift in Continuous mode: nothing either.
    click(&mut h, "Continuous");
    h.key_down_modifiers(egui::Modifiers::SHIFT, egui::Key::PageDown);
    h.run_steps(5);
    h.key_up(egui::Key::PageDown);
    h.run_steps(2);
    assert_eq!(moves(h.state()), 0, "a held Shift+PgDn jogged");
    // The same key alone does.
    click(&mut h, "Step");
    h.key_press(egui::Key::PageDown);
    step_until(&mut h, "the plain key's step", |a| moves(a) == 1);
}

#[test]
fn a_latched_pad_says_latched_not_ready_and_its_buttons_say_why() {
    let mut h = scripted(Instant::now);
    assert!(h.query_by_label("Ready to jog").is_some());
    // A key held through a STOP: the latch.
    h.key_down(egui::Key::ArrowRight);
    h.step();
    h.key_press(egui::Key::Escape);
    feed(&mut h, &Instant::now);
    assert!(h.state().pendant().stop_latch().is_some(), "latched");
    assert!(
        h.query_by_label("Ready to jog").is_none(),
        "'Ready to jog' while latched"
    );
    assert!(
        h.query_by_label_contains("Latched: STOP (Esc)").is_some(),
        "the lamp says latched and why"
    );
    // A latched button's tooltip says why: never empty.
    let shown = |h: &Harness<'_, PendantApp>| {
        h.query_all_by_label_contains("release the jog keys")
            .count()
    };
    let before = shown(&h);
    h.hover_at(button_rect(&h, "X+").center());
    let end = Instant::now() + Duration::from_secs(5);
    while shown(&h) == before && Instant::now() < end {
        feed(&mut h, &Instant::now);
    }
    assert!(
        shown(&h) > before,
        "no tooltip with the latch's words over a latched button"
    );
}

#[test]
fn lamps_from_a_stale_status_are_grey_and_say_stale() {
    let h = scripted(Instant::now);
    assert!(h.query_by_label("Controller ready").is_some());
    assert!(h.query_by_label_contains("lamp: stale").is_none());
    assert!(h.query_by_label("status stale").is_none());
    // Polls stop answering: the last status grows old, the line still up.
    let old = Instant::now()
        .checked_sub(Duration::from_secs(5))
        .expect("a clock 5 s old");
    let h = scripted(move || old);
    for lamp in [
        "Controller ready lamp: stale",
        "Mode AUTO lamp: stale",
        "Drive source lamp: stale",
        "In position lamp: stale",
    ] {
        assert!(h.query_by_label(lamp).is_some(), "{lamp} not shown");
    }
    assert!(h.query_by_label("status stale").is_some());
    assert!(h.query_by_label_contains("stale: read").is_some());
    // The window looks again soon, though no event may wake it when the polls answer
    // again as before: the lamps come back once the status is fresh.
    assert!(
        repaint_delay(&h) <= Duration::from_millis(250),
        "a stale window waits {:?} to draw again",
        repaint_delay(&h)
    );
}

/// How long the window asked to wait before its next frame.
fn repaint_delay(h: &Harness<'_, PendantApp>) -> Duration {
    h.output()
        .viewport_output
        .get(&egui::ViewportId::ROOT)
        .map_or(Duration::MAX, |v| v.repaint_delay)
}

#[test]
fn a_fresh_status_adds_no_frames_to_an_idle_window() {
    use xsel_pendant::pendant::controller::STALE_AFTER;
    let mut h = scripted(Instant::now);
    // The status must still be fresh when the last frame is drawn: on a machine so busy
    // that feeding and drawing take longer than a status stays fresh, the lamps are
    // rightly grey (and look again soon), so the status is fed again until one frame
    // comes in time.
    for _ in 0..50 {
        let fed = Instant::now();
        feed(&mut h, &Instant::now);
        if fed.elapsed() < STALE_AFTER / 2 {
            assert!(
                repaint_delay(&h) > Duration::from_secs(1),
                "an idle window with fresh lamps draws again after {:?}",
                repaint_delay(&h)
            );
            return;
        }
    }
    panic!(
        "no frame was drawn within {:?} of its status in 50 tries",
        STALE_AFTER / 2
    );
}
