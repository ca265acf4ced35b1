//! Shared helpers for the tests that run the real binaries: lines as they come, waits with deadlines.
#![allow(dead_code)]

use std::io::{BufRead, BufReader, Read};
use std::process::{Child, Command, ExitStatus, Stdio};
use std::sync::mpsc::{Receiver, RecvTimeoutError, channel};
use std::time::{Duration, Instant};

pub const PENDANT: &str = env!("CARGO_BIN_EXE_xsel-pendant");
pub const SIM: &str = env!("CARGO_BIN_EXE_xsel-sim");

/// Lines read from a pipe on a thread, so waits can have deadlines.
pub fn lines_of(pipe: impl Read + Send + 'static) -> Receiver<String> {
    let (tx, rx) = channel();
    std::thread::spawn(move || {
        for line in BufReader::new(pipe).lines() {
            let Ok(line) = line else { break };
            if tx.send(line).is_err() {
                break;
            }
        }
    });
    rx
}

/// Waits for a line matching `want`, returning it and every line read before it.
pub fn wait_line(
    rx: &Receiver<String>,
    want: impl Fn(&str) -> bool,
    within: Duration,
) -> Result<(String, Vec<String>), Vec<String>> {
    let deadline = Instant::now() + within;
    let mut before = Vec::new();
    loop {
        let left = deadline.saturating_duration_since(Instant::now());
        match rx.recv_timeout(left) {
            Ok(line) if want(&line) => return Ok((line, before)),
            Ok(line) => before.push(line),
            Err(RecvTimeoutError::Timeout | RecvTimeoutError::Disconnected) => return Err(before),
        }
    }
}

/// Waits for the child to exit; kills it (and returns `None`) at the deadline.
pub fn wait_exit(child: &mut Child, within: Duration) -> Option<ExitStatus> {
    let mut status = None;
    if crate::wait::eventually(within, || {
        status = child.try_wait().ok().flatten();
        status.is_some()
    }) {
        return status;
    }
    let _ = child.kill();
    let _ = child.wait();
    None
}

/// What a finished run left.
pub struct Run {
    pub status: Option<ExitStatus>,
    pub stdout: String,
    pub stderr: String,
}

/// Runs a binary to its end (killed after `within`), collecting both outputs.
pub fn run(bin: &str, args: &[&str], within: Duration) -> Run {
    // No display: a run that would open the window ends at once with its one-line error,
    // on a developer's desktop as in CI.
    let mut child = Command::new(bin)
        .args(args)
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the binary starts");
    let out = lines_of(child.stdout.take().expect("stdout"));
    let err = lines_of(child.stderr.take().expect("stderr"));
    let status = wait_exit(&mut child, within);
    let collect = |rx: Receiver<String>| {
        let mut text = String::new();
        while let Ok(line) = rx.recv_timeout(Duration::from_secs(2)) {
            text.push_str(&line);
            text.push('\n');
        }
        text
    };
    Run {
        status,
        stdout: collect(out),
        stderr: collect(err),
    }
}

/// No sign of a panic in a program's output.
pub fn assert_no_panic(text: &str) {
    assert!(
        !text.contains("panicked") && !text.contains("RUST_BACKTRACE"),
        "a panic:\n{text}"
    );
}

/// A loopback TCP port that refuses connections (bound, then closed).
pub fn refused_addr() -> String {
    let listener = std::net::TcpListener::bind("127.0.0.1:0").expect("bind");
    let addr = listener.local_addr().expect("addr");
    drop(listener);
    addr.to_string()
}

/// Resident memory of a process in kB, where the system tells.
#[cfg(target_os = "linux")]
pub fn rss_kb(pid: u32) -> Option<u64> {
    let status = std::fs::read_to_string(format!("/proc/{pid}/status")).ok()?;
    status
        .lines()
        .find_map(|l| l.strip_prefix("VmRSS:"))
        .and_then(|v| v.trim().trim_end_matches("kB").trim().parse().ok())
}

#[cfg(not(target_os = "linux"))]
pub fn rss_kb(_pid: u32) -> Option<u64> {
    None
}

/// `xsel-sim --tcp 127.0.0.1:0` with `flags`, ready for a client: the process (killed
/// when dropped), the address it listens on, and its log lines (stderr) as they come.
pub struct TcpSim {
    pub child: Child,
    pub addr: String,
    pub log: Receiver<String>,
}

impl TcpSim {
    pub fn start(flags: &[&str]) -> TcpSim {
        let mut child = Command::new(SIM)
            .args(["--tcp", "127.0.0.1:0"])
            .args(flags)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .expect("xsel-sim starts");
        let out = lines_of(child.stdout.take().expect("stdout"));
        let log = lines_of(child.stderr.take().expect("stderr"));
        let addr = out
            .recv_timeout(crate::wait::PROCESS)
            .expect("the address on stdout")
            .trim()
            .to_owned();
        TcpSim { child, addr, log }
    }
}

impl Drop for TcpSim {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// Runs the pendant with `flag FILE` where FILE exists: exit 2, one line saying so, and
/// the file as it was.
pub fn assert_existing_file_refused(flag: &str, path: &std::path::Path) {
    std::fs::write(path, "keep me").expect("write");
    let run = run(
        PENDANT,
        &[flag, path.to_str().expect("UTF-8")],
        crate::wait::PROCESS,
    );
    assert_eq!(run.status.and_then(|s| s.code()), Some(2), "{}", run.stderr);
    assert!(run.stderr.contains("the file exists"), "{}", run.stderr);
    assert_eq!(std::fs::read_to_string(path).expect("kept"), "keep me");
    let _ = std::fs::remove_file(path);
}
