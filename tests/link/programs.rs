//! A program on the simulator stopped by the link's STOP: 238H, 254H 00 and 238H on the
//! wire, the arm at rest and the program ended (the simulator's 238H alone would let the
//! program command its next move).

use std::time::Duration;

use crate::common::*;
use crate::wait::{LONG, until};
use xsel_pendant::link::{LinkEvent, Priority};
use xsel_pendant::protocol::{Command, ProgramAction, ProgramCall, Reply};
use xsel_pendant::sim::FaultSpec;
use xsel_pendant::sim::programs::TaskState;

fn program_state(sim: &xsel_pendant::sim::SimHandle) -> TaskState {
    sim.with(|c| c.programs().state(1).map(|(s, ..)| s))
        .unwrap_or_default()
}

#[test]
fn stop_mid_program_brakes_the_arm_and_ends_the_program() {
    let (link, events, sim) = embedded_link(
        ready_setup(Duration::from_millis(1)),
        FaultSpec::none(),
        None,
        quiet_config(),
    );
    let run = Command::Program(ProgramCall {
        action: ProgramAction::Run,
        program: 1,
    });
    let id = link.submit(run, Priority::User);
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
        "the demo runs: {answer:?}"
    );
    until("the demo moving the arm", LONG, || {
        sim.with(|c| c.in_use() != 0)
    });
    link.stop_all();
    let mut sent = Vec::new();
    let last_stop = wait_for(&events, LONG, &mut seen, |e| {
        if let LinkEvent::FrameSent { bytes, .. } = e {
            sent.push(String::from_utf8_lossy(&bytes[..6]).into_owned());
        }
        sent.len() >= 3
    });
    assert!(last_stop.is_some(), "the STOP's frames went out: {sent:?}");
    assert_eq!(sent, ["!99238", "!99254", "!99238"], "238H, 254H 00, 238H");
    until("the arm at rest and the program ended", LONG, || {
        sim.with(|c| c.at_rest()) && program_state(&sim) == TaskState::NotStarted
    });
    let error = sim.with(|c| c.programs().state(1).map(|(_, _, e)| e));
    assert_eq!(error, Some((0, 0)), "ended by 254H, not by an error");
}
