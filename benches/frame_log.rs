//! Frame log figures, on the real app (egui_kittest driving `PendantApp` on the embedded
//! simulator) with one million rows logged:
//!
//! 1. UI frame CPU time (`harness.step()` plus tessellation, as in `benches/window.rs`,
//!    and the same app driven as the real window drives it, without AccessKit)
//!    with the frame log pane open beside the messages, status and teach panes, the
//!    tail followed while the link polls (new rows arrive all the time);
//! 2. filtering the million rows by text (the work the filter thread does), and the UI
//!    frame time while such a filter runs;
//! 3. resident memory of the whole process (`VmRSS`) with the million rows logged.
//!
//! Plain timing loops; each figure prints median, p99 and max. Frames:
//! `FRAME_LOG_BENCH_FRAMES` (default 1000).

use std::hint::black_box;
use std::time::{Duration, Instant};

use egui::accesskit::Role;
use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use xsel_pendant::pendant::frame_log::filter::Filter;
use xsel_pendant::ui::frame_log::jobs::filter_now;
use xsel_pendant::ui::{PendantApp, StartOptions};

const ROWS: u64 = 1_000_000;

fn main() {
    let frames = std::env::var("FRAME_LOG_BENCH_FRAMES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(1000usize);
    println!(
        "frame log bench: {} cores available, {ROWS} rows",
        std::thread::available_parallelism().map_or(0, |n| n.get())
    );
    let rss0 = rss_kib();
    let mut h = Harness::builder()
        .with_size([1280.0, 800.0])
        .build_eframe(|cc| PendantApp::new(cc, StartOptions::fresh_simulator()));
    let end = Instant::now() + Duration::from_secs(30);
    while !h.state().pendant().line.is_up() {
        assert!(Instant::now() < end, "the simulator did not connect");
        h.step();
        std::thread::sleep(Duration::from_millis(5));
    }
    let t = Instant::now();
    synthetic(h.state_mut(), ROWS);
    println!(
        "   {ROWS} rows logged in {:.0} ms",
        t.elapsed().as_secs_f64() * 1e3
    );
    h.get_by_role_and_label(Role::Button, "Frame log").click();
    h.run_steps(10);

    let rows_before = h.state().pendant().frame_log.end();
    let mut cpu = frame_times(&mut h, frames);
    let arrived = h.state().pendant().frame_log.end() - rows_before;
    println!();
    println!(
        "1. UI frame CPU time, 1280x800, frame log open with {} rows, tail followed while \
         polling ({frames} frames, {arrived} rows arrived meanwhile)",
        h.state().pendant().frame_log.len()
    );
    report("   thread CPU: step + tessellate", &mut cpu);
    let mut cpu = window_frame_times(h.state_mut(), frames);
    report(
        "   thread CPU: logic + ui + tessellate, no AccessKit (as the real window runs)",
        &mut cpu,
    );

    println!();
    println!("2. filtering {ROWS} rows by text");
    let snapshot = h.state().pendant().frame_log.snapshot();
    for (label, text, decoded) in [
        ("raw, name and note ('&99C1F')", "&99c1f", false),
        ("raw, name and note, no hit ('zzz')", "zzz", false),
    ] {
        let matcher = Filter {
            text: text.into(),
            decoded,
            ..Filter::default()
        }
        .matcher();
        let mut times = Vec::new();
        let mut hits = 0;
        for _ in 0..7 {
            let c = cpu_time::ThreadTime::now();
            hits = black_box(filter_now(&snapshot, &matcher)).seqs.len();
            times.push(c.elapsed());
        }
        report(&format!("   {label}, {hits} hits, thread CPU"), &mut times);
    }
    // The decoded fields too (every row not matched by its bytes is decoded): once.
    let matcher = Filter {
        text: "zzz".into(),
        decoded: true,
        ..Filter::default()
    }
    .matcher();
    let c = cpu_time::ThreadTime::now();
    let hits = black_box(filter_now(&snapshot, &matcher)).seqs.len();
    println!(
        "   raw, name, note and decoded fields, no hit ('zzz'), {hits} hits, thread CPU: {:.0} ms (n=1)",
        c.elapsed().as_secs_f64() * 1e3
    );
    drop(snapshot);
    // The UI while the filter thread works: type a filter, time frames until it is done.
    // The pane at 1280x800 shows rows first; the filter rows come with a click.
    h.get_by_label("Filter, files, raw").click();
    h.run_steps(2);
    let field = h.get_by_label("Filter text");
    field.focus();
    h.step();
    h.get_by_label("Filter text").type_text("zzz");
    let mut during = Vec::new();
    let mut wall = Vec::new();
    let t = Instant::now();
    loop {
        let c = cpu_time::ThreadTime::now();
        let w = Instant::now();
        h.step();
        let shapes = h.output().shapes.clone();
        let ppp = h.output().pixels_per_point;
        black_box(h.ctx.tessellate(shapes, ppp));
        during.push(c.elapsed());
        wall.push(w.elapsed());
        if !h.state().frame_log_panel().filtering() && during.len() > 2 {
            break;
        }
        assert!(
            t.elapsed() < Duration::from_secs(30),
            "the filter never ended"
        );
    }
    println!(
        "   typed filter 'zzz' in the window: result after {:.0} ms wall, {} frames meanwhile",
        t.elapsed().as_secs_f64() * 1e3,
        during.len()
    );
    report("   UI frame thread CPU while filtering", &mut during);
    report("   UI frame wall while filtering", &mut wall);

    println!();
    let rss = rss_kib();
    println!(
        "3. resident memory (VmRSS) of the whole process with {} rows: {:.1} MiB \
         (before the window: {:.1} MiB)",
        h.state().pendant().frame_log.len(),
        rss as f64 / 1024.0,
        rss0 as f64 / 1024.0
    );
}

/// Status queries and replies (the polling traffic), every 1000th reply an error.
fn synthetic(a: &mut PendantApp, n: u64) {
    a.pendant_mut().frame_log.fill_synthetic(n);
}

fn frame_times(h: &mut Harness<'_, PendantApp>, n: usize) -> Vec<Duration> {
    let mut cpu = Vec::with_capacity(n);
    for _ in 0..n {
        let c = cpu_time::ThreadTime::now();
        h.step();
        let shapes = h.output().shapes.clone();
        let ppp = h.output().pixels_per_point;
        black_box(h.ctx.tessellate(shapes, ppp));
        cpu.push(c.elapsed());
        std::thread::sleep(Duration::from_millis(10));
    }
    cpu
}

/// Frame times of the same app driven as eframe drives it in the real window: a plain
/// context with AccessKit off (eframe is built without its `accesskit` feature), whereas
/// the kittest harness builds and consumes the whole AccessKit tree every frame.
fn window_frame_times(app: &mut PendantApp, n: usize) -> Vec<Duration> {
    use eframe::App as _;
    let ctx = egui::Context::default();
    let mut frame = eframe::Frame::_new_kittest();
    let input = || egui::RawInput {
        screen_rect: Some(egui::Rect::from_min_size(
            egui::Pos2::ZERO,
            egui::vec2(1280.0, 800.0),
        )),
        ..Default::default()
    };
    let mut run = |app: &mut PendantApp| {
        let out = ctx.run_ui(input(), |ui| {
            app.logic(ui.ctx(), &mut frame);
            app.ui(ui, &mut frame);
        });
        black_box(ctx.tessellate(out.shapes, out.pixels_per_point));
    };
    // A few frames to settle (fonts, first layout) before measuring.
    for _ in 0..10 {
        run(app);
    }
    let mut cpu = Vec::with_capacity(n);
    for _ in 0..n {
        let c = cpu_time::ThreadTime::now();
        run(app);
        cpu.push(c.elapsed());
        std::thread::sleep(Duration::from_millis(10));
    }
    cpu
}

fn report(label: &str, v: &mut [Duration]) {
    v.sort_unstable();
    let at = |q: f64| v[((v.len() - 1) as f64 * q).round() as usize];
    println!(
        "{label}: median {:.3} ms, p99 {:.3} ms, max {:.3} ms (n={})",
        at(0.5).as_secs_f64() * 1e3,
        at(0.99).as_secs_f64() * 1e3,
        at(1.0).as_secs_f64() * 1e3,
        v.len()
    );
}

fn rss_kib() -> u64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("VmRSS:"))
                .and_then(|l| l.split_whitespace().nth(1)?.parse().ok())
        })
        .unwrap_or(0)
}
