//! The Plots pane on the real app with the built-in simulators: a step of an RMC axis
//! drawn live and captured, pause, zoom, cursors, CSV and PNG export. Waits have
//! deadlines; no fixed sleeps before asserting.

use std::time::Instant;

use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use xsel_pendant::pendant::axes::{AxisIntent, RmcJogSettings};
use xsel_pendant::pendant::samples::view::TraceChoice;
use xsel_pendant::pendant::{Intent, JogMode};
use xsel_pendant::render::plot::{Layout, TRACE_COLOURS};
use xsel_pendant::robot::RelativeTo;
use xsel_pendant::ui::{PendantApp, StartOptions};

use crate::kittest_common::{click, press, replace_text, show_tab, step_until, step_until_shown};

/// The app, tall enough for the plot under the arm view, axis 1 enabled and stepped by
/// +10 pu; the Plots pane shown.
fn stepped() -> Harness<'static, PendantApp> {
    let mut h = Harness::builder()
        .with_size([1280.0, 1500.0])
        .build_eframe(|cc| PendantApp::new(cc, StartOptions::fresh_simulator()));
    let status = |a: &PendantApp| a.pendant().axes.axes.first().and_then(|v| v.status);
    step_until(&mut h, "the RMC's first status", |a| status(a).is_some());
    show_tab(&mut h, "RMC axes");
    h.get_all_by_label("Enable").next().unwrap().click();
    h.step();
    step_until(&mut h, "axis 1 enabled", |a| {
        status(a).is_some_and(|s| s.bits.enabled())
    });
    let jog = RmcJogSettings {
        mode: JogMode::Step,
        step: 10.0,
        speed: 40.0,
        accel: 200.0,
        decel: 200.0,
        relative_to: RelativeTo::Command,
    };
    h.state_mut()
        .pendant_mut()
        .apply(Intent::Axes(AxisIntent::Settings(jog)), Instant::now());
    show_tab(&mut h, "Plots");
    // A second of samples before the step, for the plot to show what came before it.
    step_until(&mut h, "a second of samples", |a| {
        let store = &a.pendant().samples.store;
        let (s, _) = store.find(&target()).unwrap();
        s.time(s.len().saturating_sub(1))
            .is_some_and(|t| t.as_secs_f64() > 1.0)
    });
    click(&mut h, "Axis 1+");
    step_until(&mut h, "the step to end in position", |a| {
        status(a).is_some_and(|s| s.command_position == 10.0 && s.bits.in_position())
    });
    h
}

fn target() -> TraceChoice {
    TraceChoice::new("Axis 1", "Target Position")
}

