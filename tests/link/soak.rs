//! Soak, threaded: 1,000 transactions through the link driver, the pipe and the
//! simulator's thread, injecting faults into 10% of the replies. Nothing panics or hangs,
//! every fault shows up as an event, and the controller receives exactly the motion
//! commands that were submitted. (Its twin of 10,000 transactions runs on the virtual
//! clock in the link core's tests.)

use std::collections::HashSet;
use std::time::{Duration, Instant};

use crate::common::*;
use xsel_pendant::link::{LinkConfig, LinkEvent, NotSentReason, Polling, Priority};
use xsel_pendant::protocol::{AxisPattern, Command, PositionSystem, ScaraStatusQuery};
use xsel_pendant::sim::{Fault, FaultSpec};

const TRANSACTIONS: usize = 1_000;

#[test]
fn a_thousand_transactions_with_ten_percent_faults() {
    let mut faults = FaultSpec::none()
        .with(Fault::Drop, 0.02)
        .with(Fault::Corrupt, 0.02)
        .with(Fault::Garbage, 0.02)
        .with(Fault::Delay, 0.015)
        .with(Fault::Truncate, 0.015)
        .with(Fault::Stall, 0.01)
        .seeded(20_261_121);
    // Both longer than the reply timeout below, so each is a fault the link must see.
    faults.delay = Duration::from_millis(40);
    faults.stall = Duration::from_millis(40);
    let mut config = LinkConfig {
        polling: Polling {
            interval: Some(Duration::ZERO),
            idle_interval: None,
            // One command a cycle: a late poll reply carries the very ID the next poll
            // waits for, the hardest case for pairing replies with commands.
            commands: vec![Command::ScaraStatus(ScaraStatusQuery {
                axes: AxisPattern::SCARA_1,
                system: PositionSystem::Work,
            })],
        },
        // This test counts every fault's event: the reader must never be left behind
        // (backpressure has its own test in link_backlog.rs).
        event_backlog: 1 << 22,
        ..LinkConfig::default()
    };
    config.timing.margin = Duration::from_millis(15);
    let (link, events, sim) = embedded_link(ready_setup(Duration::ZERO), faults, None, config);

    let deadline = Instant::now() + Duration::from_secs(240);
    let mut sent = 0usize;
    let mut motion_frames_sent = 0u64;
    let mut motion_submitted = HashSet::new();
    let mut motion_resolved = HashSet::new();
    let (mut timeouts, mut garbage, mut checksum_errors) = (0u64, 0u64, 0u64);
    let mut motion_refused_out_of_step = 0u64;
    let mut step = 200;
    while sent < TRANSACTIONS || motion_resolved.len() < motion_submitted.len() {
        assert!(
            Instant::now() < deadline,
            "the soak hung after {sent} transactions"
        );
        let Ok(event) = events.recv_timeout(Duration::from_secs(5)) else {
            panic!("no event for 5 s after {sent} transactions")
        };
        match &event {
            LinkEvent::FrameSent { id, bytes, .. } => {
                sent += 1;
                if motion_submitted.contains(id) {
                    motion_frames_sent += 1;
                    assert!(bytes.starts_with(b"!992D5"));
                }
                // A motion command about every 25 transactions, from the "user".
                if sent.is_multiple_of(25) && sent < TRANSACTIONS {
                    step = -step;
                    motion_submitted.insert(link.submit(step_x(step), Priority::User));
                }
            }
            LinkEvent::Timeout { .. } => timeouts += 1,
            LinkEvent::Garbage { error, .. } => {
                garbage += 1;
                if error.is_checksum() {
                    checksum_errors += 1;
                }
            }
            LinkEvent::NotSent { id, reason, .. } => {
                assert!(
                    motion_submitted.contains(id),
                    "only moves may be held back: {reason}"
                );
                assert_eq!(*reason, NotSentReason::OutOfStep, "{reason}");
                motion_refused_out_of_step += 1;
            }
            LinkEvent::Reply { command, reply, .. } => {
                assert_eq!(
                    reply.id(),
                    Some(command.id()),
                    "a reply paired with the wrong command"
                );
            }
            LinkEvent::Disconnected { reason } => panic!("the line was lost: {reason}"),
            LinkEvent::Dropped { frames } => panic!("{frames} traffic events were left out"),
            _ => {}
        }
        if let LinkEvent::Reply { id, .. }
        | LinkEvent::ErrorReply { id, .. }
        | LinkEvent::Timeout { id, .. }
        | LinkEvent::NotSent { id, .. } = &event
            && motion_submitted.contains(id)
        {
            motion_resolved.insert(*id);
        }
    }
    // Let the last replies land before counting: polls off, then shut the link down (the
    // transaction in flight ends first) and read every event it left, to the last.
    link.set_polling(Polling {
        interval: None,
        idle_interval: None,
        commands: Vec::new(),
    });
    let _report = link.shutdown();
    for event in events.iter() {
        match &event {
            LinkEvent::Timeout { .. } => timeouts += 1,
            LinkEvent::Garbage { error, .. } => {
                garbage += 1;
                if error.is_checksum() {
                    checksum_errors += 1;
                }
            }
            LinkEvent::Dropped { frames } => panic!("{frames} traffic events were left out"),
            _ => {}
        }
    }
    let injected = sim.fault_counts();
    let counters = sim.counters();
    eprintln!(
        "{sent} transactions; faults injected {injected:?}; timeouts {timeouts}, bad input {garbage}"
    );
    eprintln!(
        "moves held back because the line could not be proven in step: {motion_refused_out_of_step}"
    );
    assert!(
        injected.total() >= 50,
        "about 10% of replies were faulty: {injected:?}"
    );
    assert!(
        timeouts >= injected.drop + injected.delay + injected.stall,
        "every lost, late or stalled reply is a timeout: {timeouts} vs {injected:?}"
    );
    assert!(
        checksum_errors >= injected.corrupt,
        "every corrupted checksum is reported: {checksum_errors} vs {}",
        injected.corrupt
    );
    assert!(
        timeouts + garbage >= injected.total(),
        "every fault shows as an event: {timeouts} + {garbage} vs {}",
        injected.total()
    );
    assert_eq!(
        motion_frames_sent + motion_refused_out_of_step,
        motion_submitted.len() as u64,
        "each motion command went out exactly once, or was refused and said so"
    );
    assert_eq!(
        counters.motion_received, motion_frames_sent,
        "the controller received exactly the motion commands submitted"
    );
}
