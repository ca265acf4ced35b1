//! The axis panel's model: steps, hold-to-run with the STOP latch, refusals, events.

use std::time::{Duration, Instant};

use super::*;
use crate::rmc::{ErrorBits, StatusBits};

fn axis(i: usize) -> AxisId {
    AxisId::new(i).unwrap()
}

fn plus(i: usize) -> AxisJog {
    AxisJog {
        axis: axis(i),
        direction: Direction::Positive,
    }
}

/// Connected, axis 0 enabled.
fn ready(now: Instant) -> (RmcAxes, RmcSettings) {
    let mut r = RmcAxes::new(2);
    r.handle_event(
        now,
        RmcEvent::LineUp {
            name: "sim".into(),
            at: now,
        },
    );
    let status = AxisStatus {
        bits: StatusBits(0).with(StatusBits::ENABLED, true),
        ..Default::default()
    };
    r.handle_event(
        now,
        RmcEvent::Status {
            axis: axis(0),
            status,
            trusted: true,
            at: now,
        },
    );
    // Axis 2 is polled and disabled.
    r.handle_event(
        now,
        RmcEvent::Status {
            axis: axis(1),
            status: AxisStatus::default(),
            trusted: true,
            at: now,
        },
    );
    (r, RmcSettings::default())
}

fn press(r: &mut RmcAxes, s: &mut RmcSettings, p: Press<AxisJog>, now: Instant) {
    r.apply(AxisIntent::Jog(JogInput::Pointer, p), s, now);
}

#[test]
fn a_press_in_step_mode_is_one_move_relative_with_the_chosen_reference() {
    let now = Instant::now();
    let (mut r, mut s) = ready(now);
    s.jog.relative_to = crate::robot::RelativeTo::Target;
    for _ in 0..30 {
        press(&mut r, &mut s, Press::On(plus(0)), now);
    }
    press(&mut r, &mut s, Press::Up, now);
    let calls = r.take_calls();
    let moves: Vec<_> = calls
        .iter()
        .filter_map(|c| match c {
            AxisCall::Send(a, Command::MoveRelative(m)) => Some((*a, *m)),
            _ => None,
        })
        .collect();
    assert_eq!(
        moves.len(),
        1,
        "one step per press, never on a level: {calls:?}"
    );
    assert_eq!(moves[0].0, axis(0));
    assert_eq!(moves[0].1.distance, 10.0);
    assert_eq!(moves[0].1.relative_to, crate::robot::RelativeTo::Target);
}

#[test]
fn a_hold_renews_while_down_releases_on_up_and_stop_latches_until_release() {
    let now = Instant::now();
    let (mut r, mut s) = ready(now);
    s.jog.mode = JogMode::Continuous;
    press(&mut r, &mut s, Press::On(plus(0)), now);
    press(&mut r, &mut s, Press::On(plus(0)), now);
    let calls = r.take_calls();
    assert!(matches!(calls[0], AxisCall::Hold(a, _) if a == axis(0)));
    assert_eq!(calls[1], AxisCall::RenewLease);
    r.stop(StopCause::Esc);
    assert_eq!(r.take_calls(), vec![AxisCall::Release(axis(0))]);
    // Still held: nothing restarts by itself.
    for _ in 0..20 {
        press(
            &mut r,
            &mut s,
            Press::On(plus(0)),
            now + Duration::from_millis(100),
        );
    }
    assert!(r.take_calls().is_empty());
    assert!(r.hold.latch_text().is_some());
    press(&mut r, &mut s, Press::Up, now);
    assert!(r.hold.latch_text().is_none());
    press(&mut r, &mut s, Press::On(plus(0)), now);
    assert!(
        matches!(r.take_calls()[..], [AxisCall::Hold(..)]),
        "a fresh press starts again"
    );
    press(&mut r, &mut s, Press::Up, now);
    assert_eq!(r.take_calls(), vec![AxisCall::Release(axis(0))]);
}

