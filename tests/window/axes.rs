//! The RMC axes pane on the real app with the built-in RMC151: enable, step, STOP, hold.
//! Waits have deadlines; no fixed sleeps before asserting.

use std::time::{Duration, Instant};

use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use xsel_pendant::pendant::axes::{AxisIntent, AxisView, RmcJogSettings};
use xsel_pendant::pendant::{Intent, JogMode};
use xsel_pendant::rmc::{AxisId, AxisStatus, TgPhase};
use xsel_pendant::robot::RelativeTo;
use xsel_pendant::ui::{PendantApp, StartOptions};

use crate::kittest_common::{click, show_tab, step_until, type_into};

fn axis0() -> AxisId {
    AxisId::new(0).unwrap()
}

fn view(a: &PendantApp) -> AxisView {
    a.pendant().axes.axes.first().cloned().unwrap_or_default()
}

/// The built-in RMC's own state of axis 1 (its loop run up to now).
fn truth(a: &PendantApp) -> AxisStatus {
    let server = a
        .rmc()
        .and_then(|r| r.sim.as_ref())
        .expect("the built-in RMC");
    let controller = server.controller();
    let mut c = controller.lock().unwrap();
    c.advance(Instant::now());
    c.status(axis0()).unwrap()
}

/// The app on the built-in simulators, the RMC axes pane shown, axis 1 enabled, and the
/// jog choices given.
fn enabled(jog: RmcJogSettings) -> Harness<'static, PendantApp> {
    enabled_at(jog, 900.0)
}

/// A window `width` x `height` on the built-in simulators, the RMC axes tab shown and
/// axis 1 enabled.
fn enabled_window(width: f32, height: f32) -> Harness<'static, PendantApp> {
    let mut h = Harness::builder()
        .with_size([width, height])
        .build_eframe(|cc| PendantApp::new(cc, StartOptions::fresh_simulator()));
    step_until(&mut h, "the RMC's first status", |a| {
        view(a).status.is_some()
    });
    show_tab(&mut h, "RMC axes");
    h.get_all_by_label("Enable").next().unwrap().click();
    h.step();
    step_until(&mut h, "axis 1 enabled", |a| view(a).enabled());
    h
}

/// As [`enabled`], in a window `height` tall.
fn enabled_at(jog: RmcJogSettings, height: f32) -> Harness<'static, PendantApp> {
    let mut h = enabled_window(1280.0, height);
    h.state_mut()
        .pendant_mut()
        .apply(Intent::Axes(AxisIntent::Settings(jog)), Instant::now());
    h.step();
    h
}

fn slow_step(step: f32, mode: JogMode) -> RmcJogSettings {
    RmcJogSettings {
        mode,
        step,
        speed: 20.0,
        accel: 100.0,
        decel: 100.0,
        relative_to: RelativeTo::Command,
    }
}

#[test]
fn a_step_of_ten_relative_to_command_lands_and_the_lamps_pass_through_the_phases() {
    // 10 pu/s at 25 pu/s²: 0.4 s accelerating, 0.6 s cruising, 0.4 s decelerating, so a
    // 20 ms poll sees every phase even on a loaded machine.
    let mut h = enabled(RmcJogSettings {
        speed: 10.0,
        accel: 25.0,
        decel: 25.0,
        ..slow_step(10.0, JogMode::Step)
    });
    let start = view(h.state()).status.unwrap().command_position;
    click(&mut h, "Axis 1+");
    step_until(&mut h, "the step to end in position", |a| {
        view(a)
            .status
            .is_some_and(|s| s.command_position == start + 10.0 && s.bits.in_position())
    });
    assert_eq!(
        view(h.state()).phases,
        [
            TgPhase::Accelerating,
            TgPhase::ConstantVelocity,
            TgPhase::Decelerating,
            TgPhase::Complete
        ],
        "the lamps' history of the step"
    );
    assert!(
        h.query_all_by_label(&format!("{:.3}", start + 10.0))
            .count()
            >= 1,
        "the pane shows the Command Position"
    );
    assert_eq!(truth(h.state()).command_position, start + 10.0);
    // Every poll went into the plots' sample store: the Target Position's start and end
    // are there (the Actual follows with a lag and is In Position before it lands).
    let samples = &h.state().pendant().samples;
    let series = samples
        .store
        .series(samples.rmc_series(axis0()).unwrap())
        .unwrap();
    let target: Vec<f64> = (0..series.len())
        .filter_map(|r| series.value(r, 1))
        .collect();
    let near = |want: f32| target.iter().any(|v| (v - f64::from(want)).abs() < 0.001);
    assert!(
        near(start) && near(start + 10.0),
        "start and end in the samples"
    );
}

