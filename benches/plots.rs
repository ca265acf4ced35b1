//! Plot figures (issue "Motion plots"), printed as median, p99 and max:
//!
//! 1. memory of one hour of samples at the polling rates (two RMC axes at 50 polls/s,
//!    the X-SEL's work position at 10/s): the store's own count of bytes;
//! 2. decimation: four traces over that hour to 1000 pixel columns, the work of one
//!    frame of a live plot showing the whole hour;
//! 3. UI frame time of the real app (egui_kittest, 1280x800) with the Plots pane shown,
//!    four traces over the hour, and the frame log holding a million rows: thread CPU of
//!    `step()` plus tessellation, as `benches/window.rs` measures it.
//!
//! Sample counts: `PLOTS_BENCH_FRAMES` (default 300).

use std::hint::black_box;
use std::time::{Duration, Instant};

use egui_kittest::Harness;
use xsel_pendant::pendant::samples::polled::Polled;
use xsel_pendant::pendant::samples::view::{TraceChoice, live_trace};
use xsel_pendant::rmc::{AxisId, AxisStatus, StatusBits};
use xsel_pendant::ui::{PendantApp, StartOptions};

const HOUR: Duration = Duration::from_secs(3600);

fn main() {
    let frames = std::env::var("PLOTS_BENCH_FRAMES")
        .ok()
        .and_then(|v| v.parse().ok())
        .filter(|&n| n > 0)
        .unwrap_or(300);
    println!(
        "plots bench: {} cores available",
        std::thread::available_parallelism().map_or(0, |n| n.get())
    );
    let start = Instant::now();
    let polled = hour_of_samples(start);
    memory(&polled);
    decimation(&polled);
    window(frames);
}

/// An hour of polls ending now: two RMC axes moving back and forth, the X-SEL's X and Y
/// circling.
fn hour_of_samples(now: Instant) -> Polled {
    let mut p = Polled::new(2);
    let t0 = now - HOUR;
    for i in 0..3600 * 50u32 {
        let at = t0 + Duration::from_millis(u64::from(i) * 20);
        let t = f64::from(i) * 0.02;
        for axis in AxisId::first(2) {
            let x = (t * 0.5 + axis.index() as f64).sin() as f32 * 100.0;
            let s = AxisStatus {
                bits: StatusBits(0).with(StatusBits::IN_POSITION, i % 200 < 100),
                actual_position: x,
                target_position: x + 0.01,
                command_position: x.round(),
                target_velocity: x * 0.5,
                actual_velocity: x * 0.49,
                ..AxisStatus::default()
            };
            p.rmc_status(at, axis, &s);
        }
        if i % 5 == 0 {
            let pose = [
                ((t * 0.3).cos() * 250_000.0) as i32,
                ((t * 0.3).sin() * 250_000.0) as i32,
                0,
                90_000,
            ];
            p.xsel_work(at, pose, true, 0);
        }
    }
    p
}

fn four() -> [TraceChoice; 4] {
    [
        TraceChoice::new("Axis 1", "Target Position"),
        TraceChoice::new("Axis 1", "Actual Position"),
        TraceChoice::new("Axis 2", "Actual Position"),
        TraceChoice::new("Axis 1", "In Position"),
    ]
}

fn memory(p: &Polled) {
    let rows: usize = p.store.all().iter().map(|s| s.len()).sum();
    println!();
    println!(
        "1. one hour of samples: {rows} rows in {} series, {:.1} MB ({} bytes)",
        p.store.all().len(),
        p.store.bytes() as f64 / 1e6,
        p.store.bytes()
    );
}

fn decimation(p: &Polled) {
    let mut times = Vec::new();
    for _ in 0..200 {
        let t = Instant::now();
        for c in four() {
            black_box(live_trace(&p.store, &c, 0.0, 3600.0, 1000));
        }
        times.push(t.elapsed());
    }
    println!();
    report("2. decimate 4 traces x 1 h to 1000 columns", &mut times);
}

fn window(n: usize) {
    let mut h = Harness::builder()
        .with_size([1280.0, 800.0])
        .build_eframe(|cc| PendantApp::new(cc, StartOptions::fresh_simulator()));
    let a = h.state_mut();
    a.pendant_mut().samples = hour_of_samples(Instant::now());
    a.pendant_mut().frame_log.fill_synthetic(1_000_000);
    let plots = a.plots_panel_mut();
    plots.traces = four().map(Some);
    h.get_by_label_contains_first("Plots");
    h.run_steps(2);
    {
        let p = h.state_mut().plots_panel_mut();
        p.window_s = std::env::var("PLOTS_BENCH_SPAN")
            .ok()
            .and_then(|v| v.parse().ok())
            .unwrap_or(3600.0);
    }
    h.run_steps(10);
    let mut cpu = Vec::with_capacity(n);
    for _ in 0..n {
        let c0 = cpu_time::ThreadTime::now();
        h.step();
        let shapes = h.output().shapes.clone();
        let ppp = h.output().pixels_per_point;
        black_box(h.ctx.tessellate(shapes, ppp));
        cpu.push(c0.elapsed());
        std::thread::sleep(Duration::from_millis(10));
    }
    let shown = h.state().plots_panel().shown;
    println!();
    println!(
        "3. UI frame, Plots pane live over {:.0} s with 4 traces, frame log {} rows ({n} frames)",
        shown.1 - shown.0,
        h.state().pendant().frame_log.len()
    );
    report("   thread CPU: step + tessellate", &mut cpu);
}

trait FirstByLabel {
    fn get_by_label_contains_first(&mut self, label: &str);
}

impl FirstByLabel for Harness<'_, PendantApp> {
    /// Clicks the first widget whose label contains `label` (the Plots tab).
    fn get_by_label_contains_first(&mut self, label: &str) {
        use egui_kittest::kittest::Queryable;
        if let Some(n) = self.query_all_by_label(label).next() {
            n.click();
        }
        self.step();
    }
}

fn ms(d: Duration) -> String {
    format!("{:.3}", d.as_secs_f64() * 1e3)
}

fn report(what: &str, samples: &mut [Duration]) {
    samples.sort_unstable();
    let n = samples.len();
    let median = samples[n / 2];
    let p99 = samples[(n * 99).div_ceil(100).saturating_sub(1)];
    let max = samples[n - 1];
    println!(
        "{what:<44} median {:>8} ms   p99 {:>8} ms   max {:>8} ms",
        ms(median),
        ms(p99),
        ms(max)
    );
}
