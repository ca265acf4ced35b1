//! STOP survives every way out: explicit shutdown, dropping the handle (mid-jog, right
//! after `stop_all`, with the line down), and a jog whose lease is not renewed.

use std::time::Duration;

use crate::common::*;
use crate::wait::{LONG, eventually};
use xsel_pendant::link::{
    LinkConfig, LinkEvent, NotSentReason, Origin, Priority, ShutdownReport, StopOutcome,
};
use xsel_pendant::sim::FaultSpec;

/// No polling, and a lease long enough that it is not what stops the jog.
fn config() -> LinkConfig {
    LinkConfig {
        jog_lease: Duration::from_secs(600),
        ..quiet_config()
    }
}

/// Starts a continuous jog and waits until the simulator's axis runs.
fn jogging(config: LinkConfig) -> (xsel_pendant::link::LinkHandle, Events, SimHandle) {
    let (link, events, sim) = embedded_link(
        ready_setup(Duration::from_millis(1)),
        FaultSpec::none(),
        None,
        config,
    );
    let id = link.submit(jog_x(), Priority::User);
    let mut seen = Vec::new();
    let answer = wait_for(&events, LONG, &mut seen, answered(id));
    assert!(
        matches!(answer, Some(LinkEvent::Reply { .. })),
        "jog acknowledged: {answer:?}"
    );
    assert_ne!(sim.with(|c| c.in_use()), 0, "the jog runs");
    (link, events, sim)
}

type Events = crossbeam_channel::Receiver<LinkEvent>;
use xsel_pendant::sim::SimHandle;

fn last_report(events: &Events) -> Option<ShutdownReport> {
    let mut seen = Vec::new();
    match wait_for(events, LONG, &mut seen, |e| {
        matches!(e, LinkEvent::ShutDown(_))
    }) {
        Some(LinkEvent::ShutDown(report)) => Some(report),
        _ => None,
    }
}

#[test]
fn explicit_shutdown_mid_jog_stops_the_arm_and_says_so() {
    let (link, _events, sim) = jogging(config());
    let report = link.shutdown();
    assert_eq!(
        report.stops.len(),
        1,
        "one STOP of the link's own: {report:?}"
    );
    assert_eq!(report.stops[0].1, StopOutcome::Acknowledged);
    assert!(report.is_clean(), "{report}");
    assert!(stop_follows_last_jog(&sim), "{:?}", ids_received(&sim));
    assert!(
        eventually(LONG, || sim.with(|c| c.in_use()) == 0),
        "the arm stopped"
    );
}

#[test]
fn dropping_the_handle_right_after_stop_all_sends_that_stop() {
    let (link, events, sim) = jogging(config());
    let stop = link.stop_all();
    drop(link);
    // The STOP goes out before the link ends, in the loop or at shutdown.
    let mut seen = Vec::new();
    let answer = wait_for(&events, LONG, &mut seen, answered(stop));
    assert!(
        matches!(answer, Some(LinkEvent::Reply { .. })),
        "{answer:?}\n{}",
        story(&seen)
    );
    let report = last_report(&events).expect("the report is the last event");
    assert!(report.is_clean(), "{report}");
    let ids = ids_received(&sim);
    let stops = ids.iter().filter(|id| *id == "238").count();
    assert_eq!(
        (ids.last().map(String::as_str), stops),
        (Some("238"), 1),
        "that STOP covers the jog, no second one: {ids:?}"
    );
    assert!(eventually(LONG, || sim.with(|c| c.in_use()) == 0));
}

#[test]
fn dropping_the_handle_mid_jog_stops_the_arm() {
    let (link, events, sim) = jogging(config());
    drop(link);
    let report = last_report(&events).expect("the report is the last event");
    assert!(report.is_clean(), "{report}");
    assert!(stop_follows_last_jog(&sim), "{:?}", ids_received(&sim));
    assert!(
        eventually(LONG, || sim.with(|c| c.in_use()) == 0),
        "the arm stopped"
    );
}

