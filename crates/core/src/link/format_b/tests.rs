//! The link's rules on a virtual clock against the simulator's controller: twins of the
//! threaded scenarios (tests/link_*.rs), each running in milliseconds, the same way
//! every time.

use std::time::Duration;

use super::Control;
use super::harness::{Bench, jog_x, quiet_config, ready_setup, step_x};
use crate::link::core::LinkCore;
use crate::link::event::LinkEvent;
use crate::link::handle::LinkConfig;
use crate::link::reason::{BadInput, LineDownReason, NotSentReason};
use crate::link::request::Origin;
use crate::link::schedule::Polling;
use crate::link::table::TableRequest;
use crate::link::{ShutdownReport, StopOutcome};
use crate::protocol::{AxisPattern, Command, CoordKind, Reply};
use crate::sim::{Fault, FaultSpec};

const LONG: Duration = Duration::from_secs(10);

fn delayed(by: Duration) -> FaultSpec {
    let mut faults = FaultSpec::none().with(Fault::Delay, 1.0);
    faults.delay = by;
    faults
}

fn is_reply_to(id: crate::link::RequestId) -> impl Fn(&LinkEvent) -> bool {
    move |e| matches!(e, LinkEvent::Reply { id: r, .. } if *r == id)
}

fn report(bench: &Bench) -> Option<ShutdownReport> {
    bench.events.iter().rev().find_map(|e| match e {
        LinkEvent::ShutDown(r) => Some(r.clone()),
        _ => None,
    })
}

/// A bench whose simulator runs a continuous jog, acknowledged; the lease is long.
fn jogging() -> Bench {
    let mut bench = Bench::new(
        ready_setup(Duration::from_millis(1)),
        FaultSpec::none(),
        LinkConfig {
            jog_lease: Duration::from_secs(600),
            ..quiet_config()
        },
    );
    bench.settle();
    let jog = bench.submit(jog_x());
    bench
        .run_until(LONG, is_reply_to(jog))
        .expect("jog acknowledged");
    bench.run_for(Duration::from_millis(50));
    assert_ne!(bench.sim.controller.in_use(), 0, "the jog runs");
    bench
}

fn stop_follows_last_jog(bench: &Bench) -> bool {
    let ids = bench.sim.ids_received();
    ids.iter()
        .rposition(|id| id == "236")
        .is_some_and(|jog| ids[jog..].iter().any(|id| id == "238"))
}

#[test]
fn polls_bring_scara_and_system_status_and_each_reply_pairs_with_its_command() {
    let mut bench = Bench::new(
        ready_setup(Duration::from_millis(2)),
        FaultSpec::none(),
        LinkConfig::default(),
    );
    bench.run_for(Duration::from_millis(1_000));
    let polls: Vec<&LinkEvent> = bench
        .events
        .iter()
        .filter(|e| {
            matches!(
                e,
                LinkEvent::Reply {
                    origin: Origin::Poll,
                    ..
                }
            )
        })
        .collect();
    // 100 ms cycles of two polls, from t = 0: 10 cycles in a second.
    assert!((19..=22).contains(&polls.len()), "{}", polls.len());
    for e in polls {
        let LinkEvent::Reply { command, reply, .. } = e else {
            unreachable!()
        };
        match command {
            Command::SystemStatus => assert!(matches!(reply, Reply::SystemStatus(_))),
            _ => assert!(matches!(reply, Reply::ScaraStatus(_)), "{reply:?}"),
        }
    }
    assert!(
        bench
            .events
            .iter()
            .any(|e| matches!(e, LinkEvent::Health(h) if h.replies > 0)),
        "health goes out while the reader keeps up"
    );
}

#[test]
fn a_relative_step_moves_the_simulated_arm_by_exactly_the_step() {
    let mut bench = Bench::quiet();
    let before = bench.sim.controller.tip_work();
    let id = bench.submit(step_x(10_000));
    bench
        .run_until(LONG, is_reply_to(id))
        .expect("acknowledged");
    bench.run_for(Duration::from_secs(3));
    let after = bench.sim.controller.tip_work();
    assert!(
        ((after.x - before.x) - 10.0).abs() < 1e-6,
        "{before:?} -> {after:?}"
    );
}

#[test]
fn a_motion_command_that_times_out_is_never_sent_again_and_status_is_read_instead() {
    let mut config = quiet_config();
    config.timing.margin = Duration::from_millis(200);
    let mut bench = Bench::new(
        ready_setup(Duration::from_millis(1)),
        FaultSpec::none().with(Fault::Drop, 1.0),
        config,
    );
    bench.settle();
    let id = bench.submit(step_x(1_000));
    let at = bench
        .run_until(
            LONG,
            |e| matches!(e, LinkEvent::Timeout { id: t, .. } if *t == id),
        )
        .expect("timed out");
    bench.sim.faults.set_spec(FaultSpec::none());
    let LinkEvent::Timeout {
        retrying, recheck, ..
    } = bench.events[at].clone()
    else {
        unreachable!()
    };
    assert!(!retrying, "motion is never retried");
    let recheck = recheck.expect("a status recheck instead");
    bench
        .run_until(LONG, |e| {
            matches!(e, LinkEvent::Reply { id: r, origin: Origin::Recheck { after }, .. }
                if *after == id && *r == recheck)
        })
        .expect("the recheck was answered");
    let moves = bench.ids_written().iter().filter(|i| *i == "2D5").count();
    assert_eq!(moves, 1, "{:?}", bench.ids_written());
    assert_eq!(bench.sim.controller.counters().motion_received, 1);
}

