//! The link engine against the simulator: over the embedded pipe and a real
//! pseudo-terminal, with STOP, lost lines and table downloads.

use std::time::Duration;

use crate::common::*;
use crate::wait::{LONG, until};
use xsel_pendant::line::LineSettings;
use xsel_pendant::link::{LinkConfig, LinkEvent, Origin, Polling, Priority, TableRequest};
use xsel_pendant::protocol::{Command, CoordKind, ErrorCode, Reply};
use xsel_pendant::sim::FaultSpec;

#[test]
fn polls_bring_scara_and_system_status_over_the_embedded_pipe() {
    let (_link, events, _sim) = embedded_link(
        ready_setup(Duration::from_millis(2)),
        FaultSpec::none(),
        None,
        LinkConfig::default(),
    );
    let mut seen = Vec::new();
    let scara = wait_for(&events, LONG, &mut seen, |e| {
        matches!(
            e,
            LinkEvent::Reply {
                origin: Origin::Poll,
                reply: Reply::ScaraStatus(_),
                ..
            }
        )
    });
    let Some(LinkEvent::Reply {
        reply: Reply::ScaraStatus(status),
        ..
    }) = scara
    else {
        panic!("no 2A1H poll answered; saw {seen:?}")
    };
    assert_eq!(status.axes.pattern(), SCARA, "all four SCARA axes reported");
    assert!(
        seen.iter()
            .any(|e| matches!(e, LinkEvent::Connected { .. }))
    );
    let system = wait_for(&events, LONG, &mut seen, |e| {
        matches!(
            e,
            LinkEvent::Reply {
                reply: Reply::SystemStatus(_),
                ..
            }
        )
    });
    let Some(LinkEvent::Reply {
        reply: Reply::SystemStatus(s),
        ..
    }) = system
    else {
        panic!("no 215H poll answered")
    };
    assert!(s.motion_allowed(), "a ready simulator allows motion: {s:?}");
}

#[test]
fn a_relative_step_moves_the_arm_by_exactly_the_step_in_the_work_frame() {
    let (link, events, sim) = embedded_link(
        ready_setup(Duration::from_millis(1)),
        FaultSpec::none(),
        None,
        quiet_config(),
    );
    let before = sim.with(|c| c.tip_work());
    let id = link.submit(step_x(-5_000), Priority::User);
    let mut seen = Vec::new();
    let answer = wait_for(&events, LONG, &mut seen, answered(id));
    assert!(
        matches!(
            answer,
            Some(LinkEvent::Reply {
                reply: Reply::Ack(_),
                ..
            })
        ),
        "2D5H acknowledged: {answer:?}"
    );
    until("the move to end", LONG, || sim.with(|c| c.in_use()) == 0);
    let after = sim.with(|c| c.tip_work());
    assert!(
        (after.x - before.x + 5.0).abs() < 0.001,
        "x {} -> {}",
        before.x,
        after.x
    );
    assert!((after.y - before.y).abs() < 0.001);
    assert_eq!(sim.counters().motion_received, 1);
}

#[test]
fn a_refused_move_is_reported_with_the_controllers_error_code() {
    let (link, events, sim) = embedded_link(
        ready_setup(Duration::from_millis(1)),
        FaultSpec::none(),
        None,
        quiet_config(),
    );
    sim.set_emergency_stop(true);
    let id = link.submit(step_x(1_000), Priority::User);
    let mut seen = Vec::new();
    let answer = wait_for(&events, LONG, &mut seen, answered(id));
    let Some(LinkEvent::ErrorReply { code, .. }) = answer else {
        panic!("expected an error reply, got {answer:?}")
    };
    assert_eq!(code, ErrorCode(0xB04), "B04 = emergency stop active");
}

// A pseudo-terminal: Unix only.
#[cfg(unix)]
#[test]
fn link_and_simulator_talk_over_a_real_pseudo_terminal() {
    let server = pty_server(ready_setup(Duration::from_millis(2)));
    let (link, events) = serial_link(&server.path, LinkConfig::default());
    let mut seen = Vec::new();
    assert!(
        wait_for(&events, LONG, &mut seen, |e| matches!(
            e,
            LinkEvent::Reply {
                reply: Reply::ScaraStatus(_),
                ..
            }
        ))
        .is_some(),
        "no status over the pty: {seen:?}"
    );
    let id = link.submit(step_x(2_000), Priority::User);
    let answer = wait_for(
        &events,
        LONG,
        &mut seen,
        |e| matches!(e, LinkEvent::Reply { id: r, .. } if *r == id),
    );
    assert!(answer.is_some(), "move not acknowledged over the pty");
    assert_eq!(server.handle.counters().motion_received, 1);
}