#[test]
fn dropping_the_handle_with_the_jog_in_flight_never_leaves_it_running() {
    // A slow reply: the drop lands while the jog waits for its answer (or before it is
    // sent). Either the jog never goes out, or a STOP follows it.
    let (link, events, sim) = embedded_link(
        ready_setup(Duration::from_millis(30)),
        FaultSpec::none(),
        None,
        config(),
    );
    let mut seen = Vec::new();
    wait_for(&events, LONG, &mut seen, |e| {
        matches!(e, LinkEvent::Connected { .. })
    })
    .expect("connected");
    let jog = link.submit(jog_x(), Priority::User);
    wait_for(
        &events,
        LONG,
        &mut seen,
        |e| matches!(e, LinkEvent::FrameSent { id, .. } if *id == jog),
    )
    .expect("the jog went out");
    drop(link);
    let report = last_report(&events).expect("the report is the last event");
    assert!(report.is_clean(), "{report}");
    assert!(stop_follows_last_jog(&sim), "{:?}", ids_received(&sim));
    assert!(eventually(LONG, || sim.with(|c| c.in_use()) == 0));
}

#[test]
fn shutting_down_with_the_line_down_is_bounded_and_names_the_stop_it_could_not_send() {
    let (link, events, sim) = jogging(config());
    drop(sim);
    let mut seen = Vec::new();
    wait_for(&events, LONG, &mut seen, |e| {
        matches!(e, LinkEvent::Disconnected { .. })
    })
    .expect("the line was lost");
    let (tx, rx) = crossbeam_channel::bounded(1);
    std::thread::spawn(move || {
        let _ = tx.send(link.shutdown());
    });
    let report = rx.recv_timeout(LONG).expect("the shutdown did not hang");
    assert_eq!(report.stops.len(), 1, "{report:?}");
    assert_eq!(
        report.stops[0].1,
        StopOutcome::NotSent(NotSentReason::LineDown)
    );
    assert!(report.motion_may_run, "the arm may still be moving");
    assert!(!report.is_clean());
    assert!(
        report.to_string().contains("may still be moving"),
        "{report}"
    );
}

#[test]
fn a_jog_whose_lease_is_not_renewed_is_stopped_by_the_link() {
    let lease = Duration::from_millis(150);
    let (link, events, sim) = embedded_link(
        ready_setup(Duration::from_millis(1)),
        FaultSpec::none(),
        None,
        LinkConfig {
            jog_lease: lease,
            ..quiet_config()
        },
    );
    let jog = link.submit(jog_x(), Priority::User);
    let mut seen = Vec::new();
    wait_for(&events, LONG, &mut seen, answered(jog)).expect("jog answered");
    // Nobody renews the lease: the link stops the jog by itself.
    let stop = wait_for(&events, LONG, &mut seen, |e| {
        matches!(
            e,
            LinkEvent::Reply {
                origin: Origin::LeaseLapsed,
                ..
            }
        )
    });
    assert!(stop.is_some(), "{}", story(&seen));
    assert!(stop_follows_last_jog(&sim), "{:?}", ids_received(&sim));
    assert!(eventually(LONG, || sim.with(|c| c.in_use()) == 0));
    drop(link);
}

#[test]
fn a_renewed_lease_keeps_the_jog_running() {
    let lease = Duration::from_millis(150);
    let (link, events, sim) = embedded_link(
        ready_setup(Duration::from_millis(1)),
        FaultSpec::none(),
        None,
        LinkConfig {
            jog_lease: lease,
            ..quiet_config()
        },
    );
    let jog = link.submit(jog_x(), Priority::User);
    let mut seen = Vec::new();
    wait_for(&events, LONG, &mut seen, answered(jog)).expect("jog answered");
    // Renewed well within the lease for four lease lengths: no STOP goes out (the watch
    // fails the moment one does).
    let stopped = eventually(4 * lease, || {
        link.renew_jog_lease();
        ids_received(&sim).iter().any(|id| id == "238")
    });
    while let Ok(e) = events.try_recv() {
        seen.push(e);
    }
    assert!(
        !stopped,
        "a STOP while the lease was renewed: {}",
        story(&seen)
    );
    assert_ne!(sim.with(|c| c.in_use()), 0, "still jogging");
    // Released: the link stops it.
    assert!(eventually(LONG, || stop_follows_last_jog(&sim)));
    drop(link);
}

