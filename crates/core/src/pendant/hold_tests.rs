//! Hold-to-run through the pendant, on scripted inputs and a virtual clock: what an
//! operator's hand does, frame by frame, and exactly what goes to the link.

use std::time::{Duration, Instant};

use super::script::{poll_reply, ready_system, scara_status};
use super::*;
use crate::link::{LinkEvent, NotSentReason, Origin, RequestId};
use crate::protocol::Direction;
use crate::protocol::{ErrorCode, PositionSystem, Stop, SystemMode, SystemStatus};
use crate::robot::{Joints, Scara};

const FRAME: Duration = Duration::from_millis(16);
const KEY: JogInput = JogInput::Key(0);

fn x_plus() -> JogTarget {
    JogTarget::new(JogAxis::X, Direction::Positive)
}

/// A pendant connected to a ready, homed controller, in continuous mode.
fn continuous(now: Instant) -> Pendant {
    let mut p = Pendant::new(
        Settings::default(),
        crate::robot::RobotModel::default_model(),
    );
    let kin = Scara::new(&p.model);
    for event in script::ready_controller(&kin, Joints::new(30.0, 60.0, 50.0, 0.0)) {
        p.handle_event(now, event);
    }
    p.settings.jog.mode = JogMode::Continuous;
    p.take_requests();
    p
}

/// The controller keeps answering its polls: a fresh status at `now`, `system` as given.
fn poll(p: &mut Pendant, now: Instant, system: SystemStatus) {
    let polls = controller::poll_commands();
    p.handle_event(
        now,
        poll_reply(polls[1].clone(), Reply::SystemStatus(system)),
    );
    let joints = Joints::new(30.0, 60.0, 50.0, 0.0);
    let tip = p.kinematics().forward(&joints).to_array();
    for (i, sys, values) in [
        (0, PositionSystem::Work, tip),
        (2, PositionSystem::Joint, joints.to_array()),
    ] {
        let s = scara_status(sys, values, true, true);
        p.handle_event(now, poll_reply(polls[i].clone(), Reply::ScaraStatus(s)));
    }
}

/// What went to the link, counted: 236H jogs, STOPs and lease renewals.
#[derive(Debug, Default, PartialEq)]
struct Sent {
    jogs: usize,
    stops: usize,
    renewals: usize,
}

fn count(p: &mut Pendant, sent: &mut Sent) {
    for r in p.take_requests() {
        match r {
            Request::Submit(Command::Jog(_)) => sent.jogs += 1,
            Request::Stop => sent.stops += 1,
            Request::RenewJogLease => sent.renewals += 1,
            _ => {}
        }
    }
}

/// Holds `input` on `target` for `frames` frames from `*now`, with the controller polled
/// every 100 ms; answers what went out.
fn hold_for(p: &mut Pendant, now: &mut Instant, input: JogInput, frames: usize) -> Sent {
    let mut sent = Sent::default();
    for i in 0..frames {
        if i % 6 == 0 {
            poll(p, *now, ready_system());
        }
        p.apply(Intent::Jog(input, Press::On(x_plus())), *now);
        p.tick(*now);
        count(p, &mut sent);
        *now += FRAME;
    }
    sent
}

fn release(p: &mut Pendant, now: Instant, input: JogInput) -> Sent {
    let mut sent = Sent::default();
    p.apply(Intent::Jog(input, Press::Up), now);
    count(p, &mut sent);
    sent
}

#[test]
fn a_press_held_two_seconds_is_one_236h_and_no_stop_until_release() {
    for input in [KEY, JogInput::Pointer] {
        let mut now = Instant::now();
        let mut p = continuous(now);
        let held = hold_for(&mut p, &mut now, input, 125);
        assert_eq!(held.jogs, 1, "{input:?}: {held:?}");
        assert_eq!(held.stops, 0, "{input:?}: {held:?}");
        assert_eq!(
            held.renewals, 124,
            "the lease is renewed every frame while held"
        );
        let released = release(&mut p, now, input);
        assert_eq!((released.jogs, released.stops), (0, 1));
        assert!(p.held_jog().is_none());
    }
}

