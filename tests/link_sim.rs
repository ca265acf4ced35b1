//! The link engine against the simulator: over the embedded pipe and a real
//! pseudo-terminal, with faults, STOP, lost lines and table downloads.

mod common;

use std::time::{Duration, Instant};

use common::*;
use xsel_pendant::link::transport::SerialTransport;
use xsel_pendant::link::{
    LineSettings, LinkConfig, LinkEvent, Origin, Polling, Priority, TableRequest, spawn,
};
use xsel_pendant::protocol::{Command, CoordKind, Reply};
use xsel_pendant::sim::runner::{RunOptions, SimCore, start_pty};
use xsel_pendant::sim::{Controller, Fault, FaultSpec};

const LONG: Duration = Duration::from_secs(10);

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
    let answer = wait_for(&events, LONG, &mut seen, |e| match e {
        LinkEvent::Reply { id: r, .. } | LinkEvent::ErrorReply { id: r, .. } => *r == id,
        _ => false,
    });
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
    let deadline = Instant::now() + LONG;
    while sim.with(|c| c.in_use()) != 0 {
        assert!(Instant::now() < deadline, "the move never ended");
        std::thread::sleep(Duration::from_millis(10));
    }
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
fn link_and_simulator_talk_over_a_real_pseudo_terminal() {
    let setup = ready_setup(Duration::from_millis(2));
    let server = start_pty(
        SimCore::new(Controller::new(setup), FaultSpec::none()),
        RunOptions::default(),
    )
    .expect("pty");
    let path = server.path.clone();
    let connector: xsel_pendant::link::Connector = Box::new(move || {
        SerialTransport::open(&path, LineSettings::default())
            .map(|t| Box::new(t) as Box<dyn xsel_pendant::link::Transport>)
    });
    let (link, events) = spawn(connector, LinkConfig::default(), std::sync::Arc::new(|| {}));
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
    // 9600 baud pacing: a 2A1H reply takes about 85 ms on the wire, so the STOP is
    // certainly submitted while that poll is in flight.
    let byte_time = LineSettings {
        baud: 9_600,
        ..LineSettings::default()
    }
    .byte_time();
    let mut config = LinkConfig::default();
    config.timing.line.baud = 9_600;
    config.polling.interval = Some(Duration::ZERO);
    let (link, events, _sim) = embedded_link(
        ready_setup(Duration::from_millis(2)),
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
fn a_motion_command_that_times_out_is_never_sent_again_and_status_is_read_instead() {
    let mut config = quiet_config();
    config.timing.margin = Duration::from_millis(30);
    let (link, events, sim) = embedded_link(
        ready_setup(Duration::from_millis(1)),
        FaultSpec::none().with(Fault::Drop, 1.0),
        None,
        config,
    );
    let id = link.submit(step_x(1_000), Priority::User);
    let mut seen = Vec::new();
    let timeout = wait_for(
        &events,
        LONG,
        &mut seen,
        |e| matches!(e, LinkEvent::Timeout { id: t, .. } if *t == id),
    );
    let Some(LinkEvent::Timeout {
        retrying, recheck, ..
    }) = timeout
    else {
        panic!("no timeout for the dropped reply: {seen:?}")
    };
    assert!(!retrying, "motion must not be retried");
    let recheck = recheck.expect("a status recheck is queued instead");
    sim.set_faults(FaultSpec::none());
    let status = wait_for(
        &events,
        LONG,
        &mut seen,
        |e| matches!(e, LinkEvent::Reply { origin: Origin::Recheck { after }, .. } if *after == id),
    );
    assert!(
        status.is_some(),
        "the recheck {recheck} was answered: {seen:?}"
    );
    let moves_sent = seen
        .iter()
        .filter(|e| matches!(e, LinkEvent::FrameSent { bytes, .. } if bytes.starts_with(b"!992D5")))
        .count();
    assert_eq!(moves_sent, 1);
    assert_eq!(
        sim.counters().motion_received,
        1,
        "the controller saw the move once"
    );
}

#[test]
fn a_simulator_killed_mid_move_gives_disconnected_and_later_commands_are_refused() {
    let (link, events, sim) = embedded_link(
        ready_setup(Duration::from_millis(1)),
        FaultSpec::none(),
        None,
        LinkConfig::default(),
    );
    let id = link.submit(step_x(-100_000), Priority::User);
    let mut seen = Vec::new();
    assert!(
        wait_for(
            &events,
            LONG,
            &mut seen,
            |e| matches!(e, LinkEvent::Reply { id: r, .. } if *r == id)
        )
        .is_some()
    );
    assert_ne!(sim.with(|c| c.in_use()), 0, "the arm is moving");
    let pulled = Instant::now();
    drop(sim);
    let lost = wait_for(&events, LONG, &mut seen, |e| {
        matches!(e, LinkEvent::Disconnected { .. })
    });
    assert!(lost.is_some(), "no Disconnected after the simulator died");
    eprintln!(
        "Disconnected {:?} after the line was pulled",
        pulled.elapsed()
    );
    let late = link.submit(step_x(1_000), Priority::User);
    let refused = wait_for(
        &events,
        LONG,
        &mut seen,
        |e| matches!(e, LinkEvent::NotSent { id, .. } if *id == late),
    );
    assert!(
        refused.is_some(),
        "a move on a dead line is refused, not queued"
    );
}

#[test]
fn closing_the_pseudo_terminal_gives_disconnected() {
    let server = start_pty(
        SimCore::new(
            Controller::new(ready_setup(Duration::from_millis(1))),
            FaultSpec::none(),
        ),
        RunOptions::default(),
    )
    .expect("pty");
    let path = server.path.clone();
    let connector: xsel_pendant::link::Connector = Box::new(move || {
        SerialTransport::open(&path, LineSettings::default())
            .map(|t| Box::new(t) as Box<dyn xsel_pendant::link::Transport>)
    });
    let (_link, events) = spawn(connector, LinkConfig::default(), std::sync::Arc::new(|| {}));
    let mut seen = Vec::new();
    assert!(
        wait_for(&events, LONG, &mut seen, |e| matches!(
            e,
            LinkEvent::Reply { .. }
        ))
        .is_some()
    );
    drop(server);
    let lost = wait_for(&events, LONG, &mut seen, |e| {
        matches!(e, LinkEvent::Disconnected { .. })
    });
    assert!(lost.is_some(), "no Disconnected after the pty closed");
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
    let expected = sim.with(|c| c.coords().tool.entries().to_vec());
    for (n, (got, want)) in records.iter().zip(&expected).enumerate() {
        let got = got.expect("record present");
        let got: Vec<i32> = got.iter().map(|(_, v)| v.0).collect();
        assert_eq!(got, want.to_wire(), "tool {n}");
    }
}

#[test]
fn a_table_that_cannot_be_read_names_the_missing_records() {
    let mut config = quiet_config();
    config.timing.margin = Duration::from_millis(20);
    let (link, events, _sim) = embedded_link(
        ready_setup(Duration::from_millis(1)),
        FaultSpec::none().with(Fault::Drop, 1.0),
        None,
        config,
    );
    link.download_table(TableRequest {
        kind: CoordKind::Work,
        axes: SCARA,
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

#[test]
fn polling_stops_for_nothing_but_yields_to_user_commands() {
    let config = LinkConfig {
        polling: Polling {
            interval: Some(Duration::ZERO),
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
    let polls_before = after
        .iter()
        .filter(|e| matches!(e, LinkEvent::FrameSent { .. }))
        .count()
        - 1;
    assert!(
        polls_before <= 1,
        "the user's command waited behind {polls_before} polls"
    );
}
