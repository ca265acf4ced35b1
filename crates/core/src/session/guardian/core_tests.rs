//! The guardian's rules on a virtual clock: when it owes 238H, that it waits for the
//! reply in flight, holds the window's frames behind its own, and stops once per silence.

use std::time::{Duration, Instant};

use super::*;
use crate::protocol::{
    Axis, AxisPattern, CentiG, Direction, Jog, JogFrame, JogMotion, MmPerSec, checksum,
};

const LEASE: Duration = Duration::from_millis(250);

fn core(now: Instant) -> GuardianCore {
    GuardianCore::new(now, Station::DEFAULT, LEASE, Timing::default())
}

fn jog() -> Vec<u8> {
    let motion = JogMotion::Cartesian {
        frame: JogFrame::Work,
        acc: CentiG(10),
        dec: CentiG(10),
        speed: MmPerSec(5),
    };
    Command::Jog(Jog::until_stopped(
        AxisPattern::single(Axis::A1),
        Direction::Positive,
        motion,
    ))
    .to_bytes(Station::DEFAULT, ScMode::Computed)
    .unwrap()
}

fn status_query() -> Vec<u8> {
    Command::SystemStatus
        .to_bytes(Station::DEFAULT, ScMode::Computed)
        .unwrap()
}

fn stop_frame() -> Vec<u8> {
    Command::Stop(stop_all())
        .to_bytes(Station::DEFAULT, ScMode::Computed)
        .unwrap()
}

/// A reply with no data to the message `id` (3 hex digits).
fn reply(id: &str) -> Vec<u8> {
    let body = format!("#99{id}");
    let sc = checksum(body.as_bytes());
    format!("{body}{sc:02X}\r\n").into_bytes()
}

fn ms(n: u64) -> Duration {
    Duration::from_millis(n)
}

/// The window sends a continuous jog and gets its reply.
fn jogging(g: &mut GuardianCore, now: Instant) {
    g.handle_window_bytes(now, &jog());
    assert_eq!(g.poll_transmit(now), Some(jog()), "the jog is relayed");
    g.handle_line_bytes(&reply("236"));
    assert_eq!(
        g.poll_to_window(),
        Some(FromGuardian::Bytes(reply("236"))),
        "its reply goes back"
    );
    assert!(g.motion_may_run());
}

#[test]
fn a_window_killed_mid_jog_gets_one_238h_and_the_guardian_is_done_once_answered() {
    let t0 = Instant::now();
    let mut g = core(t0);
    jogging(&mut g, t0);
    g.handle_window_closed(t0 + ms(30));
    assert!(!g.is_done(), "a STOP is owed");
    assert_eq!(g.poll_transmit(t0 + ms(30)), Some(stop_frame()));
    assert_eq!(
        g.poll_transmit(t0 + ms(31)),
        None,
        "one outstanding command"
    );
    g.handle_line_bytes(&reply("238"));
    assert!(!g.motion_may_run());
    assert!(g.is_done());
    let log: Vec<String> = std::iter::from_fn(|| g.poll_log()).collect();
    assert!(log.iter().any(|l| l.contains("closed")), "{log:?}");
    assert!(log.iter().any(|l| l.contains("238H answered")), "{log:?}");
}

#[test]
fn the_stop_waits_for_the_reply_in_flight_or_its_deadline() {
    let t0 = Instant::now();
    let mut g = core(t0);
    jogging(&mut g, t0);
    // A status poll is on the line when the window dies.
    g.handle_window_bytes(t0 + ms(100), &status_query());
    assert_eq!(g.poll_transmit(t0 + ms(100)), Some(status_query()));
    g.handle_window_closed(t0 + ms(101));
    assert_eq!(
        g.poll_transmit(t0 + ms(101)),
        None,
        "the poll's reply first"
    );
    g.handle_line_bytes(b"#99215");
    assert_eq!(
        g.poll_transmit(t0 + ms(102)),
        None,
        "half a reply is no reply"
    );
    g.handle_line_bytes(b"0000000000000000000000\r\n");
    assert_eq!(g.poll_transmit(t0 + ms(103)), Some(stop_frame()));

    // No reply at all: the STOP goes when the poll's reply can no longer come.
    let mut g = core(t0);
    jogging(&mut g, t0);
    g.handle_window_bytes(t0 + ms(100), &status_query());
    assert_eq!(g.poll_transmit(t0 + ms(100)), Some(status_query()));
    g.handle_window_closed(t0 + ms(101));
    let deadline = g.poll_timeout().expect("a deadline");
    assert!(
        deadline > t0 + ms(101) && deadline < t0 + ms(1000),
        "{deadline:?}"
    );
    g.handle_timeout(deadline);
    assert_eq!(g.poll_transmit(deadline), Some(stop_frame()));
}