#[test]
fn stop_with_the_input_still_down_latches_until_release_and_a_new_press() {
    for cause in [StopCause::Esc, StopCause::Button] {
        let mut now = Instant::now();
        let mut p = continuous(now);
        hold_for(&mut p, &mut now, KEY, 10);
        p.apply(Intent::Stop(cause), now);
        assert!(p.take_requests().contains(&Request::Stop));
        assert!(p.stop_latch().is_some_and(|t| t.contains("release")));
        let held = hold_for(&mut p, &mut now, KEY, 60);
        assert_eq!(
            held.jogs, 0,
            "{cause:?}: the latch holds while the key stays down"
        );
        // Another jog key pressed meanwhile is swallowed too.
        p.apply(Intent::Jog(JogInput::Key(5), Press::On(x_plus())), now);
        assert_eq!(submitted_jogs(&mut p), 0);
        release(&mut p, now, JogInput::Key(5));
        release(&mut p, now, KEY);
        assert_eq!(p.stop_latch(), None);
        assert_eq!(
            hold_for(&mut p, &mut now, KEY, 5).jogs,
            1,
            "a new press jogs"
        );
    }
}

fn submitted_jogs(p: &mut Pendant) -> usize {
    let mut sent = Sent::default();
    count(p, &mut sent);
    sent.jogs
}

#[test]
fn a_reconnection_with_the_input_held_sends_no_236h() {
    let mut now = Instant::now();
    let mut p = continuous(now);
    hold_for(&mut p, &mut now, KEY, 10);
    p.handle_event(
        now,
        LinkEvent::Disconnected {
            reason: crate::link::LineDownReason::Closed,
        },
    );
    assert!(p.held_jog().is_none());
    p.handle_event(
        now,
        LinkEvent::Reconnected {
            line: "bridge".into(),
        },
    );
    let held = hold_for(&mut p, &mut now, KEY, 120);
    assert_eq!(held.jogs, 0, "{held:?}");
}

#[test]
fn manual_to_auto_with_the_input_held_sends_no_236h() {
    let mut now = Instant::now();
    let mut p = continuous(now);
    hold_for(&mut p, &mut now, KEY, 10);
    let manual = SystemStatus {
        mode: SystemMode::MANUAL,
        ..ready_system()
    };
    poll(&mut p, now, manual);
    p.apply(Intent::Jog(KEY, Press::On(x_plus())), now);
    p.tick(now);
    let r = p.take_requests();
    assert!(
        r.contains(&Request::Stop),
        "leaving AUTO stops the jog: {r:?}"
    );
    assert!(p.messages.iter().any(|m| m.text.contains("MANUAL")));
    // Back to AUTO, the key still down: nothing moves.
    let held = hold_for(&mut p, &mut now, KEY, 120);
    assert_eq!(held.jogs, 0, "{held:?}");
}

#[test]
fn a_refused_jog_is_never_resent_while_held_and_says_so_once() {
    let mut now = Instant::now();
    let mut p = continuous(now);
    let first = hold_for(&mut p, &mut now, KEY, 2);
    assert_eq!(first.jogs, 1);
    let jog = jog::continuous_jog(&p.jog_sent(), JogAxis::X, Direction::Positive);
    p.handle_event(
        now,
        LinkEvent::ErrorReply {
            id: RequestId(7),
            origin: Origin::User,
            command: jog,
            code: ErrorCode(0xB08),
        },
    );
    let before = p.messages.len();
    let held = hold_for(&mut p, &mut now, KEY, 125);
    assert_eq!(held.jogs, 0, "{held:?}");
    assert_eq!(p.messages.len(), before, "no message per frame");
    let refusal = p.messages.iter().rev().find(|m| m.text.contains("B08"));
    assert!(
        refusal.is_some_and(|m| m.text.contains("outside the arm's reach")),
        "the code comes with its text: {:?}",
        p.messages
    );
}

