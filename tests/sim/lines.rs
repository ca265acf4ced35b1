//! The simulator served on a pseudo-terminal and on TCP as third-party hosts use it:
//! 10,000 frames pipelined without waiting, a frame a byte at a time, a second TCP
//! client, paced replies over TCP, a host that never reads the 25BH reply. Every wait has
//! a deadline; nothing asserts on timing.

// The one threaded smoke test that keeps a fixed sleep: a third-party host's pace, with no
// condition to wait for (the simulator counts frames, not bytes read), only a speed to
// keep: `a_frame_sent_a_byte_at_a_time_is_answered` waits 3 ms between bytes, so that each
// comes to the simulator on its own.

use std::io::{Read, Write};
use std::net::TcpStream;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use xsel_pendant::line::byte_time_8n1;
use xsel_pendant::sim::runner::{RunOptions, SimCore, start_tcp};
use xsel_pendant::sim::{Controller, FaultSpec, SimSetup};

use crate::wait::{LONG, eventually, until};
use crate::wire::{frame, sc};

const FRAMES: usize = 10_000;

/// 200H test call carrying `i` as 5 digits: the reply echoes it, so order is checked.
fn numbered(i: usize) -> Vec<u8> {
    frame(&format!("!99200{i:05}"))
}

fn core(reply_delay_ms: u64) -> SimCore {
    let mut setup = SimSetup::default();
    setup.config.reply_delay = Duration::from_millis(reply_delay_ms);
    setup.config.reboot_time = Duration::from_millis(200);
    SimCore::new(Controller::new(setup), FaultSpec::none())
}

/// Notices the runner logs (client connected, refused, line full ...).
fn notices() -> (Arc<Mutex<Vec<String>>>, RunOptions) {
    let seen = Arc::new(Mutex::new(Vec::new()));
    let sink = seen.clone();
    let opts = RunOptions {
        notice: Some(Arc::new(move |line: &str| {
            sink.lock().unwrap().push(line.to_owned())
        })),
        ..RunOptions::default()
    };
    (seen, opts)
}

/// Reads lines until `want` lines came or the line is quiet for 2 s.
fn read_lines(
    mut read: impl FnMut(&mut [u8]) -> std::io::Result<usize>,
    want: usize,
) -> Vec<String> {
    let mut lines = Vec::with_capacity(want);
    let mut cur = Vec::new();
    let mut buf = [0u8; 4096];
    let mut last = Instant::now();
    while lines.len() < want && last.elapsed() < Duration::from_secs(2) {
        match read(&mut buf) {
            Ok(0) => break,
            Ok(n) => {
                last = Instant::now();
                for &b in &buf[..n] {
                    cur.push(b);
                    if b == b'\n' {
                        lines.push(String::from_utf8_lossy(&cur).into_owned());
                        cur.clear();
                    }
                }
            }
            Err(_) => continue,
        }
    }
    lines
}

fn check_in_order(lines: &[String]) {
    for (i, line) in lines.iter().enumerate() {
        let want = format!("#99200{i:05}");
        assert!(
            line.starts_with(&want),
            "reply {i} is {line:?}, not the echo of frame {i}"
        );
    }
    assert_eq!(lines.len(), FRAMES, "every frame answered");
}

#[test]
fn ten_thousand_pipelined_frames_over_tcp_are_all_answered_in_order() {
    let server = start_tcp(core(0), "127.0.0.1:0", RunOptions::default()).unwrap();
    let mut stream = TcpStream::connect(server.addr).unwrap();
    stream
        .set_read_timeout(Some(Duration::from_millis(100)))
        .unwrap();
    let mut writer = stream.try_clone().unwrap();
    let feeder = std::thread::spawn(move || {
        for i in 0..FRAMES {
            writer.write_all(&numbered(i)).unwrap();
        }
    });
    let lines = read_lines(|b| stream.read(b), FRAMES);
    feeder.join().unwrap();
    check_in_order(&lines);
    assert_eq!(server.handle.counters().replies, FRAMES as u64);
}

#[cfg(unix)]
#[test]
fn ten_thousand_pipelined_frames_over_a_pty_are_all_answered_in_order() {
    use xsel_pendant::sim::runner::start_pty;
    let server = start_pty(core(0), RunOptions::default()).unwrap();
    let mut port = serialport::new(&server.path, 115_200)
        .timeout(Duration::from_millis(100))
        .open_native()
        .unwrap();
    let mut writer = port.try_clone_native().unwrap();
    // The writer does not wait for replies: the pty fills up while the reader is slow.
    let feeder = std::thread::spawn(move || {
        for i in 0..FRAMES {
            writer.write_all(&numbered(i)).unwrap();
        }
    });
    // Nothing is read until every frame is written: the simulator's side of the pty
    // fills with replies while the writer goes on, and the writer only finishes if the
    // simulator keeps receiving while its replies wait for room.
    until("every frame written while no reply is read", LONG, || {
        feeder.is_finished()
    });
    let lines = read_lines(|b| port.read(b), FRAMES);
    feeder.join().unwrap();
    check_in_order(&lines);
    let n = server.handle.counters();
    assert_eq!((n.replies, n.input_lost_bytes), (FRAMES as u64, 0));
}

