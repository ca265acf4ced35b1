//! The link's safety rules when the line misbehaves: motion never re-sent, late replies
//! never credited to a move, a jog stopped when the line stalls, lost and regained lines.

use std::time::Duration;

use crate::common::*;
use crate::wait::{LONG, until};
use xsel_pendant::link::{LinkConfig, LinkEvent, Origin, Priority};
use xsel_pendant::protocol::{
    Axis, AxisPattern, CentiG, Command, Direction, Jog, JogFrame, JogMotion, Milli, MmPerSec, Reply,
};
use xsel_pendant::sim::runner::{RunOptions, SimCore, start_tcp};
use xsel_pendant::sim::{Controller, Fault, FaultSpec};

#[test]
fn a_motion_command_that_times_out_is_never_sent_again_and_status_is_read_instead() {
    let mut config = quiet_config();
    // Long enough that clearing the fault after the first time-out is never too late
    // for the recheck and its retries.
    config.timing.margin = Duration::from_millis(200);
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
    sim.set_faults(FaultSpec::none());
    assert!(!retrying, "motion must not be retried");
    let recheck = recheck.expect("a status recheck is queued instead");
    let status = wait_for(
        &events,
        LONG,
        &mut seen,
        |e| matches!(e, LinkEvent::Reply { id: r, origin: Origin::Recheck { after }, .. } if *after == id && *r == recheck),
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
fn a_late_error_reply_is_never_credited_to_the_next_move() {
    let mut config = quiet_config();
    config.timing.margin = Duration::from_millis(20);
    let mut faults = FaultSpec::none().with(Fault::Delay, 1.0);
    faults.delay = Duration::from_millis(120);
    let (link, events, sim) =
        embedded_link(ready_setup(Duration::from_millis(1)), faults, None, config);
    // Move A is far out of reach: the controller refuses it with '&', 120 ms late.
    let a = link.submit(step_x(-2_000_000), Priority::User);
    let mut seen = Vec::new();
    wait_for(
        &events,
        LONG,
        &mut seen,
        |e| matches!(e, LinkEvent::Timeout { id, .. } if *id == a),
    )
    .expect("move A timed out");
    sim.set_faults(FaultSpec::none());
    // Move B is fine and is submitted while A's '&' is still on its way.
    let b = link.submit(step_x(1_000), Priority::User);
    let answer = wait_for(&events, LONG, &mut seen, answered(b));
    assert!(
        matches!(
            answer,
            Some(LinkEvent::Reply {
                reply: Reply::Ack(_),
                ..
            })
        ),
        "move B is acknowledged, never refused with A's error: {answer:?}\n{}",
        story(&seen)
    );
    assert!(
        seen.iter().any(|e| matches!(e, LinkEvent::Reply { origin: Origin::Proof { before }, .. } if *before == b)),
        "a proving query put the line back in step before B"
    );
    assert_eq!(sim.counters().motion_received, 2);
}

#[test]
fn a_stalled_line_stops_a_running_jog() {
    let mut config = quiet_config();
    config.timing.margin = Duration::from_millis(50);
    // The lease is not what stops this jog: the stall is.
    config.jog_lease = Duration::from_secs(60);
    let (link, events, sim) = embedded_link(
        ready_setup(Duration::from_millis(1)),
        FaultSpec::none(),
        None,
        config,
    );
    let jog = Command::Jog(Jog {
        axes: AxisPattern::single(Axis::A1),
        direction: Direction::Negative,
        distance: Milli(0),
        motion: JogMotion::Cartesian {
            frame: JogFrame::Work,
            acc: CentiG(10),
            dec: CentiG(10),
            speed: MmPerSec(5),
        },
    });
    let id = link.submit(jog, Priority::User);
    let mut seen = Vec::new();
    wait_for(&events, LONG, &mut seen, answered(id)).expect("jog answered");
    assert_ne!(sim.with(|c| c.in_use()), 0, "the jog runs");
    // The line stalls: a status query goes unanswered.
    sim.set_faults(FaultSpec::none().with(Fault::Drop, 1.0));
    let query = link.submit(Command::SystemStatus, Priority::User);
    wait_for(
        &events,
        LONG,
        &mut seen,
        |e| matches!(e, LinkEvent::Timeout { id, .. } if *id == query),
    )
    .expect("the query timed out");
    sim.set_faults(FaultSpec::none());
    let stop = wait_for(&events, LONG, &mut seen, |e| {
        matches!(
            e,
            LinkEvent::Reply {
                origin: Origin::SafetyStop,
                ..
            }
        )
    });
    assert!(
        stop.is_some(),
        "the link stopped the jog by itself: {seen:#?}"
    );
    until("the arm to stop", LONG, || sim.with(|c| c.in_use()) == 0);
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
    drop(sim);
    let lost = wait_for(&events, LONG, &mut seen, |e| {
        matches!(e, LinkEvent::Disconnected { .. })
    });
    assert!(lost.is_some(), "no Disconnected after the simulator died");
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
fn an_idle_line_without_polling_still_notices_the_loss() {
    let (_link, events, sim) = embedded_link(
        ready_setup(Duration::from_millis(1)),
        FaultSpec::none(),
        None,
        quiet_config(),
    );
    let mut seen = Vec::new();
    wait_for(&events, LONG, &mut seen, |e| {
        matches!(e, LinkEvent::Connected { .. })
    })
    .expect("connected");
    drop(sim);
    let lost = wait_for(&events, LONG, &mut seen, |e| {
        matches!(e, LinkEvent::Disconnected { .. })
    });
    assert!(
        lost.is_some(),
        "an idle link never noticed the line was gone"
    );
}

// A pseudo-terminal: Unix only.
#[cfg(unix)]
#[test]
fn closing_the_pseudo_terminal_gives_disconnected() {
    let server = pty_server(ready_setup(Duration::from_millis(1)));
    let (_link, events) = serial_link(&server.path, LinkConfig::default());
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

// A pseudo-terminal: Unix only.
#[cfg(unix)]
#[test]
fn reconnect_on_request_reopens_the_port_and_polling_resumes() {
    let server = pty_server(ready_setup(Duration::from_millis(1)));
    let config = LinkConfig {
        auto_reconnect: false,
        ..LinkConfig::default()
    };
    let (link, events) = serial_link(&server.path, config);
    let mut seen = Vec::new();
    wait_for(&events, LONG, &mut seen, |e| {
        matches!(e, LinkEvent::Reply { .. })
    })
    .expect("polling");
    link.reconnect();
    wait_for(&events, LONG, &mut seen, |e| {
        matches!(e, LinkEvent::Disconnected { .. })
    })
    .expect("closed");
    wait_for(&events, LONG, &mut seen, |e| {
        matches!(e, LinkEvent::Reconnected { .. })
    })
    .expect("reopened");
    let polled = wait_for(&events, LONG, &mut seen, |e| {
        matches!(
            e,
            LinkEvent::Reply {
                origin: Origin::Poll,
                ..
            }
        )
    });
    assert!(polled.is_some(), "polling resumed on the reopened line");
}

#[test]
fn a_tcp_bridge_that_comes_back_is_reconnected_automatically() {
    let core = || {
        SimCore::new(
            Controller::new(ready_setup(Duration::from_millis(1))),
            FaultSpec::none(),
        )
    };
    let server = start_tcp(core(), "127.0.0.1:0", RunOptions::default()).expect("tcp");
    let addr = server.addr.to_string();
    let connect_to = addr.clone();
    let connector: xsel_pendant::link::Connector = Box::new(move |_| {
        xsel_pendant::link::TcpTransport::connect(&connect_to, Duration::from_millis(500))
            .map(|t| Box::new(t) as Box<dyn xsel_pendant::link::Transport>)
    });
    let config = LinkConfig {
        reconnect_interval: Duration::from_millis(100),
        ..LinkConfig::default()
    };
    let (_link, events) =
        xsel_pendant::link::spawn(connector, config, std::sync::Arc::new(|_| {})).expect("link");
    let mut seen = Vec::new();
    wait_for(&events, LONG, &mut seen, |e| {
        matches!(e, LinkEvent::Reply { .. })
    })
    .expect("polling");
    drop(server);
    wait_for(&events, LONG, &mut seen, |e| {
        matches!(e, LinkEvent::Disconnected { .. })
    })
    .expect("lost");
    let _again = start_tcp(core(), &addr, RunOptions::default()).expect("same address again");
    wait_for(&events, LONG, &mut seen, |e| {
        matches!(e, LinkEvent::Reconnected { .. })
    })
    .expect("reconnected");
    wait_for(&events, LONG, &mut seen, |e| {
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
fn a_line_lost_while_waiting_for_a_reply_is_reported_as_interrupted_not_timed_out() {
    // The controller swallows the reply; the line is lost while the link waits for it.
    let (link, events, sim) = embedded_link(
        ready_setup(Duration::from_millis(1)),
        FaultSpec::none().with(Fault::Drop, 1.0),
        None,
        LinkConfig {
            timing: xsel_pendant::link::timing::Timing {
                margin: Duration::from_secs(5),
                ..Default::default()
            },
            ..quiet_config()
        },
    );
    let id = link.submit(Command::SystemStatus, Priority::User);
    let mut seen = Vec::new();
    wait_for(
        &events,
        LONG,
        &mut seen,
        |e| matches!(e, LinkEvent::FrameSent { id: s, .. } if *s == id),
    )
    .expect("the query went out");
    drop(sim);
    let settled = wait_for(&events, LONG, &mut seen, |e| match e {
        LinkEvent::Interrupted { id: s, .. } | LinkEvent::Timeout { id: s, .. } => *s == id,
        _ => false,
    });
    assert!(
        matches!(settled, Some(LinkEvent::Interrupted { .. })),
        "{settled:?}\n{}",
        story(&seen)
    );
    let lost = wait_for(&events, LONG, &mut seen, |e| {
        matches!(e, LinkEvent::Disconnected { .. })
    });
    assert!(
        matches!(
            lost,
            Some(LinkEvent::Disconnected {
                reason: xsel_pendant::link::LineDownReason::Closed
            })
        ),
        "{lost:?}"
    );
}
