//! The guardian's rules on a virtual clock: when it owes 238H, that it waits for the
//! reply in flight, holds the window's frames behind its own, stops once per silence, is
//! answered only by its answer whatever noise the line carries, and stays bounded.

use std::time::{Duration, Instant};

use super::*;
use crate::link::format_b::safety::stop_all;
use crate::protocol::{
    Axis, AxisPattern, CentiG, Command, Direction, Jog, JogFrame, JogMotion, MmPerSec, Reply,
    ScMode, checksum,
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
    reply_with(id, "")
}

/// A reply to the message `id` carrying `data`.
fn reply_with(id: &str, data: &str) -> Vec<u8> {
    with_sc(&format!("#99{id}{data}"))
}

/// `body` with its SC and CR LF.
fn with_sc(body: &str) -> Vec<u8> {
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
    let answer = reply_with("215", "000000000000000");
    let (half, rest) = answer.split_at(6);
    g.handle_line_bytes(half);
    assert_eq!(
        g.poll_transmit(t0 + ms(102)),
        None,
        "half a reply is no reply"
    );
    g.handle_line_bytes(rest);
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

/// Junk lines as a noisy bridge delivers them: CR LF lines without a header, and lines
/// whose header is followed by junk.
fn junk(n: usize) -> Vec<u8> {
    let mut out = Vec::new();
    for i in 0..n {
        out.extend_from_slice(b"JJJJJJJJJJJJJJJJJJJJJJJJJJJJJJ\r\n");
        if i % 7 == 0 {
            out.extend_from_slice(b"#99JUNK\r\n&\r\n!99\r\n");
        }
    }
    out
}

fn log_of(g: &mut GuardianCore) -> Vec<String> {
    std::iter::from_fn(|| g.poll_log()).collect()
}

#[test]
fn junk_crlf_lines_and_other_frames_do_not_answer_the_guardians_238h() {
    let t0 = Instant::now();
    let mut g = core(t0);
    jogging(&mut g, t0);
    g.handle_window_closed(t0 + ms(10));
    assert_eq!(g.poll_transmit(t0 + ms(10)), Some(stop_frame()));
    g.handle_line_bytes(&junk(50));
    // A late reply of another message, another station's 238 answer, a damaged 238.
    g.handle_line_bytes(&reply_with("215", "000000000000000"));
    g.handle_line_bytes(&with_sc("#98238"));
    g.handle_line_bytes(b"#9923833\r\n");
    assert!(!g.is_done(), "none of these is the answer");
    assert!(g.motion_may_run());
    assert_eq!(g.poll_transmit(t0 + ms(20)), None, "its STOP is still out");
    g.handle_line_bytes(&reply("238"));
    assert!(g.is_done());
    assert!(!g.motion_may_run());
    let log = log_of(&mut g);
    assert!(log.iter().any(|l| l.contains("238H answered")), "{log:?}");
    assert!(!log.iter().any(|l| l.contains("JJJ")), "{log:?}");
}

#[test]
fn an_error_frame_answers_the_guardians_238h_and_it_is_sent_again() {
    let t0 = Instant::now();
    let mut g = core(t0);
    jogging(&mut g, t0);
    g.handle_window_closed(t0);
    assert_eq!(g.poll_transmit(t0), Some(stop_frame()));
    g.handle_line_bytes(&with_sc("&99C74"));
    assert!(g.motion_may_run(), "a refusal stops nothing");
    assert_eq!(
        g.poll_transmit(t0 + ms(1)),
        Some(stop_frame()),
        "sent again"
    );
    g.handle_line_bytes(&with_sc("&99C74"));
    assert_eq!(g.poll_transmit(t0 + ms(2)), None, "two tries");
    assert!(g.is_done());
    let log = log_of(&mut g);
    assert!(
        log.iter()
            .any(|l| l.contains("refused") && l.contains("motion may still run")),
        "{log:?}"
    );
}

#[test]
fn line_noise_neither_ends_the_windows_transaction_nor_lets_the_stop_overlap_it() {
    let t0 = Instant::now();
    let mut g = core(t0);
    jogging(&mut g, t0);
    g.handle_window_bytes(t0 + ms(100), &status_query());
    assert_eq!(g.poll_transmit(t0 + ms(100)), Some(status_query()));
    g.handle_window_closed(t0 + ms(101));
    for step in 0..20 {
        g.handle_line_bytes(&junk(3));
        let now = t0 + ms(102 + step);
        g.handle_timeout(now);
        assert_eq!(
            g.poll_transmit(now),
            None,
            "the poll is still on the line: no STOP over it"
        );
    }
    // Its answer, inside a burst of noise: then the STOP, at once.
    let mut burst = junk(2);
    burst.extend_from_slice(&reply_with("215", "000000000000000"));
    burst.extend_from_slice(&junk(2));
    g.handle_line_bytes(&burst);
    assert_eq!(g.poll_transmit(t0 + ms(130)), Some(stop_frame()));

    // Noise on a living window: its transaction ends with its answer only, and the answer
    // reaches it whole.
    let mut g = core(t0);
    jogging(&mut g, t0);
    g.handle_window_bytes(t0 + ms(10), &status_query());
    assert_eq!(g.poll_transmit(t0 + ms(10)), Some(status_query()));
    g.handle_window_bytes(t0 + ms(11), &stop_frame());
    g.handle_line_bytes(&junk(5));
    assert_eq!(
        g.poll_transmit(t0 + ms(12)),
        None,
        "one outstanding command"
    );
    let answer = reply_with("215", "000000000000000");
    g.handle_line_bytes(&answer);
    let relayed: Vec<u8> = std::iter::from_fn(|| g.poll_to_window())
        .flat_map(|m| match m {
            FromGuardian::Bytes(b) => b,
            other => panic!("{other:?}"),
        })
        .collect();
    assert!(relayed.ends_with(&answer), "the answer comes last, whole");
    assert_eq!(g.poll_transmit(t0 + ms(13)), Some(stop_frame()));
}

/// A controller on the virtual clock: it answers each frame `delay` after it went out
/// (238H and 236H with an acknowledge, 215H with status).
fn answer_of(frame: &[u8]) -> Vec<u8> {
    match &frame[3..6] {
        b"215" => reply_with("215", "000000000000000"),
        id => reply(std::str::from_utf8(id).unwrap()),
    }
}

#[test]
fn a_stopped_window_with_line_noise_gets_its_stop_within_the_lease_plus_one_transaction() {
    // The window jogs and polls every 100 ms; a query is on the line when it is stopped
    // (kill -STOP): no heartbeat, no reading. The line carries 2 MB/s of junk lines.
    let t0 = Instant::now();
    let delay = ms(20);
    let mut g = core(t0);
    jogging(&mut g, t0);
    let mut answer_at: Option<(Instant, Vec<u8>)> = None;
    let mut last_heard = t0;
    let mut stop_at = None;
    let stopped_at = t0 + ms(1_000);
    let mut now = t0;
    let one_ms_of_junk = junk(64); // about 2 KB
    while now < t0 + ms(3_000) {
        now += ms(1);
        let window_runs = now < stopped_at;
        if window_runs {
            if (now - t0).as_millis().is_multiple_of(50) {
                g.handle_heartbeat(now);
                last_heard = now;
            }
            if (now - t0).as_millis() % 100 == 99 {
                g.handle_window_bytes(now, &status_query());
                last_heard = now;
            }
            while g.poll_for_window().is_some() {}
        }
        g.handle_line_bytes(&one_ms_of_junk);
        if let Some((at, bytes)) = answer_at.take() {
            if now >= at {
                g.handle_line_bytes(&bytes);
            } else {
                answer_at = Some((at, bytes));
            }
        }
        g.handle_timeout(now);
        if let Some(frame) = g.poll_transmit(now) {
            if frame == stop_frame() && stop_at.is_none() {
                stop_at = Some(now);
            }
            answer_at = Some((now + delay, answer_of(&frame)));
        }
        assert!(
            g.buffered() <= WINDOW_BYTES_MAX + 4 * MAX_FRAME_LEN,
            "{} bytes held at {:?}",
            g.buffered(),
            now - t0
        );
    }
    let stop_at = stop_at.expect("a STOP");
    // One transaction: the longest a query on the line may keep the STOP waiting.
    let transaction = Timing::default().reply_timeout(status_query().len(), 25);
    assert!(
        stop_at <= last_heard + LEASE + transaction,
        "STOP {:?} after the last beat",
        stop_at - last_heard
    );
    assert!(
        stop_at >= last_heard + LEASE,
        "not before the lease ran out"
    );
    assert!(
        !g.motion_may_run(),
        "the STOP was answered through the noise"
    );
    assert!(
        g.dropped_for_window() > 0,
        "the stopped window's bytes were dropped"
    );
}

#[test]
fn the_cores_memory_stays_bounded_under_a_flood_and_the_windows_answer_is_kept() {
    let t0 = Instant::now();
    let mut g = core(t0);
    jogging(&mut g, t0);
    g.handle_window_bytes(t0, &status_query());
    assert_eq!(g.poll_transmit(t0), Some(status_query()));
    // 8 MB of junk: lines, headers without an end, runs without any line end.
    let mut chunk = junk(64);
    chunk.extend_from_slice(b"#99215");
    chunk.extend_from_slice(&[b'Z'; 1500]);
    chunk.extend_from_slice(b"!");
    let mut most = 0;
    let mut fed = 0;
    while fed < 8_000_000 {
        g.handle_line_bytes(&chunk);
        fed += chunk.len();
        most = most.max(g.buffered());
    }
    let bound = WINDOW_BYTES_MAX + 4 * MAX_FRAME_LEN;
    assert!(most <= bound, "{most} bytes held (bound {bound})");
    assert!(g.dropped_for_window() > 7_000_000);
    // The window's answer goes through a full queue.
    let answer = reply_with("215", "000000000000000");
    g.handle_line_bytes(&answer);
    let kept = std::iter::from_fn(|| g.poll_for_window())
        .filter(|m| !m.droppable)
        .map(|m| m.message)
        .collect::<Vec<_>>();
    assert_eq!(kept, vec![FromGuardian::Bytes(answer)]);
    assert!(g.buffered() < MAX_FRAME_LEN + 64);
}

#[test]
fn motion_the_window_sends_while_the_stop_is_owed_is_not_sent() {
    let t0 = Instant::now();
    let mut g = core(t0);
    jogging(&mut g, t0);
    g.handle_window_bytes(t0 + ms(10), &status_query());
    assert_eq!(g.poll_transmit(t0 + ms(10)), Some(status_query()));
    let lapse = t0 + ms(11) + LEASE;
    g.handle_timeout(lapse);
    // The window wakes: a jog and a query, sent before it heard of the STOP.
    g.handle_window_bytes(lapse + ms(1), &jog());
    g.handle_window_bytes(lapse + ms(1), &status_query());
    g.handle_line_bytes(&reply_with("215", "000000000000000"));
    assert_eq!(g.poll_transmit(lapse + ms(2)), Some(stop_frame()));
    g.handle_line_bytes(&reply("238"));
    assert_eq!(g.poll_transmit(lapse + ms(3)), Some(status_query()));
    g.handle_line_bytes(&reply_with("215", "000000000000000"));
    assert_eq!(g.poll_transmit(lapse + ms(4)), None, "the jog is not sent");
    assert!(!g.motion_may_run());
    let log = log_of(&mut g);
    assert!(log.iter().any(|l| l.contains("STOP came first")), "{log:?}");
    // After the STOP is answered, the window's new jog goes out.
    g.handle_window_bytes(lapse + ms(5), &jog());
    assert_eq!(g.poll_transmit(lapse + ms(5)), Some(jog()));
}

#[test]
fn the_log_says_how_the_window_went() {
    let t0 = Instant::now();
    let mut g = core(t0);
    jogging(&mut g, t0);
    g.handle_window_gone(t0, WindowGone::LetGo);
    let log = log_of(&mut g);
    assert!(
        log.iter()
            .any(|l| l.contains("let go of the line") && !l.contains("process ended")),
        "{log:?}"
    );
    let mut g = core(t0);
    jogging(&mut g, t0);
    g.handle_window_gone(t0, WindowGone::Ended);
    let log = log_of(&mut g);
    assert!(log.iter().any(|l| l.contains("process ended")), "{log:?}");
}

fn program_run() -> Vec<u8> {
    with_sc("!9925301")
}

fn end_all() -> Vec<u8> {
    with_sc("!9925400")
}

/// The window runs program 1 and gets its reply: a program may run.
fn program_running(g: &mut GuardianCore, now: Instant) {
    g.handle_window_bytes(now, &program_run());
    assert_eq!(g.poll_transmit(now), Some(program_run()));
    g.handle_line_bytes(&reply("253"));
    assert_eq!(g.poll_to_window(), Some(FromGuardian::Bytes(reply("253"))));
    assert!(g.motion_may_run(), "a program run is motion");
}

#[test]
fn a_window_killed_while_a_program_runs_gets_238h_254h_00_and_238h_again() {
    let t0 = Instant::now();
    let mut g = core(t0);
    program_running(&mut g, t0);
    g.handle_window_closed(t0 + ms(30));
    assert_eq!(g.poll_transmit(t0 + ms(30)), Some(stop_frame()));
    g.handle_line_bytes(&reply("238"));
    assert!(!g.is_done(), "the programs are still to end");
    assert_eq!(g.poll_transmit(t0 + ms(31)), Some(end_all()));
    assert_eq!(g.poll_transmit(t0 + ms(31)), None, "one outstanding");
    g.handle_line_bytes(&reply("254"));
    assert!(!g.is_done());
    assert_eq!(g.poll_transmit(t0 + ms(32)), Some(stop_frame()));
    g.handle_line_bytes(&reply("238"));
    assert!(g.is_done());
    assert_eq!(g.poll_transmit(t0 + ms(33)), None, "nothing more");
    let log: Vec<String> = std::iter::from_fn(|| g.poll_log()).collect();
    assert!(
        log.iter().any(|l| l.contains("every program ended")),
        "{log:?}"
    );
}

#[test]
fn a_refused_or_unanswered_254h_is_tried_once_and_the_arm_stopped_again() {
    let t0 = Instant::now();
    let mut g = core(t0);
    program_running(&mut g, t0);
    g.handle_window_closed(t0 + ms(30));
    assert_eq!(g.poll_transmit(t0 + ms(30)), Some(stop_frame()));
    g.handle_line_bytes(&reply("238"));
    assert_eq!(g.poll_transmit(t0 + ms(31)), Some(end_all()));
    let deadline = g.poll_timeout().expect("the 254H's deadline");
    g.handle_timeout(deadline);
    assert_eq!(g.poll_transmit(deadline), Some(stop_frame()));
    g.handle_line_bytes(&reply("238"));
    assert!(g.is_done(), "one 254H per STOP, whatever its answer");
    assert_eq!(g.poll_transmit(deadline + ms(1)), None);
}

#[test]
fn a_status_saying_no_program_runs_spares_the_254h() {
    let t0 = Instant::now();
    let mut g = core(t0);
    program_running(&mut g, t0);
    // The program ended by itself; the window's status poll says so.
    g.handle_window_bytes(t0 + ms(5), &status_query());
    assert_eq!(g.poll_transmit(t0 + ms(5)), Some(status_query()));
    let status = Reply::SystemStatus(crate::protocol::SystemStatus::default())
        .to_bytes(Station::DEFAULT)
        .unwrap();
    g.handle_line_bytes(&status);
    g.handle_window_closed(t0 + ms(30));
    assert_eq!(g.poll_transmit(t0 + ms(30)), Some(stop_frame()));
    g.handle_line_bytes(&reply("238"));
    assert!(g.is_done(), "no program runs: no 254H");
}