#[test]
fn a_silent_window_costs_one_stop_and_its_frames_wait_behind_it() {
    let t0 = Instant::now();
    let mut g = core(t0);
    jogging(&mut g, t0);
    g.handle_heartbeat(t0 + ms(50));
    g.handle_timeout(t0 + ms(49) + LEASE);
    assert_eq!(
        g.poll_transmit(t0 + ms(299)),
        None,
        "within the lease: nothing"
    );
    assert_eq!(g.poll_timeout(), Some(t0 + ms(50) + LEASE));
    let lapse = t0 + ms(51) + LEASE;
    g.handle_timeout(lapse);
    assert_eq!(g.poll_transmit(lapse), Some(stop_frame()));
    assert!(
        matches!(g.poll_to_window(), Some(FromGuardian::Stopped(why)) if why.contains("silent")),
        "the window hears why"
    );
    // The window wakes up and polls while the STOP is out: its frame waits.
    g.handle_window_bytes(lapse + ms(5), &status_query());
    assert_eq!(g.poll_transmit(lapse + ms(5)), None);
    g.handle_line_bytes(&reply("238"));
    assert_eq!(g.poll_to_window(), None, "the guardian's reply is its own");
    assert_eq!(g.poll_transmit(lapse + ms(20)), Some(status_query()));
    assert!(!g.motion_may_run());
    assert!(!g.is_done(), "the window is alive");

    // A second jog and a second silence: a second STOP, but one per silence.
    let t1 = lapse + ms(100);
    g.handle_line_bytes(&reply("215"));
    let _ = g.poll_to_window();
    jogging(&mut g, t1);
    g.handle_timeout(t1 + LEASE + ms(1));
    assert_eq!(g.poll_transmit(t1 + LEASE + ms(1)), Some(stop_frame()));
    g.handle_line_bytes(&reply("238"));
    g.handle_timeout(t1 + LEASE * 4);
    assert_eq!(g.poll_transmit(t1 + LEASE * 4), None);
}

#[test]
fn no_motion_no_stop_and_the_windows_own_stop_counts() {
    let t0 = Instant::now();
    let mut g = core(t0);
    g.handle_window_bytes(t0, &status_query());
    assert_eq!(g.poll_transmit(t0), Some(status_query()));
    g.handle_timeout(t0 + LEASE * 10);
    g.handle_window_closed(t0 + LEASE * 10);
    assert!(g.is_done(), "nothing moved: nothing to stop");
    assert_eq!(g.poll_transmit(t0 + LEASE * 10), None);

    let mut g = core(t0);
    jogging(&mut g, t0);
    g.handle_window_bytes(t0 + ms(10), &stop_frame());
    assert_eq!(g.poll_transmit(t0 + ms(10)), Some(stop_frame()));
    g.handle_line_bytes(&reply("238"));
    assert!(!g.motion_may_run(), "the window stopped it itself");
    g.handle_window_closed(t0 + ms(20));
    assert!(g.is_done());
}

#[test]
fn an_unanswered_stop_is_sent_once_more_then_given_up_on() {
    let t0 = Instant::now();
    let mut g = core(t0);
    jogging(&mut g, t0);
    g.handle_window_closed(t0);
    assert_eq!(g.poll_transmit(t0), Some(stop_frame()));
    let first = g.poll_timeout().expect("its deadline");
    g.handle_timeout(first);
    assert_eq!(g.poll_transmit(first), Some(stop_frame()), "tried again");
    let second = g.poll_timeout().expect("its deadline");
    g.handle_timeout(second);
    assert_eq!(g.poll_transmit(second), None);
    assert!(g.is_done(), "the guardian exits; it said so");
    let log: Vec<String> = std::iter::from_fn(|| g.poll_log()).collect();
    assert!(
        log.iter().any(|l| l.contains("motion may still run")),
        "{log:?}"
    );
}

#[test]
fn frames_are_relayed_whole_and_in_order_however_the_bytes_arrive() {
    let t0 = Instant::now();
    let mut g = core(t0);
    let both = [status_query(), jog()].concat();
    for chunk in both.chunks(3) {
        g.handle_window_bytes(t0, chunk);
    }
    assert_eq!(g.poll_transmit(t0), Some(status_query()));
    g.handle_line_bytes(&reply("215"));
    assert_eq!(g.poll_transmit(t0), Some(jog()));
    assert!(g.motion_may_run());
}
