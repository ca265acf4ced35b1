//! Connection auto-detect against the simulator served on a pseudo-terminal. A pty ignores
//! baud rates, so the simulator answers at every setting: these tests check stations,
//! cancelling and open errors; wrong-baud garbage is covered by the classifier's unit tests.
#![cfg(unix)]

use std::sync::Arc;
use std::time::{Duration, Instant};

use xsel_pendant::link::probe::{
    Outcome, ProbeEnd, ProbeError, ProbeEvent, ProbePlan, ProbeReport, spawn_probe,
};
use xsel_pendant::protocol::{Station, SystemMode};
use xsel_pendant::sim::runner::{PtyServer, RunOptions, SimCore, start_pty};
use xsel_pendant::sim::{Controller, FaultSpec, SimSetup};

fn sim_at_station(station: u8) -> PtyServer {
    let mut setup = SimSetup::default();
    setup.config.station = station;
    setup.config.reply_delay = Duration::from_millis(1);
    start_pty(
        SimCore::new(Controller::new(setup), FaultSpec::none()),
        RunOptions::default(),
    )
    .expect("pty")
}

/// Runs a probe on its thread to the end; its report and every event.
fn probe(path: &str, plan: &ProbePlan) -> (ProbeReport, Vec<ProbeEvent>) {
    let handle = spawn_probe(path.to_owned(), plan.clone(), Arc::new(|| {})).expect("thread");
    let deadline = Instant::now() + Duration::from_secs(30);
    let mut events = Vec::new();
    loop {
        let left = deadline.saturating_duration_since(Instant::now());
        let event = handle.events.recv_timeout(left).expect("the probe ends");
        events.push(event.clone());
        if let ProbeEvent::Finished(report) = event {
            assert!(
                handle.join().is_some_and(|r| r == report),
                "the thread ends with the same report"
            );
            return (report, events);
        }
    }
}

#[test]
fn finds_the_simulator_at_station_99_at_the_first_baud_rate() {
    let sim = sim_at_station(0x99);
    let (report, events) = probe(&sim.path, &ProbePlan::default());
    assert_eq!(report.end, ProbeEnd::Found, "{}", report.summary());
    let found = report.found().expect("an answer");
    assert_eq!(found.candidate.line.baud, 115_200);
    assert_eq!(found.candidate.station, Station(0x99));
    let Outcome::Answered { station, status } = &found.outcome else {
        panic!("{:?}", found.outcome);
    };
    assert_eq!(*station, Station(0x99));
    assert_eq!(status.mode, SystemMode::AUTO);
    assert!(matches!(events.last(), Some(ProbeEvent::Finished(_))));
    // The port is closed again: the next probe (or the link) can open it.
    let (again, _) = probe(&sim.path, &ProbePlan::default());
    assert_eq!(again.end, ProbeEnd::Found, "{}", again.summary());
    assert!(sim.handle.counters().frames >= 2);
}

#[test]
fn another_station_is_found_only_when_stations_are_swept() {
    let sim = sim_at_station(0x05);
    let plan = ProbePlan {
        bauds: vec![115_200],
        ..ProbePlan::default()
    };
    let (report, _) = probe(&sim.path, &plan);
    assert_eq!(report.end, ProbeEnd::Exhausted);
    assert!(report.found().is_none());
    assert!(
        report.results.iter().all(|r| r.outcome == Outcome::Silence),
        "{report:?}"
    );
    // The simulator heard 99 and stayed silent, as a controller does (PROTOCOL.md 1.6).
    assert!(sim.handle.counters().silent_station >= 1);
    let (report, _) = probe(&sim.path, &plan.with_station_sweep());
    assert_eq!(report.end, ProbeEnd::Found, "{}", report.summary());
    // 99, then 00 to 05.
    assert_eq!(report.results.len(), 7);
    assert_eq!(
        report.found().map(|r| r.candidate.station),
        Some(Station(0x05))
    );
}

#[test]
fn a_cancel_mid_sweep_ends_the_probe_promptly() {
    let sim = sim_at_station(0xFE);
    let plan = ProbePlan::default().with_station_sweep();
    let handle = spawn_probe(sim.path.clone(), plan, Arc::new(|| {})).expect("thread");
    let deadline = Instant::now() + Duration::from_secs(20);
    let mut tried = 0;
    let report = loop {
        let left = deadline.saturating_duration_since(Instant::now());
        match handle.events.recv_timeout(left) {
            Ok(ProbeEvent::Tried { tried: n, .. }) => {
                tried = n;
                if n == 3 {
                    handle.cancel();
                }
            }
            Ok(ProbeEvent::Finished(report)) => break report,
            Ok(ProbeEvent::Trying { .. }) => {}
            Err(e) => panic!("no Finished after {tried} candidates: {e}"),
        }
    };
    assert_eq!(report.end, ProbeEnd::Cancelled);
    assert!(report.results.len() >= 3 && report.results.len() < report.total);
    handle.join();
}

#[test]
fn a_missing_port_gives_a_clear_error() {
    let (report, events) = probe("/dev/no-such-xsel-port", &ProbePlan::default());
    let ProbeEnd::Failed(err) = &report.end else {
        panic!("{report:?}");
    };
    assert!(matches!(err, ProbeError::NotFound { .. }), "{err:?}");
    let text = err.to_string();
    assert!(
        text.starts_with("/dev/no-such-xsel-port: no such port"),
        "{text}"
    );
    assert_eq!(report.summary(), text);
    assert!(report.results.is_empty());
    assert_eq!(events.len(), 1);
}