#[test]
fn a_late_error_reply_is_never_credited_to_the_next_move() {
    let mut config = quiet_config();
    config.timing.margin = Duration::from_millis(20);
    let mut bench = Bench::new(
        ready_setup(Duration::from_millis(1)),
        delayed(Duration::from_millis(120)),
        config,
    );
    bench.settle();
    // Move A is far out of reach: refused with '&', 120 ms late.
    let a = bench.submit(step_x(-2_000_000));
    bench
        .run_until(
            LONG,
            |e| matches!(e, LinkEvent::Timeout { id, .. } if *id == a),
        )
        .expect("move A timed out");
    bench.sim.faults.set_spec(FaultSpec::none());
    // Move B is fine and submitted while A's '&' is on its way.
    let b = bench.submit(step_x(1_000));
    bench
        .run_until(LONG, |e| bench_answers(e, b))
        .expect("B answered");
    assert!(
        matches!(
            bench.answer_to(b),
            Some(LinkEvent::Reply {
                reply: Reply::Ack(_),
                ..
            })
        ),
        "B is acknowledged, never refused with A's error:\n{}",
        bench.story()
    );
    assert!(
        bench.events.iter().any(
            |e| matches!(e, LinkEvent::Reply { origin: Origin::Proof { before }, .. } if *before == b)
        ),
        "a proving query put the line back in step before B:\n{}", bench.story()
    );
    assert_eq!(bench.sim.controller.counters().motion_received, 2);
}

fn bench_answers(e: &LinkEvent, id: crate::link::RequestId) -> bool {
    match e {
        LinkEvent::Reply { id: r, .. }
        | LinkEvent::ErrorReply { id: r, .. }
        | LinkEvent::NotSent { id: r, .. } => *r == id,
        _ => false,
    }
}

#[test]
fn a_stalled_line_stops_a_running_jog_within_one_transaction() {
    let mut bench = jogging();
    bench
        .sim
        .faults
        .set_spec(FaultSpec::none().with(Fault::Drop, 1.0));
    let query = bench.submit(Command::SystemStatus);
    bench
        .run_until(
            LONG,
            |e| matches!(e, LinkEvent::Timeout { id, .. } if *id == query),
        )
        .expect("the query timed out");
    bench.sim.faults.set_spec(FaultSpec::none());
    // The next frame on the line is the STOP, ahead of the query's retry.
    let written = bench.written.len();
    bench
        .run_until(LONG, |e| {
            matches!(
                e,
                LinkEvent::Reply {
                    origin: Origin::SafetyStop,
                    ..
                }
            )
        })
        .expect("the link stopped the jog by itself");
    assert!(
        bench.written[written].1.starts_with(b"!99238"),
        "{:?}",
        bench.ids_written()
    );
    bench.run_for(Duration::from_secs(2));
    assert_eq!(bench.sim.controller.in_use(), 0, "the arm stopped");
}

#[test]
fn a_line_lost_mid_move_is_reported_and_later_commands_are_refused() {
    let mut bench = Bench::new(
        ready_setup(Duration::from_millis(1)),
        FaultSpec::none(),
        LinkConfig::default(),
    );
    bench.settle();
    let id = bench.submit(step_x(-100_000));
    bench
        .run_until(LONG, is_reply_to(id))
        .expect("acknowledged");
    bench.pull_line();
    assert!(
        bench
            .events
            .iter()
            .any(|e| matches!(e, LinkEvent::Disconnected { .. })),
        "{}",
        bench.story()
    );
    let late = bench.submit(step_x(1_000));
    assert!(
        matches!(
            bench.answer_to(late),
            Some(LinkEvent::NotSent {
                reason: NotSentReason::LineDown,
                ..
            })
        ),
        "a move on a dead line is refused at once, not queued"
    );
}

#[test]
fn a_line_lost_while_waiting_for_a_reply_is_interrupted_not_timed_out() {
    let mut config = quiet_config();
    config.timing.margin = Duration::from_secs(5);
    let mut bench = Bench::new(
        ready_setup(Duration::from_millis(1)),
        FaultSpec::none().with(Fault::Drop, 1.0),
        config,
    );
    bench.settle();
    let id = bench.submit(Command::SystemStatus);
    bench.run_for(Duration::from_millis(50));
    bench.pull_line();
    let settled: Vec<&LinkEvent> = bench
        .events
        .iter()
        .filter(|e| {
            matches!(e, LinkEvent::Interrupted { id: s, .. } | LinkEvent::Timeout { id: s, .. }
                if *s == id)
        })
        .collect();
    assert!(
        matches!(settled[..], [LinkEvent::Interrupted { .. }]),
        "{settled:?}"
    );
    let tail: Vec<String> = bench.events.iter().map(LinkEvent::summary).collect();
    assert!(
        matches!(
            bench.events.last(),
            Some(LinkEvent::Disconnected {
                reason: LineDownReason::Closed
            })
        ),
        "{tail:?}"
    );
}

