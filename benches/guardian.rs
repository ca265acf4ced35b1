//! The guardian's costs, against a TCP simulator paced at 115200 baud with the link
//! polling as in the window:
//! - submit of a 2D5H step to its first byte at the simulator, in-process and through the
//!   guardian (median, p99, max of 200 each);
//! - a jogging window process killed (SIGKILL / TerminateProcess) to 238H at the
//!   simulator (median and max of 15);
//! - the guardian's resident memory while polling (Linux, from /proc).
//!
//! `cargo bench --bench guardian`. The bench binary is also the window process it kills.

use std::io::{BufRead, BufReader};
use std::path::PathBuf;
use std::process::{Command as Process, Stdio};
use std::sync::Arc;
use std::time::{Duration, Instant};
use xsel_pendant::pendant::controller::poll_commands;

use xsel_pendant::link::{LinkEvent, Priority};
use xsel_pendant::pendant::{ConnectionSettings, LineKind};
use xsel_pendant::protocol::{
    ArmPolicy, Axis, AxisPattern, CentiG, Command, Direction, Jog, JogFrame, JogMotion, Milli,
    MmPerSec, PerAxis, Percent, ScaraMotion, ScaraMove,
};
use xsel_pendant::robot::RobotModel;
use xsel_pendant::session::{LineOwner, Session};
use xsel_pendant::sim::runner::{Dir, RunOptions, SimCore, TcpServer, start_tcp};
use xsel_pendant::sim::{Controller, FaultSpec, SimSetup};

const WINDOW_ADDR: &str = "XSEL_GUARDIAN_BENCH_WINDOW";
const LONG: Duration = Duration::from_secs(20);

fn main() {
    if let Ok(addr) = std::env::var(WINDOW_ADDR) {
        return window(&addr);
    }
    if std::env::args().any(|a| a == "--list") {
        return; // `cargo bench -- --list`
    }
    let sim = simulator();
    println!("guardian bench: TCP simulator paced at 115200 baud, link polling every 100 ms");
    for (name, owner) in [
        ("in-process", LineOwner::InProcess),
        ("guardian", guardian()),
    ] {
        let (mut samples, mut queued) = submit_to_first_byte(&sim, &owner, 200);
        report(&format!("submit 2D5H -> first byte, {name}"), &mut samples);
        report(
            &format!("  of which submit -> written by the link, {name}"),
            &mut queued,
        );
    }
    let (mut kills, mut exits) = (Vec::new(), Vec::new());
    for run in 0..15 {
        let (stop, exit) = kill_to_stop(&sim, run);
        kills.push(stop);
        exits.extend(exit);
    }
    report("window killed -> 238H at the simulator", &mut kills);
    if !exits.is_empty() {
        report("window killed -> guardian exited", &mut exits);
    }
}

fn guardian() -> LineOwner {
    LineOwner::Guardian {
        exe: PathBuf::from(env!("CARGO_BIN_EXE_xsel-pendant")),
    }
}

fn simulator() -> TcpServer {
    let mut setup = SimSetup::default();
    setup.config.start_ready = true;
    setup.config.reply_delay = Duration::from_millis(1);
    let core = SimCore::new(Controller::new(setup), FaultSpec::none());
    let options = RunOptions {
        pacing: Some(Duration::from_nanos(86_806)), // 10 bits at 115200 baud
        ..RunOptions::default()
    };
    start_tcp(core, "127.0.0.1:0", options).expect("a TCP simulator")
}

fn settings(sim: &TcpServer) -> ConnectionSettings {
    ConnectionSettings {
        kind: LineKind::Tcp,
        tcp: sim.addr.to_string(),
        ..ConnectionSettings::default()
    }
}

fn open(sim: &TcpServer, owner: &LineOwner) -> Session {
    let model = RobotModel::default_model();
    let session = Session::open(
        &settings(sim),
        &model,
        poll_commands(),
        Arc::new(|_| {}),
        owner,
    )
    .expect("a session");
    wait(&session, |e| matches!(e, LinkEvent::Connected { .. }));
    session
}

