//! Captures on the simulated RMC151, driven by the RMC link core on a virtual clock: the
//! pre-trigger, the move's start and end, and the summary against the simulator's own
//! profile run alongside.

use std::time::Duration;

use super::capture::CaptureSettings;
use super::polled::{Polled, rmc_channel};
use crate::rmc::link::RmcEvent;
use crate::rmc::link::harness::{Bench, axis};
use crate::rmc::{Command, MoveRelative};
use crate::robot::RelativeTo;

/// A fast move with a sharp stop: Actual lags Target by about 2 pu when the target
/// generator ends (the simulator's 10 ms follower), so settling into the 0.05 pu
/// tolerance takes tens of milliseconds.
const MOVE: MoveRelative = MoveRelative {
    distance: 50.0,
    speed: 200.0,
    accel: 2000.0,
    decel: 20000.0,
    relative_to: RelativeTo::Command,
};

/// The bench's events from `from` on, into the store and the captures as the pendant
/// takes them.
fn feed(b: &Bench, polled: &mut Polled, from: usize) -> usize {
    for (_, e) in &b.events[from..] {
        match e {
            RmcEvent::Status {
                axis, status, at, ..
            } => polled.rmc_status(*at, *axis, status),
            RmcEvent::Sent {
                axis, command, at, ..
            } if command.moves() => polled.rmc_moved(*at, *axis, command),
            _ => {}
        }
    }
    b.events.len()
}

#[test]
fn a_step_is_captured_from_before_its_command_with_a_summary_matching_the_profile() {
    let mut b = Bench::enabled();
    let mut polled = Polled::new(1);
    polled.captures.settings = CaptureSettings::default();
    let mut seen = feed(&b, &mut polled, 0);
    b.run_for(Duration::from_secs(1), None);
    seen = feed(&b, &mut polled, seen);

    // The simulator's own run of the move, loop by loop, from the moment it takes it.
    let mut twin = b.sim.clone();
    let sent_at = b.now;
    assert!(twin.command(axis(0), Command::MoveRelative(MOVE)));
    let truth: Vec<_> = (1..=4000u32)
        .map(|ms| {
            let t = sent_at + Duration::from_millis(u64::from(ms));
            twin.advance(t);
            (f64::from(ms) / 1000.0, twin.status(axis(0)).unwrap())
        })
        .collect();
    let done_s = truth
        .iter()
        .find(|(_, s)| s.bits.tg_done() && s.target_position == s.command_position)
        .map(|(t, _)| *t)
        .unwrap();
    let in_position_s = truth
        .iter()
        .rev()
        .take_while(|(_, s)| s.bits.in_position())
        .last()
        .map(|(t, _)| *t)
        .unwrap();

    b.send(axis(0), Command::MoveRelative(MOVE));
    b.run_for(Duration::from_secs(4), None);
    feed(&b, &mut polled, seen);
    polled.poll_captures(b.now);
    let c = polled.captures.list.front().expect("a capture");
    assert_eq!(c.label, "Axis 1: Move Relative 50 relative to command");

    // It starts before the command: the pre-trigger share of its length.
    let (pre, post) = polled.captures.settings.spans();
    let poll = b.core_poll_interval().as_secs_f64() + 0.002;
    assert!(
        c.times[0] < 0.0 && c.times[0] >= -pre.as_secs_f64(),
        "{}",
        c.times[0]
    );
    // The axis stood before the command: its rounds came at the idle interval then.
    let idle_poll = b.core_idle_poll_interval().as_secs_f64() + 0.002;
    assert!(c.times[0] <= -pre.as_secs_f64() + idle_poll);
    assert!(*c.times.last().unwrap() <= post.as_secs_f64());
    // Its channels hold the move's start and end positions.
    let command = &c.values[rmc_channel::COMMAND_POSITION];
    let actual = &c.values[rmc_channel::ACTUAL_POSITION];
    assert!((command[0] - 0.0).abs() < 0.001 && (actual[0] - 0.0).abs() < 0.001);
    assert!((command.last().unwrap() - 50.0).abs() < 0.001);
    assert!((actual.last().unwrap() - 50.0).abs() < 0.001);

    // The summary, read from polled samples, lies within a poll of the profile's truth.
    let s = c.summary;
    let duration = s.duration.expect("the target generator finished");
    assert!(
        duration >= done_s - 0.001 && duration <= done_s + poll,
        "duration {duration} s, profile {done_s} s"
    );
    let settling = s.settling.expect("in position");
    let true_settling = in_position_s - done_s;
    assert!(
        (settling - true_settling).abs() <= poll,
        "settling {settling} s, profile {true_settling} s"
    );
    let (_, end) = truth.last().unwrap();
    let true_error = f64::from(end.command_position - end.actual_position);
    assert!(
        (s.final_error.unwrap() - true_error).abs() < 0.001,
        "final error {:?}, profile {true_error}",
        s.final_error
    );
    assert!((s.start - 0.0).abs() < 0.001 && (s.end - 50.0).abs() < 0.001);
    assert!(
        true_settling > 0.02,
        "the profile takes time to settle: {true_settling} s"
    );
    // A first-order follower does not pass its end.
    assert!(s.overshoot.unwrap() < 0.001);
}