#[test]
fn a_step_is_plotted_paused_zoomed_cursored_and_exported_as_csv_and_png() {
    let dir = std::env::temp_dir().join(format!("xsel-plots-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut h = stepped();
    let chosen = h.state().plots_panel().chosen();
    assert_eq!(
        chosen[0],
        target(),
        "the first RMC axis's positions by default"
    );
    // Pause: the span stands still while samples keep coming.
    click(&mut h, "Pause");
    let paused = h.state().plots_panel().shown;
    let samples = |a: &PendantApp| a.pendant().samples.store.bytes();
    let before = samples(h.state());
    step_until(&mut h, "more samples behind the pause", |a| {
        samples(a) > before
    });
    assert_eq!(h.state().plots_panel().shown, paused);
    // Zoom in on the plot: a narrower span.
    let plot = h.state().plots_panel().plot_rects[0];
    h.hover_at(plot.center());
    h.event(egui::Event::Zoom(2.0));
    h.step();
    h.step();
    let zoomed = h.state().plots_panel().shown;
    assert!(
        zoomed.1 - zoomed.0 < (paused.1 - paused.0) * 0.8,
        "zoomed {zoomed:?}, was {paused:?}"
    );
    // Back to the whole span: resume, and pause again.
    click(&mut h, "Resume");
    click(&mut h, "Pause");
    // Cursors A and B, by clicks in the plot; the readout shows their difference.
    let (a, b) = (
        egui::pos2(plot.left() + plot.width() * 0.3, plot.center().y),
        egui::pos2(plot.left() + plot.width() * 0.7, plot.center().y),
    );
    for at in [a, b] {
        press(&mut h, at);
        // Apart by more than a double click's time.
        for _ in 0..30 {
            h.step();
        }
    }
    let [ca, cb] = h.state().plots_panel().cursors;
    assert!(ca.zip(cb).is_some_and(|(a, b)| b > a), "{ca:?} {cb:?}");
    assert!(h.query_all_by_label("B − A").next().is_some());

    // CSV of the shown span: one row per poll of the axis, the values exactly as polled.
    let csv = dir.join("plot.csv");
    replace_text(&mut h, "File", &csv.display().to_string());
    click(&mut h, "Export CSV");
    step_until_shown(&mut h, "saved");
    let text = std::fs::read_to_string(&csv).unwrap();
    let (from, to) = h.state().plots_panel().shown;
    let store = &h.state().pendant().samples.store;
    let (series, channel) = store.find(&target()).unwrap();
    let secs = |s: f64| std::time::Duration::from_secs_f64(s.max(0.0));
    let rows = series.rows_between(secs(from), secs(to));
    let lines: Vec<&str> = text.lines().skip(1).collect();
    assert_eq!(lines.len(), rows.len(), "one line per polled sample");
    // A byte order mark and CR LF line ends, for Excel (`files::csv_style`).
    assert!(text.starts_with("\u{feff}time_s,Axis 1 Target Position (pu)"));
    assert!(text.ends_with("\r\n"));
    for (line, row) in lines.iter().zip(rows.clone()) {
        let cell: f32 = line.split(',').nth(1).unwrap().parse().unwrap();
        assert_eq!(cell.to_bits(), series.raw(row, channel).unwrap(), "{line}");
    }
    assert!(lines.iter().any(|l| l.split(',').nth(1) == Some("10")));

    // PNG: the step drawn low on the left and high on the right in trace 1's colour.
    let png = dir.join("plot.png");
    // Live again until two and a half seconds past the step are polled, then paused:
    // the span holds the step and what follows it.
    click(&mut h, "Resume");
    let latest = |a: &PendantApp| {
        let store = &a.pendant().samples.store;
        let (s, _) = store.find(&target()).unwrap();
        s.time(s.len() - 1).unwrap().as_secs_f64()
    };
    let after = latest(h.state()) + 2.5;
    step_until(&mut h, "2.5 s more of samples", |a| latest(a) > after);
    click(&mut h, "Pause");
    // The field is clicked first, as a user would (its accessibility focus was spent on
    // the first name).
    let field = h
        .get_by_role_and_label(egui::accesskit::Role::TextInput, "File")
        .rect();
    press(&mut h, field.center());
    replace_text(&mut h, "File", &png.display().to_string());
    click(&mut h, "Export PNG");
    step_until_shown(&mut h, "1600x900 plot");
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(&png).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buf).unwrap();
    assert_eq!((info.width, info.height), (1600, 900));
    // Where the painter put the Target Position at 0 before the step and at 10 after it.
    let a = h.state();
    let (from, to) = a.plots_panel().shown;
    // The step: the first poll that read the new Command Position.
    let command = TraceChoice::new("Axis 1", "Command Position");
    let (series, channel) = a.pendant().samples.store.find(&command).unwrap();
    let trigger = (0..series.len())
        .find(|r| series.value(*r, channel) == Some(10.0))
        .and_then(|r| series.time(r))
        .map(|t| t.as_secs_f64());
    let points = [[from, 0.0], [to, 10.0]];
    let line = |unit| xsel_pendant::render::plot::PlotLine {
        label: "",
        unit,
        step: false,
        top: 1.0,
        points: &points,
        colour: 0,
    };
    // The layout the painter used: the positions' panel spans the shown traces' values
    // (0 to 10, both positions), the lanes below.
    let picture = xsel_pendant::render::plot::PlotPicture {
        title: String::new(),
        x_label: "",
        x_range: (from, to),
        lines: vec![line("pu"), line("pu")],
        cursors: vec![],
        light: false,
    };
    let mut lanes = picture.clone();
    lanes.lines.push(xsel_pendant::render::plot::PlotLine {
        step: true,
        ..line("")
    });
    lanes.lines.push(xsel_pendant::render::plot::PlotLine {
        step: true,
        ..line("")
    });
    let layout = Layout::of(&lanes, 1600, 900);
    let panel = &layout.panels[0];
    // Target (trace 1) or Actual (trace 2, drawn over it where they agree).
    let trace_near = |x: f32, y: f32| {
        (x as i64 - 2..=x as i64 + 2).any(|x| {
            (y as i64 - 2..=y as i64 + 2).any(|y| {
                let i = ((y as u32 * info.width + x as u32) * 4) as usize;
                let d = |a: u8, b: u8| i32::from(a).abs_diff(i32::from(b));
                TRACE_COLOURS[..2]
                    .iter()
                    .any(|[r, g, b]| d(buf[i], *r) + d(buf[i + 1], *g) + d(buf[i + 2], *b) < 60)
            })
        })
    };
    let step_at = trigger.expect("the step was polled");
    assert!(
        step_at - 0.3 > from && step_at + 2.0 < to,
        "the step at {step_at} s lies in the span {from}..{to}"
    );
    assert!(
        trace_near(layout.x(step_at - 0.3), panel.y(0.0)),
        "the trace at 0 before the step"
    );
    assert!(
        trace_near(layout.x(step_at + 2.0), panel.y(10.0)),
        "the trace at 10 after the step"
    );
    assert!(
        !trace_near(layout.x(step_at + 2.0), panel.y(0.0)),
        "and not at 0 after it"
    );
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn the_step_is_captured_with_its_summary_and_can_be_overlaid() {
    let mut h = stepped();
    step_until(&mut h, "the step's capture", |a| {
        !a.pendant().samples.captures.list.is_empty()
    });
    let c = h.state().pendant().samples.captures.list[0].clone();
    assert_eq!(c.label, "Axis 1: Move Relative 10 relative to command");
    assert!(c.times[0] < 0.0, "pre-trigger samples");
    let s = c.summary;
    assert!((s.end - 10.0).abs() < 0.001 && s.start.abs() < 0.001);
    assert!(s.final_error.is_some_and(|e| e.abs() < 0.05));
    assert!(s.duration.is_some_and(|d| d > 0.3), "{s:?}");
    click(&mut h, "Captures (1)");
    assert!(h.query_all_by_label(&c.label).next().is_some(), "listed");
    h.get_by_label("Overlay").click();
    h.step();
    h.step();
    assert!(h.state().plots_panel().overlaid.contains(&c.number));
    assert!(
        h.query_all_by_label_contains("#1 Target Position")
            .next()
            .is_some(),
        "the overlay's legend"
    );
}