fn wait(session: &Session, mut pred: impl FnMut(&LinkEvent) -> bool) -> LinkEvent {
    let deadline = Instant::now() + LONG;
    loop {
        let left = deadline.saturating_duration_since(Instant::now());
        let e = session.events.recv_timeout(left).expect("an event in time");
        if pred(&e) {
            return e;
        }
    }
}

/// When the simulator received the first byte of the last frame with message ID `id`
/// after `since` (its traffic log stamps each frame with the time its first byte came).
fn received_at(sim: &TcpServer, id: &[u8], since: Instant) -> Option<Instant> {
    let started = sim.handle.with_core(|c| c.started());
    sim.handle
        .traffic()
        .into_iter()
        .filter(|t| t.dir == Dir::In && t.bytes.get(3..6) == Some(id))
        .map(|t| started + t.at)
        .rfind(|&at| at >= since)
}

fn step(micrometres: i32) -> Command {
    Command::ScaraMoveRelative(ScaraMove {
        motion: ScaraMotion::Ptp {
            acc: Percent(50),
            dec: Percent(50),
            speed: Percent(30),
            arm: ArmPolicy::KeepNoSwitch,
        },
        targets: PerAxis::new().with(Axis::A1, Milli(micrometres)),
    })
}

/// Submit to arrival at the simulator, and the part of it spent before the link wrote
/// the frame (waiting for the transaction in flight).
fn submit_to_first_byte(
    sim: &TcpServer,
    owner: &LineOwner,
    n: usize,
) -> (Vec<Duration>, Vec<Duration>) {
    let session = open(sim, owner);
    let mut out = Vec::with_capacity(n);
    let mut queued = Vec::with_capacity(n);
    for i in 0..n {
        // Between polls, at a different phase each time.
        std::thread::sleep(Duration::from_millis(7 + (i as u64 * 13) % 50));
        let distance = if i % 2 == 0 { 10 } else { -10 };
        let at = Instant::now();
        let id = session.link.submit(step(distance), Priority::User);
        let mut written = None;
        wait(&session, |e| {
            if let LinkEvent::FrameSent { id: r, at, .. } = e
                && *r == id
            {
                written = Some(*at);
            }
            matches!(e, LinkEvent::Reply { id: r, .. } | LinkEvent::ErrorReply { id: r, .. } if *r == id)
        });
        if let Some(w) = written {
            queued.push(w.saturating_duration_since(at));
        }
        match received_at(sim, b"2D5", at) {
            Some(first) => out.push(first.saturating_duration_since(at)),
            None => eprintln!("sample {i}: the simulator did not log the 2D5H"),
        }
        // Let the short move end before the next.
        let idle = Instant::now() + Duration::from_secs(2);
        while sim.handle.with(|c| c.in_use()) != 0 && Instant::now() < idle {
            std::thread::sleep(Duration::from_millis(2));
        }
    }
    if let LineOwner::Guardian { .. } = owner {
        print_guardian_memory();
    }
    (out, queued)
}

#[cfg(target_os = "linux")]
fn print_guardian_memory() {
    let Ok(dir) = std::fs::read_dir("/proc") else {
        return;
    };
    for entry in dir.flatten() {
        let path = entry.path();
        let cmdline = std::fs::read(path.join("cmdline")).unwrap_or_default();
        if cmdline.windows(10).any(|w| w == b"--guardian") {
            let status = std::fs::read_to_string(path.join("status")).unwrap_or_default();
            for line in status
                .lines()
                .filter(|l| l.starts_with("VmRSS") || l.starts_with("VmHWM"))
            {
                println!("  guardian {}: {line}", path.display());
            }
        }
    }
}

#[cfg(not(target_os = "linux"))]
fn print_guardian_memory() {}