#[test]
fn a_held_jog_is_one_capture_and_a_quiet_device_still_gives_what_it_has() {
    let mut b = Bench::enabled();
    let mut polled = Polled::new(1);
    let mut seen = feed(&b, &mut polled, 0);
    for _ in 0..3 {
        b.send(
            axis(0),
            Command::MoveRelative(MoveRelative {
                distance: 1.0,
                ..MOVE
            }),
        );
        b.run_for(Duration::from_millis(100), None);
    }
    seen = feed(&b, &mut polled, seen);
    assert!(polled.captures.waiting());
    polled.poll_captures(b.now);
    assert!(polled.captures.list.is_empty(), "not yet polled to its end");
    // The device goes quiet: a second past the capture's end it is taken as it is.
    let _ = seen;
    let later = b.now + Duration::from_secs(5);
    polled.poll_captures(later);
    assert_eq!(polled.captures.list.len(), 1, "three moves in one capture");
    assert!(!polled.captures.waiting());
}

#[test]
fn a_saved_capture_reads_back_exactly_and_a_damaged_one_is_named_by_line() {
    use super::csv::{read_capture, write_capture};
    let mut b = Bench::enabled();
    let mut polled = Polled::new(1);
    let seen = feed(&b, &mut polled, 0);
    b.send(axis(0), Command::MoveRelative(MOVE));
    b.run_for(Duration::from_secs(4), None);
    feed(&b, &mut polled, seen);
    polled.poll_captures(b.now);
    let c = polled.captures.list.front().unwrap();
    let mut file = Vec::new();
    write_capture(&mut file, c).unwrap();
    let back = read_capture(file.as_slice()).unwrap();
    assert_eq!(back.label, c.label);
    assert_eq!(back.channels, c.channels);
    assert_eq!(back.roles, c.roles);
    assert_eq!(back.values, c.values, "every value exactly as polled");
    for (a, b) in back.times.iter().zip(&c.times) {
        assert!((a - b).abs() < 1e-9);
    }
    assert_eq!(back.summary.final_error, c.summary.final_error);
    assert_eq!(
        back.summary.settling.is_some(),
        c.summary.settling.is_some()
    );

    let text = String::from_utf8(file).unwrap();
    let damaged = text.replacen("\n0.", "\nzero.", 1);
    let why = read_capture(damaged.as_bytes()).unwrap_err();
    assert!(
        why.starts_with("line ") && why.contains("not a number"),
        "{why}"
    );
    assert!(
        read_capture(&b"time_s,x\n"[..])
            .unwrap_err()
            .contains("not an xsel-pendant capture")
    );
}

/// A plotted signal rides along in a move's capture: its value as last read at each of
/// the capture's samples, saved and read back with the rest.
#[test]
fn a_plotted_signal_is_held_beside_a_captured_move_and_saved_with_it() {
    use crate::pendant::signals::{Signal, SignalKind, SignalSample};
    let t0 = std::time::Instant::now();
    let ms = |n: u64| t0 + Duration::from_millis(n);
    let mut polled = Polled::new(0);
    polled.captures.settings = CaptureSettings::default();
    let sensor = |at, on: bool| SignalSample {
        at,
        signal: Signal::new(SignalKind::Input, 0, 4),
        label: "Input 4".into(),
        value: f64::from(u8::from(on)),
        bit: true,
    };
    polled.signal_samples(vec![sensor(ms(0), false)]);
    for n in 0..60u64 {
        polled.xsel_work(
            ms(n * 100),
            [i32::try_from(n).unwrap() * 1000, 0, 0, 0],
            false,
            1,
        );
        if n == 20 {
            polled.signal_samples(vec![sensor(ms(2_000), true)]);
        }
    }
    polled.xsel_moved(ms(1_000), "X+ 50".into(), 0);
    polled.poll_captures(ms(6_000));
    let c = polled.captures.list.front().expect("a capture");
    let i = c
        .channel_named("Input 4 state")
        .expect("the signal's channel");
    let at = |t: f64| c.times.iter().position(|x| (*x - t).abs() < 1e-6).unwrap();
    assert_eq!(c.values[i][at(0.5)], 0.0);
    assert_eq!(c.values[i][at(1.0)], 1.0);
    assert!(c.channels[i].step);
    let mut file = Vec::new();
    super::csv::write_capture(&mut file, c).unwrap();
    let back = super::csv::read_capture(std::io::Cursor::new(file)).unwrap();
    assert_eq!(back.values[i], c.values[i]);
    assert_eq!(back.channels[i].name, c.channels[i].name);
}
