//! The real `xsel-sim` binary under bad input: bad options, and closed stdout and stderr
//! (it keeps serving with logging off).

use std::io::{Read, Write};
use std::net::TcpStream;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use crate::bin_common::*;
use crate::wait::PROCESS;

#[test]
fn every_bad_option_exits_2_with_one_line_naming_it() {
    for (flag, value) in [
        ("--station", "099"),
        ("--station", "9"),
        ("--baud", "0"),
        ("--baud", "99999999"),
        ("--reply-buffer", "1000"),
        ("--delay-ms", "99999999999"),
        ("--linear-axes", "3"),
        ("--robot", "no-such-robot.toml"),
        ("--coords", "no-such-coords.toml"),
        ("--servo-on-ms", "10001"),
        ("--mode", "fast"),
        ("--alarm", "000"),
        ("--alarm", "C7"),
    ] {
        let run = run(SIM, &["--tcp", "127.0.0.1:0", flag, value], PROCESS);
        let code = run.status.and_then(|s| s.code());
        assert_eq!(code, Some(2), "{flag} {value}: {}", run.stderr);
        let err: Vec<&str> = run.stderr.lines().collect();
        assert_eq!(err.len(), 1, "{flag} {value}: {}", run.stderr);
        assert!(err[0].contains(flag), "{flag} {value}: {}", run.stderr);
        assert_no_panic(&run.stderr);
    }
    // A listening address that names nothing, and a robot file that never ends.
    let mut odd = vec![vec!["--tcp", "nowhere"], vec!["--tcp", "127.0.0.1:99999"]];
    if cfg!(target_os = "linux") {
        odd.push(vec!["--tcp", "127.0.0.1:0", "--robot", "/dev/zero"]);
    }
    for args in odd {
        let run = run(SIM, &args, PROCESS);
        assert_eq!(
            run.status.and_then(|s| s.code()),
            Some(2),
            "{args:?}: {}",
            run.stderr
        );
        let err: Vec<&str> = run.stderr.lines().collect();
        assert_eq!(err.len(), 1, "{args:?}: {}", run.stderr);
        assert!(
            err[0].contains(args[args.len() - 2]),
            "{args:?}: {}",
            run.stderr
        );
        assert_no_panic(&run.stderr);
    }
}

/// Sends 215H and reads the reply up to its LF, with a deadline.
fn ask(peer: &mut TcpStream) -> Result<String, String> {
    peer.write_all(b"!99215@@\r\n").map_err(|e| e.to_string())?;
    let deadline = Instant::now() + Duration::from_secs(10);
    let mut got = Vec::new();
    let mut buf = [0u8; 256];
    while !got.ends_with(b"\n") {
        if Instant::now() > deadline {
            return Err(format!(
                "no reply, got {:?}",
                got.escape_ascii().to_string()
            ));
        }
        match peer.read(&mut buf) {
            Ok(0) => return Err("closed".into()),
            Ok(n) => got.extend_from_slice(&buf[..n]),
            // Nothing yet, or a signal (another test's child ending) cut the wait short.
            Err(e)
                if matches!(
                    e.kind(),
                    std::io::ErrorKind::WouldBlock
                        | std::io::ErrorKind::TimedOut
                        | std::io::ErrorKind::Interrupted
                ) => {}
            Err(e) => return Err(e.to_string()),
        }
    }
    Ok(got.escape_ascii().to_string())
}

/// `xsel-sim` serving TCP on a free port, with its output read line by line and one
/// client connected.
struct Served {
    sim: std::process::Child,
    out: std::sync::mpsc::Receiver<String>,
    err: std::sync::mpsc::Receiver<String>,
    peer: TcpStream,
    addr: String,
}

fn serve_tcp(flags: &[&str], stdin: Stdio) -> Served {
    let mut sim = Command::new(SIM)
        .args(["--tcp", "127.0.0.1:0"])
        .args(flags)
        .stdin(stdin)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("starts");
    let out = lines_of(sim.stdout.take().expect("stdout"));
    let err = lines_of(sim.stderr.take().expect("stderr"));
    let addr = out.recv_timeout(PROCESS).expect("address");
    let peer = TcpStream::connect(&addr).expect("connects");
    peer.set_read_timeout(Some(Duration::from_millis(200)))
        .expect("timeout");
    Served {
        sim,
        out,
        err,
        peer,
        addr,
    }
}

