//! The axis panel's lamps and words from state: Stopped only after Stop (6), "jogging"
//! only while the jog runs, stale lamps while the line is down, an unacknowledged write
//! never called "did not arrive", and a held jog recorded as what went on the line.

use std::time::Instant;

use super::lamps::{Lamp, Lit};
use super::*;
use crate::rmc::StatusBits;

fn axis0() -> AxisId {
    AxisId::new(0).unwrap()
}

fn plus0() -> AxisJog {
    AxisJog {
        axis: axis0(),
        direction: Direction::Positive,
    }
}

fn standing(extra: &[u32]) -> AxisStatus {
    let mut bits = StatusBits(0)
        .with(StatusBits::ENABLED, true)
        .with(StatusBits::TG_DONE, true);
    for b in extra {
        bits = bits.with(*b, true);
    }
    AxisStatus {
        bits,
        ..Default::default()
    }
}

fn status(r: &mut RmcAxes, s: AxisStatus, now: Instant) {
    r.handle_event(
        now,
        RmcEvent::Status {
            axis: axis0(),
            status: s,
            trusted: true,
            at: now,
        },
    );
}

/// Connected, axis 1 enabled and standing.
fn ready(now: Instant) -> (RmcAxes, RmcSettings) {
    let mut r = RmcAxes::new(1);
    r.handle_event(
        now,
        RmcEvent::LineUp {
            name: "sim".into(),
            at: now,
        },
    );
    status(&mut r, standing(&[]), now);
    (r, RmcSettings::default())
}

/// Ready, in hold-to-run, with the pointer pressed on Axis 1+ this frame.
fn pressed_in_hold(now: Instant) -> (RmcAxes, RmcSettings) {
    let (mut r, mut s) = ready(now);
    s.jog.mode = JogMode::Continuous;
    r.apply(
        AxisIntent::Jog(JogInput::Pointer, Press::On(plus0())),
        &mut s,
        now,
    );
    (r, s)
}

/// `command` went out under `id` and the RMC took it.
fn taken(r: &mut RmcAxes, id: Option<RequestId>, command: Command, now: Instant) {
    r.handle_event(
        now,
        RmcEvent::Sent {
            id,
            axis: axis0(),
            command,
            req: true,
            at: now,
        },
    );
    r.handle_event(
        now,
        RmcEvent::Acknowledged {
            id,
            axis: axis0(),
            at: now,
        },
    );
}

fn lamp(r: &RmcAxes, name: &str) -> Lamp {
    r.axis_lamps(axis0())
        .into_iter()
        .flatten()
        .find(|l| l.name == name)
        .unwrap()
}

fn step() -> Command {
    Command::MoveRelative(MoveRelative {
        distance: 10.0,
        speed: 10.0,
        accel: 100.0,
        decel: 100.0,
        relative_to: RelativeTo::Command,
    })
}

#[test]
fn stopped_is_lit_after_stop_6_and_not_after_a_move_that_ends_normally() {
    let now = Instant::now();
    let (mut r, _) = ready(now);
    taken(&mut r, Some(RequestId(1)), step(), now);
    // The RMC's bit 6 reads 1 whenever the axis stands (as the simulator has it).
    status(
        &mut r,
        standing(&[StatusBits::STOPPED, StatusBits::IN_POSITION]),
        now,
    );
    assert_eq!(lamp(&r, "Stopped").lit, Lit::Off, "a normal move's end");
    assert!(lamp(&r, "In Position").on());
    taken(&mut r, None, Command::Stop { decel: 1000.0 }, now);
    status(&mut r, standing(&[StatusBits::STOPPED]), now);
    assert!(lamp(&r, "Stopped").on(), "after Stop (6)");
    taken(&mut r, Some(RequestId(2)), step(), now);
    status(&mut r, standing(&[StatusBits::STOPPED]), now);
    assert_eq!(lamp(&r, "Stopped").lit, Lit::Off, "a move after it");
}

#[test]
fn jogging_shows_only_while_the_jog_runs() {
    let now = Instant::now();
    let (mut r, mut s) = ready(now);
    s.jog.mode = JogMode::Continuous;
    let press = |r: &mut RmcAxes, s: &mut RmcSettings, p| {
        r.apply(AxisIntent::Jog(JogInput::Pointer, p), s, now);
    };
    press(&mut r, &mut s, Press::On(plus0()));
    let line = r.jog_line().unwrap().1;
    assert_eq!(line, "jogging Axis 1+");
    press(&mut r, &mut s, Press::Up);
    let line = r.jog_line().map(|l| l.1).unwrap_or_default();
    assert!(!line.contains("jogging"), "after release: {line}");
    // Ended by STOP: the latch's reason, then nothing about jogging once released.
    press(&mut r, &mut s, Press::On(plus0()));
    r.stop(StopCause::Button);
    assert!(r.jog_line().unwrap().1.contains("STOP"));
    press(&mut r, &mut s, Press::Up);
    let line = r.jog_line().map(|l| l.1).unwrap_or_default();
    assert!(!line.contains("jogging"), "after STOP and release: {line}");
}

