//! Window figures, measured headlessly on the real app (egui_kittest driving
//! `PendantApp` on the embedded simulator, its line paced at the configured baud rate):
//!
//! 1. click to 2D5H: from the frame that delivers the press on X+/X- (a step goes on the
//!    press; 0.01 mm steps, servo on and homed, idle, polling) to the simulator holding
//!    the whole 2D5H frame, and the time its first byte went on the line (that, less the
//!    frame's wire time);
//! 3. Esc to 238H: from the frame that delivers Esc (idle, polling) to the simulator
//!    holding the whole 238H, and its first byte (less the wire time);
//! 2. UI frame CPU time: `harness.step()` (logic, layout, AccessKit update) plus
//!    tessellation of the frame's shapes, on the idle main window while the link polls.
//!
//! Plain timing loops; each figure prints median, p99 and max. Sample counts:
//! `WINDOW_BENCH_STEPS` (default 200) and `WINDOW_BENCH_FRAMES` (default 2000).
//! Start-up time and resident memory of the real window: `benches/window_startup.sh`.
//!
//! Waits are bounded by deadlines; the short sleeps in them only pace the polling.

use std::hint::black_box;
use std::time::{Duration, Instant};

use egui::accesskit::Role;
use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use xsel_pendant::pendant::MotionPhase;
use xsel_pendant::protocol::HomeState;
use xsel_pendant::sim::runner::{Dir, TrafficEntry};
use xsel_pendant::ui::{PendantApp, StartOptions};

const DEADLINE: Duration = Duration::from_secs(30);

fn main() {
    let steps = env_count("WINDOW_BENCH_STEPS", 200);
    let frames = env_count("WINDOW_BENCH_FRAMES", 2000);
    println!(
        "window bench: {} cores available",
        std::thread::available_parallelism().map_or(0, |n| n.get())
    );
    let mut h = app();
    ready(&mut h);
    click_to_2d5h(&mut h, steps);
    frame_time(&mut h, frames);
    esc_to_238h(&mut h, steps);
}

fn env_count(name: &str, default: usize) -> usize {
    std::env::var(name)
        .ok()
        .and_then(|v| v.parse().ok())
        .filter(|&n| n > 0)
        .unwrap_or(default)
}

fn app<'a>() -> Harness<'a, PendantApp> {
    Harness::builder()
        .with_size([1280.0, 800.0])
        .build_eframe(|cc| PendantApp::new(cc, StartOptions::fresh_simulator()))
}

/// Steps the window until `done` holds; panics naming `what` after the deadline.
fn step_until(h: &mut Harness<'_, PendantApp>, what: &str, done: impl Fn(&PendantApp) -> bool) {
    let end = Instant::now() + DEADLINE;
    while !done(h.state()) {
        assert!(Instant::now() < end, "timed out waiting for: {what}");
        h.step();
        std::thread::sleep(Duration::from_millis(2));
    }
    h.step();
}

fn all_axes(app: &PendantApp, f: impl Fn(&xsel_pendant::protocol::AxisState) -> bool) -> bool {
    app.pendant()
        .controller
        .axes()
        .is_some_and(|axes| axes.iter().all(|(_, a)| f(&a)))
}

/// Clicks the first button with this label (Servo ON and Home are beside the pad and in
/// the Status tab).
fn click(h: &mut Harness<'_, PendantApp>, label: &str) {
    h.get_all_by_role_and_label(Role::Button, label)
        .next()
        .unwrap_or_else(|| panic!("no button {label:?}"))
        .click();
    h.step();
    h.step();
}

/// Connects, switches the servo on and homes, as an operator would.
fn ready(h: &mut Harness<'_, PendantApp>) {
    step_until(h, "the controller to accept commands", |a| {
        a.pendant().controller_ready(Instant::now()).is_ok()
    });
    click(h, "Servo ON");
    step_until(h, "servo on", |a| all_axes(a, |s| s.status.servo_on()));
    step_until(h, "the servo switch to end", |a| {
        all_axes(a, |s| !s.status.in_use())
    });
    click(h, "Home");
    step_until(h, "homed", |a| {
        all_axes(a, |s| {
            s.status.home_state() == HomeState::Done && !s.status.in_use()
        })
    });
    step_until(h, "motion allowed and tables read", |a| {
        a.pendant().motion_ready(Instant::now()).is_ok()
            && a.pendant().controller.tool_table.is_some()
    });
}

fn step_ended(a: &PendantApp) -> bool {
    a.pendant().motion_phase(Instant::now()) == MotionPhase::Done
        && all_axes(a, |s| !s.status.in_use())
        && a.sim()
            .is_some_and(|s| s.with(|c| c.snapshot().in_use) == 0)
}

