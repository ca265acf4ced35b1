//! The signals' cost to the status polls: the X-SEL status poll rate with 64 ports, 64
//! flags and 16 integer variables watched against the rate without them, and the
//! signals' own refresh rate, on the embedded simulator paced at the baud rate (115200
//! and 9600), polls every 100 ms as the pendant runs them.
//! Run: `cargo bench --bench signals` (`SIGNALS_RUNS=N` runs each figure N times,
//! `SIGNALS_SECONDS=S` for how long each run polls).

#[path = "../tests/common/mod.rs"]
mod common;

use std::time::{Duration, Instant};

use common::*;
use xsel_pendant::line::LineSettings;
use xsel_pendant::link::{LinkConfig, LinkEvent, Origin, Polling, Priority};
use xsel_pendant::pendant::controller::poll_commands;
use xsel_pendant::pendant::signals::{
    Signal, SignalKind, Signals, SignalsCx, SignalsIntent, WatchRow,
};
use xsel_pendant::sim::FaultSpec;

const REPLY_DELAY: Duration = Duration::from_millis(2);

/// 32 inputs and 32 outputs, 64 global flags, 16 global integers.
fn watched() -> Vec<WatchRow> {
    let rows = |kind, from: u16, n: u16| {
        (from..from + n).map(move |k| WatchRow::new(Signal::new(kind, 0, k), ""))
    };
    rows(SignalKind::Input, 0, 32)
        .chain(rows(SignalKind::Output, 300, 32))
        .chain(rows(SignalKind::Flag, 600, 64))
        .chain(rows(SignalKind::Integer, 200, 16))
        .collect()
}

/// What one run measured: status poll cycles and signal rounds a second.
struct Figure {
    polls_per_s: f64,
    rounds_per_s: f64,
}

fn run(baud: u32, seconds: f64, with_signals: bool) -> Figure {
    let commands = poll_commands();
    let per_cycle = commands.len();
    let mut config = LinkConfig {
        polling: Polling {
            interval: Some(Duration::from_millis(100)),
            idle_interval: None,
            commands,
        },
        ..LinkConfig::default()
    };
    config.timing.line = LineSettings {
        baud,
        ..LineSettings::default()
    };
    let byte_time = config.timing.line.byte_time();
    let (link, events, _sim) = embedded_link(
        ready_setup(REPLY_DELAY),
        FaultSpec::none(),
        Some(byte_time),
        config,
    );
    let mut seen = Vec::new();
    wait_for(&events, Duration::from_secs(5), &mut seen, |e| {
        matches!(e, LinkEvent::Reply { .. })
    })
    .expect("the simulator answers");
    let mut signals = Signals::new(if with_signals { watched() } else { vec![] });
    let cx = SignalsCx {
        ready: Ok(()),
        program_running: Some(false),
        io_interlock: false,
    };
    signals.apply(SignalsIntent::Watch(true), cx.clone(), Instant::now());
    let began = Instant::now();
    let until = began + Duration::from_secs_f64(seconds);
    let (mut polls, mut rounds_done) = (0usize, 0usize);
    let mut round_open = false;
    while Instant::now() < until {
        let now = Instant::now();
        signals.tick(now, true);
        for (command, user) in signals.take_commands() {
            round_open |= !user;
            let priority = if user {
                Priority::User
            } else {
                Priority::Spare
            };
            link.submit(command, priority);
        }
        let Ok(event) = events.recv_timeout(Duration::from_millis(5)) else {
            continue;
        };
        if let LinkEvent::Reply {
            origin: Origin::Poll,
            ..
        } = &event
        {
            polls += 1;
        }
        let _ = signals.handle_event(&event, cx.clone(), Instant::now());
        if round_open && signals.reads_in_flight() == 0 {
            rounds_done += 1;
            round_open = false;
        }
    }
    let took = began.elapsed().as_secs_f64();
    Figure {
        polls_per_s: polls as f64 / per_cycle as f64 / took,
        rounds_per_s: rounds_done as f64 / took,
    }
}

fn percentile(sorted: &[f64], p: f64) -> f64 {
    let i = ((sorted.len() as f64 - 1.0) * p).round() as usize;
    sorted[i.min(sorted.len() - 1)]
}

fn sorted(v: impl Iterator<Item = f64>) -> Vec<f64> {
    let mut v: Vec<f64> = v.collect();
    v.sort_by(f64::total_cmp);
    v
}

fn main() {
    let env = |name: &str, default: f64| {
        std::env::var(name)
            .ok()
            .and_then(|s| s.parse().ok())
            .unwrap_or(default)
    };
    let runs = env("SIGNALS_RUNS", 3.0) as usize;
    let seconds = env("SIGNALS_SECONDS", 10.0);
    let reads = Signals::new(watched()).reads_per_round();
    println!(
        "watched: 32 inputs, 32 outputs, 64 flags, 16 integers = {} rows in {reads} reads a round",
        watched().len()
    );
    for baud in [115_200, 9_600] {
        let without: Vec<Figure> = (0..runs).map(|_| run(baud, seconds, false)).collect();
        let with: Vec<Figure> = (0..runs).map(|_| run(baud, seconds, true)).collect();
        let a = sorted(without.iter().map(|f| f.polls_per_s));
        let b = sorted(with.iter().map(|f| f.polls_per_s));
        let r = sorted(with.iter().map(|f| f.rounds_per_s));
        let ratio = percentile(&b, 0.5) / percentile(&a, 0.5);
        println!(
            "{baud} baud, {runs} runs of {seconds} s: status cycles/s without signals median {:.2} (min {:.2}), with them median {:.2} (min {:.2}): {:.1} % of the rate; signal rounds/s median {:.2} (min {:.2}, p99 {:.2})",
            percentile(&a, 0.5),
            a[0],
            percentile(&b, 0.5),
            b[0],
            100.0 * ratio,
            percentile(&r, 0.5),
            r[0],
            percentile(&r, 0.99),
        );
    }
}
