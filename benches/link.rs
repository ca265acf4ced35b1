//! Link figures against the embedded simulator paced at the baud rate:
//! line efficiency while polling, idle submit-to-wire latency, STOP latency while polling.
//! Run: `cargo bench --bench link`.

#[path = "../tests/common/mod.rs"]
mod common;

use std::time::{Duration, Instant};

use common::*;
use xsel_pendant::line::LineSettings;
use xsel_pendant::link::timing::Timing;
use xsel_pendant::link::{LinkConfig, LinkEvent, Polling, Priority};
use xsel_pendant::protocol::{
    AxisPattern, Command, PositionSystem, ScMode, ScaraStatusQuery, Station,
};
use xsel_pendant::sim::FaultSpec;

const REPLY_DELAY: Duration = Duration::from_millis(2);

fn poll_command() -> Command {
    Command::ScaraStatus(ScaraStatusQuery {
        axes: AxisPattern::SCARA_1,
        system: PositionSystem::Work,
    })
}

fn line(baud: u32) -> LineSettings {
    LineSettings {
        baud,
        ..LineSettings::default()
    }
}

fn config(baud: u32, polling: Option<Duration>) -> LinkConfig {
    let mut config = LinkConfig {
        polling: Polling {
            interval: polling,
            idle_interval: None,
            commands: if polling.is_some() {
                vec![poll_command()]
            } else {
                Vec::new()
            },
        },
        ..LinkConfig::default()
    };
    config.timing.line = line(baud);
    config
}

fn percentile(sorted: &[Duration], p: f64) -> Duration {
    let i = ((sorted.len() as f64 - 1.0) * p).round() as usize;
    sorted[i.min(sorted.len() - 1)]
}

/// Polls back to back for `run`; returns (achieved per s, the wire's limit per s).
fn line_efficiency(baud: u32, run: Duration) -> (f64, f64) {
    let (_link, events, _sim) = embedded_link(
        ready_setup(REPLY_DELAY),
        FaultSpec::none(),
        Some(line(baud).byte_time()),
        config(baud, Some(Duration::ZERO)),
    );
    let mut seen = Vec::new();
    // Warm up: the first answered poll.
    wait_for(&events, Duration::from_secs(5), &mut seen, |e| {
        matches!(e, LinkEvent::Reply { .. })
    })
    .expect("the simulator answers");
    let start = Instant::now();
    let mut replies = 0u32;
    let mut reply_len = 0;
    // Where a transaction's time goes: written -> reply's last byte, and that -> the next
    // frame written (the gap).
    let (mut trips, mut gaps) = (Vec::new(), Vec::new());
    let (mut sent, mut received) = (None::<Instant>, None::<Instant>);
    while start.elapsed() < run {
        match events.recv_timeout(Duration::from_secs(1)) {
            Ok(LinkEvent::FrameReceived {
                bytes, last_byte, ..
            }) => {
                replies += 1;
                reply_len = bytes.len();
                if let Some(at) = sent.take() {
                    trips.push(last_byte.saturating_duration_since(at));
                }
                received = Some(last_byte);
            }
            Ok(LinkEvent::FrameSent { at, .. }) => {
                if let Some(end) = received.take() {
                    gaps.push(at.saturating_duration_since(end));
                }
                sent = Some(at);
            }
            _ => {}
        }
    }
    trips.sort();
    gaps.sort();
    let achieved = f64::from(replies) / start.elapsed().as_secs_f64();
    let command_len = poll_command()
        .to_bytes(Station::DEFAULT, ScMode::Computed)
        .expect("encodes")
        .len();
    let timing = Timing {
        line: line(baud),
        ..Timing::default()
    };
    let per = timing.wire_transaction_time(command_len, reply_len, REPLY_DELAY);
    println!(
        "  {baud:>6} baud: command {command_len} B + reply {reply_len} B -> wire limit {:.2}/s ({:.3} ms each), achieved {achieved:.2}/s",
        1.0 / per.as_secs_f64(),
        per.as_secs_f64() * 1e3
    );
    if !trips.is_empty() && !gaps.is_empty() {
        println!(
            "  {baud:>6} baud: written -> reply's last byte median {} (wire + delay {}), reply -> next written median {} (gap {})",
            ms(percentile(&trips, 0.5)),
            ms(per - timing.gap),
            ms(percentile(&gaps, 0.5)),
            ms(timing.gap)
        );
    }
    (achieved, 1.0 / per.as_secs_f64())
}

/// When the frame of request `id` was written (the events seen meanwhile kept in `seen`).
fn written_at(
    events: &crossbeam_channel::Receiver<LinkEvent>,
    seen: &mut Vec<LinkEvent>,
    id: xsel_pendant::link::RequestId,
) -> Instant {
    let sent = wait_for(
        events,
        Duration::from_secs(2),
        seen,
        |e| matches!(e, LinkEvent::FrameSent { id: s, .. } if *s == id),
    );
    match sent {
        Some(LinkEvent::FrameSent { at, .. }) => at,
        _ => panic!("request {id} was never written"),
    }
}