/// The first 2D5H the simulator received at or after `since`, as an `Instant`, with its
/// bytes.
fn first_2d5h_since(
    traffic: &[TrafficEntry],
    started: Instant,
    since: Instant,
) -> Option<(Instant, Vec<u8>)> {
    traffic
        .iter()
        .filter(|t| t.dir == Dir::In && t.bytes.get(3..6) == Some(b"2D5".as_slice()))
        .find(|t| started + t.at >= since)
        .map(|t| (started + t.at, t.bytes.clone()))
}

/// Figure 1: click to 2D5H on the line.
fn click_to_2d5h(h: &mut Harness<'_, PendantApp>, n: usize) {
    click(h, "0.01");
    let line = h.state().pendant().settings.connection.line();
    let sim_started = h
        .state()
        .sim()
        .expect("the embedded simulator")
        .with_core(|c| c.started());
    let mut whole = Vec::with_capacity(n);
    let mut first_byte = Vec::with_capacity(n);
    let mut click_frame = Vec::with_capacity(n);
    let mut frame = Vec::new();
    let mut lens = std::collections::BTreeSet::new();
    for i in 0..n {
        let label = if i % 2 == 0 { "X+" } else { "X-" };
        // Pointer move first; the press (which steps) and the release get frames of their
        // own, as a real window would run one for each.
        let pos = h.get_by_role_and_label(Role::Button, label).rect().center();
        h.event(egui::Event::PointerMoved(pos));
        h.step();
        let press = |pressed| egui::Event::PointerButton {
            pos,
            button: egui::PointerButton::Primary,
            pressed,
            modifiers: egui::Modifiers::default(),
        };
        h.event(press(true));
        let clicked = Instant::now();
        h.step();
        click_frame.push(clicked.elapsed());
        h.event(press(false));
        h.step();
        // Wait for the frame without running more frames: only the link and the
        // simulator threads work meanwhile.
        let sim = h.state().sim().expect("the embedded simulator").watch();
        let end = Instant::now() + DEADLINE;
        let (at, bytes) = loop {
            if let Some(found) = first_2d5h_since(&sim.traffic(), sim_started, clicked) {
                break found;
            }
            assert!(
                Instant::now() < end,
                "no 2D5H after click {i} ({label}); jog message: {:?}",
                h.state().pendant().jog.feedback
            );
            std::thread::sleep(Duration::from_micros(200));
        };
        let len = bytes.len();
        lens.insert(len);
        frame = bytes;
        let latency = at.saturating_duration_since(clicked);
        whole.push(latency);
        first_byte.push(latency.saturating_sub(line.wire_time(len)));
        step_until(h, "the step to end", step_ended);
    }
    println!();
    println!("1. click to 2D5H on the line ({n} steps of 0.01 mm, X+/X-, line {line})");
    report("   click frame (step() of the press)", &mut click_frame);
    report("   click to whole 2D5H at the sim", &mut whole);
    println!(
        "   (includes each frame's wire time: {} ms for {} bytes; lengths seen {lens:?}; \
         the last frame: {})",
        ms(line.wire_time(frame.len())),
        frame.len(),
        String::from_utf8_lossy(&frame).trim_end()
    );
    report("   click to first byte (less wire time)", &mut first_byte);
}

/// Figure 3: Esc to 238H on the line, the link polling meanwhile.
fn esc_to_238h(h: &mut Harness<'_, PendantApp>, n: usize) {
    let line = h.state().pendant().settings.connection.line();
    let sim_started = h
        .state()
        .sim()
        .expect("the embedded simulator")
        .with_core(|c| c.started());
    let sim = h.state().sim().expect("the embedded simulator").watch();
    let mut whole = Vec::with_capacity(n);
    let mut first_byte = Vec::with_capacity(n);
    let mut len = 0;
    for i in 0..n {
        // Let a poll or two go by, so Esc lands at any point of a transaction.
        let settle = Instant::now() + Duration::from_millis(20 + (i as u64 * 7) % 60);
        while Instant::now() < settle {
            h.step();
            std::thread::sleep(Duration::from_millis(2));
        }
        h.key_down(egui::Key::Escape);
        let pressed = Instant::now();
        h.step();
        let end = Instant::now() + DEADLINE;
        let at = loop {
            let found = sim
                .traffic()
                .iter()
                .filter(|t| t.dir == Dir::In && t.bytes.get(3..6) == Some(b"238".as_slice()))
                .find(|t| sim_started + t.at >= pressed)
                .map(|t| (sim_started + t.at, t.bytes.len()));
            if let Some((at, l)) = found {
                len = l;
                break at;
            }
            assert!(Instant::now() < end, "no 238H after Esc {i}");
            std::thread::sleep(Duration::from_micros(200));
        };
        h.key_up(egui::Key::Escape);
        h.step();
        let latency = at.saturating_duration_since(pressed);
        whole.push(latency);
        first_byte.push(latency.saturating_sub(line.wire_time(len)));
    }
    let polls = h
        .state()
        .pendant()
        .health
        .as_ref()
        .map(|h| h.median_round_trip);
    println!();
    println!("3. Esc to 238H on the line ({n} presses, idle and polling, line {line})");
    report("   Esc to whole 238H at the sim", &mut whole);
    report("   Esc to first byte (less wire time)", &mut first_byte);
    println!(
        "   (one transaction: median round trip {:?}; 238H wire time {} ms)",
        polls.flatten(),
        ms(line.wire_time(len))
    );
}

