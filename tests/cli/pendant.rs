//! The real `xsel-pendant` binary under bad input: bad flags, a line that cannot be opened,
//! a closed stdout, a peer that floods bytes, a line that goes down under `--watch`.

use std::io::Write;
use std::net::TcpListener;
use std::process::{Command, Stdio};
use std::sync::mpsc::{Receiver, RecvTimeoutError, channel};
use std::time::{Duration, Instant};

use crate::bin_common::*;
use crate::wait::PROCESS;

#[cfg(windows)]
const MISSING_PORT: &str = "COM199";
#[cfg(not(windows))]
const MISSING_PORT: &str = "/dev/xsel-pendant-no-such-port";

#[test]
fn every_bad_line_flag_exits_2_with_one_line_naming_it_whatever_the_line() {
    let tcp = refused_addr();
    let lines: [&[&str]; 3] = [&[], &["--tcp", &tcp], &["--port", MISSING_PORT]];
    for line in lines {
        for (flag, value) in [
            ("--baud", "0"),
            ("--baud", "99999999"),
            ("--data-bits", "9"),
            ("--stop-bits", "3"),
            ("--station", "099"),
            ("--parity", "mark"),
        ] {
            let mut args = line.to_vec();
            args.extend([flag, value, "--watch"]);
            let run = run(PENDANT, &args, PROCESS);
            let code = run.status.and_then(|s| s.code());
            assert_eq!(code, Some(2), "{args:?}: {}", run.stderr);
            let err: Vec<&str> = run.stderr.lines().collect();
            assert_eq!(err.len(), 1, "{args:?}: {}", run.stderr);
            assert!(err[0].contains(flag), "{args:?}: {}", run.stderr);
            assert_no_panic(&run.stderr);
            assert!(
                !run.stdout.contains("connected"),
                "{args:?}: {}",
                run.stdout
            );
        }
    }
}

#[test]
fn a_line_that_cannot_be_opened_is_reported_at_once() {
    let tcp = refused_addr();
    for args in [
        vec!["--headless", "--port", MISSING_PORT],
        vec!["--headless", "--tcp", &tcp],
        vec!["--tcp", &tcp, "--watch"],
    ] {
        let run = run(PENDANT, &args, PROCESS);
        let status = run.status.expect("exits by itself");
        assert!(!status.success(), "{args:?}");
        assert_ne!(status.code(), Some(101), "{args:?}");
        let err: Vec<&str> = run.stderr.lines().collect();
        assert_eq!(err.len(), 1, "{args:?}: {}", run.stderr);
        assert!(err[0].contains("cannot open"), "{args:?}: {}", run.stderr);
        assert!(
            !run.stdout.contains("desktop window") && !run.stdout.contains("no status"),
            "{args:?}: boilerplate after a failed open: {}",
            run.stdout
        );
    }
}

/// Where a window needs X11 or Wayland (Linux, the BSDs), none opens without them.
#[cfg(all(unix, not(target_os = "macos")))]
#[test]
fn with_no_display_the_window_says_to_use_headless() {
    for args in [vec![], vec!["--sim", "--baud", "9600"]] {
        let run = run(PENDANT, &args, PROCESS);
        let status = run.status.expect("exits by itself");
        assert_eq!(status.code(), Some(2), "{args:?}");
        let err: Vec<&str> = run.stderr.lines().collect();
        assert_eq!(err.len(), 1, "{args:?}: {}", run.stderr);
        assert!(
            err[0].contains("no display") && err[0].contains("--headless"),
            "{}",
            err[0]
        );
        assert_no_panic(&run.stderr);
    }
}

/// Windows needs no DISPLAY: without one the window opens (under Wine, on Wine's own
/// display) and runs until it is closed, killed here; it is not refused.
#[cfg(windows)]
#[test]
fn on_windows_the_window_opens_without_a_display_variable() {
    let run = run(PENDANT, &["--no-rmc"], Duration::from_secs(8));
    assert!(
        run.status.is_none(),
        "the window ran until it was closed: {:?} {}",
        run.status,
        run.stderr
    );
    assert!(!run.stderr.contains("no display"), "{}", run.stderr);
    assert_no_panic(&run.stderr);
}

#[test]
fn a_closed_stdout_ends_watch_quietly() {
    let mut child = Command::new(PENDANT)
        .args(["--watch"])
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("starts");
    let out = lines_of(child.stdout.take().expect("stdout"));
    let err = lines_of(child.stderr.take().expect("stderr"));
    let got = wait_line(&out, |l| l.starts_with("link: connected"), PROCESS);
    assert!(got.is_ok(), "no connection: {got:?}");
    // Closing our end of the pipe is `| head -2`.
    drop(out);
    let status = wait_exit(&mut child, PROCESS);
    let status = status.expect("ends by itself once stdout is closed");
    assert_ne!(status.code(), Some(101));
    assert!(status.success(), "{status:?}");
    let stderr: Vec<String> = err.try_iter().collect();
    assert_no_panic(&stderr.join("\n"));
}

