//! Coordinate-table figures: reading 32 work + 128 tool records with 2A4H at 115200 baud
//! from the embedded simulator paced at that rate, against the wire-time lower bound of
//! the same frames (as `benches/link.rs` computes it); and diffing two full tables.
//! Run: `cargo bench --bench coords`.

#[path = "../tests/common/mod.rs"]
mod common;

use std::hint::black_box;
use std::time::{Duration, Instant};

use common::*;
use criterion::{Criterion, criterion_group, criterion_main};
use xsel_pendant::line::LineSettings;
use xsel_pendant::link::timing::Timing;
use xsel_pendant::link::{LinkEvent, TableRequest};
use xsel_pendant::pendant::coords::diff;
use xsel_pendant::protocol::{AxisPattern, CoordKind};
use xsel_pendant::robot::CoordSystem;
use xsel_pendant::sim::FaultSpec;

const BAUD: u32 = 115_200;
const REPLY_DELAY: Duration = Duration::from_millis(2);

fn line() -> LineSettings {
    LineSettings {
        baud: BAUD,
        ..LineSettings::default()
    }
}

/// Reads both tables once; the time and the (command, reply) lengths of each chunk.
fn read_both(
    link: &xsel_pendant::link::LinkHandle,
    events: &crossbeam_channel::Receiver<LinkEvent>,
) -> (Duration, Vec<(usize, usize)>) {
    let start = Instant::now();
    let mut frames = Vec::new();
    let mut sent = 0;
    for (kind, records) in [(CoordKind::Work, 32), (CoordKind::Tool, 128)] {
        link.download_table(TableRequest {
            kind,
            axes: AxisPattern::SCARA_1,
            first: 0,
            records,
            reply_buffer: 2048,
        });
        loop {
            match events.recv_timeout(Duration::from_secs(10)) {
                Ok(LinkEvent::FrameSent { bytes, .. }) => sent = bytes.len(),
                Ok(LinkEvent::FrameReceived { bytes, .. }) => frames.push((sent, bytes.len())),
                Ok(LinkEvent::TableDone { missing, .. }) => {
                    assert!(missing.is_empty(), "records missing: {missing:?}");
                    break;
                }
                Ok(_) => {}
                Err(e) => panic!("no table: {e}"),
            }
        }
    }
    (start.elapsed(), frames)
}

fn table_read(c: &mut Criterion) {
    let (link, events, _sim) = embedded_link(
        ready_setup(REPLY_DELAY),
        FaultSpec::none(),
        Some(line().byte_time()),
        quiet_config_at(BAUD),
    );
    let mut seen = Vec::new();
    wait_for(&events, Duration::from_secs(5), &mut seen, |e| {
        matches!(e, LinkEvent::Connected { .. })
    })
    .expect("the link connects");
    let (_, frames) = read_both(&link, &events);
    let timing = Timing {
        line: line(),
        ..Timing::default()
    };
    let bound: Duration = frames
        .iter()
        .map(|&(cmd, reply)| timing.wire_transaction_time(cmd, reply, REPLY_DELAY))
        .sum();
    let mut samples = Vec::new();
    c.bench_function("read 32 work + 128 tool records, 115200 baud", |b| {
        b.iter_custom(|iters| {
            let mut total = Duration::ZERO;
            for _ in 0..iters {
                let (t, _) = read_both(&link, &events);
                samples.push(t);
                total += t;
            }
            total
        })
    });
    samples.sort_unstable();
    let median = samples[samples.len() / 2];
    println!(
        "  {} transactions, {} B on the wire: lower bound {:.1} ms, median {:.1} ms = {:.3}x the bound ({} reads)",
        frames.len(),
        frames.iter().map(|(a, b)| a + b).sum::<usize>(),
        bound.as_secs_f64() * 1e3,
        median.as_secs_f64() * 1e3,
        median.as_secs_f64() / bound.as_secs_f64(),
        samples.len()
    );
}

fn quiet_config_at(baud: u32) -> xsel_pendant::link::LinkConfig {
    let mut config = quiet_config();
    config.timing.line = LineSettings {
        baud,
        ..LineSettings::default()
    };
    config
}

fn table_diff(c: &mut Criterion) {
    let table = |seed: i32| -> Vec<Option<CoordSystem>> {
        (0..128)
            .map(|n| Some(CoordSystem::from_wire([n * 1000 + seed, -n, n % 7, seed])))
            .collect()
    };
    let (a, mut b) = (table(0), table(0));
    for n in (0..128).step_by(5) {
        b[n] = Some(CoordSystem::from_wire([n as i32, 1, 2, 3]));
    }
    let (wa, wb) = (a[..32].to_vec(), b[..32].to_vec());
    c.bench_function("diff two full tables (32 work + 128 tool)", |bench| {
        bench.iter(|| {
            let w = diff(black_box(&wa), black_box(&wb));
            let t = diff(black_box(&a), black_box(&b));
            black_box((w, t))
        })
    });
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(10).measurement_time(Duration::from_secs(8));
    targets = table_read, table_diff
}
criterion_main!(benches);