#[test]
fn a_disabled_axis_or_a_down_line_refuses_with_a_reason() {
    let now = Instant::now();
    let (mut r, mut s) = ready(now);
    press(&mut r, &mut s, Press::On(plus(1)), now);
    assert!(r.take_calls().is_empty());
    assert!(r.feedback.as_ref().unwrap().text.contains("not enabled"));
    press(&mut r, &mut s, Press::Up, now);
    r.handle_event(
        now,
        RmcEvent::LineDown {
            reason: "reset".into(),
            at: now,
        },
    );
    press(&mut r, &mut s, Press::On(plus(0)), now);
    assert!(r.take_calls().is_empty());
    assert!(r.feedback.as_ref().unwrap().text.contains("not connected"));
}

#[test]
fn a_stop_drops_motion_asked_for_this_frame() {
    let now = Instant::now();
    let (mut r, mut s) = ready(now);
    press(&mut r, &mut s, Press::On(plus(0)), now);
    r.apply(AxisIntent::ClearFaults(axis(0)), &mut s, now);
    r.stop(StopCause::Button);
    assert_eq!(
        r.take_calls(),
        vec![AxisCall::Send(axis(0), Command::ClearFaults)]
    );
}

#[test]
fn a_lapsed_lease_latches_and_a_halt_ends_the_jog() {
    let now = Instant::now();
    let (mut r, mut s) = ready(now);
    s.jog.mode = JogMode::Continuous;
    press(&mut r, &mut s, Press::On(plus(0)), now);
    r.take_calls();
    r.handle_event(
        now,
        RmcEvent::SafetyStop {
            why: crate::rmc::link::SafetyStop::LeaseLapsed,
            axes: vec![axis(0)],
        },
    );
    assert!(r.hold.jog().is_none());
    assert!(
        r.hold.latch_text().is_some(),
        "latched while the button is still down"
    );
    // Errors are named for the operator.
    let status = AxisStatus {
        errors: ErrorBits(1 << ErrorBits::POSITIVE_LIMIT),
        ..Default::default()
    };
    assert_eq!(status.errors.names(), ["positive limit"]);
}

#[test]
fn a_halted_axis_or_program_mode_refuses_a_jog_with_the_reason() {
    let now = Instant::now();
    let (mut r, mut s) = ready(now);
    let halted = AxisStatus {
        bits: StatusBits(0)
            .with(StatusBits::ENABLED, true)
            .with(StatusBits::HALTED, true),
        errors: ErrorBits(1 << ErrorBits::FAULT_INPUT),
        ..Default::default()
    };
    r.handle_event(
        now,
        RmcEvent::Status {
            axis: axis(0),
            status: halted,
            trusted: true,
            at: now,
        },
    );
    press(&mut r, &mut s, Press::On(plus(0)), now);
    press(&mut r, &mut s, Press::Up, now);
    assert!(r.take_calls().is_empty());
    assert!(r.feedback.as_ref().unwrap().text.contains("halted"));
    let (mut r, mut s) = ready(now);
    r.handle_event(
        now,
        RmcEvent::Controller {
            status: crate::rmc::ControllerStatus(0b10),
            at: now,
        },
    );
    press(&mut r, &mut s, Press::On(plus(0)), now);
    assert!(r.take_calls().is_empty());
    assert!(r.feedback.as_ref().unwrap().text.contains("PROGRAM"));
}

