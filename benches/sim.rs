//! Simulator figures (issue 4): 2A1H queries per second in process, motion simulation
//! speed against real time, and reply timing with `--baud 115200` pacing over a pty;
//! (issue 38) the SEL parser on the demo and on a 9999-step program, and one advance of
//! a program that never waits (the bounded 2000 steps).
//!
//! `cargo bench --bench sim` (criterion for the first two; the timing one prints its own
//! median). `cargo bench --bench sim -- --quick` for a short run.

use std::hint::black_box;
use std::time::{Duration, Instant};

use criterion::{Criterion, Throughput};
use xsel_pendant::sim::{Controller, SimSetup};

fn frame(body: &str) -> Vec<u8> {
    let sc = body.bytes().fold(0u8, |s, b| s.wrapping_add(b));
    format!("{body}{sc:02X}\r\n").into_bytes()
}

fn ready() -> Controller {
    let mut s = SimSetup::default();
    s.config.start_ready = true;
    Controller::new(s)
}

fn status_queries(c: &mut Criterion) {
    let mut g = c.benchmark_group("sim");
    g.throughput(Throughput::Elements(1));
    for (name, body) in [("2A1H base", "!992A10F0"), ("2A1H work", "!992A10F1")] {
        let mut ctl = ready();
        ctl.select_work(2);
        let f = frame(body);
        let mut out = Vec::with_capacity(128);
        let mut t = Duration::ZERO;
        g.bench_function(name, |b| {
            b.iter(|| {
                t += Duration::from_nanos(100);
                black_box(ctl.handle_into(black_box(&f), t, &mut out));
            })
        });
    }
    g.finish();
}

/// Simulates a 10 s CP move in 1 ms steps; returns the wall time it took.
fn long_move() -> Duration {
    let mut ctl = ready();
    // CP, Y -300 mm at 30 mm/s from the home pose (250, 250): 10 s of motion.
    let body = format!("!992D50200000000001E03{:08X}", (-300_000i32) as u32);
    let start = Instant::now();
    let mut t = Duration::ZERO;
    assert!(ctl.handle(&frame(&body), t).is_some_and(|r| r[0] == b'#'));
    while ctl.in_use() != 0 {
        t += Duration::from_millis(1);
        ctl.advance(t);
    }
    assert!(t >= Duration::from_secs(10));
    start.elapsed()
}

fn motion(c: &mut Criterion) {
    let mut g = c.benchmark_group("sim");
    g.sample_size(10);
    g.bench_function("10 s CP move in 1 ms steps", |b| b.iter(long_move));
    g.finish();
}

/// Reply timing over a pseudo-terminal (Unix only).
#[cfg(unix)]
mod pty {
    use std::io::{Read, Write};
    use std::time::{Duration, Instant};

    use xsel_pendant::line::byte_time_8n1;
    use xsel_pendant::sim::runner::{RunOptions, SimCore, start_pty};
    use xsel_pendant::sim::{Controller, FaultSpec, SimSetup};

    use super::frame;

    /// Over a pty (Unix) paced at 115200 baud with a 2 ms reply delay: time from the command's last
    /// byte written to the reply's last byte read, minus the delay, against the wire time.
    pub fn pacing_timing() {
        let mut setup = SimSetup::default();
        setup.config.start_ready = true;
        let delay = Duration::from_millis(2);
        setup.config.reply_delay = delay;
        let opts = RunOptions {
            pacing: Some(byte_time_8n1(115_200)),
            ..RunOptions::default()
        };
        let server = start_pty(
            SimCore::new(Controller::new(setup), FaultSpec::none()),
            opts,
        )
        .unwrap();
        let mut port = serialport::new(&server.path, 115_200)
            .timeout(Duration::from_millis(200))
            .open_native()
            .unwrap();
        let mut errors = Vec::new();
        let mut reply_len = 0;
        for i in 0..200 {
            let f = frame(if i % 2 == 0 { "!992A10F0" } else { "!99215" });
            port.write_all(&f).unwrap();
            let sent = Instant::now();
            let mut got = Vec::new();
            let mut buf = [0u8; 256];
            while !got.ends_with(b"\n") {
                let n = port.read(&mut buf).unwrap_or(0);
                got.extend_from_slice(&buf[..n]);
            }
            let took = sent.elapsed();
            let wire = Duration::from_nanos(got.len() as u64 * 10 * 1_000_000_000 / 115_200);
            reply_len = reply_len.max(got.len());
            errors.push((took.as_secs_f64() - delay.as_secs_f64() - wire.as_secs_f64()) * 1e3);
            std::thread::sleep(Duration::from_millis(2));
        }
        errors.sort_by(|a, b| a.total_cmp(b));
        let pct = |p: f64| errors[((errors.len() - 1) as f64 * p) as usize];
        println!(
            "pacing 115200 baud over a pty, replies up to {reply_len} bytes, 200 transactions: \
             (measured - delay - wire time) median {:+.3} ms, p90 {:+.3} ms, max {:+.3} ms",
            pct(0.5),
            pct(0.9),
            pct(1.0)
        );
    }
}

/// The SEL parser and interpreter.
fn programs(c: &mut Criterion) {
    use xsel_pendant::sel;
    use xsel_pendant::sim::programs::MAX_STEPS_PER_ADVANCE;
    let mut g = c.benchmark_group("sim programs");
    g.bench_function("parse the demo (15 steps)", |b| {
        b.iter(|| black_box(sel::parse(black_box(sel::DEMO))))
    });
    let long = format!(
        "PROGRAM 1 long\n{}",
        "CPLT 1 5 900\n900 ADD 1 1\nBTON 300 307 - 610\n".repeat(sel::MAX_STEPS / 3)
    );
    g.throughput(Throughput::Elements(sel::MAX_STEPS as u64));
    g.bench_function("parse 9999 steps", |b| {
        b.iter(|| black_box(sel::parse(black_box(&long))))
    });
    let forever = "PROGRAM 8 forever\nTAG 1\nADD 1 1\nCPLT 1 100 600\nGOTO 1\n";
    let mut ctl = Controller::new(SimSetup {
        programs: sel::parse(forever).programs,
        ..SimSetup::default()
    });
    let mut t = Duration::ZERO;
    assert!(
        ctl.handle(&frame("!9925308"), t)
            .is_some_and(|r| r[0] == b'#')
    );
    g.throughput(Throughput::Elements(u64::from(MAX_STEPS_PER_ADVANCE)));
    g.bench_function("one advance of an endless loop", |b| {
        b.iter(|| {
            t += Duration::from_secs(10);
            ctl.advance(black_box(t));
        })
    });
    g.finish();
}

fn main() {
    let mut c = Criterion::default()
        .configure_from_args()
        .measurement_time(Duration::from_secs(3))
        .warm_up_time(Duration::from_secs(1));
    status_queries(&mut c);
    motion(&mut c);
    programs(&mut c);
    c.final_summary();
    #[cfg(unix)]
    pty::pacing_timing();
}
