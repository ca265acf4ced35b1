//! The guardian process with a real window process around it: a child "window" (this test
//! binary run again as `window_process`) opens a TCP line to a simulator through a
//! guardian (`xsel-pendant --guardian`) and holds a continuous jog; then it is killed,
//! stopped or exits, and the simulator must see 238H after the jog and be idle, and its
//! line must be free for the next client. A relay between guardian and simulator can add
//! junk CR LF lines to what the simulator sends (a noisy bridge).

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

use crate::common::{answered, ids_received, jog_x, ready_setup, stop_follows_last_jog, wait_for};
use crate::wait::{LONG, PROCESS, eventually};

/// Set for the child "window": the simulator's address, and how the window ends.
const WINDOW_ADDR: &str = "XSEL_GUARDIAN_TEST_WINDOW";
const WINDOW_ENDS: &str = "XSEL_GUARDIAN_TEST_ENDS";

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
    let connected = wait_for(&session.events, PROCESS, &mut seen, |e| {
        matches!(e, LinkEvent::Connected { .. })
    });
    let Some(LinkEvent::Connected { line }) = connected else {
        panic!("not connected: {seen:?}");
    };
    println!("connected {line}");
    let id = session.link.submit(jog_x(), Priority::User);
    match wait_for(&session.events, PROCESS, &mut seen, answered(id)) {
        Some(LinkEvent::Reply { .. }) => println!("jogging"),
        other => panic!("the jog was not accepted: {other:?}"),
    }
    let _ = std::io::stdout().flush();
    if std::env::var(WINDOW_ENDS).is_ok_and(|e| e == "exit") {
        // Ten frames of a window, each woken by the link's events or a 20 ms timer.
        for _ in 0..10 {
            session.link.renew_jog_lease();
            let _ = session.events.recv_timeout(Duration::from_millis(20));
        }
        drop(session);
        println!("exited");
        return;
    }
    // Held until the test kills or stops this process: a frame whenever events come, and
    // at least every 20 ms.
    loop {
        session.link.renew_jog_lease();
        let _ = session.events.recv_timeout(Duration::from_millis(20));
        let _ = session.events.try_iter().count();
    }
}

/// A window process jogging on the simulator through its guardian.
struct Window {
    child: Child,
    lines: Receiver<String>,
}

impl Window {
    fn start(sim: &TcpServer, ends: &str) -> Window {
        Window::start_at(&sim.addr.to_string(), sim, ends)
    }

    /// A window whose line goes to `addr` (the simulator `sim`, or a relay to it).
    fn start_at(addr: &str, sim: &TcpServer, ends: &str) -> Window {
        let mut child = Process::new(std::env::current_exe().expect("the test binary"))
            .args([
                "--exact",
                "guardian::window_process",
                "--nocapture",
                "--test-threads=1",
            ])
            .env(WINDOW_ADDR, addr)
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
            match self.lines.recv_timeout(PROCESS) {
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
        eventually(LONG, || sim.handle.with(|c| c.in_use()) == 0),
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
    let free = eventually(LONG, || {
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

/// A noisy bridge: junk lines on top of the simulator's replies.
#[cfg(unix)]
mod noisy_line {
    use std::io::{Read, Write};
    use std::net::{SocketAddr, TcpListener, TcpStream};
    use std::sync::atomic::{AtomicBool, Ordering};
    use std::sync::{Arc, Mutex};
    use std::time::Duration;

    use crossbeam_channel::{RecvTimeoutError, Sender, bounded};

    use super::{Window, assert_stopped, simulator};

    /// A TCP relay from one client to `upstream` that adds junk CR LF lines to what the
    /// client receives once `junk` is set, at about `bytes_per_sec`. Lines from upstream go
    /// to the client whole (junk never cuts a frame).
    struct JunkRelay {
        addr: SocketAddr,
        junk: Arc<AtomicBool>,
        /// Dropped with the relay: its junk writer ends.
        _stop: Sender<()>,
    }

    impl JunkRelay {
        fn start(upstream: SocketAddr, bytes_per_sec: usize) -> JunkRelay {
            let listener = TcpListener::bind("127.0.0.1:0").expect("a relay port");
            let addr = listener.local_addr().expect("its address");
            let junk = Arc::new(AtomicBool::new(false));
            let (stop, stopping) = bounded::<()>(0);
            let junk_on = junk.clone();
            std::thread::spawn(move || {
                let Ok((client, _)) = listener.accept() else {
                    return;
                };
                let Ok(server) = TcpStream::connect(upstream) else {
                    return;
                };
                let _ = client.set_nodelay(true);
                let _ = server.set_nodelay(true);
                let to_client = Arc::new(Mutex::new(client.try_clone().expect("a clone")));
                let (mut from_client, mut to_server) =
                    (client, server.try_clone().expect("a clone"));
                std::thread::spawn(move || {
                    let mut buf = [0u8; 4096];
                    while let Ok(n) = from_client.read(&mut buf) {
                        if n == 0 || to_server.write_all(&buf[..n]).is_err() {
                            return;
                        }
                    }
                });
                let replies = to_client.clone();
                std::thread::spawn(move || {
                    let (mut from_server, mut line) = (server, Vec::new());
                    let mut buf = [0u8; 4096];
                    while let Ok(n) = from_server.read(&mut buf) {
                        if n == 0 {
                            return;
                        }
                        line.extend_from_slice(&buf[..n]);
                        if let Some(end) = line.iter().rposition(|&b| b == b'\n') {
                            let whole: Vec<u8> = line.drain(..=end).collect();
                            let mut c = replies.lock().unwrap_or_else(|p| p.into_inner());
                            if c.write_all(&whole).is_err() {
                                return;
                            }
                        }
                    }
                });
                // Junk in 10 ms slices; a client that does not read holds the writer back.
                let slice: Vec<u8> =
                    b"JJJJJJJJJJJJJJJJJJJJJJJJJJJJJJJJJJJJJJJJJJJJJJJJJJJJJJJJJJJJ\r\n"
                        .repeat((bytes_per_sec / 100 / 62).max(1));
                // A slice every 10 ms until the relay is dropped.
                while let Err(RecvTimeoutError::Timeout) =
                    stopping.recv_timeout(Duration::from_millis(10))
                {
                    if junk_on.load(Ordering::Relaxed) {
                        let mut c = to_client.lock().unwrap_or_else(|p| p.into_inner());
                        if c.write_all(&slice).is_err() {
                            return;
                        }
                    }
                }
            });
            JunkRelay {
                addr,
                junk,
                _stop: stop,
            }
        }
    }

    /// The window is stopped (kill -STOP) mid-jog while the line also carries 400 KB/s of
    /// junk lines: the guardian still stops the arm while the window stays stopped (it used
    /// to block writing the junk to the window's full pipe and send nothing until SIGCONT).
    #[test]
    fn a_stopped_window_on_a_noisy_line_has_the_arm_stopped_while_it_is_stopped() {
        let sim = simulator();
        let relay = JunkRelay::start(sim.addr, 400_000);
        let window = Window::start_at(&relay.addr.to_string(), &sim, "kill");
        relay.junk.store(true, Ordering::Relaxed);
        window.signal("-STOP");
        assert_stopped(&sim);
        window.signal("-CONT");
    }
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
        match wait_for(&session.events, PROCESS, &mut seen, |e| {
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