/// A peer that sends bytes with no line end at about 10 MB/s until `stop` is dropped.
fn flood_server(stop: Receiver<()>) -> String {
    let listener = TcpListener::bind("127.0.0.1:0").expect("bind");
    let addr = listener.local_addr().expect("addr").to_string();
    std::thread::spawn(move || {
        let Ok((mut peer, _)) = listener.accept() else {
            return;
        };
        let chunk = vec![b'x'; 64 * 1024];
        let start = Instant::now();
        let mut sent = 0u64;
        // Bounded in time whatever the test does.
        while start.elapsed() < Duration::from_secs(30) {
            let due = start.elapsed().as_secs_f64() * 10e6;
            if (sent as f64) < due {
                if peer.write_all(&chunk).is_err() {
                    return;
                }
                sent += chunk.len() as u64;
            } else {
                // Ahead of the rate: a moment's wait, which the stop ends.
                match stop.recv_timeout(Duration::from_millis(2)) {
                    Err(RecvTimeoutError::Timeout) => {}
                    Ok(()) | Err(RecvTimeoutError::Disconnected) => return,
                }
            }
        }
    });
    addr
}

#[test]
fn a_flooding_peer_gets_a_few_short_lines_and_little_memory() {
    let (stop, stopped) = channel::<()>();
    let addr = flood_server(stopped);
    let started = Instant::now();
    let mut child = Command::new(PENDANT)
        .args(["--tcp", &addr, "--watch"])
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("starts");
    let out = lines_of(child.stdout.take().expect("stdout"));
    let mut lines = Vec::new();
    let mut bad = 0;
    let mut max_rss = 0;
    let deadline = started + Duration::from_secs(30);
    // Watch until the third line about bad input (about 2 s of flood).
    while bad < 3 && Instant::now() < deadline {
        if let Ok(line) = out.recv_timeout(Duration::from_millis(100)) {
            bad += usize::from(line.contains("bad input"));
            lines.push(line);
        }
        max_rss = max_rss.max(rss_kb(child.id()).unwrap_or(0));
    }
    let ran = started.elapsed();
    drop(stop);
    let _ = child.kill();
    let _ = child.wait();
    let text = lines.join("\n");
    assert_eq!(bad, 3, "the flood was not reported:\n{text}");
    // At most one line a second (plus the first at once).
    let allowed = ran.as_secs_f64().ceil() as usize + 1;
    assert!(bad <= allowed, "{bad} lines in {ran:?}:\n{text}");
    for line in &lines {
        assert!(line.len() < 400, "a long line: {} characters", line.len());
    }
    assert!(text.len() < 16 * 1024, "{} bytes of output", text.len());
    assert!(max_rss < 200 * 1024, "resident memory {max_rss} kB");
}

#[test]
fn watch_shows_the_controller_and_no_position_while_the_line_is_down() {
    let start_sim = |addr: &str| {
        let mut sim = Command::new(SIM)
            .args(["--tcp", addr, "--quiet"])
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(Stdio::null())
            .spawn()
            .expect("simulator starts");
        let out = lines_of(sim.stdout.take().expect("stdout"));
        let addr = out.recv_timeout(PROCESS).expect("address");
        (sim, addr)
    };
    let (mut sim, addr) = start_sim("127.0.0.1:0");
    let mut pendant = Command::new(PENDANT)
        .args(["--tcp", &addr, "--watch"])
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .expect("starts");
    let out = lines_of(pendant.stdout.take().expect("stdout"));
    let within = PROCESS;
    let first = wait_line(&out, |l| l.starts_with("controller: "), within);
    assert!(first.is_ok(), "no controller line: {first:?}");
    assert!(wait_line(&out, |l| l.starts_with("SCARA: "), within).is_ok());
    let _ = sim.kill();
    let _ = sim.wait();
    let down = wait_line(&out, |l| l.contains("line down"), within);
    assert!(down.is_ok(), "the loss was not reported: {down:?}");
    // Three watch periods (500 ms each) with the line down, failing the moment a position
    // is printed; then the simulator comes back on the same address.
    let down_for = Duration::from_millis(1500);
    let early = wait_line(
        &out,
        |l| l.starts_with("SCARA") || l.starts_with("  "),
        down_for,
    );
    assert!(
        early.is_err(),
        "a position printed while the line was down: {early:?}"
    );
    let (mut sim, _) = start_sim(&addr);
    let back = wait_line(&out, |l| l.contains("reconnected"), within);
    let _ = pendant.kill();
    let _ = pendant.wait();
    let _ = sim.kill();
    let _ = sim.wait();
    let (_, while_down) = back.expect("reconnected");
    assert!(
        !while_down
            .iter()
            .any(|l| l.starts_with("SCARA") || l.starts_with("  ")),
        "a position printed while the line was down: {while_down:?}"
    );
}