#[test]
fn closed_stdout_and_stderr_leave_it_serving_with_logging_off() {
    let Served {
        mut sim,
        out,
        err,
        mut peer,
        ..
    } = serve_tcp(&[], Stdio::null());
    let first = ask(&mut peer);
    assert!(
        first.as_ref().is_ok_and(|r| r.starts_with("#99215")),
        "{first:?}"
    );
    // Two lines of log (the banner, the frame in), then `| head -2` closes the pipe.
    let logged = wait_line(&err, |l| l.contains("rx "), PROCESS);
    assert!(logged.is_ok(), "no log line: {logged:?}");
    // The reader thread lets go of the pipe at the next line it cannot pass on, so
    // later log lines meet a closed pipe.
    drop(err);
    drop(out);
    for _ in 0..20 {
        let reply = ask(&mut peer);
        assert!(
            reply.as_ref().is_ok_and(|r| r.starts_with("#99215")),
            "{reply:?}"
        );
    }
    let still = sim.try_wait().expect("status");
    let _ = sim.kill();
    let _ = sim.wait();
    assert_eq!(
        still, None,
        "the simulator ended when its output was closed"
    );
}

/// Sends one frame (`@@` as SC) and reads the reply up to its LF.
fn send(peer: &mut TcpStream, body: &str) -> String {
    peer.write_all(format!("{body}@@\r\n").as_bytes())
        .expect("write");
    let deadline = Instant::now() + Duration::from_secs(10);
    let mut got = Vec::new();
    let mut buf = [0u8; 1];
    while !got.ends_with(b"\n") && Instant::now() < deadline {
        if let Ok(1) = peer.read(&mut buf) {
            got.push(buf[0]);
        }
    }
    String::from_utf8_lossy(&got).trim_end().to_owned()
}

#[test]
fn the_operator_console_and_start_flags_set_e_stop_mode_and_alarms() {
    let Served {
        mut sim,
        out,
        err,
        mut peer,
        addr,
    } = serve_tcp(&["--estop", "--servo-on-ms", "5"], Stdio::piped());
    let mut console = sim.stdin.take().expect("stdin");
    // Started with the E-stop pressed: servo on is refused (B04).
    assert!(send(&mut peer, "!992320F1").starts_with("&99B04"));
    let mut type_line = |line: &str, want: &str| {
        writeln!(console, "{line}").expect("console");
        let got = wait_line(&out, |l| l.contains(want), PROCESS);
        assert!(got.is_ok(), "`{line}`: no `{want}` on stdout: {got:?}");
    };
    type_line("estop off", "E-stop off");
    assert!(send(&mut peer, "!992320F1").starts_with("#99232"));
    type_line("mode manual", "mode MANUAL");
    assert!(send(&mut peer, "!992330F000000").starts_with("&99B05"));
    type_line("mode auto", "mode AUTO");
    type_line("alarm C74 4", "alarm C74 on axis 4");
    assert!(send(&mut peer, "!992320F1").starts_with("&99B07"));
    // 216H names the alarm.
    assert_eq!(send(&mut peer, "!99216000000").get(6..9), Some("C74"));
    type_line("status", "alarm C74");
    type_line("frobnicate", "unknown command");
    // A second TCP client is refused at once, and the log says so.
    let mut second = TcpStream::connect(&addr).expect("connects");
    second
        .set_read_timeout(Some(Duration::from_secs(5)))
        .expect("timeout");
    let mut buf = [0u8; 8];
    assert!(!matches!(second.read(&mut buf), Ok(n) if n > 0));
    let refused = wait_line(&err, |l| l.contains("refused a second client"), PROCESS);
    assert!(refused.is_ok(), "no log line: {refused:?}");
    type_line("quit", "stopping");
    let status = wait_exit(&mut sim, PROCESS);
    assert!(
        status.is_some_and(|s| s.success()),
        "quit ends it: {status:?}"
    );
}

#[test]
fn help_states_the_client_rule_units_and_console() {
    let run = run(SIM, &["--help"], PROCESS);
    for want in [
        "second client is refused at once",
        "0.001 deg",
        "234H/235H move the linear axes 5-6 only",
        "--servo-on-ms",
        "estop on|off",
        "before homing",
    ] {
        assert!(run.stdout.contains(want), "--help lacks `{want}`");
    }
    // Each program calls itself by its own name.
    assert!(run.stdout.contains("Usage: xsel-sim"), "{}", run.stdout);
    for (exe, name) in [
        (SIM, "xsel-sim"),
        (env!("CARGO_BIN_EXE_rmc-sim"), "rmc-sim"),
    ] {
        let version = crate::bin_common::run(exe, &["--version"], PROCESS);
        assert!(
            version.stdout.starts_with(&format!("{name} ")),
            "{exe} --version says {:?}",
            version.stdout
        );
    }
}
