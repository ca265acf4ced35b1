//! The real window on the embedded simulator, driven headlessly with egui_kittest: an
//! operator's clicks, and what reached the simulator's line. Waits are bounded by a
//! deadline; nothing sleeps a fixed time before asserting.

use std::time::{Duration, Instant};

use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use xsel_pendant::pendant::{MotionPhase, NotReady};
use xsel_pendant::protocol::HomeState;
use xsel_pendant::sim::runner::Dir;
use xsel_pendant::ui::{PendantApp, StartOptions};

use crate::kittest_common::wait::{eventually, until};
use crate::kittest_common::{DEADLINE, alarm_code, click, replace_text, show_tab, step_until};

pub(crate) fn app<'a>() -> Harness<'a, PendantApp> {
    Harness::builder()
        .with_size([1280.0, 800.0])
        .build_eframe(|cc| PendantApp::new(cc, StartOptions::fresh_simulator()))
}

pub(crate) fn sim_in_frames(app: &PendantApp, id: &str) -> Vec<String> {
    app.sim()
        .map(|s| s.traffic())
        .unwrap_or_default()
        .into_iter()
        .filter(|t| t.dir == Dir::In)
        .map(|t| String::from_utf8_lossy(&t.bytes).into_owned())
        .filter(|f| f.get(3..6) == Some(id))
        .collect()
}

/// The simulator's tool tip X in its selected work frame, mm.
fn sim_x(app: &PendantApp) -> f64 {
    app.sim().map_or(f64::NAN, |s| {
        s.with(|c| {
            let snap = c.snapshot();
            let work = c.coords().work.get(snap.work).copied().unwrap_or_default();
            work.base_to_work(&snap.tip_base).x
        })
    })
}

fn all_axes(app: &PendantApp, f: impl Fn(&xsel_pendant::protocol::AxisState) -> bool) -> bool {
    app.pendant()
        .controller
        .axes()
        .is_some_and(|axes| axes.iter().all(|(_, a)| f(&a)))
}

/// Connects, switches the servo on and homes, as an operator would.
pub(crate) fn ready(h: &mut Harness<'_, PendantApp>) {
    step_until(h, "the controller to accept commands", |a| {
        a.pendant().controller_ready(Instant::now()).is_ok()
    });
    click(h, "Servo ON");
    step_until(h, "servo on", |a| all_axes(a, |s| s.status.servo_on()));
    step_until(h, "the servo switch to end", |a| {
        all_axes(a, |s| !s.status.in_use())
    });
    click(h, "Home");
    step_until(h, "homed", |a| {
        all_axes(a, |s| {
            s.status.home_state() == HomeState::Done && !s.status.in_use()
        })
    });
    step_until(h, "motion allowed and tables read", |a| {
        a.pendant().motion_ready(Instant::now()).is_ok()
            && a.pendant().controller.tool_table.is_some()
    });
}

/// The `n`-th 2D5H has reached the simulator, its move has run to its end there, and the
/// pendant has seen it end (the polled status alone may predate the move).
fn step_ended(n: usize) -> impl Fn(&PendantApp) -> bool {
    move |a| {
        sim_in_frames(a, "2D5").len() == n
            && !sim_busy(a)
            && a.pendant().motion_phase(Instant::now()) == MotionPhase::Done
            && a.pendant().motion_ready(Instant::now()).is_ok()
    }
}

fn refused(a: &PendantApp) -> bool {
    a.pendant()
        .jog
        .feedback
        .as_ref()
        .is_some_and(|m| m.text.starts_with("refused"))
}

fn checksum_frame(body: &str) -> String {
    let sc = body.bytes().fold(0u8, |s, b| s.wrapping_add(b));
    format!("{body}{sc:02X}\r\n")
}

#[test]
fn servo_home_and_a_10_mm_step_move_the_simulated_arm() {
    let mut h = app();
    ready(&mut h);
    let x0 = sim_x(h.state());
    click(&mut h, "10");
    click(&mut h, "X+");
    step_until(&mut h, "the arm to move 10 mm in X", |a| {
        (sim_x(a) - x0 - 10.0).abs() < 0.0015
    });
    let sent = sim_in_frames(h.state(), "2D5");
    // PROTOCOL.md 3.20: pattern 01, acc 30 %, dec 30 %, speed 3 % (the 20 % asked for,
    // capped at the reduced jog speed of 250 mm/s), type 02 (PTP, work frame, current
    // arm), distance +10.000 mm.
    let expected = checksum_frame("!992D501001E001E00030200002710");
    assert_eq!(sent, vec![expected], "exactly one 2D5H, with these bytes");
}

