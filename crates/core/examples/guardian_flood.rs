//! The guardian on a flooding line, measured (issue 35, finding 5): a stand-in window on a
//! TCP bridge to `xsel-sim --tcp` that adds junk CR LF lines to what the simulator sends
//! (2 MB/s by default), a continuous jog, then `kill -STOP` of the window: the time from
//! the stop to the 238H on the line, and the guardian's resident memory (VmRSS, VmHWM from
//! /proc) after 30 s of junk. Min/median/max over the runs. Linux only.
//!
//! The stand-in window is this program run again: the pendant's own `Session` over a
//! `GuardianLine` (the link, its polls and heartbeats exactly as the window runs them),
//! holding a continuous jog whose lease it renews every 20 ms as the window does while a
//! jog key is held. Its guardian is this program too (`--guardian` runs the same
//! `session::guardian::run` as `xsel-pendant --guardian`).
//!
//! `scripts/guardian-flood.sh` builds and runs it; by hand:
//! `guardian_flood SIM_ADDR [RUNS] [SECONDS] [JUNK_BYTES_PER_SEC]`.

use std::io::{BufRead, BufReader, Read, Write};
use std::net::{Shutdown, SocketAddr, TcpListener, TcpStream};
use std::process::{Child, Command as Process, ExitCode, Stdio};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use crossbeam_channel::{Receiver, unbounded};
use xsel_pendant_core::line::{ConnectionSettings, LineKind};
use xsel_pendant_core::link::transport::guardian_of;
use xsel_pendant_core::link::{LinkEvent, Priority};
use xsel_pendant_core::pendant::controller::poll_commands;
use xsel_pendant_core::protocol::{
    Axis, AxisPattern, CentiG, Command, Direction, Jog, JogFrame, JogMotion, Milli, MmPerSec,
};
use xsel_pendant_core::robot::RobotModel;
use xsel_pendant_core::session::guardian::GUARDIAN_FLAG;
use xsel_pendant_core::session::{LineOwner, Session};

const WINDOW_ADDR: &str = "GUARDIAN_FLOOD_WINDOW";
const WINDOW_DIRECTION: &str = "GUARDIAN_FLOOD_DIRECTION";
const LONG: Duration = Duration::from_secs(20);

fn main() -> ExitCode {
    if std::env::args().nth(1).as_deref() == Some(GUARDIAN_FLAG) {
        return xsel_pendant_core::session::guardian::run();
    }
    if let Ok(addr) = std::env::var(WINDOW_ADDR) {
        window(&addr);
        return ExitCode::SUCCESS;
    }
    let args: Vec<String> = std::env::args().skip(1).collect();
    let Some(sim) = args.first().and_then(|a| a.parse::<SocketAddr>().ok()) else {
        eprintln!("usage: guardian_flood SIM_ADDR [RUNS] [SECONDS] [JUNK_BYTES_PER_SEC]");
        return ExitCode::from(2);
    };
    let arg = |i: usize, default: u64| args.get(i).and_then(|a| a.parse().ok()).unwrap_or(default);
    let (runs, seconds, rate) = (arg(1, 5), arg(2, 30), arg(3, 2_000_000));
    println!(
        "guardian flood: {runs} runs, junk {rate} B/s, window stopped mid-jog for {seconds} s"
    );
    let (mut stops, mut rss, mut hwm) = (Vec::new(), Vec::new(), Vec::new());
    for run in 0..runs {
        let r = measure(sim, run, Duration::from_secs(seconds), rate as usize);
        println!(
            "run {run}: 238H {} after SIGSTOP; guardian VmRSS {} kB before the stop, {} kB after {seconds} s (VmHWM {} kB); junk delivered {:.2} MB/s; window bytes dropped: see the guardian's log",
            r.stop.map_or("never".to_owned(), |d| format!(
                "{:.1} ms",
                d.as_secs_f64() * 1e3
            )),
            r.rss_before,
            r.rss_after,
            r.hwm,
            r.junk_rate / 1e6,
        );
        stops.push(r.stop.map_or(f64::INFINITY, |d| d.as_secs_f64() * 1e3));
        rss.push(r.rss_after as f64 / 1024.0);
        hwm.push(r.hwm as f64 / 1024.0);
    }
    summary("SIGSTOP -> 238H on the line, ms", &mut stops);
    summary("guardian VmRSS after the flood, MB", &mut rss);
    summary("guardian VmHWM (peak), MB", &mut hwm);
    ExitCode::SUCCESS
}

fn summary(name: &str, v: &mut [f64]) {
    v.sort_by(f64::total_cmp);
    let median = v[v.len() / 2];
    println!(
        "{name}: min {:.1}, median {median:.1}, max {:.1} (n = {})",
        v[0],
        v[v.len() - 1],
        v.len()
    );
}