/// One jogging window process killed: the time from the kill to 238H at the simulator,
/// and to the guardian's exit (Linux).
fn kill_to_stop(sim: &TcpServer, run: usize) -> (Duration, Option<Duration>) {
    let mut child = Process::new(std::env::current_exe().expect("this bench"))
        .env(WINDOW_ADDR, sim.addr.to_string())
        .env(
            "XSEL_GUARDIAN_BENCH_DIR",
            if run.is_multiple_of(2) { "-" } else { "+" },
        )
        .stdout(Stdio::piped())
        .spawn()
        .expect("a window process");
    let stdout = child.stdout.take().expect("its stdout");
    let mut lines = BufReader::new(stdout).lines();
    let mut guardian_pid = None;
    loop {
        match lines.next() {
            Some(Ok(l)) if l == "jogging" => break,
            Some(Ok(l)) if l.starts_with("guardian ") => {
                guardian_pid = l["guardian ".len()..].parse::<u32>().ok();
            }
            Some(_) => {}
            None => panic!("the window process ended before jogging"),
        }
    }
    // The next poll's phase differs run to run.
    std::thread::sleep(Duration::from_millis(30 + (run as u64 * 17) % 100));
    let killed = Instant::now();
    child.kill().expect("kill");
    let _ = child.wait();
    let deadline = killed + Duration::from_secs(5);
    let stopped = loop {
        if let Some(at) = received_at(sim, b"238", killed) {
            break at.saturating_duration_since(killed);
        }
        assert!(Instant::now() < deadline, "no 238H after the kill");
        std::thread::sleep(Duration::from_millis(1));
    };
    let exited = guardian_pid.and_then(|pid| {
        while Instant::now() < deadline {
            if !process_runs(pid) {
                return Some(killed.elapsed());
            }
            std::thread::sleep(Duration::from_millis(1));
        }
        None
    });
    // Let the guardian leave before the next window connects.
    std::thread::sleep(Duration::from_millis(300));
    (stopped, exited)
}

/// Whether process `pid` runs (a zombie waiting to be reaped has exited).
#[cfg(target_os = "linux")]
fn process_runs(pid: u32) -> bool {
    std::fs::read_to_string(format!("/proc/{pid}/stat")).is_ok_and(|s| {
        !s.rsplit_once(") ")
            .is_some_and(|(_, rest)| rest.starts_with('Z'))
    })
}

#[cfg(not(target_os = "linux"))]
fn process_runs(_pid: u32) -> bool {
    false
}

/// The window process: a continuous jog held through a guardian until killed.
fn window(addr: &str) {
    let model = RobotModel::default_model();
    let settings = ConnectionSettings {
        kind: LineKind::Tcp,
        tcp: addr.to_owned(),
        ..ConnectionSettings::default()
    };
    let session = loop {
        // The previous guardian may still hold the simulator for a moment.
        let s = Session::open(
            &settings,
            &model,
            poll_commands(),
            Arc::new(|_| {}),
            &guardian(),
        )
        .expect("a session");
        let e = wait(&s, |e| {
            matches!(
                e,
                LinkEvent::Connected { .. } | LinkEvent::Disconnected { .. }
            )
        });
        if let LinkEvent::Connected { line } = &e {
            if let Some(pid) = xsel_pendant::link::transport::guardian_of(line) {
                println!("guardian {pid}");
            }
            break s;
        }
    };
    let direction = if std::env::var("XSEL_GUARDIAN_BENCH_DIR").is_ok_and(|d| d == "+") {
        Direction::Positive
    } else {
        Direction::Negative
    };
    let jog = Command::Jog(Jog {
        axes: AxisPattern::single(Axis::A1),
        direction,
        distance: Milli(0),
        motion: JogMotion::Cartesian {
            frame: JogFrame::Work,
            acc: CentiG(10),
            dec: CentiG(10),
            speed: MmPerSec(5),
        },
    });
    let id = session.link.submit(jog, Priority::User);
    wait(
        &session,
        |e| matches!(e, LinkEvent::Reply { id: r, .. } if *r == id),
    );
    println!("jogging");
    loop {
        session.link.renew_jog_lease();
        let _ = session.events.try_iter().count();
        std::thread::sleep(Duration::from_millis(20));
    }
}

fn report(what: &str, samples: &mut [Duration]) {
    samples.sort();
    let ms = |d: Duration| d.as_secs_f64() * 1e3;
    let at = |q: f64| samples[((samples.len() - 1) as f64 * q).round() as usize];
    println!(
        "{what}: n {}, median {:.2} ms, p99 {:.2} ms, max {:.2} ms",
        samples.len(),
        ms(at(0.5)),
        ms(at(0.99)),
        ms(samples[samples.len() - 1])
    );
}