#[test]
fn cp_and_arm_policies_change_the_operation_type_on_the_line() {
    let mut h = app();
    ready(&mut h);
    click(&mut h, "CP");
    click(&mut h, "Y-");
    step_until(&mut h, "a CP 2D5H", |a| sim_in_frames(a, "2D5").len() == 1);
    let cp = sim_in_frames(h.state(), "2D5").remove(0);
    assert_eq!(&cp[20..22], "03", "CP, work frame: {cp}");
    click(&mut h, "PTP");
    step_until(&mut h, "the CP step to end", step_ended(1));
    click(&mut h, "X-");
    step_until(&mut h, "a PTP 2D5H", |a| sim_in_frames(a, "2D5").len() == 2);
    let ptp = sim_in_frames(h.state(), "2D5").remove(1);
    assert_eq!(&ptp[20..22], "02", "PTP, current arm, no switching: {ptp}");
}

#[test]
fn a_step_beyond_reach_is_refused_beside_the_button_and_nothing_is_sent() {
    let mut h = app();
    ready(&mut h);
    click(&mut h, "50");
    // Step X+ until the arm's reach refuses the next step.
    for n in 1..=20 {
        click(&mut h, "X+");
        step_until(&mut h, "the step to end or be refused", |a| {
            refused(a) || step_ended(n)(a)
        });
        if refused(h.state()) {
            break;
        }
    }
    let before = sim_in_frames(h.state(), "2D5").len();
    let text = h.state().pendant().jog.feedback.clone().unwrap().text;
    assert!(text.starts_with("refused"), "{text}");
    assert!(
        h.query_all_by_label_contains("refused").count() >= 1,
        "the refusal is shown"
    );
    h.run_steps(5);
    assert_eq!(sim_in_frames(h.state(), "2D5").len(), before);
}

#[test]
fn stop_during_a_long_move_ends_it_short() {
    let mut h = app();
    ready(&mut h);
    let x0 = sim_x(h.state());
    click(&mut h, "1");
    click(&mut h, "Y-");
    step_until(&mut h, "a small step to end", step_ended(1));
    click(&mut h, "50");
    click(&mut h, "X-");
    step_until(&mut h, "the move to start", |a| {
        a.sim()
            .is_some_and(|s| s.with(|c| c.snapshot().in_use) != 0)
    });
    click(&mut h, "STOP");
    step_until(&mut h, "the arm to stop", |a| {
        a.sim()
            .is_some_and(|s| s.with(|c| c.snapshot().in_use) == 0)
    });
    let moved = (sim_x(h.state()) - x0).abs();
    assert!(moved < 49.9, "the move ran to its end: {moved} mm");
    assert_eq!(sim_in_frames(h.state(), "238").len(), 1);
}

/// Message IDs of the frames the simulator received, in order.
fn ids_in(traffic: &[xsel_pendant::sim::runner::TrafficEntry]) -> Vec<String> {
    traffic
        .iter()
        .filter(|t| t.dir == Dir::In)
        .filter_map(|t| {
            String::from_utf8_lossy(&t.bytes)
                .get(3..6)
                .map(str::to_owned)
        })
        .filter(|id| id != "2A1" && id != "215")
        .collect()
}

pub(crate) fn sim_busy(app: &PendantApp) -> bool {
    app.sim()
        .is_some_and(|s| s.with(|c| c.snapshot().in_use) != 0)
}

