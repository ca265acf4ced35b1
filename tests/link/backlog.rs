//! A reader that stops reading: the event backlog stays bounded, traffic is left out and
//! counted exactly, and replies, line state and health are never left out.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use crate::common::*;
use crate::wait::{LONG, eventually, until};
use xsel_pendant::link::{LinkConfig, LinkEvent, Origin, Polling, spawn};
use xsel_pendant::protocol::Command;
use xsel_pendant::sim::{EmbeddedOptions, FaultSpec, start_embedded};

#[test]
fn a_reader_that_stops_reading_leaves_a_bounded_backlog_and_an_exact_dropped_count() {
    let backlog = 200;
    let config = LinkConfig {
        polling: Polling {
            interval: Some(Duration::ZERO),
            idle_interval: None,
            commands: vec![Command::SystemStatus],
        },
        event_backlog: backlog,
        ..LinkConfig::default()
    };
    let (pipe, sim) = start_embedded(EmbeddedOptions {
        setup: ready_setup(Duration::ZERO),
        byte_time: None,
        read_timeout: Duration::from_millis(20),
        faults: FaultSpec::none(),
        ..EmbeddedOptions::default()
    });
    // The pause of the polls is told in a health figure, which is never left out: seen
    // here as the link queues it.
    let paused = Arc::new(AtomicBool::new(false));
    let told = paused.clone();
    let repaint = Arc::new(move |e: &LinkEvent| {
        if matches!(e, LinkEvent::Health(h) if h.polling_paused) {
            told.store(true, Ordering::Relaxed);
        }
    });
    let (link, events) = spawn(pipe_connector(pipe), config, repaint).expect("link thread");
    // Not reading: the polls (due at once, over and over) fill the backlog, and the link
    // pauses them.
    assert!(
        eventually(LONG, || events.len() >= backlog),
        "the backlog filled"
    );
    until("the polls paused for the reader", LONG, || {
        paused.load(Ordering::Relaxed)
    });
    // From the pause on, only the poll in flight may still be answered; watched for a
    // second, failing the moment the simulator gets a second poll or the backlog grows
    // by more than that reply and the pause's own health figure (polls that went on
    // would do both within milliseconds).
    let (frames, queued) = (sim.counters().frames, events.len());
    let grew = eventually(Duration::from_secs(1), || {
        sim.counters().frames > frames + 1 || events.len() > queued + 2
    });
    let held = events.len();
    assert!(
        !grew,
        "polling went on after the pause: {} frames polled, {held} events held (from {queued})",
        sim.counters().frames - frames
    );
    assert!(
        held <= backlog + 10,
        "{held} events held for a reader that reads nothing (limit {backlog})"
    );
    // Reading again: polling resumes, and at shutdown every count adds up.
    let mut seen: Vec<LinkEvent> = Vec::new();
    wait_for(&events, LONG, &mut seen, |e| {
        matches!(e, LinkEvent::Dropped { .. })
    })
    .expect("the left-out traffic is reported once the reader is back");
    wait_for(
        &events,
        LONG,
        &mut seen,
        |e| matches!(e, LinkEvent::Health(h) if !h.polling_paused),
    )
    .expect("polling resumes");
    link.set_polling(Polling {
        interval: None,
        idle_interval: None,
        commands: Vec::new(),
    });
    // The second health figure after polling stopped counts every poll.
    for _ in 0..2 {
        wait_for(&events, LONG, &mut seen, |e| {
            matches!(e, LinkEvent::Health(_))
        })
        .expect("health while idle");
    }
    drop(link);
    while let Ok(e) = events.recv_timeout(LONG) {
        let last = matches!(e, LinkEvent::ShutDown(_));
        seen.push(e);
        if last {
            break;
        }
    }
    let count = |f: fn(&LinkEvent) -> bool| seen.iter().filter(|e| f(e)).count() as u64;
    let sent = count(|e| matches!(e, LinkEvent::FrameSent { .. }));
    let received = count(|e| matches!(e, LinkEvent::FrameReceived { .. }));
    let replies = count(|e| {
        matches!(
            e,
            LinkEvent::Reply {
                origin: Origin::Poll,
                ..
            }
        )
    });
    let dropped: u64 = seen
        .iter()
        .map(|e| match e {
            LinkEvent::Dropped { frames } => *frames,
            _ => 0,
        })
        .sum();
    let health = seen
        .iter()
        .rev()
        .find_map(|e| match e {
            LinkEvent::Health(h) => Some(h.clone()),
            _ => None,
        })
        .expect("health");
    assert!(dropped > 0, "traffic was left out");
    assert!(health.reader_stalls >= 1, "{health:?}");
    assert!(
        !seen.iter().any(|e| matches!(e, LinkEvent::Timeout { .. })),
        "no poll timed out"
    );
    // Every poll sent was answered, and every reply arrived; each transaction made one
    // FrameSent and one FrameReceived, each either delivered or counted as dropped.
    assert_eq!(
        sent + received + dropped,
        2 * replies,
        "sent {sent} + received {received} + dropped {dropped} vs {replies} replies"
    );
    assert_eq!(
        health.replies, replies,
        "every reply of the link's last health figure reached the reader"
    );
}