/// A host that writes 3,000 frames with blocking writes before it reads a byte: the
/// simulator keeps receiving while its replies wait for room, as a controller's UART
/// does, so every write goes through and every frame is answered in order.
#[cfg(unix)]
#[test]
fn a_host_that_writes_everything_before_it_reads_is_served() {
    use xsel_pendant::sim::runner::start_pty;
    const WRITTEN: usize = 3_000;
    let server = start_pty(core(0), RunOptions::default()).unwrap();
    let mut port = serialport::new(&server.path, 115_200)
        .timeout(Duration::from_millis(100))
        .open_native()
        .unwrap();
    let deadline = Instant::now() + Duration::from_secs(30);
    for i in 0..WRITTEN {
        let frame = numbered(i);
        let mut sent = 0;
        while sent < frame.len() {
            assert!(
                Instant::now() < deadline,
                "frame {i} could not be written: the simulator stopped listening"
            );
            match port.write(&frame[sent..]) {
                Ok(n) => sent += n,
                Err(e) if e.kind() == std::io::ErrorKind::TimedOut => {}
                Err(e) => panic!("write failed: {e}"),
            }
        }
    }
    let lines = read_lines(|b| port.read(b), WRITTEN);
    for (i, line) in lines.iter().enumerate() {
        assert!(
            line.starts_with(&format!("#99200{i:05}")),
            "reply {i}: {line:?}"
        );
    }
    assert_eq!(lines.len(), WRITTEN, "every frame answered");
    assert_eq!(server.handle.counters().input_lost_bytes, 0);
}

#[test]
fn a_frame_sent_a_byte_at_a_time_is_answered() {
    let server = start_tcp(core(1), "127.0.0.1:0", RunOptions::default()).unwrap();
    let mut s = TcpStream::connect(server.addr).unwrap();
    s.set_nodelay(true).unwrap();
    s.set_read_timeout(Some(Duration::from_millis(50))).unwrap();
    for b in frame("!99200AB") {
        s.write_all(&[b]).unwrap();
        std::thread::sleep(Duration::from_millis(3));
    }
    let lines = read_lines(|b| s.read(b), 1);
    assert_eq!(lines, [format!("#99200AB{}\r\n", sc("#99200AB"))]);
}

#[test]
fn a_second_tcp_client_is_refused_at_once_and_logged() {
    let (seen, opts) = notices();
    let server = start_tcp(core(1), "127.0.0.1:0", opts).unwrap();
    let mut first = TcpStream::connect(server.addr).unwrap();
    first
        .set_read_timeout(Some(Duration::from_millis(100)))
        .unwrap();
    first.write_all(&numbered(0)).unwrap();
    assert_eq!(
        read_lines(|b| first.read(b), 1).len(),
        1,
        "first client served"
    );
    let mut second = TcpStream::connect(server.addr).unwrap();
    second
        .set_read_timeout(Some(Duration::from_secs(3)))
        .unwrap();
    let _ = second.write_all(&numbered(1));
    let mut buf = [0u8; 64];
    let got = second.read(&mut buf);
    assert!(
        matches!(got, Ok(0))
            || matches!(&got, Err(e) if e.kind() != std::io::ErrorKind::WouldBlock && e.kind() != std::io::ErrorKind::TimedOut),
        "the second client is closed at once, not left waiting: {got:?}"
    );
    let logged = eventually(LONG, || {
        seen.lock().unwrap().iter().any(|l| l.contains("refused"))
    });
    assert!(logged, "no log line: {:?}", seen.lock().unwrap());
    // The first client is still served.
    first.write_all(&numbered(2)).unwrap();
    let lines = read_lines(|b| first.read(b), 1);
    assert!(lines[0].starts_with("#9920000002"), "{lines:?}");
    drop(first);
    // Once it left, the next client is served.
    let mut third = TcpStream::connect(server.addr).unwrap();
    third
        .set_read_timeout(Some(Duration::from_millis(100)))
        .unwrap();
    third.write_all(&numbered(3)).unwrap();
    let lines = read_lines(|b| third.read(b), 1);
    assert!(
        lines.first().is_some_and(|l| l.starts_with("#9920000003")),
        "the next client is served: {lines:?}"
    );
}

#[test]
fn paced_replies_over_tcp_arrive_as_whole_lines() {
    let opts = RunOptions {
        pacing: Some(byte_time_8n1(9_600)),
        ..RunOptions::default()
    };
    let server = start_tcp(core(1), "127.0.0.1:0", opts).unwrap();
    let mut s = TcpStream::connect(server.addr).unwrap();
    s.set_read_timeout(Some(Duration::from_secs(3))).unwrap();
    let want = format!("#99200ABCDEFGHIJ{}\r\n", sc("#99200ABCDEFGHIJ"));
    for _ in 0..3 {
        s.write_all(&frame("!99200ABCDEFGHIJ")).unwrap();
        let mut buf = [0u8; 64];
        let n = s.read(&mut buf).unwrap();
        assert_eq!(
            String::from_utf8_lossy(&buf[..n]),
            want,
            "one read, one whole reply line"
        );
    }
}

/// A host sends 25BH and goes on without reading its reply.
#[test]
fn a_host_that_never_reads_the_reset_reply_is_served_after_the_reboot() {
    let server = start_tcp(core(1), "127.0.0.1:0", RunOptions::default()).unwrap();
    {
        let mut s = TcpStream::connect(server.addr).unwrap();
        s.write_all(&frame("!9925B")).unwrap();
        // Closed without reading.
    }
    // It connects again at once: refused while the simulator still serves the first
    // connection, then served (silent while rebooting, then answering).
    let deadline = Instant::now() + Duration::from_secs(10);
    loop {
        let mut s = TcpStream::connect(server.addr).unwrap();
        s.set_read_timeout(Some(Duration::from_millis(100)))
            .unwrap();
        let _ = s.write_all(&frame("!99215"));
        if let Some(l) = read_lines(|b| s.read(b), 1).first() {
            assert!(l.starts_with("#99215"), "{l}");
            break;
        }
        assert!(Instant::now() < deadline, "never served after the reset");
    }
    assert_eq!(server.handle.counters().resets, 1);
}
