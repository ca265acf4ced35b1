//! The RMC link core on a virtual clock against the simulated RMC151: REQ/ACK, no blind
//! re-send, zeros first, STOP first, the held jog's chain, and backing off from a device
//! that answers badly.

use std::time::Duration;

use super::harness::{Bench, Fault, Sick, axis};
use super::{BACKOFF_MAX, HoldJog, RmcEvent, RmcLinkConfig, RmcRequest, SafetyStop};
use crate::link::core::{Input, LinkCore};
use crate::rmc::{Command, MoveRelative};
use crate::robot::RelativeTo;

fn move_by(distance: f32, relative_to: RelativeTo) -> Command {
    Command::MoveRelative(MoveRelative {
        distance,
        speed: 50.0,
        accel: 500.0,
        decel: 500.0,
        relative_to,
    })
}

const SECOND: Duration = Duration::from_secs(1);

#[test]
fn every_connection_starts_with_zeros_and_each_command_toggles_req() {
    let mut b = Bench::enabled();
    let id = b.send(axis(0), move_by(10.0, RelativeTo::Command));
    assert!(b.run_until(2 * SECOND, |b| {
        b.core
            .last_status(axis(0))
            .is_some_and(|s| s.bits.in_position() && s.command_position == 10.0)
    }));
    let written = b.commands_to(axis(0));
    assert_eq!(
        written[0],
        (Command::NoOp, false),
        "zeros first: {written:?}"
    );
    assert_eq!(written[1], (Command::Enable(true), true));
    assert_eq!(written[2], (move_by(10.0, RelativeTo::Command), false));
    assert_eq!(written.len(), 3, "nothing else written: {written:?}");
    assert_eq!(b.core.last_status(axis(0)).unwrap().command_position, 10.0);
    assert!(b.saw(|e| matches!(
        e,
        RmcEvent::Acknowledged { id: Some(i), .. } if *i == id
    )));
}

#[test]
fn status_is_not_trusted_until_ack_equals_req() {
    let mut b = Bench::enabled();
    let before = b.core.last_status(axis(0)).unwrap();
    assert!(before.bits.in_position());
    b.faults.extend([Fault::AckLate, Fault::AckLate]);
    let id = b.send(axis(0), move_by(5.0, RelativeTo::Command));
    let acked =
        |b: &Bench| b.saw(|e| matches!(e, RmcEvent::Acknowledged { id: Some(i), .. } if *i == id));
    assert!(b.run_until(SECOND, acked));
    let statuses: Vec<bool> = b
        .events
        .iter()
        .skip_while(|(_, e)| !matches!(e, RmcEvent::Sent { id: Some(i), .. } if *i == id))
        .filter_map(|(_, e)| match e {
            RmcEvent::Status {
                axis: a, trusted, ..
            } if *a == axis(0) => Some(*trusted),
            _ => None,
        })
        .collect();
    assert_eq!(
        &statuses[..3],
        &[false, false, true],
        "two late reads, then ACK = REQ"
    );
    // While untrusted, the In Position of the old state was never taken for the move's.
    let moving = b.events.iter().find_map(|(_, e)| match e {
        RmcEvent::Status {
            axis: a,
            status,
            trusted: true,
            ..
        } if *a == axis(0) && status.command_position == 5.0 => Some(*status),
        _ => None,
    });
    assert!(
        moving.is_some_and(|s| !s.bits.in_position()),
        "the first trusted status is the move's"
    );
}

#[test]
fn a_timed_out_write_whose_ack_matches_is_not_sent_again() {
    let mut b = Bench::enabled();
    b.faults.push(Fault::LoseNextWriteReply);
    let id = b.send(axis(0), move_by(10.0, RelativeTo::Command));
    assert!(b.run_until(2 * SECOND, |b| {
        b.saw(|e| matches!(e, RmcEvent::Acknowledged { id: Some(i), .. } if *i == id))
    }));
    b.run_for(SECOND, None);
    let moves = b.moves_to(axis(0));
    assert_eq!(moves, 1, "the move arrived: it is not written again");
    assert_eq!(
        b.truth(axis(0)).command_position,
        10.0,
        "it moved once, not twice"
    );
}