#[test]
fn a_step_past_a_soft_limit_is_refused_in_the_axis_units_and_one_within_goes() {
    let now = Instant::now();
    let (mut r, mut s) = ready(now);
    let own = s.axis_mut(axis(0));
    own.units = "mm".into();
    own.limits = settings::SoftLimits {
        min: Some(-5.0),
        max: Some(15.0),
    };
    s.jog.step = 20.0;
    press(&mut r, &mut s, Press::On(plus(0)), now);
    press(&mut r, &mut s, Press::Up, now);
    assert!(r.take_calls().is_empty(), "nothing sent past the limit");
    let said = &r.feedback.as_ref().unwrap().text;
    assert_eq!(
        said,
        "Axis 1+ refused: its end 20.000 mm is beyond the soft limit 15.000 mm"
    );
    s.jog.step = 15.0;
    press(&mut r, &mut s, Press::On(plus(0)), now);
    press(&mut r, &mut s, Press::Up, now);
    assert!(matches!(
        r.take_calls()[..],
        [AxisCall::Send(_, Command::MoveRelative(_))]
    ));
    // Axis 2 has no limits of its own and takes the RMC's units name.
    assert_eq!(s.units(axis(1)), "pu");
    assert_eq!(s.limits(axis(1)), settings::SoftLimits::default());
    // Limits the wrong way round are refused, whatever the step.
    s.axis_mut(axis(0)).limits.min = Some(20.0);
    press(&mut r, &mut s, Press::On(plus(0)), now);
    press(&mut r, &mut s, Press::Up, now);
    assert!(r.take_calls().is_empty());
    assert!(
        r.feedback
            .as_ref()
            .unwrap()
            .text
            .contains("wrong way round")
    );
}

#[test]
fn a_held_jog_stops_within_stopping_distance_of_the_soft_limit_and_latches() {
    let now = Instant::now();
    let (mut r, mut s) = ready(now);
    s.jog.mode = JogMode::Continuous;
    s.axis_mut(axis(0)).limits.max = Some(10.0);
    press(&mut r, &mut s, Press::On(plus(0)), now);
    assert!(matches!(r.take_calls()[..], [AxisCall::Hold(..)]));
    let moving = |at: f32| AxisStatus {
        bits: StatusBits(0).with(StatusBits::ENABLED, true),
        target_position: at,
        target_velocity: 50.0,
        ..Default::default()
    };
    // 50 pu/s at STOP's 1000 pu/s² needs 1.25 pu, and 2 pu more for a late poll.
    assert!(r.keep_limits(axis(0), &moving(6.0), &s, now).is_none());
    let said = r.keep_limits(axis(0), &moving(7.0), &s, now).unwrap().1;
    assert!(
        said.contains("stopped short of its soft limit 10.000 pu"),
        "{said}"
    );
    assert_eq!(r.take_calls(), vec![AxisCall::Release(axis(0))]);
    // Still held: nothing restarts; a fresh press at the limit is refused.
    press(&mut r, &mut s, Press::On(plus(0)), now);
    assert!(r.take_calls().is_empty());
    press(&mut r, &mut s, Press::Up, now);
    r.handle_event(
        now,
        RmcEvent::Status {
            axis: axis(0),
            status: AxisStatus {
                target_position: 10.0,
                ..moving(10.0)
            },
            trusted: true,
            at: now,
        },
    );
    press(&mut r, &mut s, Press::On(plus(0)), now);
    assert!(r.take_calls().is_empty());
    assert!(
        r.feedback
            .as_ref()
            .unwrap()
            .text
            .contains("at its soft limit")
    );
    // The other way is free.
    press(&mut r, &mut s, Press::Up, now);
    press(
        &mut r,
        &mut s,
        Press::On(AxisJog {
            axis: axis(0),
            direction: Direction::Negative,
        }),
        now,
    );
    assert!(matches!(r.take_calls()[..], [AxisCall::Hold(..)]));
}

#[test]
fn a_taught_point_beyond_a_soft_limit_is_refused_whole() {
    let now = Instant::now();
    let (r, mut s) = ready(now);
    s.axis_mut(axis(0)).limits.max = Some(100.0);
    assert!(r.go_moves(&[50_000], &s).is_ok());
    let why = r.go_moves(&[150_000], &s).unwrap_err();
    assert_eq!(
        why,
        "Axis 1's move refused: its end 150.000 pu is beyond the soft limit 100.000 pu"
    );
}
