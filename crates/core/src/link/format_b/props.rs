//! The link's safety invariants as properties: random requests at random times against a
//! simulator with random faults and a line that comes and goes, on the virtual clock.

use std::collections::{HashMap, HashSet};
use std::time::{Duration, Instant};

use proptest::prelude::*;

use super::harness::{Bench, jog_x, quiet_config, ready_setup, step_x};
use crate::link::RequestId;
use crate::link::core::LinkCore;
use crate::link::event::LinkEvent;
use crate::link::handle::LinkConfig;
use crate::protocol::{AxisPattern, Command};
use crate::sim::{Fault, FaultSpec};

#[derive(Debug, Clone, Copy)]
enum Op {
    Query,
    Step(i32),
    Jog,
    Stop,
    Renew,
    PullLine,
    PlugIn,
}

fn op() -> impl Strategy<Value = Op> {
    prop_oneof![
        3 => Just(Op::Query),
        3 => (-20_000i32..20_000).prop_map(Op::Step),
        2 => Just(Op::Jog),
        1 => Just(Op::Stop),
        4 => Just(Op::Renew),
        1 => Just(Op::PullLine),
        1 => Just(Op::PlugIn),
    ]
}

fn faults() -> impl Strategy<Value = FaultSpec> {
    (0u64..1_000, 0usize..6, 0.0f64..0.3)
        .prop_map(|(seed, which, p)| FaultSpec::none().with(Fault::ALL[which], p).seeded(seed))
}

/// What a run did: the bench after it, and which ids were motion.
struct Run {
    bench: Bench,
    motion: HashSet<RequestId>,
    stops_before_close: Vec<RequestId>,
}

fn run(script: &[(u16, Op)], faults: FaultSpec, polling: bool) -> Run {
    let lease = Duration::from_millis(150);
    let config = LinkConfig {
        jog_lease: lease,
        reconnect_interval: Duration::from_millis(100),
        ..if polling {
            LinkConfig::default()
        } else {
            quiet_config()
        }
    };
    let mut bench = Bench::new(ready_setup(Duration::from_millis(2)), faults, config);
    let mut motion = HashSet::new();
    let mut stops = Vec::new();
    for &(wait, op) in script {
        bench.run_for(Duration::from_millis(u64::from(wait)));
        match op {
            Op::Query => {
                bench.submit(Command::SystemStatus);
            }
            Op::Step(um) => {
                motion.insert(bench.submit(step_x(um)));
            }
            Op::Jog => {
                motion.insert(bench.submit(jog_x()));
            }
            Op::Stop => stops.push(bench.stop_all()),
            Op::Renew => bench.renew_lease(),
            Op::PullLine => bench.pull_line(),
            Op::PlugIn => bench.plug_in(),
        }
    }
    bench.close();
    bench.run_for(Duration::from_secs(30));
    Run {
        bench,
        motion,
        stops_before_close: stops,
    }
}