#[test]
fn reconnect_on_request_reopens_the_line_and_polling_resumes() {
    let config = LinkConfig {
        auto_reconnect: false,
        ..LinkConfig::default()
    };
    let mut bench = Bench::new(
        ready_setup(Duration::from_millis(1)),
        FaultSpec::none(),
        config,
    );
    bench.run_for(Duration::from_millis(150));
    bench.control(Control::Reconnect);
    let down = bench
        .run_until(LONG, |e| matches!(e, LinkEvent::Disconnected { .. }))
        .expect("closed");
    assert!(matches!(
        bench.events[down],
        LinkEvent::Disconnected {
            reason: LineDownReason::ReconnectRequested
        }
    ));
    bench
        .run_until(LONG, |e| matches!(e, LinkEvent::Reconnected { .. }))
        .expect("reopened");
    bench
        .run_until(LONG, |e| {
            matches!(
                e,
                LinkEvent::Reply {
                    origin: Origin::Poll,
                    ..
                }
            )
        })
        .expect("polling resumed");
}

#[test]
fn a_line_that_comes_back_is_reopened_by_itself_and_an_open_failure_is_said_once() {
    let config = LinkConfig {
        reconnect_interval: Duration::from_millis(100),
        ..LinkConfig::default()
    };
    let mut bench = Bench::new(
        ready_setup(Duration::from_millis(1)),
        FaultSpec::none(),
        config,
    );
    bench.run_for(Duration::from_millis(150));
    bench.pull_line();
    bench.run_for(Duration::from_millis(1_000));
    let downs = bench
        .events
        .iter()
        .filter(|e| matches!(e, LinkEvent::Disconnected { .. }))
        .count();
    assert_eq!(
        downs,
        2,
        "the loss, then one open failure:\n{}",
        bench.story()
    );
    bench.plug_in();
    let back = bench
        .run_until(Duration::from_millis(150), |e| {
            matches!(e, LinkEvent::Reconnected { .. })
        })
        .expect("reopened within one interval");
    assert!(
        bench.events[back..]
            .iter()
            .all(|e| !matches!(e, LinkEvent::Disconnected { .. }))
    );
    bench
        .run_until(LONG, |e| {
            matches!(
                e,
                LinkEvent::Reply {
                    origin: Origin::Poll,
                    ..
                }
            )
        })
        .expect("polling resumed");
}

#[test]
fn after_the_line_is_lost_mid_jog_the_first_frame_on_the_new_line_is_a_stop() {
    let mut bench = jogging();
    // Another jog in flight when the line goes: it may or may not have run.
    bench
        .sim
        .faults
        .set_spec(FaultSpec::none().with(Fault::Drop, 1.0));
    bench.submit(jog_x());
    bench.run_for(Duration::from_millis(5));
    bench.pull_line();
    bench.sim.faults.set_spec(FaultSpec::none());
    let written = bench.written.len();
    bench.plug_in();
    bench
        .run_until(LONG, |e| matches!(e, LinkEvent::Reconnected { .. }))
        .expect("reopened");
    bench.run_for(Duration::from_millis(50));
    assert!(
        bench.written[written].1.starts_with(b"!99238"),
        "{:?}",
        &bench.ids_written()[written..]
    );
}

#[test]
fn stop_is_the_next_frame_after_the_reply_of_the_poll_in_flight_and_keeps_the_gap() {
    let mut bench = poll_in_flight();
    let from = bench.events.len();
    let stop = bench.stop_all();
    let sent = bench
        .run_until(
            LONG,
            |e| matches!(e, LinkEvent::FrameSent { id, .. } if *id == stop),
        )
        .expect("the STOP went out");
    let between: Vec<&LinkEvent> = bench.events[from..sent]
        .iter()
        .filter(|e| {
            matches!(
                e,
                LinkEvent::FrameSent { .. } | LinkEvent::FrameReceived { .. }
            )
        })
        .collect();
    let [
        LinkEvent::FrameReceived {
            bytes, last_byte, ..
        },
    ] = between[..]
    else {
        panic!(
            "only the poll's reply between the poll and the STOP: {between:?}\n{}",
            bench.story()
        )
    };
    assert!(bytes.starts_with(b"#992A1"));
    let LinkEvent::FrameSent { at, .. } = bench.events[sent] else {
        unreachable!()
    };
    let gap = at - *last_byte;
    assert_eq!(gap, Duration::from_millis(1), "the 1 ms gap, no more");
}

/// A bench at 9600 baud, replies after 150 ms, polling as fast as it may, with a poll
/// on the line.
fn poll_in_flight() -> Bench {
    let mut config = LinkConfig::default();
    config.timing.line.baud = 9_600;
    config.polling.interval = Some(Duration::ZERO);
    let mut bench = Bench::new(
        ready_setup(Duration::from_millis(150)),
        FaultSpec::none(),
        config,
    );
    bench
        .run_until(
            LONG,
            |e| matches!(e, LinkEvent::FrameSent { bytes, .. } if bytes.starts_with(b"!992A1")),
        )
        .expect("a poll went out");
    bench
}

fn stopped_first(bench: &Bench, id: crate::link::RequestId) -> bool {
    bench.events.iter().any(|e| {
        matches!(e, LinkEvent::NotSent { id: n, reason: NotSentReason::StopCameFirst, .. } if *n == id)
    })
}