struct Run {
    stop: Option<Duration>,
    rss_before: u64,
    rss_after: u64,
    hwm: u64,
    junk_rate: f64,
}

fn measure(sim: SocketAddr, run: u64, hold: Duration, rate: usize) -> Run {
    let relay = Relay::start(sim, rate);
    let mut window = Window::start(relay.addr, run);
    let guardian = window.guardian;
    relay.junk.store(true, Ordering::Relaxed);
    std::thread::sleep(Duration::from_secs(1)); // the living window reads the junk
    let rss_before = status_kb(guardian, "VmRSS:");
    let junk_from = relay.junk_bytes.load(Ordering::Relaxed);
    let stopped = Instant::now();
    signal(window.child.id(), "-STOP");
    let deadline = stopped + hold;
    let mut stop = None;
    while Instant::now() < deadline {
        if stop.is_none() {
            stop = relay
                .stops
                .lock()
                .unwrap_or_else(|p| p.into_inner())
                .iter()
                .find(|&&t| t >= stopped)
                .map(|&t| t - stopped);
        }
        std::thread::sleep(Duration::from_millis(1));
    }
    let junk_rate =
        (relay.junk_bytes.load(Ordering::Relaxed) - junk_from) as f64 / hold.as_secs_f64();
    let rss_after = status_kb(guardian, "VmRSS:");
    let hwm = status_kb(guardian, "VmHWM:");
    signal(window.child.id(), "-CONT");
    let _ = window.child.kill();
    let _ = window.child.wait();
    // The guardian exits once the window's pipe is closed (and frees the simulator).
    let gone = Instant::now() + Duration::from_secs(5);
    while std::path::Path::new(&format!("/proc/{guardian}")).exists() && Instant::now() < gone {
        std::thread::sleep(Duration::from_millis(10));
    }
    drop(relay);
    std::thread::sleep(Duration::from_millis(300));
    Run {
        stop,
        rss_before,
        rss_after,
        hwm,
        junk_rate,
    }
}

/// A field of /proc/PID/status in kB (0 when unreadable).
fn status_kb(pid: u32, field: &str) -> u64 {
    std::fs::read_to_string(format!("/proc/{pid}/status"))
        .ok()
        .and_then(|s| {
            s.lines()
                .find_map(|l| l.strip_prefix(field))
                .and_then(|v| v.split_whitespace().next()?.parse().ok())
        })
        .unwrap_or(0)
}

fn signal(pid: u32, name: &str) {
    let _ = Process::new("kill").args([name, &pid.to_string()]).status();
}

