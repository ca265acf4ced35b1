//! The Signals view with 1,000 watched rows (300 inputs, 300 outputs, 300 global flags,
//! 100 integer variables), every one read twice and a third of them changed: the CPU
//! time of one frame (layout of the view and tessellation, no AccessKit), still and while
//! scrolling. Plain timing loops; each figure prints median, p99
//! and max. Target: p99 <= 4 ms.
//! Run: `cargo bench --bench signals_view` (`SIGNALS_VIEW_FRAMES`, default 2000).

#[path = "view_frames/mod.rs"]
mod view_frames;

use std::path::Path;
use std::time::{Duration, Instant};

use xsel_pendant::link::{LinkEvent, Origin, RequestId};
use xsel_pendant::pendant::signals::{Signal, SignalKind, SignalsCx, SignalsIntent};
use xsel_pendant::pendant::{Pendant, Settings};
use xsel_pendant::protocol::{BitData, Command, Reply, VarData, VarValues};
use xsel_pendant::robot::RobotModel;
use xsel_pendant::ui::signals::SignalsPanel;

fn cx() -> SignalsCx {
    SignalsCx {
        ready: Ok(()),
        program_running: Some(false),
        io_interlock: false,
    }
}

/// One round of reads answered as the link would deliver them; `round` shifts the values
/// so a second round changes a third of them.
fn answer_round(p: &mut Pendant, now: Instant, round: u16) {
    p.signals.tick(now, true);
    for (command, _) in p.signals.take_commands() {
        let reply = match &command {
            Command::BitQuery(q) => Reply::Bits(BitData::from_fn(
                q.space,
                q.program,
                q.start,
                q.count,
                |n| (n + round).is_multiple_of(3),
            )),
            Command::VarQuery(q) => Reply::Vars(VarData {
                program: q.program,
                start: q.start,
                values: VarValues::Integer(
                    (0..q.count)
                        .map(|i| i32::from(i) * 10 + i32::from(round))
                        .collect(),
                ),
            }),
            _ => continue,
        };
        let _ = p.signals.handle_event(
            &LinkEvent::Reply {
                id: RequestId(1),
                origin: Origin::User,
                command,
                reply,
                round_trip: Duration::ZERO,
            },
            cx(),
            now,
        );
    }
}

/// A pendant watching 1,000 signals, each read.
fn watched() -> Pendant {
    let mut p = Pendant::new(Settings::default(), RobotModel::default_model());
    let now = Instant::now();
    let _ = p.signals.apply(SignalsIntent::Clear, cx(), now);
    for (kind, number, count) in [
        (SignalKind::Input, 0, 300),
        (SignalKind::Output, 300, 300),
        (SignalKind::Flag, 600, 300),
        (SignalKind::Integer, 200, 100),
    ] {
        let _ = p.signals.apply(
            SignalsIntent::Add {
                signal: Signal::new(kind, 0, number),
                count,
                name: "sensor".into(),
                chars: 0,
            },
            cx(),
            now,
        );
    }
    assert_eq!(p.signals.rows().len(), 1_000, "1,000 rows watched");
    let _ = p.signals.apply(SignalsIntent::Watch(true), cx(), now);
    answer_round(&mut p, now, 0);
    answer_round(&mut p, now + Duration::from_millis(200), 1);
    assert!(
        p.signals
            .rows()
            .iter()
            .all(|r| p.signals.state(&r.signal).is_some()),
        "every row read"
    );
    p
}

fn main() {
    let frames: usize = std::env::var("SIGNALS_VIEW_FRAMES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(2000);
    let pendant = watched();
    let ctx = egui::Context::default();
    let mut panel = SignalsPanel::default();
    // Within the highlight after the second round's changes: highlighted rows drawn too.
    let now = Instant::now() + Duration::from_millis(300);
    let run = |panel: &mut SignalsPanel, scroll: bool| {
        let mut out = Vec::new();
        view_frames::frame(&ctx, scroll, |ui| {
            panel.show(ui, &pendant, Path::new("."), now, &mut out);
        })
    };
    for _ in 0..50 {
        run(&mut panel, false);
    }
    let still: Vec<Duration> = (0..frames).map(|_| run(&mut panel, false)).collect();
    view_frames::stats("Signals view, 1,000 rows, a still frame", still);
    let scrolling: Vec<Duration> = (0..frames).map(|_| run(&mut panel, true)).collect();
    view_frames::stats(
        "Signals view, 1,000 rows, scrolling 220 px a frame",
        scrolling,
    );
}
