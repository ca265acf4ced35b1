//! The window's Simulator panel: an operator rehearses an E-stop on the built-in
//! simulator, and the window shows it and disables motion. Waits have deadlines.

use std::time::Instant;

use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use xsel_pendant::pendant::NotReady;
use xsel_pendant::ui::{PendantApp, StartOptions};

use crate::kittest_common::{alarm_code, click, show_tab, step_until};

#[test]
fn pressing_e_stop_in_the_simulator_panel_shows_e_stop_and_disables_motion() {
    let mut h = Harness::builder()
        .with_size([1280.0, 900.0])
        .build_eframe(|cc| PendantApp::new(cc, StartOptions::fresh_simulator()));
    step_until(&mut h, "the controller to accept commands", |a| {
        a.pendant().controller_ready(Instant::now()).is_ok()
    });
    assert!(h.query_by_label("E-stop off").is_some());
    show_tab(&mut h, "Simulator");
    click(&mut h, "Press E-stop");
    step_until(&mut h, "the pendant to see the E-stop", |a| {
        a.pendant().controller_ready(Instant::now()) == Err(NotReady::EmergencyStop)
    });
    assert!(
        h.state()
            .sim()
            .is_some_and(|s| s.with(|c| c.snapshot().emergency_stop)),
        "the simulator's E-stop is pressed"
    );
    assert!(
        h.query_by_label("E-STOP ACTIVE").is_some(),
        "top bar shows it"
    );
    assert_eq!(
        h.state().pendant().motion_ready(Instant::now()),
        Err(NotReady::EmergencyStop),
        "motion is disabled for the E-stop"
    );
    // The servo button refuses, and nothing reaches the line.
    let servo_before = h.state().sim().map(|s| s.counters().servo_commands);
    click(&mut h, "Servo ON");
    assert_eq!(
        h.state().sim().map(|s| s.counters().servo_commands),
        servo_before
    );
    // Released: the window sees it gone.
    click(&mut h, "Release E-stop");
    step_until(&mut h, "the E-stop to clear", |a| {
        a.pendant().controller_ready(Instant::now()).is_ok()
    });
    assert!(h.query_by_label("E-stop off").is_some());
}

#[test]
fn an_alarm_raised_in_the_simulator_panel_reaches_the_top_bar() {
    let mut h = Harness::builder()
        .with_size([1280.0, 900.0])
        .build_eframe(|cc| PendantApp::new(cc, StartOptions::fresh_simulator()));
    step_until(&mut h, "the controller to accept commands", |a| {
        a.pendant().controller_ready(Instant::now()).is_ok()
    });
    show_tab(&mut h, "Simulator");
    // The field holds a real code from the start: Raise alarm works without typing.
    assert_eq!(h.get_by_label("Code").value().as_deref(), Some("C74"));
    click(&mut h, "Raise alarm");
    step_until(&mut h, "the pendant to see the alarm", |a| {
        alarm_code(a) == Some(0xC74)
    });
    // The top bar (from the polled 215H) and the panel both show it.
    assert_eq!(h.query_all_by_label_contains("Alarm C74").count(), 2);
    assert_eq!(
        h.state().pendant().motion_ready(Instant::now()),
        Err(NotReady::Alarm)
    );
    click(&mut h, "Clear alarm");
    step_until(&mut h, "the alarm to clear", |a| alarm_code(a) == Some(0));
    h.step();
    // A cleared alarm is no longer shown as one; 215H's latest error stays as history.
    assert_eq!(h.query_all_by_label_contains("Alarm C74").count(), 0);
    assert!(h.query_by_label_contains("last error C74").is_some());
    assert!(h.state().pendant().controller_ready(Instant::now()).is_ok());
}
