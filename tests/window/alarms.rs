//! The Alarms view in the real window on the embedded simulator, driven headlessly with
//! egui_kittest: two alarms provoked on the simulator seen arriving and in the history,
//! one opened to show its frames; a snapshot taken, a position and a variable changed on
//! the controller, a second snapshot, and the compare showing exactly those two
//! differences. Waits are bounded by a deadline; nothing sleeps.

use egui::accesskit::Role;
use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use xsel_pendant::protocol::{Axis, Milli};
use xsel_pendant::ui::PendantApp;

use crate::kittest_common::{click_button, show_tab, step_until, step_until_shown};
use crate::main_window::app;

fn sim<R>(a: &PendantApp, f: impl FnOnce(&mut xsel_pendant::sim::Controller) -> R) -> R {
    a.sim().expect("the built-in simulator").with(f)
}

/// Clicks through the accessible action (the section may be scrolled out of sight).
fn press(h: &mut Harness<'_, PendantApp>, label: &str) {
    h.get_by_role_and_label(Role::Button, label)
        .click_accesskit();
    h.step();
    h.step();
}

#[test]
fn alarms_arrive_with_their_frames_and_two_snapshots_show_exactly_what_changed() {
    let mut h = app();
    step_until(&mut h, "the history read on connect", |a| {
        a.pendant().alarms.reading().is_none() && a.pendant().controller.system.is_some()
    });
    show_tab(&mut h, "Alarms");
    // Two alarms raised on the simulator (as its front panel does), each cleared.
    for (code, axis) in [(0xC74, Some(2)), (0xB07, None)] {
        sim(h.state(), |c| {
            c.raise_alarm(code, axis, "provoked by the test")
        });
        step_until(&mut h, "the alarm seen arriving", |a| {
            a.pendant().alarms.live().iter().any(|l| l.code.0 == code)
        });
        sim(h.state(), |c| c.reset_alarm());
        step_until(&mut h, "the alarm cleared", |a| {
            a.pendant()
                .controller
                .system
                .as_ref()
                .is_some_and(|s| s.value.critical_error.0 == 0)
        });
    }
    step_until(&mut h, "both in the history", |a| {
        a.pendant().alarms.records().len() >= 2 && a.pendant().alarms.reading().is_none()
    });
    step_until_shown(&mut h, "Seen arriving (2)");
    // The newest live alarm opened: the frames around it.
    h.query_all_by_label_contains("B07")
        .next()
        .expect("the live alarm listed")
        .click_accesskit();
    h.step();
    h.step();
    step_until_shown(&mut h, "215H");

    // A snapshot, a change on the controller, another snapshot, the compare.
    press(&mut h, "Take snapshot");
    step_until(&mut h, "the first snapshot", |a| {
        a.pendant().snapshots.latest.is_some() && a.pendant().snapshots.part().is_none()
    });
    let first = h.state().pendant().snapshots.latest.clone().unwrap();
    assert!(first.missing.is_empty(), "{:?}", first.missing);
    assert_eq!(first.alarms.len(), 2);
    sim(h.state(), |c| {
        let mut p = c.positions()[&1];
        p.coords.set(Axis::new(2).unwrap(), Milli(-12_500));
        c.positions_mut().insert(1, p);
        c.signals_mut().set_int(210, 0, 42).unwrap();
    });
    press(&mut h, "Take snapshot");
    step_until(&mut h, "the second snapshot", |a| {
        a.pendant().snapshots.previous.is_some() && a.pendant().snapshots.part().is_none()
    });
    click_button(&mut h, "Compare the last two");
    step_until_shown(&mut h, "2 difference(s)");
    let c = h.state().pendant().snapshots.comparison.clone().unwrap();
    let rows: Vec<(&str, &str)> = c
        .differences
        .iter()
        .map(|d| (d.table, d.row.as_str()))
        .collect();
    assert_eq!(
        rows,
        [("positions", "No. 00001"), ("integer variables", "210")]
    );
    step_until_shown(&mut h, "axis 2 -12.500");

    // Restore: the first snapshot's positions into the Positions draft, where only
    // No. 1 differs from the controller; nothing goes out until Write there.
    let before = sim(h.state(), |c| c.positions()[&1]);
    click_button(&mut h, "Restore positions to the draft");
    step_until_shown(&mut h, "put into the Positions draft");
    let changed = h.state().pendant().positions.changed();
    assert_eq!(changed.iter().map(|r| r.number).collect::<Vec<_>>(), [1]);
    assert_ne!(changed[0], before);
    assert_eq!(
        sim(h.state(), |c| c.positions()[&1]),
        before,
        "nothing sent"
    );
}