fn script() -> impl Strategy<Value = Vec<(u16, Op)>> {
    prop::collection::vec((0u16..400, op()), 1..40)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 96, ..ProptestConfig::default() })]

    #[test]
    fn a_motion_frame_is_never_sent_twice(script in script(), faults in faults(), polling in any::<bool>()) {
        let run = run(&script, faults, polling);
        let mut sent: HashMap<RequestId, usize> = HashMap::new();
        for e in &run.bench.events {
            if let LinkEvent::FrameSent { id, .. } = e {
                *sent.entry(*id).or_default() += 1;
            }
        }
        for id in &run.motion {
            prop_assert!(sent.get(id).copied().unwrap_or(0) <= 1, "motion {id} sent twice:\n{}", run.bench.story());
        }
        let received = run.bench.sim.controller.counters().motion_received;
        let written = run.bench.written.iter().filter(|(_, f)| {
            f.starts_with(b"!992D5") || f.starts_with(b"!99236")
        }).count();
        prop_assert!(received as usize <= written);
    }

    #[test]
    fn every_motion_ends_in_exactly_one_answer(script in script(), faults in faults(), polling in any::<bool>()) {
        let run = run(&script, faults, polling);
        for id in &run.motion {
            let ends = run.bench.events.iter().filter(|e| match e {
                LinkEvent::Reply { id: r, .. }
                | LinkEvent::ErrorReply { id: r, .. }
                | LinkEvent::NotSent { id: r, .. }
                | LinkEvent::Interrupted { id: r, .. }
                | LinkEvent::Timeout { id: r, .. } => r == id,
                _ => false,
            }).count();
            prop_assert_eq!(ends, 1, "motion {} ended {} times:\n{}", id, ends, run.bench.story());
        }
        prop_assert!(run.bench.core.is_closed(), "the close ended");
        prop_assert!(matches!(run.bench.events.last(), Some(LinkEvent::ShutDown(_))));
    }

    #[test]
    fn after_a_line_lost_while_moving_a_stop_is_the_first_frame_on_the_next_line(script in script(), faults in faults()) {
        let run = run(&script, faults, false);
        let events = &run.bench.events;
        let mut may_move = false;
        let mut lost_while_moving = false;
        for (i, e) in events.iter().enumerate() {
            match e {
                LinkEvent::FrameSent { bytes, .. } if lost_while_moving => {
                    prop_assert!(bytes.starts_with(b"!99238"), "first frame after reopening: {:?}\n{}", String::from_utf8_lossy(bytes), run.bench.story());
                    lost_while_moving = false;
                }
                LinkEvent::FrameSent { bytes, .. } if bytes.starts_with(b"!99236") || bytes.starts_with(b"!992D5") => may_move = true,
                LinkEvent::Reply { command: Command::Stop(s), .. } if s.axes == AxisPattern::ALL => may_move = false,
                LinkEvent::Disconnected { .. } if may_move && i > 0 => lost_while_moving = true,
                _ => {}
            }
        }
    }

    #[test]
    fn a_close_sends_every_owed_stop(script in script(), faults in faults(), polling in any::<bool>()) {
        let run = run(&script, faults, polling);
        let report = run.bench.core.shutdown_report();
        let tried: HashSet<RequestId> = report.stops.iter().map(|(id, _)| *id).collect();
        for id in &run.stops_before_close {
            let settled_before = run.bench.events.iter().any(|e| match e {
                LinkEvent::Reply { id: r, .. }
                | LinkEvent::ErrorReply { id: r, .. }
                | LinkEvent::NotSent { id: r, .. }
                | LinkEvent::Interrupted { id: r, .. } => r == id,
                LinkEvent::Timeout { id: r, retrying, .. } => r == id && !retrying,
                _ => false,
            });
            prop_assert!(settled_before || tried.contains(id), "STOP {id} neither answered nor tried at the close:\n{}", run.bench.story());
        }
        // Motion written after the last acknowledged STOP of all axes is owed a STOP.
        let events = &run.bench.events;
        let closing = events.iter().rposition(|e| matches!(e, LinkEvent::ShutDown(_))).unwrap_or(events.len());
        let owed = events[..closing].iter().fold(false, |owed, e| match e {
            LinkEvent::FrameSent { bytes, .. } if bytes.starts_with(b"!99236") || bytes.starts_with(b"!992D5") => true,
            LinkEvent::Reply { command: Command::Stop(s), .. } if s.axes == AxisPattern::ALL => false,
            _ => owed,
        });
        let acknowledged = report.stops.iter().any(|(_, o)| *o == crate::link::StopOutcome::Acknowledged);
        if owed {
            prop_assert!(!report.stops.is_empty(), "motion may run and no STOP was owed:\n{}", run.bench.story());
            prop_assert_eq!(report.motion_may_run, !acknowledged, "{}", report);
        }
        prop_assert!(!report.motion_may_run || !report.is_clean());
    }
}

/// A jog acknowledged, renewals at a steady pace, queries beside it (some answered late),
/// then nobody renews.
fn lease_scene() -> impl Strategy<Value = (u64, u32, Vec<u16>, FaultSpec)> {
    (
        10u64..140,
        0u32..20,
        prop::collection::vec(0u16..3_000, 0..12),
        faults(),
    )
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 96, ..ProptestConfig::default() })]

    #[test]
    fn a_lapsed_lease_puts_a_stop_on_the_line_within_one_transaction(
        (every, renewals, queries, faults) in lease_scene(),
    ) {
        let lease = Duration::from_millis(150);
        let mut bench = Bench::new(
            ready_setup(Duration::from_millis(2)),
            faults,
            LinkConfig { jog_lease: lease, ..quiet_config() },
        );
        bench.settle();
        let t0 = bench.now;
        bench.submit(jog_x());
        let jog_written = bench.now;
        let mut last_renewal = bench.now;
        let mut queries: Vec<Instant> = queries.iter().map(|ms| t0 + Duration::from_millis(u64::from(*ms))).collect();
        queries.sort();
        let mut queries = queries.into_iter().peekable();
        for _ in 0..renewals {
            let next = bench.now + Duration::from_millis(every);
            while let Some(at) = queries.next_if(|at| *at <= next) {
                bench.run_for(at.saturating_duration_since(bench.now));
                bench.submit(Command::SystemStatus);
            }
            bench.run_for(next.saturating_duration_since(bench.now));
            bench.renew_lease();
            last_renewal = bench.now;
        }
        for at in queries {
            bench.run_for(at.saturating_duration_since(bench.now));
            bench.submit(Command::SystemStatus);
        }
        bench.run_for(Duration::from_secs(5));
        let lapse = last_renewal + lease;
        let stopped_before = bench.written.iter().any(|(at, f)| *at >= jog_written && *at <= lapse && f.starts_with(b"!99238"));
        if !stopped_before {
            let first_after = bench.written.iter().find(|(at, _)| *at > lapse);
            prop_assert!(
                first_after.is_some_and(|(_, f)| f.starts_with(b"!99238")),
                "first frame after the lapse at {:.1} ms: {:?}\n{}",
                bench.ms(lapse),
                first_after.map(|(at, f)| (bench.ms(*at), String::from_utf8_lossy(f).into_owned())),
                bench.story()
            );
        }
    }
}
