//! File figures of the real window (egui_kittest driving `PendantApp` on the built-in
//! simulator, 1280x800), plain timing loops printing median, p99 and max:
//!
//! 1. resident memory while a 200 MB CSV of commas is refused as a teach list (peak RSS
//!    of this process above the idle window's, Linux `/proc/self/status`);
//! 2. Load of a 10,000-point teach file: from the frame that delivers the click on Load
//!    to the frame that asks "Replace ...?" (the read and parse run as a job), and from
//!    the click on Replace to the frame that draws the list;
//! 3. UI frame CPU time (step + tessellate) with one point in the list, then with the
//!    10,000-point list shown.
//!
//! Samples: `FILES_BENCH_LOADS` (default 20), `FILES_BENCH_FRAMES` (default 1000).

use std::hint::black_box;
use std::path::Path;
use std::time::{Duration, Instant};

use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use xsel_pendant::pendant::teach::{MAX_POINTS, TaughtPose, TeachList};
use xsel_pendant::protocol::ArmSystem;
use xsel_pendant::ui::{PendantApp, StartOptions};

#[path = "../tests/kittest_common/mod.rs"]
mod kittest_common;
use kittest_common::{click, replace_text, show_tab, step_until, type_into};

fn main() {
    let loads = env_count("FILES_BENCH_LOADS", 20);
    let frames = env_count("FILES_BENCH_FRAMES", 1000);
    let dir = std::env::temp_dir().join(format!("xsel-files-bench-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("a temp folder");
    println!(
        "files bench: {} cores available",
        std::thread::available_parallelism().map_or(0, |n| n.get())
    );
    let mut h = Harness::builder()
        .with_size([1280.0, 800.0])
        .build_eframe(|cc| PendantApp::new(cc, StartOptions::fresh_simulator()));
    step_until(&mut h, "a position", |a| {
        a.pendant().controller.work.is_some()
    });
    show_tab(&mut h, "Teach list");
    // One point, so that every load asks before it replaces the list.
    type_into(&mut h, "Name", "KEEP");
    step_until(&mut h, "a fresh position", |a| {
        !a.pendant().controller.is_stale(Instant::now())
    });
    click(&mut h, "Record");
    step_until(&mut h, "a point", |a| !a.pendant().teach.list().is_empty());
    h.run_steps(20);
    refuse_huge(&mut h, &dir);
    frame_time(
        &mut h,
        frames,
        "3a. UI frame CPU time, one point in the list",
    );
    // Twenty points fill the list's view as 10,000 do: the two cost the same if only
    // the rows in sight are laid out.
    let twenty = list_file(&dir, 20);
    load(&mut h, &twenty);
    step_until(&mut h, "20 points read", |a| {
        a.pendant().teach.pending().is_some()
    });
    click(&mut h, "Replace");
    frame_time(
        &mut h,
        frames,
        "3b. UI frame CPU time, a 20-point list shown",
    );
    let file = list_file(&dir, MAX_POINTS);
    load_times(&mut h, &file, loads);
    assert!(h.query_by_label("P0").is_some(), "the list is not shown");
    let with = format!("3c. UI frame CPU time, the {MAX_POINTS}-point list shown");
    frame_time(&mut h, frames, &with);
    let _ = std::fs::remove_dir_all(&dir);
}

fn env_count(name: &str, default: usize) -> usize {
    std::env::var(name)
        .ok()
        .and_then(|v| v.parse().ok())
        .filter(|&n| n > 0)
        .unwrap_or(default)
}

/// `VmRSS` and `VmHWM` of this process in MB (Linux; zeros elsewhere).
fn rss_mb() -> (f64, f64) {
    let text = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    let field = |name: &str| {
        text.lines()
            .find_map(|l| l.strip_prefix(name))
            .and_then(|v| v.trim().trim_end_matches("kB").trim().parse::<f64>().ok())
            .map_or(0.0, |kb| kb / 1024.0)
    };
    (field("VmRSS:"), field("VmHWM:"))
}

fn load(h: &mut Harness<'_, PendantApp>, file: &Path) {
    replace_text(h, "File", &file.display().to_string());
    click(h, "Load");
}

fn refuse_huge(h: &mut Harness<'_, PendantApp>, dir: &Path) {
    let huge = dir.join("commas.csv");
    {
        // Written in pieces: this process's own peak must stay the window's.
        use std::io::Write;
        let mut out = std::fs::File::create(&huge).expect("a file");
        let piece = vec![b','; 1_000_000];
        for _ in 0..200 {
            out.write_all(&piece).expect("200 MB written");
        }
    }
    let (idle, idle_peak) = rss_mb();
    let before = h.state().pendant().teach.feedback().cloned();
    load(h, &huge);
    step_until(h, "the 200 MB file refused", |a| {
        a.pendant().teach.feedback().cloned() != before
    });
    let (after, peak) = rss_mb();
    println!();
    println!("1. a 200 MB CSV of commas as a teach list");
    println!(
        "   said: {:?}",
        h.state().pendant().teach.feedback().map(|f| &f.1)
    );
    println!(
        "   RSS idle {idle:.1} MB, after {after:.1} MB; peak {idle_peak:.1} MB before, \
         {peak:.1} MB after: {:.1} MB above the idle window",
        (peak - idle).max(0.0)
    );
    let _ = std::fs::remove_file(&huge);
}

fn list_file(dir: &Path, points: usize) -> std::path::PathBuf {
    let at = TaughtPose {
        pose: [250_000, 250_000, 0, 90_000],
        arm: ArmSystem::Right,
        work: 0,
        tool: 0,
    };
    let mut big = TeachList::new();
    for i in 0..points {
        big.record(&format!("P{i}"), at).expect("a point");
    }
    let file = dir.join(format!("{points}-points.csv"));
    std::fs::write(&file, big.to_csv()).expect("the list written");
    file
}

fn load_times(h: &mut Harness<'_, PendantApp>, file: &Path, n: usize) {
    let mut to_question = Vec::with_capacity(n);
    let mut to_list = Vec::with_capacity(n);
    for _ in 0..n {
        replace_text(h, "File", &file.display().to_string());
        let button = h.get_by_label("Load");
        button.click();
        let t0 = Instant::now();
        h.step();
        while h.state().pendant().teach.pending().is_none() {
            h.step();
            assert!(t0.elapsed() < Duration::from_secs(60), "no answer");
        }
        // The frame that shows the question.
        h.step();
        to_question.push(t0.elapsed());
        h.get_by_label("Replace").click();
        let t1 = Instant::now();
        h.step();
        while h.state().pendant().teach.list().len() != MAX_POINTS {
            h.step();
        }
        to_list.push(t1.elapsed());
        h.step();
    }
    println!();
    println!("2. Load of a {MAX_POINTS}-point teach file ({n} loads)");
    report("   click Load to \"Replace ...?\" shown", &mut to_question);
    report("   click Replace to the list drawn", &mut to_list);
}

fn frame_time(h: &mut Harness<'_, PendantApp>, n: usize, what: &str) {
    let mut cpu = Vec::with_capacity(n);
    h.run_steps(10);
    for _ in 0..n {
        let c0 = cpu_time::ThreadTime::now();
        h.step();
        let shapes = h.output().shapes.clone();
        let ppp = h.output().pixels_per_point;
        let c_tess = cpu_time::ThreadTime::now();
        let step = c0.elapsed();
        black_box(h.ctx.tessellate(shapes, ppp));
        cpu.push(step + c_tess.elapsed());
        // Paced like a window repainting on poll replies.
        std::thread::sleep(Duration::from_millis(10));
    }
    println!();
    println!("{what} ({n} frames)");
    report("   thread CPU: step + tessellate", &mut cpu);
}

fn report(what: &str, samples: &mut [Duration]) {
    samples.sort_unstable();
    let n = samples.len();
    let at = |q: usize| samples[(n * q).div_ceil(100).saturating_sub(1)];
    println!(
        "{what:<44} median {:>8.3} ms   p99 {:>8.3} ms   max {:>8.3} ms",
        at(50).as_secs_f64() * 1e3,
        at(99).as_secs_f64() * 1e3,
        samples[n - 1].as_secs_f64() * 1e3
    );
}