/// Figure 2: the UI thread's work for one frame of the idle, polling main window.
fn frame_time(h: &mut Harness<'_, PendantApp>, n: usize) {
    let mut cpu_total = Vec::with_capacity(n);
    let mut cpu_step = Vec::with_capacity(n);
    let mut cpu_tess = Vec::with_capacity(n);
    let mut wall_total = Vec::with_capacity(n);
    let mut primitives = 0;
    let mut repaint_now = 0;
    // A few frames to settle (fonts, first layout) before measuring.
    h.run_steps(10);
    let polls_before = frames_received(h.state());
    for _ in 0..n {
        let (c0, w0) = (cpu_time::ThreadTime::now(), Instant::now());
        h.step();
        let c_step = c0.elapsed();
        let w_step = w0.elapsed();
        // The copy is left out: eframe moves the shapes into the tessellator.
        let shapes = h.output().shapes.clone();
        let ppp = h.output().pixels_per_point;
        let immediate = h
            .output()
            .viewport_output
            .get(&egui::ViewportId::ROOT)
            .is_some_and(|v| v.repaint_delay.is_zero());
        repaint_now += usize::from(immediate);
        let (c1, w1) = (cpu_time::ThreadTime::now(), Instant::now());
        let clipped = h.ctx.tessellate(shapes, ppp);
        let c_tess = c1.elapsed();
        let w_tess = w1.elapsed();
        primitives = black_box(clipped).len();
        cpu_step.push(c_step);
        cpu_tess.push(c_tess);
        cpu_total.push(c_step + c_tess);
        wall_total.push(w_step + w_tess);
        // A window repaints on poll replies and every 100 ms; pace the frames likewise.
        std::thread::sleep(Duration::from_millis(10));
    }
    let polls = frames_received(h.state()).saturating_sub(polls_before);
    let mut slowest: Vec<(usize, Duration)> = cpu_total.iter().copied().enumerate().collect();
    slowest.sort_unstable_by_key(|&(_, d)| std::cmp::Reverse(d));
    let slowest: Vec<String> = slowest
        .iter()
        .take(5)
        .map(|(i, d)| format!("#{i} {} ms", ms(*d)))
        .collect();
    println!();
    println!(
        "2. UI frame time, idle main window 1280x800 while polling ({n} frames, \
         {polls} frames received by the simulator meanwhile, {primitives} clipped primitives)"
    );
    report("   thread CPU: step + tessellate", &mut cpu_total);
    report("   thread CPU: step (logic+layout)", &mut cpu_step);
    report("   thread CPU: tessellate", &mut cpu_tess);
    report("   wall: step + tessellate", &mut wall_total);
    println!("   slowest frames (CPU): {}", slowest.join(", "));
    println!("   frames asking for another frame at once: {repaint_now} of {n}");
}

/// Frames the simulator has received so far (polls, mostly, on an idle window).
fn frames_received(a: &PendantApp) -> u64 {
    a.sim().map_or(0, |s| s.counters().frames)
}

fn ms(d: Duration) -> String {
    format!("{:.3}", d.as_secs_f64() * 1e3)
}

/// Prints median, p99 and max of `samples` (sorted in place).
fn report(what: &str, samples: &mut [Duration]) {
    samples.sort_unstable();
    let n = samples.len();
    if n == 0 {
        println!("{what}: no samples");
        return;
    }
    let median = samples[n / 2];
    let p99 = samples[(n * 99).div_ceil(100).saturating_sub(1)];
    let max = samples[n - 1];
    println!(
        "{what:<42} median {:>8} ms   p99 {:>8} ms   max {:>8} ms",
        ms(median),
        ms(p99),
        ms(max)
    );
}
