//! Arm view figures: building the scene with a 10,000-point trail, painting it with egui
//! (shapes and tessellation), and a 1920x1080 PNG with tiny-skia, encoding included.
//!
//! ```sh
//! cargo bench --bench arm_view
//! ```

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use xsel_pendant::render::paint_png::PngPainter;
use xsel_pendant::render::{
    Ghost, GhostCheck, Mm, OverlayFrame, Palette, SceneInput, SelectedFrame, View, build_scene,
    paint_egui,
};
use xsel_pendant::robot::{CoordSystem, FrameKind, Joints, Pose, RobotModel, Scara};

/// A busy scene's inputs: a 10,000-point trail, frames, an overlay and a reachable ghost.
struct Inputs {
    kin: Scara,
    trail: Vec<Mm>,
    overlays: Vec<OverlayFrame>,
    ghost: Ghost,
}

fn inputs() -> Inputs {
    let kin = Scara::new(&RobotModel::default_model());
    // A spiral through the reach: every point a different pixel at 1920x1080.
    let trail = (0..10_000)
        .map(|i| {
            let t = f64::from(i) / 10_000.0;
            Mm::ORIGIN.polar(
                150.0 + 300.0 * t,
                -100.0 + 200.0 * t + 40.0 * (t * 60.0).sin(),
            )
        })
        .collect();
    let overlays = vec![OverlayFrame {
        label: "work 4".into(),
        kind: FrameKind::Work,
        system: CoordSystem::from_wire([150_000, -200_000, 0, 30_000]),
    }];
    let ghost = Ghost {
        label: "X+ 10 mm".into(),
        joints: Some(Joints::new(35.0, 55.0, 50.0, 10.0)),
        tip: Pose::new(300.0, 300.0, 50.0, 100.0),
        check: GhostCheck::Reachable,
        line: Some((Mm::new(200.0, 300.0), Mm::new(300.0, 300.0))),
    };
    Inputs {
        kin,
        trail,
        overlays,
        ghost,
    }
}

fn scene_input(i: &Inputs) -> SceneInput<'_> {
    SceneInput {
        kin: &i.kin,
        joints: Some(Joints::new(30.0, 60.0, 50.0, 10.0)),
        stale: false,
        work: Some(SelectedFrame {
            number: 1,
            system: CoordSystem::from_wire([100_000, 50_000, 0, 15_000]),
        }),
        tool: Some(SelectedFrame {
            number: 2,
            system: CoordSystem::from_wire([30_000, 0, 20_000, 0]),
        }),
        overlays: &i.overlays,
        ghost: Some(&i.ghost),
        trail: &i.trail,
        reported_tip: None,
    }
}

fn benches(c: &mut Criterion) {
    let i = inputs();
    let input = scene_input(&i);
    c.bench_function("arm_view/scene_10k_trail", |b| {
        b.iter(|| build_scene(black_box(&input)))
    });

    let scene = build_scene(&input);
    let palette = Palette::dark();
    let ctx = egui::Context::default();
    let raw = egui::RawInput {
        screen_rect: Some(egui::Rect::from_min_size(
            egui::Pos2::ZERO,
            egui::vec2(1280.0, 800.0),
        )),
        ..Default::default()
    };
    let view = View::fit(&scene.bounds, [0.0, 0.0], [1280.0, 800.0], 12.0);
    // Text layout is cached by egui from one frame to the next, as in the window.
    c.bench_function("arm_view/egui_shapes_and_tessellation", |b| {
        b.iter(|| {
            let out = ctx.run_ui(raw.clone(), |ui| {
                paint_egui::paint(ui.painter(), black_box(&scene), &palette, &view);
            });
            ctx.tessellate(out.shapes, out.pixels_per_point)
        })
    });

    let mut painter = PngPainter::new();
    c.bench_function("arm_view/tiny_skia_png_1920x1080", |b| {
        b.iter(|| {
            painter
                .render_png(black_box(&scene), &palette, 1920, 1080)
                .map(|png| png.len())
        })
    });
}

criterion_group! {
    name = arm_view;
    config = Criterion::default().sample_size(30);
    targets = benches
}
criterion_main!(arm_view);