#[test]
fn a_press_while_not_ready_says_not_sent_once_per_press() {
    let mut now = Instant::now();
    let mut p = continuous(now);
    let manual = SystemStatus {
        mode: SystemMode::MANUAL,
        ..ready_system()
    };
    let not_sent = |p: &Pendant| {
        p.messages
            .iter()
            .filter(|m| m.text.contains("not sent"))
            .count()
    };
    for press in 1..=3 {
        for _ in 0..60 {
            poll(&mut p, now, manual);
            p.apply(Intent::Jog(KEY, Press::On(x_plus())), now);
            now += FRAME;
        }
        assert_eq!(submitted_jogs(&mut p), 0);
        assert_eq!(not_sent(&p), press, "one message per press");
        release(&mut p, now, KEY);
    }
}

/// The link answers the X+ jog's 236H: not sent, for `reason`.
fn jog_not_sent(p: &mut Pendant, now: Instant, reason: NotSentReason) {
    let jog = jog::continuous_jog(&p.jog_sent(), JogAxis::X, Direction::Positive);
    p.handle_event(
        now,
        LinkEvent::NotSent {
            id: RequestId(3),
            command: jog,
            reason,
        },
    );
}

#[test]
fn a_not_sent_jog_from_the_link_ends_the_hold_and_is_not_resent() {
    let mut now = Instant::now();
    let mut p = continuous(now);
    hold_for(&mut p, &mut now, KEY, 2);
    jog_not_sent(&mut p, now, NotSentReason::LineDown);
    assert!(p.held_jog().is_none());
    assert_eq!(hold_for(&mut p, &mut now, KEY, 60).jogs, 0);
}

#[test]
fn the_link_lease_stop_is_said_in_messages_and_latches() {
    let mut now = Instant::now();
    let mut p = continuous(now);
    hold_for(&mut p, &mut now, KEY, 2);
    let stop = Command::Stop(Stop {
        axes: crate::protocol::AxisPattern::ALL,
        cancel_held_outputs: false,
    });
    p.handle_event(
        now,
        LinkEvent::Reply {
            id: RequestId(11),
            origin: Origin::LeaseLapsed,
            command: stop.clone(),
            reply: Reply::Ack(stop.id()),
            round_trip: Duration::from_millis(2),
        },
    );
    assert!(p.messages.iter().any(|m| m.text.contains("lease")));
    assert!(p.stop_latch().is_some());
    assert_eq!(hold_for(&mut p, &mut now, KEY, 30).jogs, 0);
}

#[test]
fn the_guardians_own_stop_is_said_in_messages_and_latches_a_held_jog() {
    let mut now = Instant::now();
    let mut p = continuous(now);
    assert_eq!(hold_for(&mut p, &mut now, KEY, 2).jogs, 1);
    p.handle_event(
        now,
        LinkEvent::GuardianStopped("the window was silent for 260 ms".into()),
    );
    assert!(
        p.messages
            .iter()
            .any(|m| m.text.contains("guardian") && m.text.contains("silent")),
        "not in Messages"
    );
    assert!(p.stop_latch().is_some(), "not latched");
    assert_eq!(
        hold_for(&mut p, &mut now, KEY, 30).jogs,
        0,
        "restarted by itself"
    );
    release(&mut p, now, KEY);
    assert_eq!(
        hold_for(&mut p, &mut now, KEY, 2).jogs,
        1,
        "a new press jogs"
    );
}

#[test]
fn focus_loss_stops_and_a_key_still_down_after_it_starts_nothing() {
    let mut now = Instant::now();
    let mut p = continuous(now);
    hold_for(&mut p, &mut now, KEY, 5);
    p.apply(Intent::FocusLost, now);
    assert!(p.take_requests().contains(&Request::Stop));
    assert_eq!(hold_for(&mut p, &mut now, KEY, 30).jogs, 0);
}