#[test]
fn a_stop_of_all_axes_refuses_the_motion_still_queued_behind_a_poll() {
    let mut bench = poll_in_flight();
    let from = bench.written.len();
    let step = bench.submit(step_x(10_000));
    let home = bench.submit(Command::Home(crate::protocol::Home {
        axes: AxisPattern::SCARA_1,
        search: crate::protocol::MmPerSec(0),
        creep: crate::protocol::MmPerSec(0),
    }));
    let query = bench.submit(Command::SystemStatus);
    bench.stop_all();
    bench.run_for(Duration::from_secs(2));
    let after: Vec<String> = bench.ids_written()[from..].to_vec();
    assert_eq!(after.first().map(String::as_str), Some("238"), "{after:?}");
    assert!(
        !after.iter().any(|id| id == "2D5" || id == "233"),
        "no motion after the STOP: {after:?}\n{}",
        bench.story()
    );
    assert!(stopped_first(&bench, step) && stopped_first(&bench, home));
    // A query queued before the STOP still goes: only motion is ended.
    assert!(bench.events.iter().any(is_reply_to(query)));
}

#[test]
fn motion_submitted_before_a_stop_that_overtook_it_on_the_way_is_not_sent() {
    let mut bench = poll_in_flight();
    let from = bench.written.len();
    let step = bench.number(step_x(10_000));
    let step_id = step.id;
    bench.stop_all();
    bench.deliver(step);
    let later = bench.submit(step_x(10_000));
    bench.run_for(Duration::from_secs(2));
    let after: Vec<String> = bench.ids_written()[from..].to_vec();
    assert!(stopped_first(&bench, step_id), "{}", bench.story());
    // Motion submitted after the STOP goes out after it, once.
    let moves: Vec<&String> = after.iter().filter(|id| *id == "2D5").collect();
    assert_eq!(moves.len(), 1, "{after:?}");
    let stop_at = after.iter().position(|id| id == "238").expect("STOP sent");
    assert!(after.iter().position(|id| id == "2D5").unwrap() > stop_at);
    assert!(bench.events.iter().any(is_reply_to(later)));
}

#[test]
fn polls_give_way_to_user_commands() {
    let config = LinkConfig {
        polling: Polling {
            interval: Some(Duration::ZERO),
            idle_interval: None,
            commands: vec![Command::SystemStatus],
        },
        ..LinkConfig::default()
    };
    let mut bench = Bench::new(
        ready_setup(Duration::from_millis(1)),
        FaultSpec::none(),
        config,
    );
    bench.run_for(Duration::from_millis(20));
    let from = bench.written.len();
    bench.submit(Command::AlarmReset);
    bench.run_for(Duration::from_millis(20));
    let next: Vec<String> = bench.ids_written()[from..].to_vec();
    // At most the poll in flight was written after the submission, before it.
    assert!(next.iter().take(2).any(|id| id == "252"), "{next:?}");
}

fn tool_table(first: u16, records: u16) -> TableRequest {
    TableRequest {
        kind: CoordKind::Tool,
        axes: AxisPattern::SCARA_1,
        first,
        records,
        reply_buffer: 2048,
    }
}

fn assert_tool_table_matches(
    bench: &Bench,
    records: &[Option<crate::protocol::PerAxis<crate::protocol::Milli>>],
) {
    let expected = bench.sim.controller.coords().tool.entries().to_vec();
    assert_eq!(records.len(), expected.len());
    for (n, (got, want)) in records.iter().zip(&expected).enumerate() {
        let got: Vec<i32> = got
            .expect("record present")
            .iter()
            .map(|(_, v)| v.0)
            .collect();
        assert_eq!(got, want.to_wire(), "tool {n}");
    }
}

#[test]
fn a_whole_tool_table_downloads_in_buffer_sized_chunks() {
    let mut bench = Bench::quiet();
    bench.control(Control::DownloadTable(tool_table(0, 128)));
    let done = bench
        .run_until(LONG, |e| matches!(e, LinkEvent::TableDone { .. }))
        .expect("done");
    let LinkEvent::TableDone {
        records, missing, ..
    } = bench.events[done].clone()
    else {
        unreachable!()
    };
    assert!(missing.is_empty(), "{missing:?}");
    let chunks = bench.ids_written().iter().filter(|i| *i == "2A4").count();
    assert_eq!(chunks, 3, "63 + 63 + 2 records");
    assert_tool_table_matches(&bench, &records);
}

#[test]
fn a_download_replaced_midway_keeps_its_records_apart() {
    let mut bench = Bench::new(
        ready_setup(Duration::from_millis(5)),
        FaultSpec::none(),
        quiet_config(),
    );
    bench.settle();
    bench.control(Control::DownloadTable(TableRequest {
        kind: CoordKind::Work,
        ..tool_table(0, 32)
    }));
    bench.control(Control::DownloadTable(tool_table(0, 128)));
    let first = bench
        .run_until(LONG, |e| matches!(e, LinkEvent::TableDone { .. }))
        .expect("the first download was reported");
    assert!(matches!(
        bench.events[first],
        LinkEvent::TableDone {
            kind: CoordKind::Work,
            ..
        }
    ));
    let second = bench
        .run_until(LONG, |e| matches!(e, LinkEvent::TableDone { .. }))
        .expect("the tool table");
    let LinkEvent::TableDone {
        kind: CoordKind::Tool,
        records,
        missing,
        ..
    } = bench.events[second].clone()
    else {
        panic!("{:?}", bench.events[second])
    };
    assert!(missing.is_empty());
    assert_tool_table_matches(&bench, &records);
}

