//! Position table figures against the embedded simulator paced at the baud rate, the
//! status polls running: reading 3,000 SCARA positions and writing 100 changed ones (with
//! the read-back), each against the wire's bound: every transaction's bytes × 10 bits /
//! baud + the controller's reply delay + the inter-frame gap, the polls' share counted in.
//! Run: `cargo bench --bench positions` (`POSITIONS_RUNS=N` runs each figure N times;
//! `POSITIONS_SLOW=1` adds the 9600-baud figures, about 3 minutes a read).

#[path = "../tests/common/mod.rs"]
mod common;

use std::time::{Duration, Instant};

use common::*;
use xsel_pendant::line::LineSettings;
use xsel_pendant::link::{LinkConfig, LinkEvent, Polling, Priority};
use xsel_pendant::pendant::controller::poll_commands;
use xsel_pendant::pendant::positions::{Positions, record_of_pose};
use xsel_pendant::protocol::RecordArm;
use xsel_pendant::sim::FaultSpec;

const REPLY_DELAY: Duration = Duration::from_millis(2);

fn line(baud: u32) -> LineSettings {
    LineSettings {
        baud,
        ..LineSettings::default()
    }
}

/// What one figure measured.
struct Figure {
    took: Duration,
    bound: Duration,
    transactions: usize,
}

/// Runs `positions` (a read or a write already started) on a fresh link to a simulator
/// holding `stored` SCARA positions, the pendant's status polls at 100 ms.
fn run(baud: u32, stored: u16, start: impl FnOnce(&mut Positions)) -> Figure {
    let mut setup = ready_setup(REPLY_DELAY);
    setup.positions.clear();
    for n in 1..=stored {
        let x = 200_000 + i32::from(n);
        setup.positions.insert(
            n,
            record_of_pose(n, [x, 150_000, 20_000, 45_000], RecordArm::Right),
        );
    }
    let mut config = LinkConfig {
        polling: Polling {
            interval: Some(Duration::from_millis(100)),
            idle_interval: None,
            commands: poll_commands(),
        },
        ..LinkConfig::default()
    };
    config.timing.line = line(baud);
    let timing = config.timing;
    let (link, events, _sim) = embedded_link(
        setup,
        FaultSpec::none(),
        Some(line(baud).byte_time()),
        config,
    );
    let mut seen = Vec::new();
    wait_for(&events, Duration::from_secs(5), &mut seen, |e| {
        matches!(e, LinkEvent::Reply { .. })
    })
    .expect("the simulator answers");
    let mut positions = Positions::new();
    let began = Instant::now();
    start(&mut positions);
    let (mut bound, mut transactions) = (Duration::ZERO, 0usize);
    let mut command_len = None;
    loop {
        for (command, user) in positions.take_commands() {
            let priority = if user {
                Priority::User
            } else {
                Priority::Background
            };
            link.submit(command, priority);
        }
        if positions.read.is_none() && positions.write.is_none() {
            break;
        }
        let event = events
            .recv_timeout(Duration::from_secs(30))
            .expect("the link answers");
        match &event {
            LinkEvent::FrameSent { bytes, .. } => command_len = Some(bytes.len()),
            LinkEvent::FrameReceived { bytes, .. } => {
                if let Some(c) = command_len.take() {
                    bound += timing.wire_transaction_time(c, bytes.len(), REPLY_DELAY);
                    transactions += 1;
                }
            }
            _ => {}
        }
        let _ = positions.handle_event(&event);
    }
    Figure {
        took: began.elapsed(),
        bound,
        transactions,
    }
}

fn percentile(sorted: &[f64], p: f64) -> f64 {
    let i = ((sorted.len() as f64 - 1.0) * p).round() as usize;
    sorted[i.min(sorted.len() - 1)]
}

fn report(what: &str, figures: &[Figure]) {
    let mut ratios: Vec<f64> = figures
        .iter()
        .map(|f| f.took.as_secs_f64() / f.bound.as_secs_f64())
        .collect();
    ratios.sort_by(f64::total_cmp);
    let mut took: Vec<f64> = figures.iter().map(|f| f.took.as_secs_f64()).collect();
    took.sort_by(f64::total_cmp);
    let f = &figures[0];
    println!(
        "{what}: {} runs, took median {:.3} s (p99 {:.3} s), wire bound {:.3} s over {} transactions; ratio median {:.3}, p99 {:.3}",
        figures.len(),
        percentile(&took, 0.5),
        percentile(&took, 0.99),
        f.bound.as_secs_f64(),
        f.transactions,
        percentile(&ratios, 0.5),
        percentile(&ratios, 0.99),
    );
}

fn main() {
    let runs: usize = std::env::var("POSITIONS_RUNS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(5);
    let mut bauds = vec![115_200];
    if std::env::var_os("POSITIONS_SLOW").is_some() {
        bauds.push(9_600);
    }
    for &baud in &bauds {
        let n = if baud < 115_200 { 1 } else { runs };
        let reads: Vec<Figure> = (0..n)
            .map(|_| {
                run(baud, 3000, |p| {
                    p.start_read(1..=3000).expect("starts");
                })
            })
            .collect();
        report(&format!("read 3000 SCARA positions at {baud} baud"), &reads);
        let writes: Vec<Figure> = (0..runs)
            .map(|_| {
                run(baud, 100, |p| {
                    for n in 1..=100u16 {
                        let moved = record_of_pose(
                            n,
                            [250_000 + i32::from(n), -50_000, 0, 0],
                            RecordArm::Left,
                        );
                        p.put(moved).expect("a position number");
                    }
                    p.preview(false, |_| Ok(())).expect("a preview");
                    p.confirm_write(false, false).expect("writes");
                })
            })
            .collect();
        report(
            &format!("write 100 changed positions (and read them back) at {baud} baud"),
            &writes,
        );
    }
}