#[test]
fn a_tap_inside_one_frame_sends_no_jog_only_its_stop() {
    for input in [KEY, JogInput::Pointer] {
        let now = Instant::now();
        let mut p = continuous(now);
        // The window reports the press, then the release, in one frame.
        p.apply_all(
            [
                Intent::Jog(input, Press::On(x_plus())),
                Intent::Jog(input, Press::Up),
            ],
            now,
        );
        assert_eq!(p.take_requests(), vec![Request::Stop], "{input:?}");
        assert!(p.held_jog().is_none());
        // No "jogging X+" for a jog that never went out.
        assert!(!p.messages.iter().any(|m| m.text.starts_with("jogging")));
        assert!(
            p.messages
                .iter()
                .any(|m| m.text == "X+ pressed and released in one frame: no jog sent, only STOP")
        );
        assert!(p.stop_latch().is_none(), "a tap latches nothing");
        // The next press starts a jog as usual.
        let held = hold_for(&mut p, &mut now.clone(), input, 3);
        assert_eq!(held.jogs, 1);
    }
}

#[test]
fn a_jog_ended_by_a_stop_before_it_went_out_keeps_the_stops_latch() {
    let mut now = Instant::now();
    let mut p = continuous(now);
    hold_for(&mut p, &mut now, KEY, 2);
    p.apply(Intent::Stop(StopCause::Esc), now);
    p.take_requests();
    jog_not_sent(&mut p, now, NotSentReason::StopCameFirst);
    assert_eq!(p.jog.hold.latch(), Some(StopCause::Esc));
    assert!(
        p.messages
            .iter()
            .any(|m| m.text.contains("not sent: STOP came first"))
    );
}

/// A 2A1H in the work system at the ready joints, every axis in use or none.
fn poll_in_use(p: &mut Pendant, now: Instant, in_use: bool) {
    let joints = Joints::new(30.0, 60.0, 50.0, 0.0);
    let tip = p.kinematics().forward(&joints).to_array();
    let mut s = scara_status(PositionSystem::Work, tip, true, true);
    let old = s.axes;
    s.axes = crate::protocol::PerAxis::from_fn(crate::protocol::AxisPattern::SCARA_1, |axis| {
        let mut a = old.get(axis).unwrap_or_default();
        a.status = a.status.with_in_use(in_use);
        a
    });
    let polls = controller::poll_commands();
    p.handle_event(now, poll_reply(polls[0].clone(), Reply::ScaraStatus(s)));
}

#[test]
fn a_held_jog_the_controller_ended_reads_stopped_not_jogging() {
    let mut now = Instant::now();
    let mut p = continuous(now);
    hold_for(&mut p, &mut now, KEY, 2);
    // A poll answered before the 236H's reply says nothing of the jog.
    poll_in_use(&mut p, now, false);
    assert_eq!(p.motion_phase(now), MotionPhase::Jogging);
    let jog = jog::continuous_jog(&p.jog_sent(), JogAxis::X, Direction::Positive);
    now += FRAME;
    p.handle_event(
        now,
        LinkEvent::Reply {
            id: RequestId(5),
            origin: Origin::User,
            command: jog.clone(),
            reply: Reply::Ack(jog.id()),
            round_trip: Duration::from_millis(2),
        },
    );
    now += FRAME;
    poll_in_use(&mut p, now, true);
    p.tick(now);
    assert_eq!(p.motion_phase(now), MotionPhase::Jogging);
    // At the edge of reach the controller stops the jog: no axis in use.
    now += FRAME;
    poll_in_use(&mut p, now, false);
    p.tick(now);
    assert_eq!(p.motion_phase(now), MotionPhase::Stopped);
    p.tick(now);
    let said = p
        .messages
        .iter()
        .filter(|m| m.text.contains("stopped by the controller"))
        .count();
    assert_eq!(said, 1, "said once: {:?}", p.messages);
}