#[test]
fn a_held_continuous_jog_runs_until_the_key_is_released() {
    let mut h = app();
    ready(&mut h);
    click(&mut h, "Continuous");
    h.key_down(egui::Key::ArrowRight);
    step_until(&mut h, "the jog to run", sim_busy);
    // Held for 600 ms, more than two jog leases: the lease is renewed every frame, and
    // the jog runs at every frame (the watch fails the moment it does not).
    let stopped = eventually(Duration::from_millis(600), || {
        h.key_down(egui::Key::ArrowRight);
        h.step();
        !sim_busy(h.state())
    });
    assert!(!stopped, "the jog stopped while the key was held");
    h.key_up(egui::Key::ArrowRight);
    step_until(&mut h, "the jog to stop on release", |a| !sim_busy(a));
    let ids = ids_in(&h.state().sim().map(|s| s.traffic()).unwrap_or_default());
    let jog = ids
        .iter()
        .rposition(|id| id == "236")
        .expect("a 236H went out");
    assert_eq!(
        ids[jog + 1..].first().map(String::as_str),
        Some("238"),
        "{ids:?}"
    );
}

#[test]
fn closing_the_window_mid_jog_stops_the_arm() {
    let mut h = app();
    ready(&mut h);
    click(&mut h, "Continuous");
    h.key_down(egui::Key::ArrowUp);
    step_until(&mut h, "the jog to run", sim_busy);
    let watch = h
        .state()
        .sim()
        .map(|s| s.watch())
        .expect("the built-in simulator");
    // The window closes with the key still held: the app, its link and the simulator go.
    drop(h);
    until("the arm to stop after the window closed", DEADLINE, || {
        watch.with(|c| c.snapshot().in_use) == 0
    });
    let ids = ids_in(&watch.traffic());
    assert_eq!(ids.last().map(String::as_str), Some("238"), "{ids:?}");
}

/// The tool tip the arm view painted last, base frame.
fn view_tip(app: &PendantApp) -> Option<xsel_pendant::render::Mm> {
    use xsel_pendant::render::{Role, Shape};
    app.arm_view()
        .scene()?
        .with_role(Role::Tool)
        .find_map(|s| match s {
            Shape::Circle { centre, .. } => Some(*centre),
            _ => None,
        })
}

#[test]
fn after_a_jog_the_arm_view_shows_the_new_pose() {
    use xsel_pendant::render::{Role, Shape};
    let mut h = app();
    ready(&mut h);
    let Some(before) = view_tip(h.state()) else {
        panic!("the arm view draws the arm once the position is read")
    };
    click(&mut h, "10");
    // The button under the pointer shows its step as a reachable ghost.
    h.get_by_role_and_label(egui::accesskit::Role::Button, "X+")
        .hover();
    h.step();
    h.step();
    let ghost = h.state().arm_view().scene().is_some_and(|s| {
        s.with_role(Role::GhostReachable)
            .any(|g| matches!(g, Shape::Cross { centre, .. } if (centre.distance(before) - 10.0).abs() < 0.01))
    });
    assert!(ghost, "hovering X+ shows the 10 mm step's ghost");
    click(&mut h, "X+");
    step_until(&mut h, "the step to end", step_ended(1));
    // Joints come in 0.001 deg: their forward kinematics is good to about 0.01 mm.
    step_until(&mut h, "the view to show the arm 10 mm on", |a| {
        view_tip(a).is_some_and(|t| (t.distance(before) - 10.0).abs() < 0.02)
    });
    // What the view shows is the forward kinematics of the polled joints.
    let app = h.state();
    let kin = *app.pendant().kinematics();
    let Some(j) = app.pendant().controller.joint_position() else {
        panic!("joints polled")
    };
    let tool = app.pendant().controller.tool_frame().unwrap_or_default();
    let tip = tool.flange_to_tip(&kin.forward(&j));
    let Some(shown) = view_tip(app) else {
        panic!("tip drawn")
    };
    assert!((shown.x - tip.x).abs() < 0.001 && (shown.y - tip.y).abs() < 0.001);
    // The Z bar and R dial say what the Position pane says, from the same sample.
    let Some((_, base)) = app.pendant().controller.sample() else {
        panic!("a position sample")
    };
    let texts: Vec<String> = app
        .arm_view()
        .scene()
        .map(|s| {
            s.items
                .iter()
                .filter_map(|i| match &i.shape {
                    Shape::Text { text, .. } => Some(text.clone()),
                    _ => None,
                })
                .collect()
        })
        .unwrap_or_default();
    for label in [format!("Z {:.3}", base.z), format!("R {:.3}", base.r)] {
        assert!(texts.contains(&label), "{label} not among {texts:?}");
    }
}

