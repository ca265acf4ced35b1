//! Timing one frame of a view in a bench: a 1280x800 input with the pointer over the
//! view (and a wheel turn when scrolling), layout and tessellation timed; median, p99
//! and max printed.

use std::hint::black_box;
use std::time::{Duration, Instant};

/// Median, p99 and max of `d`, printed under `what`.
pub fn stats(what: &str, mut d: Vec<Duration>) {
    d.sort();
    let at = |p: f64| d[((d.len() as f64 - 1.0) * p).round() as usize];
    println!(
        "{what}: {} samples, median {:.3} ms, p99 {:.3} ms, max {:.3} ms",
        d.len(),
        at(0.5).as_secs_f64() * 1e3,
        at(0.99).as_secs_f64() * 1e3,
        d[d.len() - 1].as_secs_f64() * 1e3
    );
}

/// The CPU time of one frame drawn by `draw` (layout and tessellation, no AccessKit),
/// scrolling 220 px when `scroll`.
pub fn frame(ctx: &egui::Context, scroll: bool, draw: impl FnMut(&mut egui::Ui)) -> Duration {
    let screen = egui::Rect::from_min_size(egui::Pos2::ZERO, egui::vec2(1280.0, 800.0));
    let mut input = egui::RawInput {
        screen_rect: Some(screen),
        ..Default::default()
    };
    input
        .events
        .push(egui::Event::PointerMoved(egui::pos2(600.0, 500.0)));
    if scroll {
        input.events.push(egui::Event::MouseWheel {
            unit: egui::MouseWheelUnit::Point,
            delta: egui::vec2(0.0, -220.0),
            modifiers: egui::Modifiers::NONE,
            phase: egui::TouchPhase::Move,
            source: egui::MouseWheelSource::Wheel,
        });
    }
    let started = Instant::now();
    let output = ctx.run_ui(input, draw);
    let shapes = ctx.tessellate(output.shapes, output.pixels_per_point);
    black_box(shapes);
    started.elapsed()
}
