//! The RMC151 through a guardian process: a child "window" (this test binary run again as
//! `rmc_window_process`) connects to a simulated RMC151 through `xsel-pendant --guardian`
//! and starts a long move; it is killed mid-move, and the guardian must stop the axis
//! short of the move's end with Stop (6) (the RMC has no host watchdog of its own).

use std::io::{BufRead, BufReader, Write};
use std::net::TcpListener;
use std::path::PathBuf;
use std::process::{Command as Process, Stdio};
use std::sync::Arc;
use std::time::{Duration, Instant};

use xsel_pendant::pendant::axes::RmcSettings;
use xsel_pendant::rmc::{AxisId, Command, MoveRelative, RmcEvent};
use xsel_pendant::robot::RelativeTo;
use xsel_pendant::session::LineOwner;
use xsel_pendant::session::rmc::RmcSession;
use xsel_pendant::sim::rmc::{RmcConfig, RmcServer};

use crate::wait::{PROCESS, until};

const WINDOW_ADDR: &str = "XSEL_RMC_GUARDIAN_TEST_WINDOW";

fn axis0() -> AxisId {
    AxisId::new(0).unwrap()
}

/// The child process's body (returns at once unless started as a window below).
#[test]
fn rmc_window_process() {
    let Ok(addr) = std::env::var(WINDOW_ADDR) else {
        return;
    };
    let settings = RmcSettings {
        address: addr,
        ..RmcSettings::default()
    };
    let owner = LineOwner::Guardian {
        exe: PathBuf::from(env!("CARGO_BIN_EXE_xsel-pendant")),
    };
    let session = RmcSession::open(&settings, Arc::new(|_| {}), &owner).expect("a session");
    let end = Instant::now() + PROCESS;
    let wait = |what: &str, done: &dyn Fn(&RmcEvent) -> bool| loop {
        assert!(Instant::now() < end, "the window never saw {what}");
        if let Ok(e) = session.events.recv_timeout(Duration::from_millis(100))
            && done(&e)
        {
            return;
        }
    };
    wait("the line", &|e| matches!(e, RmcEvent::LineUp { .. }));
    println!("connected");
    session.link.send(axis0(), Command::Enable(true));
    wait(
        "the axis enabled",
        &|e| matches!(e, RmcEvent::Status { status, trusted: true, .. } if status.bits.enabled()),
    );
    session.link.send(
        axis0(),
        Command::MoveRelative(MoveRelative {
            distance: 100.0,
            speed: 10.0,
            accel: 100.0,
            decel: 100.0,
            relative_to: RelativeTo::Command,
        }),
    );
    wait("the move acknowledged", &|e| {
        matches!(e, RmcEvent::Acknowledged { id: Some(_), .. })
    });
    println!("moving");
    let _ = std::io::stdout().flush();
    // Held until the test kills this process.
    loop {
        let _ = session.events.recv_timeout(Duration::from_millis(20));
        let _ = session.events.try_iter().count();
    }
}

/// The window process, killed when the test ends however it ends.
struct Window(std::process::Child);

impl Drop for Window {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

#[test]
fn a_killed_window_leaves_the_rmc_axis_stopped_by_its_guardian() {
    let listener = TcpListener::bind("127.0.0.1:0").unwrap();
    let server = RmcServer::start(listener, RmcConfig::default()).unwrap();
    let controller = server.controller();
    let truth = || {
        let mut c = controller.lock().unwrap();
        c.advance(Instant::now());
        c.status(axis0()).unwrap()
    };
    let mut child = Window(
        Process::new(std::env::current_exe().unwrap())
            .args([
                "--exact",
                "rmc_guardian::rmc_window_process",
                "--nocapture",
                "--test-threads=1",
            ])
            .env(WINDOW_ADDR, server.local_addr().to_string())
            .stdout(Stdio::piped())
            .spawn()
            .expect("the window process"),
    );
    let mut lines = BufReader::new(child.0.stdout.take().unwrap()).lines();
    let moving = lines.any(|l| l.is_ok_and(|l| l.starts_with("moving")));
    assert!(moving, "the window never started its move");
    until("the axis to move", PROCESS, || {
        truth().target_velocity != 0.0
    });
    child.0.kill().expect("kill the window");
    let _ = child.0.wait();
    until("the axis to stop after the window died", PROCESS, || {
        truth().target_velocity == 0.0
    });
    let s = truth();
    assert!(
        s.target_position < 50.0,
        "stopped short of the move's end: {}",
        s.target_position
    );
    assert!(
        !s.bits.in_position(),
        "stopped by Stop (6), not by reaching the end"
    );
}
