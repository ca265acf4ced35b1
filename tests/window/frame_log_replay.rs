//! A saved frame log replays into the simulator: the commands of a capture, fed to a
//! fresh simulated controller at their recorded times, bring back the recorded replies
//! byte for byte.

use std::time::Duration;

use xsel_pendant::pendant::frame_log::file::{read_jsonl, write_jsonl};
use xsel_pendant::pendant::frame_log::{Dir, FrameLog};
use xsel_pendant::robot::RobotModel;
use xsel_pendant::sim::{Controller, SimSetup};

use crate::wire::frame as framed;

/// A capture made against one simulator: servo on, home, status reads, a step.
fn capture() -> FrameLog {
    let mut sim = Controller::new(SimSetup::for_model(RobotModel::default_model()));
    let mut log = FrameLog::new(1000);
    let commands = [
        "!99201000",
        "!99215",
        "!99232010",
        "!99232011",
        "!9921201",
        "!99233010000000",
        "!99215",
        "!99212",
    ];
    let mut t = Duration::from_millis(10);
    for (i, c) in commands.iter().cycle().take(40).enumerate() {
        let frame = framed(c);
        log.push_sent(&frame, t.as_nanos() as u64);
        let reply = sim.handle(&frame, t + Duration::from_micros(500));
        if let Some(r) = reply {
            log.push_received(&r, (t + Duration::from_micros(900)).as_nanos() as u64);
        } else {
            log.push_timeout(
                "no reply",
                (t + Duration::from_millis(100)).as_nanos() as u64,
            );
        }
        t += Duration::from_millis(25 + i as u64 % 7);
    }
    log
}

#[test]
fn a_saved_log_replays_into_the_simulator_with_the_same_replies() {
    let log = capture();
    let snap = log.snapshot();
    let mut file = Vec::new();
    write_jsonl(&mut file, snap.origin_wall, snap.rows()).unwrap();
    let opened = read_jsonl(file.as_slice(), 1000).unwrap();
    assert_eq!(opened.len(), log.len());

    let mut sim = Controller::new(SimSetup::for_model(RobotModel::default_model()));
    let mut compared = 0;
    let mut errors = 0;
    for i in 0..opened.len() {
        let row = opened.nth(i).unwrap();
        if row.dir() != Dir::Sent {
            continue;
        }
        let t = Duration::from_nanos(row.t_ns()) + Duration::from_micros(500);
        let replayed = sim.handle(&row.bytes(), t);
        let recorded = opened
            .reply_of(row.seq())
            .and_then(|s| opened.row(s))
            .unwrap();
        match replayed {
            Some(r) => {
                assert_eq!(recorded.dir(), Dir::Received);
                assert_eq!(r, *recorded.bytes(), "row {}: {}", row.seq(), row.ascii());
                errors += usize::from(recorded.is_error_reply());
                compared += 1;
            }
            None => assert_eq!(recorded.dir(), Dir::Timeout),
        }
    }
    assert!(compared >= 30, "only {compared} replies compared");
    // The capture holds accepted commands, not only refusals.
    assert!(
        errors < compared / 2,
        "{errors} of {compared} were error replies"
    );
}
