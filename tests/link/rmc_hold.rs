//! The first held RMC jog over TCP through a guardian process runs until it is released:
//! the pendant's axes model, driven frame by frame as the window drives it (a press, the
//! lease renewed once a frame, the calls forwarded to the link in order), holds a jog for
//! 3 s on a fresh connection; no Stop (6) of the link's own comes before the release.

use std::net::TcpListener;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::{Duration, Instant};

use xsel_pendant::link::RENEW_EVERY;
use xsel_pendant::pendant::axes::{AxisCall, AxisIntent, AxisJog, RmcAxes, RmcSettings};
use xsel_pendant::pendant::{JogInput, JogMode, Press};
use xsel_pendant::protocol::Direction;
use xsel_pendant::rmc::{AxisId, Command, RmcEvent};
use xsel_pendant::session::LineOwner;
use xsel_pendant::session::rmc::RmcSession;
use xsel_pendant::sim::rmc::{RmcConfig, RmcServer};

const HOLD: Duration = Duration::from_secs(3);

#[test]
fn the_first_hold_over_tcp_with_the_guardian_runs_until_release() {
    let listener = TcpListener::bind("127.0.0.1:0").unwrap();
    let server = RmcServer::start(listener, RmcConfig::default()).unwrap();
    let mut settings = RmcSettings {
        address: server.local_addr().to_string(),
        ..RmcSettings::default()
    };
    settings.jog.mode = JogMode::Continuous;
    let owner = LineOwner::Guardian {
        exe: PathBuf::from(env!("CARGO_BIN_EXE_xsel-pendant")),
    };
    let session = RmcSession::open(&settings, Arc::new(|_| {}), &owner).expect("a session");
    let mut model = RmcAxes::new(settings.axis_count());
    let axis = AxisId::new(0).unwrap();
    let target = AxisJog {
        axis,
        direction: Direction::Positive,
    };
    let deadline = Instant::now() + Duration::from_secs(30);
    let mut enable_sent = false;
    let mut pressed: Option<Instant> = None;
    let mut released: Option<Instant> = None;
    let mut safety_stops = Vec::new();
    let mut stops_after_release = 0;
    // One loop turn is one frame of the window: events in, the pointer's state, the calls
    // out in the order the model gives them. As the window does, a frame comes when the
    // link has events, and at the latest a lease renewal after the last one.
    loop {
        assert!(Instant::now() < deadline, "the hold never ended");
        let woke = session.events.recv_timeout(RENEW_EVERY).ok();
        let now = Instant::now();
        for event in woke.into_iter().chain(session.events.try_iter()) {
            match &event {
                RmcEvent::SafetyStop { why, .. } => {
                    safety_stops.push((pressed.map(|p| now - p), why.text()))
                }
                RmcEvent::Sent {
                    command: Command::Stop { .. },
                    ..
                } if released.is_some() => stops_after_release += 1,
                _ => {}
            }
            model.handle_event(now, event);
        }
        if !enable_sent && model.view(axis).is_some_and(|v| v.status.is_some()) {
            model.apply(AxisIntent::Enable(axis, true), &mut settings, now);
            enable_sent = true;
        }
        if pressed.is_none() && model.view(axis).is_some_and(|v| v.enabled()) {
            pressed = Some(now);
        }
        if let Some(p) = pressed
            && released.is_none()
        {
            let press = if now - p < HOLD {
                Press::On(target)
            } else {
                released = Some(now);
                Press::Up
            };
            model.apply(
                AxisIntent::Jog(JogInput::Pointer, press),
                &mut settings,
                now,
            );
        }
        for call in model.take_calls() {
            match call {
                AxisCall::Send(a, c) => {
                    let id = session.link.send(a, c);
                    model.sent(id, a, c);
                }
                AxisCall::Hold(a, j) => {
                    session.link.hold(a, j);
                }
                AxisCall::Release(a) => session.link.release(a),
                AxisCall::RenewLease => session.link.renew_lease(),
                AxisCall::Connect | AxisCall::Disconnect => {}
            }
        }
        if stops_after_release > 0 {
            break;
        }
        if released.is_none() {
            assert!(
                safety_stops.is_empty(),
                "a Stop (6) of the link's own during the hold: {safety_stops:?}"
            );
        }
    }
    assert!(safety_stops.is_empty(), "{safety_stops:?}");
    let moved = {
        let controller = server.controller();
        let mut c = controller.lock().unwrap();
        c.advance(Instant::now());
        c.status(axis).unwrap().target_position
    };
    // At the jog's speed for 3 s, less what a slow frame costs on a loaded machine.
    let least = settings.jog.speed * 2.0;
    assert!(
        moved >= least,
        "the axis ran {moved}, at least {least} expected"
    );
}

/// A hold let go at once (a press and a release a moment apart, the release on the STOP
/// channel): however the link thread takes the two in, the release ends the hold; no jog
/// is left running for the link to stop when its lease lapses.
#[test]
fn a_hold_released_at_once_never_runs_until_its_lease_lapses() {
    let listener = TcpListener::bind("127.0.0.1:0").unwrap();
    let server = RmcServer::start(listener, RmcConfig::default()).unwrap();
    let settings = RmcSettings {
        address: server.local_addr().to_string(),
        ..RmcSettings::default()
    };
    let session =
        RmcSession::open(&settings, Arc::new(|_| {}), &LineOwner::InProcess).expect("a session");
    let axis = AxisId::new(0).unwrap();
    let deadline = Instant::now() + Duration::from_secs(30);
    let wait = |what: &str, done: &dyn Fn(&RmcEvent) -> bool| loop {
        assert!(Instant::now() < deadline, "never saw {what}");
        if let Ok(e) = session.events.recv_timeout(Duration::from_millis(100))
            && done(&e)
        {
            return;
        }
    };
    session.link.send(axis, Command::Enable(true));
    wait(
        "the axis enabled",
        &|e| matches!(e, RmcEvent::Status { status, trusted: true, .. } if status.bits.enabled()),
    );
    let jog = xsel_pendant::rmc::HoldJog {
        direction: 1.0,
        speed: 10.0,
        accel: 100.0,
        decel: 100.0,
    };
    let mut lapsed = 0;
    // Before the release was sent again in order, about one in ten was left running.
    for _ in 0..16 {
        session.link.hold(axis, jog);
        session.link.release(axis);
        // Longer than a lease: a jog left running would be stopped for it by now.
        let until = Instant::now() + xsel_pendant::link::JOG_LEASE * 2;
        while Instant::now() < until {
            if let Ok(RmcEvent::SafetyStop { .. }) =
                session.events.recv_timeout(Duration::from_millis(20))
            {
                lapsed += 1;
            }
        }
    }
    assert_eq!(lapsed, 0, "holds left running until their lease lapsed");
}