#[test]
fn lamps_of_a_line_that_is_down_are_stale_and_never_lit() {
    let now = Instant::now();
    let (mut r, _) = ready(now);
    r.handle_event(
        now,
        RmcEvent::Controller {
            status: crate::rmc::ControllerStatus(u32::MAX),
            at: now,
        },
    );
    status(&mut r, standing(&[StatusBits::IN_POSITION]), now);
    assert!(lamp(&r, "Enabled").on());
    assert!(r.controller_lamps().iter().all(Lamp::on));
    assert_eq!(r.stale_text(), None);
    r.handle_event(
        now,
        RmcEvent::LineDown {
            reason: "connection reset".into(),
            at: now,
        },
    );
    let lamps: Vec<Lamp> = r
        .axis_lamps(axis0())
        .into_iter()
        .flatten()
        .chain(r.controller_lamps())
        .collect();
    assert!(lamps.iter().all(|l| matches!(l.lit, Lit::Stale { .. })));
    assert_eq!(lamp(&r, "Enabled").lit, Lit::Stale { was_on: true });
    let text = r.stale_text().unwrap();
    assert!(text.starts_with("stale") && text.contains("down"), "{text}");
}

#[test]
fn a_write_answered_and_never_acknowledged_says_check_the_axis() {
    let now = Instant::now();
    let (mut r, _) = ready(now);
    let id = RequestId(7);
    r.sent(id, axis0(), step());
    for answered in [true, false] {
        r.handle_event(
            now,
            RmcEvent::Sent {
                id: Some(id),
                axis: axis0(),
                command: step(),
                req: true,
                at: now,
            },
        );
        let said = r
            .handle_event(
                now,
                RmcEvent::Unconfirmed {
                    id: Some(id),
                    axis: axis0(),
                    answered,
                },
            )
            .unwrap()
            .1;
        assert!(said.contains(UNACKNOWLEDGED), "{said}");
        assert!(!said.contains("did not arrive"), "{said}");
    }
}

#[test]
fn a_held_jog_is_recorded_as_the_move_that_went_out() {
    let now = Instant::now();
    let (mut r, mut s) = pressed_in_hold(now);
    assert!(matches!(r.take_calls()[..], [AxisCall::Hold(..)]));
    // The link's first move of the chain, under the hold's id.
    let chunk = Command::MoveRelative(MoveRelative {
        distance: 12.5,
        speed: 10.0,
        accel: 100.0,
        decel: 100.0,
        relative_to: RelativeTo::Target,
    });
    taken(&mut r, Some(RequestId(3)), chunk, now);
    assert_eq!(r.view(axis0()).unwrap().following, Some(chunk));
    // A hold the link refuses ends the jog, though nothing was recorded for it.
    r.apply(AxisIntent::Jog(JogInput::Pointer, Press::Up), &mut s, now);
    r.apply(
        AxisIntent::Jog(JogInput::Pointer, Press::On(plus0())),
        &mut s,
        now,
    );
    assert!(r.hold.jog().is_some());
    let said = r
        .handle_event(
            now,
            RmcEvent::NotSent {
                id: RequestId(4),
                axis: axis0(),
                what: crate::rmc::link::HELD_JOG,
                reason: "a jog runs on Axis 1".into(),
            },
        )
        .unwrap()
        .1;
    assert!(r.hold.jog().is_none(), "the refused hold ended");
    assert!(said.starts_with("Held jog not sent"), "{said}");
}

#[test]
fn a_jog_stopped_by_focus_loss_is_said() {
    let now = Instant::now();
    let (mut r, mut s) = pressed_in_hold(now);
    r.take_calls();
    let said = r.focus_lost_at(now).unwrap().1;
    assert!(said.contains("lost focus"), "{said}");
    assert_eq!(r.take_calls(), vec![AxisCall::Release(axis0())]);
    r.apply(AxisIntent::Jog(JogInput::Pointer, Press::Up), &mut s, now);
    let line = r.jog_line().unwrap().1;
    assert!(
        line.contains("lost focus"),
        "said after release too: {line}"
    );
    assert_eq!(r.focus_lost_at(now), None, "nothing runs: nothing to say");
}

#[test]
fn a_tap_in_hold_mode_sends_nothing() {
    let now = Instant::now();
    // Pressed and released within one frame: the window reports both before it
    // forwards the frame's calls.
    let (mut r, mut s) = pressed_in_hold(now);
    r.apply(AxisIntent::Jog(JogInput::Pointer, Press::Up), &mut s, now);
    assert_eq!(
        r.take_calls(),
        vec![],
        "no hold, and no release to overtake it"
    );
    assert!(r.hold.jog().is_none());
    let line = r.jog_line().unwrap().1;
    assert!(line.contains("nothing sent"), "{line}");
    // A hold that went out in an earlier frame is released with Stop (6).
    r.apply(
        AxisIntent::Jog(JogInput::Pointer, Press::On(plus0())),
        &mut s,
        now,
    );
    assert!(matches!(r.take_calls()[..], [AxisCall::Hold(..)]));
    r.apply(AxisIntent::Jog(JogInput::Pointer, Press::Up), &mut s, now);
    assert_eq!(r.take_calls(), vec![AxisCall::Release(axis0())]);
}