#[test]
fn a_stop_in_the_same_frame_as_a_press_wins() {
    let now = Instant::now();
    let mut p = continuous(now);
    p.apply_all(
        [
            Intent::Stop(StopCause::Esc),
            Intent::Jog(KEY, Press::On(x_plus())),
        ],
        now,
    );
    let r = p.take_requests();
    assert_eq!(r, vec![Request::Stop], "the press never goes out");
    assert!(p.stop_latch().is_some());
}

#[test]
fn step_mode_steps_once_per_press_however_long_held() {
    let mut now = Instant::now();
    let mut p = continuous(now);
    p.settings.jog.mode = JogMode::Step;
    let mut steps = 0;
    for _ in 0..60 {
        p.apply(Intent::Jog(KEY, Press::On(x_plus())), now);
        steps += submitted(&mut p)
            .iter()
            .filter(|c| matches!(c, Command::ScaraMoveRelative(_)))
            .count();
        now += FRAME;
    }
    assert_eq!(steps, 1);
}

fn submitted(p: &mut Pendant) -> Vec<Command> {
    super::tests::submitted(p)
}

#[test]
fn servo_and_e_stop_changes_reach_messages() {
    let now = Instant::now();
    let mut p = continuous(now);
    let estop = SystemStatus {
        status1: crate::protocol::SystemStatus1::default().with_emergency_stop(true),
        ..ready_system()
    };
    poll(&mut p, now, estop);
    poll(&mut p, now, ready_system());
    let texts: Vec<&str> = p.messages.iter().map(|m| m.text.as_str()).collect();
    assert!(
        texts.iter().any(|t| t.contains("E-stop pressed")),
        "{texts:?}"
    );
    assert!(
        texts.iter().any(|t| t.contains("E-stop released")),
        "{texts:?}"
    );
    let polls = controller::poll_commands();
    let off = scara_status(PositionSystem::Work, [0.0; 4], false, true);
    p.handle_event(now, poll_reply(polls[0].clone(), Reply::ScaraStatus(off)));
    assert!(p.messages.back().is_some_and(|m| m.text == "servo off"));
}

#[test]
fn the_speed_cap_limits_the_speed_a_jog_sends() {
    let mut now = Instant::now();
    let mut p = continuous(now);
    p.settings.jog.cp_speed_mm_s = 900;
    poll(&mut p, now, ready_system());
    now += FRAME;
    p.apply(Intent::Jog(KEY, Press::On(x_plus())), now);
    let sent = submitted(&mut p);
    let Some(Command::Jog(j)) = sent.first() else {
        panic!("{sent:?}");
    };
    assert_eq!(
        j.motion,
        crate::protocol::JogMotion::Cartesian {
            frame: crate::protocol::JogFrame::Work,
            acc: crate::protocol::CentiG(30),
            dec: crate::protocol::CentiG(30),
            speed: crate::protocol::MmPerSec(250),
        }
    );
}

#[test]
fn each_poll_records_the_work_position_joints_in_position_and_phase_for_the_plots() {
    let now = Instant::now();
    let mut p = continuous(now);
    poll(&mut p, now + FRAME, ready_system());
    let store = &p.samples.store;
    let work = store.series(p.samples.xsel_series()).unwrap();
    let last = work.len() - 1;
    let joints = store
        .all()
        .iter()
        .find(|s| s.name == "X-SEL joints")
        .unwrap();
    // The joint poll's J2 and J3 exactly as polled; the work poll's in-position bit and
    // the pendant's phase (standing: idle) beside its position.
    assert_eq!(joints.value(joints.len() - 1, 1), Some(60.0));
    assert_eq!(joints.value(joints.len() - 1, 2), Some(50.0));
    assert_eq!(
        work.value(
            last,
            crate::pendant::samples::polled::xsel_channel::MOTION_PHASE
        ),
        Some(0.0)
    );
    assert!(
        work.value(
            last,
            crate::pendant::samples::polled::xsel_channel::IN_POSITION
        )
        .is_some()
    );
}