/// The frames of message `id` the simulator has received.
pub(crate) fn count_in(app: &PendantApp, id: &str) -> usize {
    sim_in_frames(app, id).len()
}

/// Steps the window for `d` of real time (the simulator runs on the clock), checking
/// `each` after every frame: a hold is a length of time, watched frame by frame.
fn hold_for(h: &mut Harness<'_, PendantApp>, d: Duration, each: impl Fn(&PendantApp)) {
    let _ = eventually(d, || {
        h.step();
        each(h.state());
        false
    });
}

pub(crate) fn button_rect(h: &Harness<'_, PendantApp>, label: &str) -> egui::Rect {
    h.get_by_role_and_label(egui::accesskit::Role::Button, label)
        .rect()
}

#[test]
fn a_mouse_held_continuous_jog_is_one_236h_and_one_238h_on_release() {
    let mut h = app();
    ready(&mut h);
    click(&mut h, "Continuous");
    let (jogs, stops) = (count_in(h.state(), "236"), count_in(h.state(), "238"));
    let at = button_rect(&h, "X+").center();
    h.hover_at(at);
    h.drag_at(at);
    step_until(&mut h, "the jog to run", sim_busy);
    // Held still for 2 s: one 236H, never sent again (no stutter). A STOP while held can
    // only be the link's own, when a frame took longer than the jog lease (a loaded
    // machine); then the pendant says so.
    let lapsed = std::cell::Cell::new(false);
    hold_for(&mut h, Duration::from_secs(2), |a| {
        assert_eq!(count_in(a, "236"), jogs + 1, "a held jog is sent once");
        lapsed.set(lapsed.get() || count_in(a, "238") > stops);
    });
    h.drop_at(at);
    step_until(&mut h, "the jog to stop", |a| !sim_busy(a));
    h.run_steps(3);
    assert_eq!(count_in(h.state(), "236"), jogs + 1);
    if lapsed.get() {
        let said = h
            .state()
            .pendant()
            .messages
            .iter()
            .any(|m| m.text.contains("lease"));
        assert!(said, "a STOP while held that is not the lease's");
    } else {
        assert_eq!(
            count_in(h.state(), "238"),
            stops + 1,
            "one STOP, on release"
        );
    }
}

#[test]
fn esc_with_a_jog_key_held_stops_until_the_key_is_released_and_pressed_again() {
    let mut h = app();
    ready(&mut h);
    click(&mut h, "Continuous");
    h.key_down(egui::Key::ArrowRight);
    step_until(&mut h, "the jog to run", sim_busy);
    let jogs = count_in(h.state(), "236");
    h.key_press(egui::Key::Escape);
    step_until(&mut h, "the arm to stop", |a| !sim_busy(a));
    assert_eq!(
        h.query_all_by_label_contains("release the jog keys")
            .count(),
        3,
        "the jog lamp, the pad and the safety band show the latch"
    );
    assert!(
        h.query_by_label("Ready to jog").is_none(),
        "'Ready to jog' while latched"
    );
    // The key still held: nothing moves again.
    hold_for(&mut h, Duration::from_secs(1), |a| {
        assert!(!sim_busy(a), "the arm moved again with the key still held");
        assert_eq!(count_in(a, "236"), jogs);
    });
    h.key_up(egui::Key::ArrowRight);
    // The release is applied after the frame that sees it is drawn: the next shows it.
    h.run_steps(2);
    assert_eq!(
        h.query_all_by_label_contains("release the jog keys")
            .count(),
        0
    );
    h.key_down(egui::Key::ArrowRight);
    step_until(&mut h, "a new press to jog", sim_busy);
    assert_eq!(count_in(h.state(), "236"), jogs + 1);
    h.key_up(egui::Key::ArrowRight);
    step_until(&mut h, "the jog to stop on release", |a| !sim_busy(a));
}

/// Every pad button's label.
pub(crate) const PAD: [&str; 16] = [
    "X+",
    "X-",
    "Y+",
    "Y-",
    "Z up\nZ-",
    "Z down\nZ+",
    "R ccw\nR+",
    "R cw\nR-",
    "J1-",
    "J1+",
    "J2-",
    "J2+",
    "J3-",
    "J3+",
    "J4-",
    "J4+",
];