#[test]
fn a_lost_write_is_reported_and_never_sent_again() {
    let mut b = Bench::enabled();
    b.faults.push(Fault::LoseNextWrite);
    let id = b.send(axis(0), move_by(10.0, RelativeTo::Command));
    assert!(b.run_until(2 * SECOND, |b| {
        b.saw(
            |e| matches!(e, RmcEvent::Unconfirmed { id: Some(i), answered: false, .. } if *i == id),
        )
    }));
    b.run_for(SECOND, None);
    let moves = b.moves_to(axis(0));
    assert_eq!(moves, 1, "written once, never again");
    assert_eq!(b.truth(axis(0)).command_position, 0.0, "it never arrived");
    // The next command works, with REQ back in step with ACK.
    b.send(axis(0), move_by(2.0, RelativeTo::Command));
    assert!(b.run_until(2 * SECOND, |b| b.truth(axis(0)).command_position == 2.0));
}

#[test]
fn a_reconnect_writes_zeros_first_then_stops_what_may_be_moving() {
    let mut b = Bench::enabled();
    b.send(axis(0), move_by(100.0, RelativeTo::Command));
    b.run_for(Duration::from_millis(300), None);
    assert!(b.truth(axis(0)).target_velocity > 0.0, "moving");
    b.lose_line();
    let cut_at = b.wire.len();
    assert!(
        b.run_until(2 * SECOND, |b| b.core.last_status(axis(0)).is_some()
            && b.wire.len() > cut_at + 4)
    );
    b.run_for(Duration::from_millis(200), None);
    let after: Vec<_> = b.wire[cut_at..]
        .iter()
        .filter_map(|(_, r)| match r {
            crate::rmc::modbus::Request::Write { address, words } => {
                Some((*address, Command::from_block(words).ok()))
            }
            _ => None,
        })
        .collect();
    assert_eq!(
        after[0],
        (axis(0).command_block(), Some((Command::NoOp, false)))
    );
    assert_eq!(
        after[1],
        (axis(1).command_block(), Some((Command::NoOp, false)))
    );
    assert!(
        matches!(after[2], (a, Some((Command::Stop { .. }, true))) if a == axis(0).command_block()),
        "then Stop (6) to the axis that was moving: {after:?}"
    );
    assert!(
        after
            .iter()
            .all(|(_, c)| !c.is_some_and(|(c, _)| c.moves())),
        "no move re-sent"
    );
    assert!(b.saw(|e| matches!(
        e,
        RmcEvent::SafetyStop {
            why: SafetyStop::Reconnected,
            ..
        }
    )));
    assert!(b.run_until(2 * SECOND, |b| b.truth(axis(0)).target_velocity == 0.0));
    assert!(
        b.truth(axis(0)).target_position < 100.0,
        "stopped short of the move's end"
    );
}

#[test]
fn stop_goes_ahead_of_a_queued_move_which_is_dropped() {
    let mut b = Bench::enabled();
    // A read is in flight; a move and then STOP arrive before it is answered.
    b.run_until(SECOND, |b| b.core.awaits_bytes());
    let id = b.send(axis(0), move_by(10.0, RelativeTo::Command));
    b.request(RmcRequest::StopAll);
    b.run_for(Duration::from_millis(100), None);
    let written = b.commands_to(axis(0));
    assert!(
        matches!(written.last(), Some((Command::Stop { .. }, _))),
        "{written:?}"
    );
    assert!(
        written.iter().all(|(c, _)| !c.moves()),
        "the move never went out"
    );
    assert!(b.saw(|e| matches!(e, RmcEvent::NotSent { id: i, .. } if *i == id)));
}

fn hold() -> HoldJog {
    HoldJog {
        direction: 1.0,
        speed: 50.0,
        accel: 500.0,
        decel: 500.0,
    }
}

#[test]
fn a_held_jog_runs_smoothly_while_renewed_and_stops_on_release() {
    let mut b = Bench::enabled();
    let id = b.next_id();
    b.request(RmcRequest::Hold {
        id,
        axis: axis(0),
        jog: hold(),
    });
    // Half a second of renewals at 40 ms: after the ramp the target runs at full speed
    // all the time (the chain never lets it slow down).
    b.run_for(Duration::from_millis(200), Some(Duration::from_millis(40)));
    for _ in 0..100 {
        b.run_for(Duration::from_millis(5), Some(Duration::from_millis(40)));
        assert_eq!(
            b.truth(axis(0)).target_velocity,
            50.0,
            "at {:?}",
            b.now - b.start
        );
    }
    b.request(RmcRequest::Release { axis: axis(0) });
    let at = b.truth(axis(0)).target_position;
    assert!(b.run_until(SECOND, |b| b.truth(axis(0)).target_velocity == 0.0));
    let stopped = b.truth(axis(0)).target_position;
    // 50 pu/s at 1000 pu/s² (STOP's deceleration) stops within 1.25 pu.
    assert!(
        stopped - at <= 1.3,
        "stopped {} after release",
        stopped - at
    );
    assert!(matches!(
        b.commands_to(axis(0)).last(),
        Some((Command::Stop { .. }, _))
    ));
}