/// The stand-in window's body: a session through a guardian, a continuous jog held.
fn window(addr: &str) {
    let settings = ConnectionSettings {
        kind: LineKind::Tcp,
        tcp: addr.to_owned(),
        ..ConnectionSettings::default()
    };
    let owner = LineOwner::Guardian {
        exe: std::env::current_exe().expect("this program"),
    };
    let model = RobotModel::default_model();
    let session = Session::open(&settings, &model, poll_commands(), Arc::new(|_| {}), &owner)
        .expect("a session");
    let deadline = Instant::now() + LONG;
    let line = loop {
        let left = deadline.saturating_duration_since(Instant::now());
        match session.events.recv_timeout(left) {
            Ok(LinkEvent::Connected { line }) => break line,
            Ok(_) => {}
            Err(_) => panic!("not connected"),
        }
    };
    println!(
        "guardian {}",
        guardian_of(&line).expect("a guardian's line")
    );
    let direction = match std::env::var(WINDOW_DIRECTION).as_deref() {
        Ok("-") => Direction::Negative,
        _ => Direction::Positive,
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
    session.link.renew_jog_lease();
    let id = session.link.submit(jog, Priority::User);
    loop {
        let left = deadline.saturating_duration_since(Instant::now());
        match session.events.recv_timeout(left) {
            Ok(LinkEvent::Reply { id: got, .. }) if got == id => break,
            Ok(LinkEvent::ErrorReply { id: got, code, .. }) if got == id => {
                panic!("the jog was refused: {code}")
            }
            Ok(_) => {}
            Err(_) => panic!("the jog was not answered"),
        }
    }
    println!("jogging");
    let _ = std::io::stdout().flush();
    loop {
        session.link.renew_jog_lease();
        let _ = session.events.try_iter().count();
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// A stand-in window process.
struct Window {
    child: Child,
    guardian: u32,
}

impl Window {
    fn start(relay: SocketAddr, run: u64) -> Window {
        let mut child = Process::new(std::env::current_exe().expect("this program"))
            .env(WINDOW_ADDR, relay.to_string())
            .env(
                WINDOW_DIRECTION,
                if run.is_multiple_of(2) { "+" } else { "-" },
            )
            .stdout(Stdio::piped())
            .spawn()
            .expect("the window process");
        let lines = lines_of(child.stdout.take().expect("its stdout"));
        let guardian = expect(&lines, "guardian ")
            .trim()
            .parse()
            .expect("a guardian pid");
        expect(&lines, "jogging");
        Window { child, guardian }
    }
}

fn lines_of(stdout: std::process::ChildStdout) -> Receiver<String> {
    let (tx, rx) = unbounded();
    std::thread::spawn(move || {
        for line in BufReader::new(stdout).lines().map_while(Result::ok) {
            if tx.send(line).is_err() {
                return;
            }
        }
    });
    rx
}

/// The rest of the first line starting with `prefix`.
fn expect(lines: &Receiver<String>, prefix: &str) -> String {
    loop {
        match lines.recv_timeout(LONG) {
            Ok(line) => {
                if let Some(rest) = line.strip_prefix(prefix) {
                    return rest.to_owned();
                }
            }
            Err(_) => panic!("the window never said {prefix:?}"),
        }
    }
}

/// A TCP bridge from one client (the guardian) to the simulator that adds junk CR LF lines
/// to what the client receives once `junk` is set, paced in 10 ms slices; lines from the
/// simulator go through whole (junk never cuts a frame). It notes when each 238H passes
/// towards the simulator.
struct Relay {
    addr: SocketAddr,
    junk: Arc<AtomicBool>,
    junk_bytes: Arc<AtomicU64>,
    stops: Arc<Mutex<Vec<Instant>>>,
    stop: Arc<AtomicBool>,
}

impl Relay {
    fn start(upstream: SocketAddr, rate: usize) -> Relay {
        let listener = TcpListener::bind("127.0.0.1:0").expect("a relay port");
        let addr = listener.local_addr().expect("its address");
        let relay = Relay {
            addr,
            junk: Arc::new(AtomicBool::new(false)),
            junk_bytes: Arc::new(AtomicU64::new(0)),
            stops: Arc::new(Mutex::new(Vec::new())),
            stop: Arc::new(AtomicBool::new(false)),
        };
        let (junk_on, junk_bytes, stops, stopping) = (
            relay.junk.clone(),
            relay.junk_bytes.clone(),
            relay.stops.clone(),
            relay.stop.clone(),
        );
        std::thread::spawn(move || {
            let Ok((client, _)) = listener.accept() else {
                return;
            };
            let server = TcpStream::connect(upstream).expect("the simulator");
            let _ = client.set_nodelay(true);
            let _ = server.set_nodelay(true);
            let to_client = Arc::new(Mutex::new(client.try_clone().expect("a clone")));
            let (mut from_client, mut to_server) = (client, server.try_clone().expect("a clone"));
            std::thread::spawn(move || {
                let mut buf = [0u8; 4096];
                let mut tail: Vec<u8> = Vec::new();
                while let Ok(n) = from_client.read(&mut buf) {
                    if n == 0 || to_server.write_all(&buf[..n]).is_err() {
                        break;
                    }
                    let now = Instant::now();
                    tail.extend_from_slice(&buf[..n]);
                    if tail.windows(6).any(|w| w == b"!99238") {
                        stops.lock().unwrap_or_else(|p| p.into_inner()).push(now);
                    }
                    let keep = tail.len().saturating_sub(5);
                    tail.drain(..keep);
                }
                let _ = to_server.shutdown(Shutdown::Both);
            });
            let replies = to_client.clone();
            std::thread::spawn(move || {
                let (mut from_server, mut line) = (server, Vec::new());
                let mut buf = [0u8; 4096];
                while let Ok(n) = from_server.read(&mut buf) {
                    if n == 0 {
                        break;
                    }
                    line.extend_from_slice(&buf[..n]);
                    if let Some(end) = line.iter().rposition(|&b| b == b'\n') {
                        let whole: Vec<u8> = line.drain(..=end).collect();
                        let mut c = replies.lock().unwrap_or_else(|p| p.into_inner());
                        if c.write_all(&whole).is_err() {
                            break;
                        }
                    }
                }
            });
            let line = b"JJJJJJJJJJJJJJJJJJJJJJJJJJJJJJJJJJJJJJJJJJJJJJJJJJJJJJJJJJJJ\r\n";
            let slice = line.repeat((rate / 100 / line.len()).max(1));
            let mut next = Instant::now();
            while !stopping.load(Ordering::Relaxed) {
                next += Duration::from_millis(10);
                std::thread::sleep(next.saturating_duration_since(Instant::now()));
                if junk_on.load(Ordering::Relaxed) {
                    let mut c = to_client.lock().unwrap_or_else(|p| p.into_inner());
                    if c.write_all(&slice).is_err() {
                        break;
                    }
                    junk_bytes.fetch_add(slice.len() as u64, Ordering::Relaxed);
                }
            }
            let _ = to_client
                .lock()
                .unwrap_or_else(|p| p.into_inner())
                .shutdown(Shutdown::Both);
        });
        relay
    }
}

impl Drop for Relay {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
    }
}
