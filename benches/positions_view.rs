//! The Positions view with a full 20,000-row table: the CPU time of one frame (layout of
//! the view and tessellation, no AccessKit), still and while scrolling, and the filter
//! over 20,000 rows. Plain timing loops; each figure prints median, p99 and max.
//! Run: `cargo bench --bench positions_view` (`POSITIONS_VIEW_FRAMES`, default 2000).

#[path = "view_frames/mod.rs"]
mod view_frames;

use std::hint::black_box;

use std::path::Path;
use std::time::{Duration, Instant};

use xsel_pendant::link::{LinkEvent, Origin, RequestId};
use xsel_pendant::pendant::positions::{Filter, record_of_pose};
use xsel_pendant::pendant::{Pendant, Settings};
use xsel_pendant::protocol::{Command, PositionData, RecordArm, Reply};
use xsel_pendant::robot::RobotModel;
use xsel_pendant::ui::positions::PositionsPanel;

/// A pendant whose position table holds all 20,000 numbers, read as the link would
/// deliver them.
fn full_table() -> Pendant {
    let mut p = Pendant::new(Settings::default(), RobotModel::default_model());
    p.positions.start_read(1..=20_000).expect("a read");
    loop {
        let commands = p.positions.take_commands();
        if commands.is_empty() {
            break;
        }
        for (command, _) in commands {
            let Command::PositionQuery(q) = command else {
                continue;
            };
            let records = (q.first..q.first + q.count)
                .map(|n| {
                    let x = 200_000 + i32::from(n);
                    record_of_pose(n, [x, -150_000, 20_000, 45_000], RecordArm::Right)
                })
                .collect();
            let _ = p.positions.handle_event(&LinkEvent::Reply {
                id: RequestId(1),
                origin: Origin::User,
                command: Command::PositionQuery(q),
                reply: Reply::Positions(PositionData {
                    kind: q.kind,
                    records,
                }),
                round_trip: Duration::ZERO,
            });
        }
    }
    assert!(p.positions.read.is_none(), "the table is read");
    p
}

fn main() {
    let frames: usize = std::env::var("POSITIONS_VIEW_FRAMES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(2000);
    let mut pendant = full_table();
    // A draft row every 100 numbers, so "only rows that differ" has work to do.
    for n in (1..=20_000u16).step_by(100) {
        let rec = record_of_pose(n, [1, 2, 3, 4], RecordArm::Left);
        pendant.positions.put(rec).expect("a number");
    }
    let ctx = egui::Context::default();
    let mut panel = PositionsPanel::default();
    let now = Instant::now();
    let mut run = |scroll: bool| {
        let mut out = Vec::new();
        view_frames::frame(&ctx, scroll, |ui| {
            panel.show(ui, &pendant, Path::new("."), now, &mut out);
        })
    };
    for _ in 0..50 {
        run(false);
    }
    let still: Vec<Duration> = (0..frames).map(|_| run(false)).collect();
    view_frames::stats("Positions view, 20,000 rows, a still frame", still);
    let scrolling: Vec<Duration> = (0..frames).map(|_| run(true)).collect();
    view_frames::stats(
        "Positions view, 20,000 rows, scrolling 220 px a frame",
        scrolling,
    );
    for (what, filter) in [
        ("filter, all rows", Filter::default()),
        (
            "filter, used only",
            Filter {
                used_only: true,
                ..Filter::default()
            },
        ),
        (
            "filter, only rows that differ",
            Filter {
                differ_only: true,
                ..Filter::default()
            },
        ),
    ] {
        let times: Vec<Duration> = (0..500)
            .map(|_| {
                let started = Instant::now();
                black_box(pendant.positions.visible(black_box(&filter)));
                started.elapsed()
            })
            .collect();
        view_frames::stats(&format!("{what} of 20,000"), times);
    }
}