pub(crate) fn pad_rects(h: &Harness<'_, PendantApp>) -> Vec<egui::Rect> {
    PAD.iter().map(|l| button_rect(h, l)).collect()
}

#[test]
fn the_pad_keeps_every_rectangle_whatever_the_state() {
    let mut h = app();
    ready(&mut h);
    let base = pad_rects(&h);
    for r in &base {
        assert!(
            r.width() >= 56.0 && r.height() >= 40.0,
            "{r:?} too small to hit"
        );
    }
    let same = |h: &mut Harness<'_, PendantApp>, after: &str| {
        h.run_steps(2);
        assert_eq!(pad_rects(h), base, "the pad moved after {after}");
    };
    for (label, after) in [
        ("Continuous", "Step -> Continuous"),
        ("Step", "Continuous -> Step"),
        ("CP", "PTP -> CP"),
        ("PTP", "CP -> PTP"),
        ("base", "the base frame"),
        ("tool", "the tool frame"),
        ("work", "the work frame"),
    ] {
        click(&mut h, label);
        same(&mut h, after);
    }
    show_tab(&mut h, "Simulator");
    click(&mut h, "Press E-stop");
    step_until(&mut h, "the E-stop to show", |a| {
        a.pendant().controller_ready(Instant::now()) == Err(NotReady::EmergencyStop)
    });
    same(&mut h, "an E-stop");
    click(&mut h, "Release E-stop");
    step_until(&mut h, "the E-stop to clear", |a| {
        a.pendant().controller_ready(Instant::now()).is_ok()
    });
    same(&mut h, "the E-stop's release");
    // An alarm raised and cleared in the simulator (the field starts with C74 in it).
    replace_text(&mut h, "Code", "C74");
    click(&mut h, "Raise alarm");
    step_until(&mut h, "the alarm to show", |a| {
        alarm_code(a) == Some(0xC74)
    });
    same(&mut h, "an alarm");
    click(&mut h, "Clear alarm");
    step_until(&mut h, "the alarm to clear", |a| alarm_code(a) == Some(0));
    same(&mut h, "the alarm's reset");
    // A refusal: J1 steps of 50 deg until the joint limit refuses one.
    click(&mut h, "Servo ON");
    step_until(&mut h, "motion allowed", |a| {
        a.pendant().motion_ready(Instant::now()).is_ok()
    });
    click(&mut h, "50");
    for _ in 0..4 {
        click(&mut h, "J1+");
        step_until(&mut h, "the step to end or be refused", |a| {
            refused(a)
                || (!sim_busy(a) && a.pendant().motion_phase(Instant::now()) == MotionPhase::Done)
        });
        if refused(h.state()) {
            break;
        }
    }
    assert!(refused(h.state()), "a J1 step beyond its limit is refused");
    same(&mut h, "a refusal");
}

#[test]
fn e_stop_shows_the_band_and_every_change_reaches_messages() {
    let mut h = app();
    ready(&mut h);
    show_tab(&mut h, "Simulator");
    click(&mut h, "Press E-stop");
    // Waits for the E-stop itself (a stale status under load also stops motion).
    step_until(&mut h, "the pendant to see the E-stop", |a| {
        a.pendant().controller_ready(Instant::now()) == Err(NotReady::EmergencyStop)
    });
    assert!(h.query_by_label_contains("EMERGENCY STOP").is_some());
    let texts: Vec<String> = h
        .state()
        .pendant()
        .messages
        .iter()
        .map(|m| m.text.clone())
        .collect();
    for said in [
        "servo on",
        "homing started",
        "homing done",
        "E-stop pressed",
    ] {
        assert!(
            texts.iter().any(|t| t.starts_with(said)),
            "{said:?} not in {texts:?}"
        );
    }
}

/// The simulator's Z joint, mm (counting down from the top of the stroke).
fn sim_z(app: &PendantApp) -> f64 {
    app.sim()
        .map_or(f64::NAN, |s| s.with(|c| c.snapshot().joints.z))
}