/// Submit on an idle line -> the frame written; `n` samples.
fn idle_latency(n: usize) -> Vec<Duration> {
    let (link, events, _sim) = embedded_link(
        ready_setup(REPLY_DELAY),
        FaultSpec::none(),
        Some(line(115_200).byte_time()),
        config(115_200, None),
    );
    let mut seen = Vec::new();
    let mut samples = Vec::with_capacity(n);
    for _ in 0..n {
        std::thread::sleep(Duration::from_millis(3));
        let submitted = Instant::now();
        let id = link.submit(Command::SystemStatus, Priority::User);
        let at = written_at(&events, &mut seen, id);
        samples.push(at.saturating_duration_since(submitted));
        wait_for(
            &events,
            Duration::from_secs(2),
            &mut seen,
            |e| matches!(e, LinkEvent::Reply { id: r, .. } if *r == id),
        );
        seen.clear();
    }
    samples.sort();
    samples
}

/// STOP submitted while polls run back to back: (submit -> STOP written) and
/// (end of the in-flight reply -> STOP written).
fn stop_latency(n: usize) -> (Vec<Duration>, Vec<Duration>) {
    let (link, events, _sim) = embedded_link(
        ready_setup(REPLY_DELAY),
        FaultSpec::none(),
        Some(line(115_200).byte_time()),
        config(115_200, Some(Duration::ZERO)),
    );
    let mut total = Vec::with_capacity(n);
    let mut after_reply = Vec::with_capacity(n);
    let mut seen = Vec::new();
    for i in 0..n {
        // A varying moment inside the poll cycle.
        std::thread::sleep(Duration::from_micros(2_000 + (i as u64 * 397) % 9_000));
        let submitted = Instant::now();
        let id = link.stop_all();
        seen.clear();
        let at = written_at(&events, &mut seen, id);
        total.push(at.saturating_duration_since(submitted));
        let last_reply = seen.iter().rev().find_map(|e| match e {
            LinkEvent::FrameReceived { last_byte, .. } => Some(*last_byte),
            _ => None,
        });
        if let Some(end) = last_reply {
            after_reply.push(at.saturating_duration_since(end));
        }
    }
    total.sort();
    after_reply.sort();
    (total, after_reply)
}

/// Simulator killed -> `Disconnected` reported, with polling on or off.
fn loss_detection(polling: bool, n: usize) -> Vec<Duration> {
    let mut samples = Vec::with_capacity(n);
    for _ in 0..n {
        let interval = polling.then_some(Duration::from_millis(50));
        let (_link, events, sim) = embedded_link(
            ready_setup(REPLY_DELAY),
            FaultSpec::none(),
            Some(line(115_200).byte_time()),
            config(115_200, interval),
        );
        let mut seen = Vec::new();
        wait_for(&events, Duration::from_secs(5), &mut seen, |e| {
            matches!(e, LinkEvent::Connected { .. })
        })
        .expect("connected");
        std::thread::sleep(Duration::from_millis(120));
        let pulled = Instant::now();
        drop(sim);
        wait_for(&events, Duration::from_secs(5), &mut seen, |e| {
            matches!(e, LinkEvent::Disconnected { .. })
        })
        .expect("loss reported");
        samples.push(pulled.elapsed());
    }
    samples.sort();
    samples
}

fn ms(d: Duration) -> String {
    format!("{:.3} ms", d.as_secs_f64() * 1e3)
}

fn main() {
    if std::env::args().any(|a| a == "--list") {
        return;
    }
    println!(
        "link figures (embedded simulator, reply delay {} ms, paced pipe)",
        REPLY_DELAY.as_millis()
    );
    println!(
        "line efficiency: wire limit per poll = (command + reply bytes) x bits per char / baud + 1 ms gap + reply delay"
    );
    for (baud, run) in [
        (115_200, Duration::from_secs(5)),
        (9_600, Duration::from_secs(8)),
    ] {
        let (achieved, limit) = line_efficiency(baud, run);
        println!(
            "  {baud:>6} baud: efficiency {:.1} %",
            100.0 * achieved / limit
        );
    }
    let idle = idle_latency(500);
    println!(
        "idle line, submit -> frame written ({} samples): median {}, p99 {}, max {}",
        idle.len(),
        ms(percentile(&idle, 0.5)),
        ms(percentile(&idle, 0.99)),
        ms(*idle.last().unwrap())
    );
    for polling in [true, false] {
        let loss = loss_detection(polling, 20);
        println!(
            "line pulled -> Disconnected, polling {} ({} samples): median {}, max {}",
            if polling { "every 50 ms" } else { "off" },
            loss.len(),
            ms(percentile(&loss, 0.5)),
            ms(*loss.last().unwrap())
        );
    }
    let (total, after) = stop_latency(300);
    println!(
        "STOP while polling at 115200 ({} samples): submit -> written median {}, p99 {}; end of in-flight reply -> written median {}, p99 {}, max {}",
        total.len(),
        ms(percentile(&total, 0.5)),
        ms(percentile(&total, 0.99)),
        ms(percentile(&after, 0.5)),
        ms(percentile(&after, 0.99)),
        ms(*after.last().unwrap())
    );
}