#[test]
fn a_table_that_cannot_be_read_names_the_missing_records_after_two_retries() {
    let mut config = quiet_config();
    config.timing.margin = Duration::from_millis(20);
    let mut bench = Bench::new(
        ready_setup(Duration::from_millis(1)),
        FaultSpec::none().with(Fault::Drop, 1.0),
        config,
    );
    bench.settle();
    bench.control(Control::DownloadTable(TableRequest {
        kind: CoordKind::Work,
        ..tool_table(0, 32)
    }));
    let done = bench
        .run_until(LONG, |e| matches!(e, LinkEvent::TableDone { .. }))
        .expect("done");
    let LinkEvent::TableDone { missing, .. } = &bench.events[done] else {
        unreachable!()
    };
    assert_eq!(missing.len(), 1);
    assert_eq!(missing[0], 0..32);
    assert_eq!(
        bench.ids_written().iter().filter(|i| *i == "2A4").count(),
        3
    );
}

#[test]
fn a_close_mid_jog_stops_the_arm_and_reports_it_clean() {
    let mut bench = jogging();
    bench.close();
    bench.run_for(LONG);
    assert!(bench.core.is_closed());
    let report = report(&bench).expect("the report is the last event");
    assert!(matches!(bench.events.last(), Some(LinkEvent::ShutDown(_))));
    assert_eq!(report.stops.len(), 1, "{report:?}");
    assert_eq!(report.stops[0].1, StopOutcome::Acknowledged);
    assert!(report.is_clean(), "{report}");
    assert!(stop_follows_last_jog(&bench));
    assert_eq!(bench.sim.controller.in_use(), 0);
}

#[test]
fn a_close_right_after_stop_all_sends_that_stop_and_no_second() {
    let mut bench = jogging();
    let stop = bench.stop_all();
    bench.close();
    bench.run_for(LONG);
    assert!(matches!(
        bench.answer_to(stop),
        Some(LinkEvent::Reply { .. })
    ));
    let report = report(&bench).expect("report");
    assert!(report.is_clean(), "{report}");
    let ids = bench.sim.ids_received();
    assert_eq!(ids.iter().filter(|i| *i == "238").count(), 1, "{ids:?}");
    assert_eq!(ids.last().map(String::as_str), Some("238"));
}

#[test]
fn a_close_with_the_jog_on_the_line_waits_for_its_answer_then_stops_it() {
    let mut bench = Bench::new(
        ready_setup(Duration::from_millis(30)),
        FaultSpec::none(),
        LinkConfig {
            jog_lease: Duration::from_secs(600),
            ..quiet_config()
        },
    );
    bench.settle();
    let jog = bench.submit(jog_x());
    assert!(
        bench
            .written
            .last()
            .is_some_and(|(_, f)| f.starts_with(b"!99236"))
    );
    bench.close();
    bench.run_for(LONG);
    assert!(matches!(
        bench.answer_to(jog),
        Some(LinkEvent::Reply { .. })
    ));
    let report = report(&bench).expect("report");
    assert!(report.is_clean(), "{report}");
    assert!(stop_follows_last_jog(&bench));
    assert_eq!(bench.sim.controller.in_use(), 0);
}

#[test]
fn a_close_with_the_line_down_tries_once_to_reopen_and_names_the_stop_it_could_not_send() {
    let mut bench = jogging();
    bench.pull_line();
    bench.close();
    bench.run_for(LONG);
    let report = report(&bench).expect("report");
    assert_eq!(report.stops.len(), 1, "{report:?}");
    assert_eq!(
        report.stops[0].1,
        StopOutcome::NotSent(NotSentReason::LineDown)
    );
    assert!(report.motion_may_run && !report.is_clean());
    assert!(
        report.to_string().contains("may still be moving"),
        "{report}"
    );
}

#[test]
fn a_close_with_the_line_down_reopens_it_to_deliver_the_stop() {
    let mut bench = jogging();
    bench.pull_line();
    bench.plug_in();
    bench.close();
    bench.run_for(LONG);
    let report = report(&bench).expect("report");
    assert!(report.is_clean(), "{report}");
    assert!(stop_follows_last_jog(&bench));
}

#[test]
fn requests_after_a_close_are_refused_except_stops() {
    let mut bench = jogging();
    bench.close();
    bench.run_for(Duration::from_millis(1));
    let step = bench.submit(step_x(1_000));
    bench.run_for(LONG);
    assert!(matches!(
        bench.answer_to(step),
        Some(LinkEvent::NotSent {
            reason: NotSentReason::ShuttingDown,
            ..
        })
    ));
    assert_eq!(report(&bench).map(|r| r.abandoned), Some(1));
    assert!(!bench.ids_written().iter().any(|i| i == "2D5"));
}

#[test]
fn a_jog_whose_lease_is_not_renewed_is_stopped_one_lease_after_its_last_renewal() {
    let lease = Duration::from_millis(150);
    let mut bench = Bench::new(
        ready_setup(Duration::from_millis(1)),
        FaultSpec::none(),
        LinkConfig {
            jog_lease: lease,
            ..quiet_config()
        },
    );
    bench.settle();
    let jog = bench.submit(jog_x());
    let renewed = bench.now;
    bench
        .run_until(LONG, is_reply_to(jog))
        .expect("jog acknowledged");
    let stop = bench
        .run_until(LONG, |e| {
            matches!(
                e,
                LinkEvent::FrameSent { bytes, .. } if bytes.starts_with(b"!99238")
            )
        })
        .expect("the link stopped the jog by itself");
    let LinkEvent::FrameSent { at, .. } = bench.events[stop] else {
        unreachable!()
    };
    let after = at - renewed;
    assert!(
        after > lease && after <= lease + Duration::from_millis(1),
        "STOP {after:?} after the last renewal"
    );
    bench.run_for(Duration::from_secs(1));
    assert!(bench.events.iter().any(|e| matches!(
        e,
        LinkEvent::Reply {
            origin: Origin::LeaseLapsed,
            ..
        }
    )));
    assert_eq!(bench.sim.controller.in_use(), 0);
}