#[test]
fn stop_mid_move_stops_the_axis_short() {
    let mut h = enabled(slow_step(100.0, JogMode::Step));
    click(&mut h, "Axis 1+");
    step_until(&mut h, "the axis to move", |a| {
        truth(a).target_velocity > 5.0
    });
    click(&mut h, "STOP");
    step_until(&mut h, "the axis to stop", |a| {
        truth(a).target_velocity == 0.0
    });
    let s = truth(h.state());
    assert!(
        s.target_position < 90.0,
        "stopped short: {}",
        s.target_position
    );
    assert!(
        !s.bits.in_position(),
        "In Position is never set after Stop (6)"
    );
}

#[test]
fn a_held_axis_jog_stops_on_release_and_within_one_chunk_when_the_cable_is_cut() {
    let mut h = enabled(slow_step(10.0, JogMode::Continuous));
    let plus = h.get_by_label("Axis 1+").rect().center();
    h.hover_at(plus);
    h.drag_at(plus);
    step_until(&mut h, "the jog to run", |a| {
        truth(a).target_velocity == 20.0
    });
    let end = Instant::now() + Duration::from_millis(500);
    while Instant::now() < end {
        h.step();
    }
    h.drop_at(plus);
    // The frame that sees the button up sends the release (Stop (6)) at its end; the
    // distance is counted from there, so a slow frame on a loaded machine costs nothing.
    h.step();
    let released = truth(h.state()).target_position;
    step_until(&mut h, "the axis to stop", |a| {
        truth(a).target_velocity == 0.0
    });
    // 20 pu/s at STOP's 1000 pu/s² stops within 0.2 pu; allow the poll's delay.
    let ran = truth(h.state()).target_position - released;
    assert!(ran < 2.0, "ran {ran} after release");

    // Held again, then the cable is cut: nothing more reaches the RMC, which runs out its
    // last move of the chain only (speed × lease plus the stopping distance).
    h.step();
    h.hover_at(plus);
    h.drag_at(plus);
    step_until(&mut h, "the jog to run again", |a| {
        truth(a).target_velocity == 20.0
    });
    h.state()
        .rmc()
        .and_then(|r| r.sim.as_ref())
        .unwrap()
        .unplug(true);
    let cut = truth(h.state()).target_position;
    let stopped = |a: &PendantApp| truth(a).target_velocity == 0.0;
    step_until(&mut h, "the axis to stop by itself", stopped);
    let ran = truth(h.state()).target_position - cut;
    let chunk = 20.0 * 0.25 + 20.0 * 20.0 / (2.0 * 100.0);
    assert!(
        ran <= chunk,
        "ran {ran} after the cut; one chunk is {chunk}"
    );
    h.drop_at(plus);
    h.step();
}

/// The first row of the live log whose name starts with `name`.
fn row_named(a: &PendantApp, name: &str) -> Option<u64> {
    let log = &a.pendant().frame_log;
    (0..log.len())
        .filter_map(|i| log.nth(i))
        .find(|r| r.name().starts_with(name))
        .map(|r| r.seq())
}