#[test]
fn a_held_jog_stops_within_one_chunk_when_the_pendant_goes_quiet() {
    let lease = RmcLinkConfig::default().lease.as_secs_f32();
    let chunk = 50.0 * lease + 50.0 * 50.0 / (2.0 * 500.0);
    // The window freezes: no more renewals, the link core goes on and sends Stop (6).
    let mut b = Bench::enabled();
    let id = b.next_id();
    b.request(RmcRequest::Hold {
        id,
        axis: axis(0),
        jog: hold(),
    });
    b.run_for(Duration::from_millis(500), Some(Duration::from_millis(40)));
    let quiet_at = b.truth(axis(0)).target_position;
    assert!(
        b.run_until(2 * SECOND, |b| b.truth(axis(0)).target_velocity == 0.0
            && b.truth(axis(0)).target_position > quiet_at)
    );
    let ran = b.truth(axis(0)).target_position - quiet_at;
    assert!(
        ran <= chunk,
        "ran {ran} after the last renewal; one chunk is {chunk}"
    );
    assert!(b.saw(|e| matches!(
        e,
        RmcEvent::SafetyStop {
            why: SafetyStop::LeaseLapsed,
            ..
        }
    )));
    // The whole pendant dies (no link either): the axis runs out its last move only.
    let mut b = Bench::enabled();
    let id = b.next_id();
    b.request(RmcRequest::Hold {
        id,
        axis: axis(0),
        jog: hold(),
    });
    b.run_for(Duration::from_millis(500), Some(Duration::from_millis(40)));
    let died_at = b.truth(axis(0)).target_position;
    let mut sim = b.sim.clone();
    let mut t = b.now;
    for _ in 0..3000 {
        t += Duration::from_millis(1);
        sim.advance(t);
    }
    let s = sim.status(axis(0)).unwrap();
    assert_eq!(s.target_velocity, 0.0, "it stops by itself");
    let ran = s.target_position - died_at;
    assert!(
        ran <= chunk,
        "ran {ran} after the pendant died; one chunk is {chunk}"
    );
}

#[test]
fn closing_stops_a_moving_axis_before_the_line_closes() {
    let mut b = Bench::enabled();
    b.send(axis(0), move_by(100.0, RelativeTo::Command));
    b.run_for(Duration::from_millis(300), None);
    b.core.handle_request(b.now, Input::Close);
    assert!(b.run_until(SECOND, |b| b.core.is_closed()));
    assert!(matches!(
        b.commands_to(axis(0)).last(),
        Some((Command::Stop { .. }, _))
    ));
    assert!(b.saw(|e| matches!(e, RmcEvent::Closed)));
}

#[test]
fn motion_to_a_disabled_axis_is_refused_before_sending() {
    let mut b = Bench::new(RmcLinkConfig::default());
    b.run_until(SECOND, |b| b.core.last_status(axis(1)).is_some());
    let id = b.send(axis(1), move_by(1.0, RelativeTo::Command));
    assert!(b.saw(|e| matches!(
        e, RmcEvent::NotSent { id: i, reason, .. } if *i == id && reason.contains("not enabled")
    )));
    assert!(b.commands_to(axis(1)).iter().all(|(c, _)| !c.moves()));
}

#[test]
fn an_ack_that_never_comes_is_reported_and_the_link_goes_on() {
    let mut b = Bench::enabled();
    b.faults.push(Fault::AckNever);
    let id = b.send(axis(0), move_by(1.0, RelativeTo::Command));
    let unconfirmed = |b: &Bench| {
        b.saw(
            |e| matches!(e, RmcEvent::Unconfirmed { id: Some(i), answered: true, .. } if *i == id),
        )
    };
    assert!(b.run_until(2 * SECOND, unconfirmed));
    let waited = b
        .events
        .iter()
        .find(|(_, e)| matches!(e, RmcEvent::Unconfirmed { .. }))
        .map(|(t, _)| *t - b.start)
        .unwrap();
    assert!(
        waited < Duration::from_millis(700),
        "given up after {waited:?}"
    );
    // The other axis is polled again afterwards.
    let before = b.events.len();
    b.run_for(Duration::from_millis(100), None);
    assert!(b.events[before..].iter().any(|(_, e)| matches!(
        e,
        RmcEvent::Status { axis: a, .. } if *a == axis(1)
    )));
    let moves = b.moves_to(axis(0));
    assert_eq!(moves, 1, "never sent again");
}