#[test]
fn a_renewed_lease_keeps_the_jog_running_and_a_released_one_stops_it() {
    let lease = Duration::from_millis(150);
    let mut bench = Bench::new(
        ready_setup(Duration::from_millis(1)),
        FaultSpec::none(),
        LinkConfig {
            jog_lease: lease,
            ..quiet_config()
        },
    );
    bench.settle();
    let jog = bench.submit(jog_x());
    bench
        .run_until(LONG, is_reply_to(jog))
        .expect("acknowledged");
    for _ in 0..30 {
        bench.renew_lease();
        bench.run_for(Duration::from_millis(20));
    }
    assert!(!bench.sim.ids_received().iter().any(|i| i == "238"));
    assert_ne!(bench.sim.controller.in_use(), 0, "still jogging");
    bench.run_for(lease * 2);
    assert!(stop_follows_last_jog(&bench));
}

#[test]
fn a_refused_jog_leaves_no_lease_to_lapse_but_a_running_one_keeps_its_lease() {
    let lease = Duration::from_millis(150);
    let mut bench = Bench::new(
        ready_setup(Duration::from_millis(1)),
        FaultSpec::none(),
        LinkConfig {
            jog_lease: lease,
            ..quiet_config()
        },
    );
    bench.settle();
    let running = bench.submit(jog_x());
    bench.run_until(LONG, is_reply_to(running)).expect("runs");
    let busy = bench.submit(jog_x());
    bench
        .run_until(LONG, |e| bench_answers(e, busy))
        .expect("answered");
    assert!(
        matches!(bench.answer_to(busy), Some(LinkEvent::ErrorReply { .. })),
        "{}",
        bench.story()
    );
    bench
        .run_until(LONG, |e| {
            matches!(
                e,
                LinkEvent::Reply {
                    origin: Origin::LeaseLapsed,
                    ..
                }
            )
        })
        .expect("the running jog lost its lease");
    bench.run_for(Duration::from_secs(1));
    assert_eq!(bench.sim.controller.in_use(), 0);
    // Refused with nothing running (E-stop): the lease has nothing to stop.
    let stops = |b: &Bench| b.sim.ids_received().iter().filter(|i| *i == "238").count();
    let before = stops(&bench);
    bench.sim.controller.set_emergency_stop(true);
    let refused = bench.submit(jog_x());
    bench
        .run_until(LONG, |e| bench_answers(e, refused))
        .expect("answered");
    assert!(matches!(
        bench.answer_to(refused),
        Some(LinkEvent::ErrorReply { .. })
    ));
    bench.run_for(lease * 4);
    assert_eq!(stops(&bench), before, "{}", bench.story());
}

#[test]
fn a_jog_whose_lease_lapses_before_it_is_sent_is_not_sent() {
    let mut bench = Bench::new(
        ready_setup(Duration::from_millis(1)),
        delayed(Duration::from_millis(200)),
        LinkConfig {
            jog_lease: Duration::from_millis(50),
            ..quiet_config()
        },
    );
    bench.settle();
    bench.submit(Command::SystemStatus);
    let jog = bench.submit(jog_x());
    bench.run_for(LONG);
    assert!(
        matches!(
            bench.answer_to(jog),
            Some(LinkEvent::NotSent {
                reason: NotSentReason::LeaseLapsed,
                ..
            })
        ),
        "{}",
        bench.story()
    );
    assert!(!bench.sim.ids_received().iter().any(|i| i == "236"));
}

#[test]
fn requests_submitted_before_the_first_open_are_judged_against_the_opened_line() {
    let mut bench = Bench::new(
        ready_setup(Duration::from_millis(1)),
        FaultSpec::none(),
        quiet_config(),
    );
    let id = bench.submit(Command::SystemStatus);
    bench
        .run_until(LONG, is_reply_to(id))
        .expect("answered, not refused");
    assert!(matches!(bench.events[0], LinkEvent::Connected { .. }));
}

#[test]
fn a_reply_stalled_past_its_time_out_is_one_row_whole_never_a_head_and_a_tail() {
    let mut config = quiet_config();
    config.timing.margin = Duration::from_millis(20);
    let mut faults = FaultSpec::none().with(Fault::Stall, 1.0);
    faults.stall = Duration::from_millis(100);
    let mut bench = Bench::new(ready_setup(Duration::from_millis(1)), faults, config);
    bench.settle();
    let id = bench.submit(Command::SystemStatus);
    bench
        .run_until(
            LONG,
            |e| matches!(e, LinkEvent::Timeout { id: t, retrying: true, .. } if *t == id),
        )
        .expect("timed out and retried");
    bench.sim.faults.set_spec(FaultSpec::none());
    bench.run_for(Duration::from_millis(1_000));
    // Every reply the controller sent is one row: received (as an answer) or late.
    let replies = bench.sim.controller.counters().frames;
    let rows: Vec<&LinkEvent> = bench
        .events
        .iter()
        .filter(|e| {
            matches!(
                e,
                LinkEvent::FrameReceived { .. } | LinkEvent::Garbage { .. }
            )
        })
        .collect();
    assert_eq!(rows.len() as u64, replies, "{}", bench.story());
    assert!(
        rows.iter().all(|e| matches!(
            e,
            LinkEvent::FrameReceived { .. }
                | LinkEvent::Garbage {
                    error: BadInput::Late,
                    ..
                }
        )),
        "no head or tail of a reply logged apart:\n{}",
        bench.story()
    );
}

