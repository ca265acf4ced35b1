//! RMC151 figures: the codec (a command block encoded as its FC16 frame, a 116-register
//! status reply decoded), status polls per second against `rmc-sim` on loopback (2 axes),
//! click-to-wire of a Move Relative and STOP-to-wire of Stop (6) while polling, seen by a
//! timestamping TCP relay between the link and `rmc-sim`. Plain timing loops; each figure
//! prints median, p99 and max. Run: `cargo bench --bench rmc`.

use std::hint::black_box;
use std::io::{BufRead, BufReader, Read, Write};
use std::net::{TcpListener, TcpStream};
use std::process::{Child, Command as Process, Stdio};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use crossbeam_channel::Receiver;
use xsel_pendant::link::Connector;
use xsel_pendant::link::transport::{TcpTransport, Transport};
use xsel_pendant::rmc::modbus::{
    FrameBuffer, Header, Request, Response, decode_request, decode_response, encode_request,
    encode_response,
};
use xsel_pendant::rmc::{
    AxisId, AxisStatus, Command, MoveRelative, RmcEvent, RmcHandle, RmcLinkConfig, StatusBits,
};
use xsel_pendant::robot::RelativeTo;

struct Sim(Child, String);

impl Drop for Sim {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

fn rmc_sim() -> Sim {
    let mut child = Process::new(env!("CARGO_BIN_EXE_rmc-sim"))
        .args(["--tcp", "127.0.0.1:0", "--axes", "2"])
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .expect("rmc-sim starts");
    let mut line = String::new();
    BufReader::new(child.stdout.take().unwrap())
        .read_line(&mut line)
        .unwrap();
    let addr = line.trim().trim_start_matches("listening on ").to_string();
    Sim(child, addr)
}

fn report(what: &str, samples: &mut [Duration]) {
    samples.sort();
    let at = |p: f64| samples[((samples.len() - 1) as f64 * p).round() as usize];
    println!(
        "{what:<44} n {:>5}  median {:>7.3} ms  p99 {:>7.3} ms  max {:>7.3} ms",
        samples.len(),
        at(0.5).as_secs_f64() * 1e3,
        at(0.99).as_secs_f64() * 1e3,
        at(1.0).as_secs_f64() * 1e3,
    );
}

fn rate(what: &str, n: u32, f: impl Fn()) {
    let mut per = Vec::new();
    for _ in 0..15 {
        let t = Instant::now();
        for _ in 0..n {
            f();
        }
        per.push(t.elapsed().as_secs_f64() * 1e9 / f64::from(n));
    }
    per.sort_by(f64::total_cmp);
    let median = per[per.len() / 2];
    println!(
        "{what:<44} median {median:>8.1} ns  ({:.2} M/s)",
        1e3 / median
    );
}

fn codec() {
    let block = Command::MoveRelative(MoveRelative {
        distance: 10.0,
        speed: 5.0,
        accel: 100.0,
        decel: 100.0,
        relative_to: RelativeTo::Target,
    });
    let axis = AxisId::new(0).unwrap();
    let header = Header {
        transaction: 7,
        unit: 1,
    };
    rate("encode Move Relative block + FC16 frame", 200_000, || {
        let words = black_box(block).block(true);
        let frame = encode_request(
            header,
            &Request::Write {
                address: axis.command_block(),
                words,
            },
        );
        black_box(frame);
    });
    let status = AxisStatus {
        bits: StatusBits(0x8000_2201),
        actual_position: 1.5,
        command_position: 10.0,
        ..Default::default()
    };
    let reply = encode_response(
        header,
        &Response::Registers {
            function: 3,
            words: status.encode(),
        },
    );
    rate("decode 116-register status reply", 200_000, || {
        let decoded = decode_response(black_box(&reply)).ok();
        let s = decoded.and_then(|(_, r)| match r {
            Response::Registers { words, .. } => AxisStatus::decode(&words),
            _ => None,
        });
        black_box(s);
    });
}

/// Every request the relay saw, with when it arrived whole.
type Seen = Arc<Mutex<Vec<(Instant, Request)>>>;

/// A relay between the link and `rmc-sim` that notes when each request arrived whole.
fn relay(to: String) -> (String, Seen) {
    let listener = TcpListener::bind("127.0.0.1:0").unwrap();
    let addr = listener.local_addr().unwrap().to_string();
    let seen = Arc::new(Mutex::new(Vec::new()));
    let log = seen.clone();
    std::thread::spawn(move || {
        for client in listener.incoming().flatten() {
            let server = TcpStream::connect(&to).unwrap();
            let _ = (client.set_nodelay(true), server.set_nodelay(true));
            let (mut c_in, mut s_out) = (client.try_clone().unwrap(), server.try_clone().unwrap());
            let (mut s_in, mut c_out) = (server, client);
            let log = log.clone();
            std::thread::spawn(move || {
                let mut frames = FrameBuffer::default();
                let mut buf = [0u8; 2048];
                while let Ok(n) = c_in.read(&mut buf) {
                    if n == 0 || s_out.write_all(&buf[..n]).is_err() {
                        return;
                    }
                    let at = Instant::now();
                    frames.push(&buf[..n]);
                    while let Some(Ok(f)) = frames.next_frame() {
                        if let Ok((_, r)) = decode_request(&f) {
                            log.lock().unwrap().push((at, r));
                        }
                    }
                }
            });
            std::thread::spawn(move || {
                let mut buf = [0u8; 2048];
                while let Ok(n) = s_in.read(&mut buf) {
                    if n == 0 || c_out.write_all(&buf[..n]).is_err() {
                        return;
                    }
                }
            });
        }
    });
    (addr, seen)
}

fn link(addr: String, poll: Duration) -> (RmcHandle, Receiver<RmcEvent>) {
    let connector: Connector = Box::new(move |_| {
        TcpTransport::connect(&addr, Duration::from_secs(1))
            .map(|t| Box::new(t) as Box<dyn Transport>)
    });
    // The same rounds however still the axes stand (the figure is the link's rate).
    let config = RmcLinkConfig {
        poll_interval: poll,
        idle_poll_interval: poll,
        ..RmcLinkConfig::default()
    };
    xsel_pendant::rmc::spawn(connector, config, Arc::new(|_: &RmcEvent| {})).unwrap()
}

fn wait_for(events: &Receiver<RmcEvent>, mut done: impl FnMut(&RmcEvent) -> bool) {
    let end = Instant::now() + Duration::from_secs(10);
    while Instant::now() < end {
        if let Ok(e) = events.recv_timeout(Duration::from_millis(50))
            && done(&e)
        {
            return;
        }
    }
    panic!("the RMC link did not get there");
}

fn polls_per_second(sim: &Sim) {
    let (handle, events) = link(sim.1.clone(), Duration::ZERO);
    wait_for(&events, |e| matches!(e, RmcEvent::Status { .. }));
    let t = Instant::now();
    let mut polls = 0u32;
    while t.elapsed() < Duration::from_secs(3) {
        if let Ok(RmcEvent::Status { .. } | RmcEvent::Controller { .. }) =
            events.recv_timeout(Duration::from_millis(50))
        {
            polls += 1;
        }
    }
    let per_s = f64::from(polls) / t.elapsed().as_secs_f64();
    println!("status polls per second, 2 axes + controller   {per_s:>8.0} /s (back to back)");
    drop(handle);
}

fn latencies(sim: &Sim) {
    let (addr, seen) = relay(sim.1.clone());
    // The pendant's own polling: a round every 20 ms.
    let (handle, events) = link(addr, Duration::from_millis(20));
    let a0 = AxisId::new(0).unwrap();
    let a1 = AxisId::new(1).unwrap();
    wait_for(&events, |e| matches!(e, RmcEvent::Status { .. }));
    for a in [a0, a1] {
        handle.send(a, Command::Enable(true));
    }
    wait_for(
        &events,
        |e| matches!(e, RmcEvent::Acknowledged { axis, .. } if *axis == a1),
    );
    let mut click = Vec::new();
    let mut stop = Vec::new();
    for i in 0..200 {
        // At a different point of the polling cycle each time.
        std::thread::sleep(Duration::from_micros(2_000 + 1_237 * (i % 13)));
        let at = Instant::now();
        let mark = seen.lock().unwrap().len();
        let distance = if i % 2 == 0 { 0.5 } else { -0.5 };
        handle.send(
            a0,
            Command::MoveRelative(MoveRelative {
                distance,
                speed: 100.0,
                accel: 10_000.0,
                decel: 10_000.0,
                relative_to: RelativeTo::Command,
            }),
        );
        click.push(wire_time(&seen, mark, at, 21));
        std::thread::sleep(Duration::from_micros(3_000 + 911 * (i % 7)));
        let at = Instant::now();
        let mark = seen.lock().unwrap().len();
        handle.stop_all();
        stop.push(wire_time(&seen, mark, at, 6));
    }
    report("click to Move Relative (21) on the wire", &mut click);
    report("STOP to Stop (6) on the wire, polling", &mut stop);
    drop(handle);
}

/// When the first write of command `number` after `mark` reached the relay, from `at`.
fn wire_time(
    seen: &Mutex<Vec<(Instant, Request)>>,
    mark: usize,
    at: Instant,
    number: u16,
) -> Duration {
    let end = Instant::now() + Duration::from_secs(2);
    loop {
        if let Some(t) = seen.lock().unwrap()[mark..]
            .iter()
            .find_map(|(t, r)| match r {
                Request::Write { words, .. } => Command::from_block(words)
                    .ok()
                    .filter(|(c, _)| c.number() == number)
                    .map(|_| *t),
                _ => None,
            })
        {
            return t.saturating_duration_since(at);
        }
        assert!(
            Instant::now() < end,
            "command {number} never reached the wire"
        );
        std::thread::sleep(Duration::from_micros(100));
    }
}

fn main() {
    if std::env::args().any(|a| a == "--list") {
        return;
    }
    codec();
    let sim = rmc_sim();
    polls_per_second(&sim);
    latencies(&sim);
}
