//! The `xsel-sim` binary over TCP under abuse, as a hostile or careless host would treat
//! it: an idle client is dropped after `--idle-timeout` and the next one served; a long run
//! of random bytes is followed by an answered frame on the same connection; a stderr
//! nobody reads does not stop it serving; a long reply is logged whole.

use std::io::{Read, Write};
use std::net::TcpStream;
use std::process::ChildStderr;
use std::sync::{Arc, Mutex};

use crate::spawn;
use crate::spawn::{Guard, collect};
use crate::wait::{LONG, PROCESS, eventually, until};
use crate::wire::frame;

/// Starts `xsel-sim --tcp 127.0.0.1:0` with `extra` flags; its address and its stderr.
fn start(extra: &[&str]) -> (Guard, String, ChildStderr) {
    let mut args = vec!["--tcp", "127.0.0.1:0", "--no-console", "--delay-ms", "0"];
    args.extend_from_slice(extra);
    spawn::start(env!("CARGO_BIN_EXE_xsel-sim"), &args)
}

fn has(lines: &Arc<Mutex<Vec<String>>>, what: &str) -> bool {
    lines.lock().unwrap().iter().any(|l| l.contains(what))
}

fn connect(addr: &str) -> TcpStream {
    let s = TcpStream::connect(addr).expect("connects");
    s.set_read_timeout(Some(LONG)).unwrap();
    s
}

/// Sends `bytes` and reads one reply line (up to its LF).
fn ask(s: &mut TcpStream, bytes: &[u8]) -> String {
    s.write_all(bytes).expect("sends");
    let mut reply = Vec::new();
    let mut b = [0u8; 1];
    while reply.last() != Some(&b'\n') {
        match s.read(&mut b) {
            Ok(1) => reply.push(b[0]),
            other => panic!("no reply to {bytes:?} ({other:?}); so far {reply:?}"),
        }
    }
    String::from_utf8_lossy(&reply).into_owned()
}

/// 215H, system status: answered whatever the robot does.
fn status_query() -> Vec<u8> {
    frame("!99215")
}

#[test]
fn an_idle_client_is_dropped_after_the_timeout_and_the_next_one_is_served() {
    let (_sim, addr, stderr) = start(&["--idle-timeout", "1"]);
    let log = collect(stderr);
    let mut idle = connect(&addr);
    until("the client is served", PROCESS, || has(&log, "connected"));
    // It stays connected, silent, as a PC that lost its network (no FIN).
    until("the silent client is dropped", PROCESS, || {
        has(&log, "dropped: silent for 1 s")
    });
    let mut b = [0u8; 1];
    assert_eq!(idle.read(&mut b).ok(), Some(0), "its connection is closed");
    let mut next = connect(&addr);
    assert!(ask(&mut next, &status_query()).starts_with("#99215"));
}

#[test]
fn the_idle_timeout_zero_keeps_a_silent_client() {
    let (_sim, addr, stderr) = start(&["--idle-timeout", "0"]);
    let log = collect(stderr);
    let mut first = connect(&addr);
    assert!(ask(&mut first, &status_query()).starts_with("#99215"));
    // A second client is refused while the first, silent, is still served.
    let _second = connect(&addr);
    until("the second client is refused", PROCESS, || {
        has(&log, "refused a second client")
    });
    assert!(!has(&log, "dropped: silent"));
    assert!(ask(&mut first, &status_query()).starts_with("#99215"));
}

#[test]
fn five_megabytes_of_random_bytes_are_followed_by_an_answered_frame() {
    let (_sim, addr, stderr) = start(&[]);
    let _log = collect(stderr);
    let mut s = connect(&addr);
    assert!(ask(&mut s, &status_query()).starts_with("#99215"));
    // A fixed xorshift stream: random bytes, the same on every run.
    let mut x: u64 = 0x9E37_79B9_7F4A_7C15;
    let mut chunk = vec![0u8; 64 * 1024];
    for _ in 0..80 {
        for b in &mut chunk {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            *b = x as u8;
        }
        s.write_all(&chunk).expect("the simulator keeps reading");
    }
    // Whatever the garbage ended in, the next '!' starts a frame the controller answers.
    let reply = ask(&mut s, &status_query());
    assert!(reply.ends_with("\r\n"), "{reply:?}");
    assert!(reply.contains("#99215"), "{reply:?}");
    assert!(ask(&mut s, &status_query()).starts_with("#99215"));
}

/// Its log written to a pipe nobody reads (a full pipe blocks its writer): the simulator
/// keeps answering, and says how many lines it could not write once the pipe is read.
#[test]
fn a_stderr_nobody_reads_does_not_stop_it_serving() {
    let (_sim, addr, stderr) = start(&[]);
    let mut s = connect(&addr);
    // Two log lines a frame, about 130 bytes: 2000 frames are far more than a pipe holds.
    for i in 0..2000 {
        let reply = ask(&mut s, &status_query());
        assert!(reply.starts_with("#99215"), "frame {i}: {reply:?}");
    }
    let log = collect(stderr);
    until("the lines not written are counted", PROCESS, || {
        has(&log, "log lines not written: stderr was not being read")
    });
}

#[test]
fn a_long_reply_is_logged_whole() {
    let (_sim, addr, stderr) = start(&["--ready", "--linear-axes", "2"]);
    let log = collect(stderr);
    let mut s = connect(&addr);
    // 2A1H of axes 1-6 in the base system.
    let reply = ask(&mut s, &frame("!992A13F0"));
    assert!(reply.starts_with("#992A1"), "{reply}");
    assert!(reply.len() > 80, "a long reply: {} bytes", reply.len());
    let logged = reply.trim_end().to_owned() + "\\r\\n";
    let ok = eventually(PROCESS, || {
        log.lock()
            .unwrap()
            .iter()
            .any(|l| l.contains(" tx ") && l.contains(&logged))
    });
    let lines = log.lock().unwrap().clone();
    assert!(ok, "the reply {logged:?} whole in the log: {lines:#?}");
    assert!(
        !lines.iter().any(|l| l.contains("does not end with CR LF")),
        "{lines:#?}"
    );
}