#[test]
fn a_refused_jog_leaves_no_lease_to_lapse_but_a_running_one_keeps_its_lease() {
    let lease = Duration::from_millis(150);
    let (link, events, sim) = embedded_link(
        ready_setup(Duration::from_millis(1)),
        FaultSpec::none(),
        None,
        LinkConfig {
            jog_lease: lease,
            ..quiet_config()
        },
    );
    let mut seen = Vec::new();
    // A jog that runs, then a second one refused while it runs (axis busy): the first
    // still lives on the lease, and the link stops it when nobody renews.
    let running = link.submit(jog_x(), Priority::User);
    let answer = wait_for(&events, LONG, &mut seen, answered(running));
    assert!(
        matches!(answer, Some(LinkEvent::Reply { .. })),
        "{}",
        story(&seen)
    );
    let busy = link.submit(jog_x(), Priority::User);
    let answer = wait_for(&events, LONG, &mut seen, answered(busy));
    assert!(
        matches!(answer, Some(LinkEvent::ErrorReply { .. })),
        "{}",
        story(&seen)
    );
    let stop = wait_for(&events, LONG, &mut seen, |e| {
        matches!(
            e,
            LinkEvent::Reply {
                origin: Origin::LeaseLapsed,
                ..
            }
        )
    });
    assert!(
        stop.is_some(),
        "the running jog lost its lease: {}",
        story(&seen)
    );
    assert!(eventually(LONG, || sim.with(|c| c.in_use()) == 0));
    // Refused with nothing running (E-stop): the lease has nothing to stop.
    let stops = || ids_received(&sim).iter().filter(|id| *id == "238").count();
    let before = stops();
    sim.set_emergency_stop(true);
    let refused = link.submit(jog_x(), Priority::User);
    let answer = wait_for(&events, LONG, &mut seen, answered(refused));
    assert!(
        matches!(answer, Some(LinkEvent::ErrorReply { .. })),
        "{}",
        story(&seen)
    );
    // Watched for four lease lengths, failing the moment a STOP goes out: no later event
    // could show that a lease never armed did not lapse.
    let stopped = eventually(4 * lease, || stops() != before);
    assert!(
        !stopped,
        "a STOP for a jog that never ran: {}",
        story(&seen)
    );
    drop(link);
}

#[test]
fn a_jog_whose_lease_lapses_before_it_is_sent_is_not_sent() {
    let (link, events, sim) = embedded_link(
        ready_setup(Duration::from_millis(1)),
        FaultSpec::none(),
        None,
        LinkConfig {
            jog_lease: Duration::from_millis(50),
            ..quiet_config()
        },
    );
    // A query answered late holds the line while the jog waits behind it and nobody
    // renews the jog's lease.
    sim.set_faults({
        let mut f = FaultSpec::none().with(xsel_pendant::sim::Fault::Delay, 1.0);
        f.delay = Duration::from_millis(200);
        f
    });
    let _slow = link.submit(
        xsel_pendant::protocol::Command::SystemStatus,
        Priority::User,
    );
    let jog = link.submit(jog_x(), Priority::User);
    let mut seen = Vec::new();
    let answer = wait_for(&events, LONG, &mut seen, answered(jog));
    assert!(
        matches!(
            answer,
            Some(LinkEvent::NotSent {
                reason: NotSentReason::LeaseLapsed,
                ..
            })
        ),
        "{answer:?}\n{}",
        story(&seen)
    );
    assert!(!ids_received(&sim).iter().any(|id| id == "236"));
    assert_eq!(sim.with(|c| c.in_use()), 0);
    drop(link);
}
