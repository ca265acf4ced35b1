//! The guardian process with a real window process around it: a child "window" (this test
//! binary run again as `window_process`) opens a TCP line to a simulator through a
//! guardian (`xsel-pendant --guardian`) and holds a continuous jog; then it is killed,
//! stopped or exits, and the simulator must see 238H after the jog and be idle, and its
//! line must be free for the next client.

use std::io::{BufRead, BufReader, Write};
use std::path::PathBuf;
use std::process::{Child, Command as Process, Stdio};
use std::sync::Arc;
use std::time::Duration;
use xsel_pendant::pendant::controller::poll_commands;

use crossbeam_channel::{Receiver, unbounded};
use xsel_pendant::link::{LinkEvent, Priority, TcpTransport, Transport};
use xsel_pendant::pendant::{ConnectionSettings, LineKind};
use xsel_pendant::protocol::Command;
use xsel_pendant::robot::RobotModel;
use xsel_pendant::session::{LineOwner, Session};
use xsel_pendant::sim::runner::{RunOptions, SimCore, TcpServer, start_tcp};
use xsel_pendant::sim::{Controller, FaultSpec};

use crate::common::{
    answered, eventually, ids_received, jog_x, ready_setup, stop_follows_last_jog, wait_for,
};

/// Set for the child "window": the simulator's address, and how the window ends.
const WINDOW_ADDR: &str = "XSEL_GUARDIAN_TEST_WINDOW";
const WINDOW_ENDS: &str = "XSEL_GUARDIAN_TEST_ENDS";
const LONG: Duration = Duration::from_secs(20);

fn guardian() -> LineOwner {
    LineOwner::Guardian {
        exe: PathBuf::from(env!("CARGO_BIN_EXE_xsel-pendant")),
    }
}

fn tcp_settings(addr: &str) -> ConnectionSettings {
    ConnectionSettings {
        kind: LineKind::Tcp,
        tcp: addr.to_owned(),
        ..ConnectionSettings::default()
    }
}

fn simulator() -> TcpServer {
    let core = SimCore::new(
        Controller::new(ready_setup(Duration::from_millis(1))),
        FaultSpec::none(),
    );
    start_tcp(core, "127.0.0.1:0", RunOptions::default()).expect("a TCP simulator")
}