#[test]
fn every_frame_is_reported_for_the_log_and_a_lost_reply_as_a_time_out() {
    let mut b = Bench::enabled();
    b.faults.push(Fault::LoseNextWriteReply);
    b.send(axis(0), move_by(1.0, RelativeTo::Command));
    b.run_for(SECOND, None);
    let transaction = |bytes: &[u8]| u16::from_be_bytes([bytes[0], bytes[1]]);
    let mut waiting: Option<u16> = None;
    let (mut sent, mut timeouts) = (0, 0);
    for (_, e) in &b.events {
        match e {
            RmcEvent::FrameSent { bytes, .. } => {
                assert_eq!(waiting, None, "one transaction at a time");
                waiting = Some(transaction(bytes));
                sent += 1;
            }
            RmcEvent::FrameReceived { bytes, .. } => {
                assert_eq!(
                    waiting.take(),
                    Some(transaction(bytes)),
                    "a reply to its request"
                );
            }
            RmcEvent::Timeout { what, .. } => {
                let t = waiting.take().expect("a time-out ends a request");
                assert!(what.contains(&format!("transaction {t}")), "{what}");
                timeouts += 1;
            }
            _ => {}
        }
    }
    assert_eq!(sent, b.wire.len(), "every request written is reported");
    assert_eq!(timeouts, 1, "the lost write reply, once");
}

#[test]
fn still_axes_are_polled_slowly_and_a_command_brings_the_fast_rounds_back() {
    let mut b = Bench::enabled();
    b.run_for(2 * SECOND, None);
    let reads_between = |b: &Bench, from: std::time::Instant, to: std::time::Instant| {
        b.wire
            .iter()
            .filter(|(at, r)| {
                *at >= from
                    && *at < to
                    && matches!(r, crate::rmc::modbus::Request::Read { count: 116, address }
                        if *address == axis(0).status_block())
            })
            .count()
    };
    let idle = reads_between(&b, b.now - SECOND, b.now);
    assert!(
        (3..=5).contains(&idle),
        "{idle} reads of a still axis in 1 s"
    );
    let sent_at = b.now;
    b.send(axis(0), move_by(50.0, RelativeTo::Command));
    b.run_for(Duration::from_millis(500), None);
    let moving = reads_between(&b, sent_at, b.now);
    assert!(moving >= 20, "{moving} reads of a moving axis in 0.5 s");
    // The ACK was read within a fast round of the write.
    let acked = b
        .events
        .iter()
        .find(|(at, e)| *at >= sent_at && matches!(e, RmcEvent::Acknowledged { .. }))
        .map(|(at, _)| *at - sent_at)
        .unwrap();
    assert!(acked <= Duration::from_millis(45), "ACK after {acked:?}");
}

/// What the driver hands the core in one go when a Release or STOP (on the STOP channel)
/// overtook requests sent before it: the STOP first, then the others, then the STOP's
/// copy in order (`RmcHandle::release`, `stop_all`).
fn overtaken(b: &mut Bench, stop: RmcRequest, before: Vec<RmcRequest>, again: RmcRequest) {
    use crate::link::core::Input;
    for r in std::iter::once(stop).chain(before).chain([again]) {
        b.core.handle_request(b.now, Input::App(r));
    }
    b.pump();
}

#[test]
fn a_release_that_overtook_its_hold_still_ends_it_and_nothing_moves() {
    let mut b = Bench::enabled();
    let id = b.next_id();
    let hold = RmcRequest::Hold {
        id,
        axis: axis(0),
        jog: hold(),
    };
    overtaken(
        &mut b,
        RmcRequest::Release { axis: axis(0) },
        vec![hold],
        RmcRequest::StopsInOrder {
            axis: Some(axis(0)),
        },
    );
    // Nobody renews: the pendant released it.
    b.run_for(SECOND, None);
    assert_eq!(b.moves_to(axis(0)), 0, "{:?}", b.commands_to(axis(0)));
    assert!(b.saw(|e| matches!(e, RmcEvent::NotSent { id: i, .. } if *i == id)));
    assert!(
        !b.saw(|e| matches!(e, RmcEvent::SafetyStop { .. })),
        "no jog ran for its lease to lapse"
    );
}