#[test]
fn a_reader_far_behind_pauses_polls_and_they_resume_when_it_catches_up() {
    let mut bench = Bench::new(
        ready_setup(Duration::from_millis(1)),
        FaultSpec::none(),
        LinkConfig::default(),
    );
    bench.run_for(Duration::from_millis(250));
    bench.core.handle_request(
        bench.now,
        crate::link::core::Input::Backlog {
            behind: true,
            dropped: 7,
        },
    );
    bench.run_for(Duration::from_millis(50));
    let from = bench.written.len();
    bench.run_for(Duration::from_millis(500));
    assert_eq!(
        bench.written.len(),
        from,
        "no polls while the reader is behind"
    );
    assert!(
        bench.events.iter().any(
            |e| matches!(e, LinkEvent::Health(h) if h.polling_paused && h.events_dropped == 7)
        )
    );
    bench.core.handle_request(
        bench.now,
        crate::link::core::Input::Backlog {
            behind: false,
            dropped: 7,
        },
    );
    bench.run_for(Duration::from_millis(50));
    assert!(bench.written.len() > from, "polls resumed at once");
}

#[test]
fn a_failed_write_is_not_sent_and_the_line_is_lost() {
    let mut bench = Bench::quiet();
    let id = bench.submit(step_x(1_000));
    bench.write_failed();
    bench.run_for(Duration::from_millis(1));
    assert!(matches!(
        bench.answer_to(id),
        Some(LinkEvent::NotSent {
            reason: NotSentReason::WriteFailed(_),
            ..
        })
    ));
    assert!(bench.events.iter().any(|e| matches!(
        e,
        LinkEvent::Disconnected {
            reason: LineDownReason::WriteFailed(_)
        }
    )));
}

/// The soak of tests/link/soak.rs on the virtual clock: 10,000 transactions against a
/// simulator that spoils 10% of its replies. Every fault shows as an event, replies pair
/// with their commands, and the controller receives exactly the moves that went out.
#[test]
fn ten_thousand_transactions_with_ten_percent_faults_on_the_virtual_clock() {
    const TRANSACTIONS: usize = 10_000;
    let mut faults = FaultSpec::none()
        .with(Fault::Drop, 0.02)
        .with(Fault::Corrupt, 0.02)
        .with(Fault::Garbage, 0.02)
        .with(Fault::Delay, 0.015)
        .with(Fault::Truncate, 0.015)
        .with(Fault::Stall, 0.01)
        .seeded(20_261_121);
    faults.delay = Duration::from_millis(40);
    faults.stall = Duration::from_millis(40);
    let mut config = LinkConfig {
        polling: Polling {
            interval: Some(Duration::ZERO),
            idle_interval: None,
            commands: vec![Command::ScaraStatus(crate::protocol::ScaraStatusQuery {
                axes: AxisPattern::SCARA_1,
                system: crate::protocol::PositionSystem::Work,
            })],
        },
        ..LinkConfig::default()
    };
    config.timing.margin = Duration::from_millis(15);
    let mut bench = Bench::new(ready_setup(Duration::ZERO), faults, config);
    let mut moves = Vec::new();
    let mut step = 200;
    let limit = bench.now + Duration::from_secs(3_600);
    while bench.written.len() < TRANSACTIONS {
        let before = bench.written.len();
        assert!(bench.step(limit), "the link went quiet");
        // A move about every 25 transactions, from the "user".
        if bench.written.len() / 25 > before / 25 {
            step = -step;
            moves.push(bench.submit(step_x(step)));
        }
    }
    // Every move answered (a time-out of a move is final) before the close.
    while !moves.iter().all(|id| bench.answer_to(*id).is_some()) {
        assert!(bench.step(limit), "a move was never answered");
    }
    bench.control(Control::SetPolling(Polling {
        interval: None,
        idle_interval: None,
        commands: Vec::new(),
    }));
    bench.close();
    bench.run_for(Duration::from_secs(10));
    assert!(bench.core.is_closed());
    let (mut timeouts, mut garbage, mut checksum_errors, mut out_of_step) = (0, 0, 0, 0);
    for e in &bench.events {
        match e {
            LinkEvent::Timeout { .. } => timeouts += 1,
            LinkEvent::Garbage { error, .. } => {
                garbage += 1;
                checksum_errors += u64::from(error.is_checksum());
            }
            LinkEvent::NotSent { id, reason, .. } => {
                assert!(moves.contains(id), "only moves may be held back: {reason}");
                assert_eq!(*reason, NotSentReason::OutOfStep);
                out_of_step += 1;
            }
            LinkEvent::Reply { command, reply, .. } => {
                assert_eq!(reply.id(), Some(command.id()), "a reply paired wrongly");
            }
            LinkEvent::Disconnected { reason } => panic!("the line was lost: {reason}"),
            _ => {}
        }
    }
    let injected = bench.sim.faults.counts();
    assert!(
        injected.total() >= 800,
        "about 10% of replies spoilt: {injected:?}"
    );
    assert!(
        timeouts >= injected.drop + injected.delay + injected.stall,
        "every lost, late or stalled reply is a time-out: {timeouts} vs {injected:?}"
    );
    assert!(
        checksum_errors >= injected.corrupt,
        "{checksum_errors} vs {injected:?}"
    );
    assert!(timeouts + garbage >= injected.total());
    let moves_sent = bench
        .written
        .iter()
        .filter(|(_, f)| f.starts_with(b"!992D5"))
        .count() as u64;
    assert_eq!(
        moves_sent + out_of_step,
        moves.len() as u64,
        "each move went out once, or was refused and said so"
    );
    assert_eq!(bench.sim.controller.counters().motion_received, moves_sent);
}