#[test]
fn a_step_shows_in_the_frame_log_as_modbus_rows_decoded_field_by_field() {
    const WRITE: &str = "FC16 write Command Area, Axis 1: Move Relative (21)";
    // Tall enough for the frame log's tools and rows under the arm view.
    let mut h = enabled_at(slow_step(2.0, JogMode::Step), 1500.0);
    click(&mut h, "Axis 1+");
    step_until(
        &mut h,
        "the Move Relative write and its reply in the log",
        |a| row_named(a, WRITE).is_some_and(|s| a.pendant().frame_log.reply_of(s).is_some()),
    );
    let write = row_named(h.state(), WRITE).unwrap();
    show_tab(&mut h, "Frame log");
    type_into(&mut h, "Filter text", "Move Relative");
    step_until(&mut h, "the filter to finish", |a| {
        let p = a.frame_log_panel();
        !p.filtering() && p.shown(a.pendant()) >= 1
    });
    let ascii = h.state().pendant().frame_log.row(write).unwrap().ascii();
    h.get_by_label_contains(&ascii).click_accesskit();
    h.step();
    h.step();
    assert_eq!(h.state().frame_log_panel().selected(), Some(write));
    // The decode names the Command Area's registers and reads the REALs.
    assert!(
        h.query_all_by_label_contains("Command Area: command, Axis 1")
            .next()
            .is_some()
    );
    assert!(
        h.query_all_by_label_contains("Move Relative (21), REQ")
            .next()
            .is_some()
    );
    click(&mut h, "Go to reply");
    let reply = h.state().frame_log_panel().selected().unwrap();
    let row = h.state().pendant().frame_log.row(reply).unwrap();
    assert!(
        row.name()
            .starts_with("FC16 reply: wrote Command Area, Axis 1"),
        "{}",
        row.name()
    );
    assert!(row.latency_us().is_some());
    assert!(
        h.query_all_by_label_contains("registers written")
            .next()
            .is_some()
    );
}

#[test]
fn no_rmc_on_the_command_line_leaves_it_off_this_run_and_the_saved_choice_as_it_was() {
    let mut h = Harness::builder()
        .with_size([1280.0, 800.0])
        .build_eframe(|cc| {
            PendantApp::new(
                cc,
                StartOptions {
                    rmc: Some(None),
                    ..StartOptions::fresh_simulator()
                },
            )
        });
    step_until(&mut h, "the X-SEL's first status", |a| {
        a.pendant().controller_ready(Instant::now()).is_ok()
    });
    assert!(h.state().rmc().is_none(), "no RMC link this run");
    assert!(
        h.state().pendant().settings.rmc.enabled,
        "the saved choice (on) is kept for the next run"
    );
}

/// Where the axes' − / + buttons are now.
fn jog_button_rects(h: &Harness<'_, PendantApp>) -> Vec<egui::Rect> {
    ["Axis 1-", "Axis 1+", "Axis 2-", "Axis 2+"]
        .iter()
        .map(|l| h.get_by_label(l).rect())
        .collect()
}

#[test]
fn the_axis_buttons_stay_put_whatever_the_jog_choices_and_the_words_say() {
    for (width, height) in [(1280.0, 800.0), (1024.0, 700.0)] {
        let mut h = enabled_window(width, height);
        let set = |h: &mut Harness<'_, PendantApp>, jog: RmcJogSettings| {
            h.state_mut()
                .pendant_mut()
                .apply(Intent::Axes(AxisIntent::Settings(jog)), Instant::now());
            h.step();
            h.step();
        };
        set(&mut h, slow_step(1.0, JogMode::Step));
        let at = jog_button_rects(&h);
        let mut choices = Vec::new();
        for relative_to in [RelativeTo::Actual, RelativeTo::Target, RelativeTo::Command] {
            for mode in [JogMode::Continuous, JogMode::Step] {
                for step in [0.1, 1234.567] {
                    choices.push(RmcJogSettings {
                        relative_to,
                        ..slow_step(step, mode)
                    });
                }
            }
        }
        for jog in choices {
            set(&mut h, jog);
            assert_eq!(
                jog_button_rects(&h),
                at,
                "{width}x{height}: the buttons moved with {jog:?}"
            );
        }
        // Words beside the buttons (a refusal) and the lamps of a line that went down.
        set(&mut h, slow_step(1.0, JogMode::Step));
        click(&mut h, "Axis 1+");
        assert!(h.state().pendant().axes.feedback.is_some());
        assert_eq!(jog_button_rects(&h), at, "{width}x{height}: after a word");
        h.state()
            .rmc()
            .and_then(|r| r.sim.as_ref())
            .unwrap()
            .unplug(true);
        step_until(&mut h, "the line down", |a| {
            a.pendant().axes.stale_text().is_some()
        });
        assert_eq!(jog_button_rects(&h), at, "{width}x{height}: line down");
    }
}