#[test]
fn a_stop_that_overtook_a_hold_and_a_move_sends_neither() {
    let mut b = Bench::enabled();
    let (jog, step) = (b.next_id(), b.next_id());
    let before = vec![
        RmcRequest::Hold {
            id: jog,
            axis: axis(0),
            jog: hold(),
        },
        RmcRequest::Send {
            id: step,
            axis: axis(0),
            command: move_by(5.0, RelativeTo::Command),
        },
    ];
    overtaken(
        &mut b,
        RmcRequest::StopAll,
        before,
        RmcRequest::StopsInOrder { axis: None },
    );
    b.run_for(SECOND, None);
    assert_eq!(b.moves_to(axis(0)), 0, "{:?}", b.commands_to(axis(0)));
    for id in [jog, step] {
        assert!(b.saw(|e| matches!(e, RmcEvent::NotSent { id: i, .. } if *i == id)));
    }
    // The copy adds no second Stop (6) to an axis with nothing running.
    let stops = b
        .commands_to(axis(0))
        .iter()
        .filter(|(c, _)| matches!(c, Command::Stop { .. }))
        .count();
    assert!(stops <= 1, "{stops} Stop (6) writes");
}

/// Requests written in `[from, to)`.
fn requests_between(b: &Bench, from: std::time::Instant, to: std::time::Instant) -> usize {
    b.wire
        .iter()
        .filter(|(at, _)| *at >= from && *at < to)
        .count()
}

/// The health line's words (the name of the latest `LineUp`) from `from` on.
fn health_lines(b: &Bench, from: std::time::Instant) -> Vec<String> {
    b.events
        .iter()
        .filter(|(at, _)| *at >= from)
        .filter_map(|(_, e)| match e {
            RmcEvent::LineUp { name, .. } => Some(name.clone()),
            _ => None,
        })
        .collect()
}

#[test]
fn a_device_that_keeps_answering_badly_is_backed_off_from_and_paced_again_once_healed() {
    for sick in [Sick::Exceptions, Sick::ShortReads] {
        let mut b = Bench::enabled();
        let fell_ill = b.now;
        b.sick = Some(sick);
        // The wait doubles from the poll interval (20 ms) to a second within about 1.3 s.
        b.run_for(2 * SECOND, None);
        assert_eq!(b.core.backoff(), Some(BACKOFF_MAX), "{sick:?}");
        let from = b.now;
        b.run_for(10 * SECOND, None);
        let sent = requests_between(&b, from, b.now);
        assert!(
            sent <= 11,
            "{sick:?}: {sent} requests in 10 s to a device answering badly"
        );
        let said = health_lines(&b, fell_ill);
        assert_eq!(said.len(), 1, "{sick:?}: said once: {said:?}");
        assert!(
            said[0].starts_with("sim - backing off: 3 bad replies in a row"),
            "{sick:?}: {said:?}"
        );
        // Healed: the next request, at most a second later, answers well and the pace is
        // back; the health line says so once a whole round answered.
        b.sick = None;
        let healed = b.now;
        assert!(
            b.run_until(2 * SECOND, |b| b.core.backoff().is_none()),
            "{sick:?}"
        );
        let took = b.now - healed;
        assert!(
            took <= BACKOFF_MAX + Duration::from_millis(100),
            "{sick:?}: paced again after {took:?}"
        );
        assert_eq!(health_lines(&b, healed), ["sim"], "{sick:?}");
        let from = b.now;
        b.run_for(SECOND, None);
        let sent = requests_between(&b, from, b.now);
        // Still axes: a round of three reads every 250 ms.
        assert!((9..=15).contains(&sent), "{sick:?}: {sent} requests in 1 s");
        assert!(b.core.last_status(axis(0)).is_some());
    }
}

#[test]
fn an_owed_stop_is_never_held_back_by_the_back_off() {
    let mut b = Bench::enabled();
    b.send(axis(0), move_by(100.0, RelativeTo::Command));
    b.run_for(Duration::from_millis(300), None);
    b.sick = Some(Sick::Exceptions);
    b.run_for(2 * SECOND, None);
    assert_eq!(b.core.backoff(), Some(BACKOFF_MAX));
    // Just after a bad reply: the next request waits a second, STOP does not.
    assert!(b.run_until(2 * SECOND, |b| b.core.awaits_bytes()));
    b.run_until(SECOND, |b| !b.core.awaits_bytes());
    let asked = b.now;
    b.request(RmcRequest::StopAll);
    b.run_for(Duration::from_millis(5), None);
    let stop_at = b.wire.iter().find_map(|(at, r)| match r {
        crate::rmc::modbus::Request::Write { address, words }
            if *at >= asked
                && *address == axis(0).command_block()
                && matches!(Command::from_block(words), Ok((Command::Stop { .. }, _))) =>
        {
            Some(*at)
        }
        _ => None,
    });
    assert_eq!(stop_at, Some(asked), "Stop (6) written at once");
}