/// The child process's body: not a test of its own (it returns at once unless this
/// binary was started as a window by one of the tests below).
#[test]
fn window_process() {
    let Ok(addr) = std::env::var(WINDOW_ADDR) else {
        return;
    };
    let model = RobotModel::default_model();
    let session = Session::open(
        &tcp_settings(&addr),
        &model,
        poll_commands(),
        Arc::new(|_| {}),
        &guardian(),
    )
    .expect("a session");
    let mut seen = Vec::new();
    let connected = wait_for(&session.events, LONG, &mut seen, |e| {
        matches!(e, LinkEvent::Connected { .. })
    });
    let Some(LinkEvent::Connected { line }) = connected else {
        panic!("not connected: {seen:?}");
    };
    println!("connected {line}");
    let id = session.link.submit(jog_x(), Priority::User);
    match wait_for(&session.events, LONG, &mut seen, answered(id)) {
        Some(LinkEvent::Reply { .. }) => println!("jogging"),
        other => panic!("the jog was not accepted: {other:?}"),
    }
    let _ = std::io::stdout().flush();
    if std::env::var(WINDOW_ENDS).is_ok_and(|e| e == "exit") {
        for _ in 0..10 {
            session.link.renew_jog_lease();
            std::thread::sleep(Duration::from_millis(20));
        }
        drop(session);
        println!("exited");
        return;
    }
    // Held until the test kills or stops this process.
    loop {
        session.link.renew_jog_lease();
        let _ = session.events.try_iter().count();
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// A window process jogging on the simulator through its guardian.
struct Window {
    child: Child,
    lines: Receiver<String>,
}

impl Window {
    fn start(sim: &TcpServer, ends: &str) -> Window {
        let mut child = Process::new(std::env::current_exe().expect("the test binary"))
            .args([
                "--exact",
                "guardian::window_process",
                "--nocapture",
                "--test-threads=1",
            ])
            .env(WINDOW_ADDR, sim.addr.to_string())
            .env(WINDOW_ENDS, ends)
            .stdout(Stdio::piped())
            .spawn()
            .expect("the window process");
        let stdout = child.stdout.take().expect("its stdout");
        let (tx, lines) = unbounded();
        std::thread::spawn(move || {
            for line in BufReader::new(stdout).lines().map_while(Result::ok) {
                if tx.send(line).is_err() {
                    return;
                }
            }
        });
        let mut window = Window { child, lines };
        window.expect("jogging");
        assert!(
            sim.handle.with(|c| c.in_use()) != 0,
            "the simulator's axis is not moving"
        );
        window
    }

    /// Waits for a line of the window's output starting with `text`.
    fn expect(&mut self, text: &str) -> String {
        loop {
            match self.lines.recv_timeout(LONG) {
                Ok(line) if line.starts_with(text) => return line,
                Ok(_) => {}
                Err(_) => panic!("the window never said {text:?}"),
            }
        }
    }

    #[cfg(unix)]
    fn signal(&self, name: &str) {
        let status = Process::new("kill")
            .args([name, &self.child.id().to_string()])
            .status()
            .expect("kill");
        assert!(status.success(), "kill {name} failed");
    }
}

impl Drop for Window {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// The arm is idle and the frames after the last jog include 238H.
fn assert_stopped(sim: &TcpServer) {
    assert!(
        eventually(Duration::from_secs(10), || sim.handle.with(|c| c.in_use())
            == 0),
        "the arm still moves"
    );
    assert!(
        stop_follows_last_jog(&sim.handle),
        "no 238H after the jog: {:?}",
        ids_received(&sim.handle)
    );
}

/// A second client is served: the guardian has let go of the line.
fn assert_line_free(sim: &TcpServer) {
    let free = eventually(Duration::from_secs(10), || {
        let Ok(mut t) = TcpTransport::connect(&sim.addr.to_string(), Duration::from_secs(1)) else {
            return false;
        };
        if t.write_all_bytes(b"!992152B\r\n").is_err() {
            return false;
        }
        let mut buf = [0u8; 64];
        matches!(t.read_timeout(&mut buf, Duration::from_millis(500)), Ok(n) if n > 0 && buf[0] == b'#')
    });
    assert!(free, "the line is still held");
}

#[test]
fn a_killed_window_leaves_the_arm_stopped_by_its_guardian_and_the_line_free() {
    let sim = simulator();
    let mut window = Window::start(&sim, "kill");
    window.child.kill().expect("kill the window");
    let _ = window.child.wait();
    assert_stopped(&sim);
    assert_line_free(&sim);
}

#[cfg(unix)]
#[test]
fn a_stopped_window_process_has_the_arm_stopped_while_it_is_stopped() {
    let sim = simulator();
    let window = Window::start(&sim, "kill");
    window.signal("-STOP");
    assert_stopped(&sim);
    window.signal("-CONT");
}

#[test]
fn a_window_that_exits_stops_the_arm_and_its_guardian_frees_the_line() {
    let sim = simulator();
    let mut window = Window::start(&sim, "exit");
    window.expect("exited");
    let _ = window.child.wait();
    assert_stopped(&sim);
    assert_line_free(&sim);
}

#[test]
fn hundreds_of_queries_through_the_guardian_are_all_answered_in_order() {
    let sim = simulator();
    let model = RobotModel::default_model();
    let session = Session::open(
        &tcp_settings(&sim.addr.to_string()),
        &model,
        poll_commands(),
        Arc::new(|_| {}),
        &guardian(),
    )
    .expect("a session");
    let ids: Vec<_> = (0..300)
        .map(|_| session.link.submit(Command::SystemStatus, Priority::User))
        .collect();
    let mut answered_ids = Vec::new();
    let mut seen = Vec::new();
    while answered_ids.len() < ids.len() {
        match wait_for(&session.events, LONG, &mut seen, |e| {
            matches!(
                e,
                LinkEvent::Reply { .. }
                    | LinkEvent::ErrorReply { .. }
                    | LinkEvent::NotSent { .. }
                    | LinkEvent::Timeout { .. }
            )
        }) {
            Some(LinkEvent::Reply { id, .. }) if ids.contains(&id) => answered_ids.push(id),
            Some(LinkEvent::Reply { .. }) => {} // the link's own polls
            other => panic!("not answered: {other:?}"),
        }
    }
    assert_eq!(answered_ids, ids, "answers lost or out of order");
}