#[test]
fn a_standing_arm_is_polled_at_the_idle_interval_and_a_moving_one_at_the_fast_one() {
    let second = Duration::from_secs(1);
    let config = LinkConfig {
        polling: Polling {
            idle_interval: Some(Duration::from_millis(250)),
            ..Polling::default()
        },
        jog_lease: Duration::from_secs(600),
        ..LinkConfig::default()
    };
    let polls = config.polling.commands.clone();
    let mut bench = Bench::new(
        ready_setup(Duration::from_millis(1)),
        FaultSpec::none(),
        config,
    );
    // Cycles (of two polls) begun in the last second.
    let mut first = Vec::new();
    polls[0]
        .encode_into(
            crate::protocol::Station::DEFAULT,
            crate::protocol::ScMode::Computed,
            &mut first,
        )
        .expect("a poll encodes");
    let cycles = |bench: &Bench| {
        bench
            .written
            .iter()
            .filter(|(at, bytes)| *at + second > bench.now && *bytes == first)
            .count()
    };
    bench.run_for(3 * second);
    assert!(
        (3..=5).contains(&cycles(&bench)),
        "{} cycles in a second of a standing arm (4 expected)",
        cycles(&bench)
    );
    // A jog: its answers change with every poll, so the polls stay fast long after the
    // jog itself went out.
    let jog = bench.submit(jog_x());
    bench
        .run_until(LONG, is_reply_to(jog))
        .expect("jog acknowledged");
    bench.run_for(3 * second);
    assert_ne!(bench.sim.controller.in_use(), 0, "the jog runs");
    assert!(
        cycles(&bench) >= 9,
        "{} cycles in a second of a moving arm (10 expected)",
        cycles(&bench)
    );
    // Stopped and standing again: back to the idle interval.
    let stop = bench.stop_all();
    bench
        .run_until(LONG, is_reply_to(stop))
        .expect("STOP acknowledged");
    bench.run_for(3 * second);
    assert!(
        (3..=5).contains(&cycles(&bench)),
        "{} cycles in a second once the arm stands again",
        cycles(&bench)
    );
}

/// A bench whose link sent program 1 a run (253H): a program may run from then on.
fn program_started() -> Bench {
    let mut bench = Bench::new(
        ready_setup(Duration::from_millis(1)),
        FaultSpec::none(),
        quiet_config(),
    );
    bench.settle();
    let run = bench.submit(Command::Program(crate::protocol::ProgramCall {
        action: crate::protocol::ProgramAction::Run,
        program: 1,
    }));
    bench
        .run_until(LONG, |e| {
            matches!(e, LinkEvent::Reply { id, .. } | LinkEvent::ErrorReply { id, .. } if *id == run)
        })
        .expect("run answered");
    bench
}

/// The IDs the simulator received from the first 253H on, polls left out.
fn after_run(bench: &Bench) -> Vec<String> {
    let ids = bench.sim.ids_received();
    let from = ids
        .iter()
        .position(|id| id == "253")
        .expect("253H went out");
    ids[from..]
        .iter()
        .filter(|id| !matches!(id.as_str(), "215" | "2A1" | "2A3" | "212"))
        .cloned()
        .collect()
}

#[test]
fn a_stop_while_a_program_may_run_ends_every_program_between_two_stops() {
    let mut bench = program_started();
    let stop = bench.submit(Command::Stop(crate::link::format_b::safety::stop_all()));
    bench
        .run_until(LONG, is_reply_to(stop))
        .expect("STOP answered");
    bench.run_for(Duration::from_millis(200));
    assert_eq!(after_run(&bench), ["253", "238", "254", "238"]);
    assert!(
        bench
            .sim
            .received
            .iter()
            .any(|(_, f)| f.starts_with(b"!99254008E")),
        "254H with 00: every running program"
    );
}

#[test]
fn a_run_queued_before_a_stop_never_goes_out() {
    let mut bench = Bench::new(
        ready_setup(Duration::from_millis(1)),
        FaultSpec::none(),
        quiet_config(),
    );
    bench.settle();
    // A query first, so the run and the STOP both wait in the queue.
    bench.submit(Command::SystemStatus);
    let run = bench.submit(Command::Program(crate::protocol::ProgramCall {
        action: crate::protocol::ProgramAction::Run,
        program: 1,
    }));
    bench.submit(Command::Stop(crate::link::format_b::safety::stop_all()));
    bench.run_for(Duration::from_millis(300));
    assert!(bench.events.iter().any(|e| matches!(e,
        LinkEvent::NotSent { id, reason: NotSentReason::StopCameFirst, .. } if *id == run)));
    assert!(!bench.sim.ids_received().contains(&"253".to_string()));
}

#[test]
fn a_close_while_a_program_may_run_ends_it_and_stops_the_arm_again() {
    let mut bench = program_started();
    bench.close();
    bench.run_for(LONG);
    let report = report(&bench).expect("report");
    assert_eq!(report.stops.len(), 3, "{report:?}");
    assert_eq!(after_run(&bench), ["253", "238", "254", "238"]);
}