#[test]
fn stop_is_the_next_frame_after_the_reply_of_the_poll_in_flight() {
    // 9600 baud pacing and a 150 ms reply delay: the STOP is certainly submitted while
    // the poll is in flight.
    let byte_time = LineSettings {
        baud: 9_600,
        ..LineSettings::default()
    }
    .byte_time();
    let mut config = LinkConfig::default();
    config.timing.line.baud = 9_600;
    config.polling.interval = Some(Duration::ZERO);
    let (link, events, _sim) = embedded_link(
        ready_setup(Duration::from_millis(150)),
        FaultSpec::none(),
        Some(byte_time),
        config,
    );
    let mut seen = Vec::new();
    let poll = wait_for(
        &events,
        LONG,
        &mut seen,
        |e| matches!(e, LinkEvent::FrameSent { bytes, .. } if bytes.starts_with(b"!992A1")),
    );
    assert!(poll.is_some(), "no poll went out");
    let stop_id = link.stop_all();
    let mut after_poll = Vec::new();
    let stop = wait_for(
        &events,
        LONG,
        &mut after_poll,
        |e| matches!(e, LinkEvent::FrameSent { id, .. } if *id == stop_id),
    );
    assert!(stop.is_some(), "STOP never went out");
    let sent: Vec<_> = after_poll
        .iter()
        .filter(|e| matches!(e, LinkEvent::FrameSent { .. }))
        .collect();
    assert_eq!(
        sent.len(),
        1,
        "nothing went out between the poll and the STOP: {sent:?}"
    );
    let replies = after_poll
        .iter()
        .filter(
            |e| matches!(e, LinkEvent::FrameReceived { bytes, .. } if bytes.starts_with(b"#992A1")),
        )
        .count();
    assert_eq!(replies, 1, "the poll's reply came before the STOP went out");
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
    let (link, events, _sim) = embedded_link(
        ready_setup(Duration::from_millis(1)),
        FaultSpec::none(),
        None,
        config,
    );
    let mut seen = Vec::new();
    wait_for(&events, LONG, &mut seen, |e| {
        matches!(e, LinkEvent::FrameSent { .. })
    });
    let id = link.submit(Command::AlarmReset, Priority::User);
    let mut after = Vec::new();
    wait_for(
        &events,
        LONG,
        &mut after,
        |e| matches!(e, LinkEvent::FrameSent { id: s, .. } if *s == id),
    )
    .expect("the user's command went out");
    // Ids come from one counter: a poll numbered after the command was chosen after it
    // was submitted. At most one may slip in (chosen as the submission raced the
    // link's look at its queue); polls chosen earlier may still be going out.
    let later_polls = after
        .iter()
        .filter(|e| matches!(e, LinkEvent::FrameSent { id: s, .. } if *s > id))
        .count();
    assert!(
        later_polls <= 1,
        "{later_polls} polls chosen after the user's command went out before it"
    );
}

#[test]
fn a_whole_tool_table_downloads_in_buffer_sized_chunks() {
    let (link, events, sim) = embedded_link(
        ready_setup(Duration::from_millis(1)),
        FaultSpec::none(),
        None,
        quiet_config(),
    );
    link.download_table(TableRequest {
        kind: CoordKind::Tool,
        axes: SCARA,
        first: 0,
        records: 128,
        reply_buffer: 2048,
    });
    let mut seen = Vec::new();
    let done = wait_for(&events, LONG, &mut seen, |e| {
        matches!(e, LinkEvent::TableDone { .. })
    });
    let Some(LinkEvent::TableDone {
        records, missing, ..
    }) = done
    else {
        panic!("no TableDone: {seen:?}")
    };
    assert!(missing.is_empty(), "missing {missing:?}");
    let chunks = seen
        .iter()
        .filter(|e| matches!(e, LinkEvent::FrameSent { bytes, .. } if bytes.starts_with(b"!992A4")))
        .count();
    assert_eq!(chunks, 3, "63 + 63 + 2 records");
    assert_tool_table_matches(&records, &sim);
}

fn assert_tool_table_matches(
    records: &[Option<xsel_pendant::protocol::PerAxis<xsel_pendant::protocol::Milli>>],
    sim: &xsel_pendant::sim::SimHandle,
) {
    let expected = sim.with(|c| c.coords().tool.entries().to_vec());
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
fn a_download_replaced_midway_keeps_its_records_apart() {
    let (link, events, sim) = embedded_link(
        ready_setup(Duration::from_millis(5)),
        FaultSpec::none(),
        None,
        quiet_config(),
    );
    link.download_table(TableRequest {
        kind: CoordKind::Work,
        axes: SCARA,
        first: 0,
        records: 32,
        reply_buffer: 2048,
    });
    link.download_table(TableRequest {
        kind: CoordKind::Tool,
        axes: SCARA,
        first: 0,
        records: 128,
        reply_buffer: 2048,
    });
    let mut seen = Vec::new();
    let first = wait_for(&events, LONG, &mut seen, |e| {
        matches!(e, LinkEvent::TableDone { .. })
    });
    assert!(
        matches!(
            first,
            Some(LinkEvent::TableDone {
                kind: CoordKind::Work,
                ..
            })
        ),
        "{first:?}"
    );
    let done = wait_for(&events, LONG, &mut seen, |e| {
        matches!(e, LinkEvent::TableDone { .. })
    });
    let Some(LinkEvent::TableDone {
        kind: CoordKind::Tool,
        records,
        missing,
        ..
    }) = done
    else {
        panic!("no tool TableDone: {done:?}")
    };
    assert!(missing.is_empty(), "missing {missing:?}");
    assert_tool_table_matches(&records, &sim);
}

#[test]
fn a_table_that_cannot_be_read_names_the_missing_records() {
    let mut config = quiet_config();
    config.timing.margin = Duration::from_millis(20);
    let (link, events, _sim) = embedded_link(
        ready_setup(Duration::from_millis(1)),
        FaultSpec::none().with(xsel_pendant::sim::Fault::Drop, 1.0),
        None,
        config,
    );
    link.download_table(TableRequest {
        kind: CoordKind::Work,
        axes: SCARA,
        first: 0,
        records: 32,
        reply_buffer: 2048,
    });
    let mut seen = Vec::new();
    let done = wait_for(&events, LONG, &mut seen, |e| {
        matches!(e, LinkEvent::TableDone { .. })
    });
    let Some(LinkEvent::TableDone { missing, .. }) = done else {
        panic!("no TableDone")
    };
    assert_eq!(missing, vec![0..32]);
    let tries = seen
        .iter()
        .filter(|e| matches!(e, LinkEvent::FrameSent { bytes, .. } if bytes.starts_with(b"!992A4")))
        .count();
    assert_eq!(tries, 3, "the chunk was sent once and retried twice");
}