#[test]
fn pgup_raises_the_tool_and_pgdn_lowers_it() {
    let mut h = app();
    ready(&mut h);
    click(&mut h, "10");
    let z0 = sim_z(h.state());
    h.key_press(egui::Key::PageDown);
    step_until(&mut h, "the tool to go down 10 mm", |a| {
        (sim_z(a) - z0 - 10.0).abs() < 0.0015 && step_ended(1)(a)
    });
    h.key_press(egui::Key::PageUp);
    step_until(&mut h, "the tool to come back up", |a| {
        (sim_z(a) - z0).abs() < 0.0015 && step_ended(2)(a)
    });
}

#[test]
fn an_idle_connected_window_is_woken_by_a_handful_of_events_in_5_s_of_polling() {
    let mut h = app();
    ready(&mut h);
    // Let the move of homing settle and every first answer arrive: four polls in a row
    // that woke nothing.
    let mut quiet_from = (h.state().link_wakes(), sim_polls(h.state()));
    until("four polls in a row that woke nothing", DEADLINE, || {
        h.step();
        let (wakes, polls) = (h.state().link_wakes(), sim_polls(h.state()));
        if wakes != quiet_from.0 {
            quiet_from = (wakes, polls);
        }
        polls >= quiet_from.1 + 4
    });
    // 5 s of polling, failing the moment a sixth wake comes.
    let (wakes, polls) = (h.state().link_wakes(), sim_polls(h.state()));
    let woke = |h: &Harness<'_, PendantApp>| h.state().link_wakes() - wakes;
    let too_many = eventually(Duration::from_secs(5), || {
        h.step();
        woke(&h) > 5
    });
    let polled = sim_polls(h.state()) - polls;
    let woke = woke(&h);
    assert!(
        !too_many,
        "{woke} wakes for {polled} polls that answered the same as before"
    );
    assert!(polled >= 20, "the link polled only {polled} times in 5 s");
    // A change is still drawn at once: a step moves the arm, and its replies wake.
    click(&mut h, "X+");
    step_until(&mut h, "the step's replies to wake the window", |a| {
        a.link_wakes() > woke + wakes + 2
    });
}

/// Frames the simulator has received (polls, on an idle window).
fn sim_polls(app: &PendantApp) -> u64 {
    app.sim().map_or(0, |s| s.counters().frames)
}

#[test]
fn ctrl_q_asks_the_window_to_close() {
    let mut h = app();
    h.run_steps(2);
    let closes = |h: &Harness<'_, PendantApp>| {
        h.output()
            .viewport_output
            .get(&egui::ViewportId::ROOT)
            .is_some_and(|v| v.commands.contains(&egui::ViewportCommand::Close))
    };
    assert!(!closes(&h));
    // One event, one frame: that frame's output holds what the app asked of the window.
    h.event(egui::Event::Key {
        key: egui::Key::Q,
        physical_key: None,
        pressed: true,
        repeat: false,
        modifiers: egui::Modifiers::COMMAND,
    });
    h.step();
    assert!(closes(&h), "Ctrl+Q did not close the window");
}

#[test]
fn ctrl_plus_enlarges_the_window_keeps_the_size_and_leaves_the_step_alone() {
    let mut h = app();
    h.run_steps(2);
    let step = h.state().pendant().settings.jog.step;
    for pressed in [true, false] {
        h.event(egui::Event::Key {
            key: egui::Key::Plus,
            physical_key: None,
            pressed,
            repeat: false,
            modifiers: egui::Modifiers::COMMAND,
        });
        h.step();
    }
    h.run_steps(2);
    assert!(
        h.ctx.zoom_factor() > 1.0,
        "Ctrl + did not enlarge the window"
    );
    let kept = h.state().pendant().settings.ui_scale;
    assert!(
        kept.is_some_and(|s| s > 1.0),
        "the size is not kept: {kept:?}"
    );
    assert_eq!(
        h.state().pendant().settings.jog.step,
        step,
        "Ctrl + changed the step"
    );
    // Plain + is still the step ladder.
    h.key_press(egui::Key::Plus);
    h.run_steps(2);
    assert!(
        h.state().pendant().settings.jog.step > step,
        "+ did not take a larger step"
    );
}
