//! Arm view figures: building the scene with a 10,000-point trail, 200 taught positions,
//! 8 zones and a PTP ghost's whole path, painting it with egui (shapes and tessellation), a 1920x1080 PNG
//! with tiny-skia, encoding included; the path check of a PTP move (joint interpolation
//! at 1 mm of the tool) against 8 zones; and the p99 of a whole frame (scene, egui
//! shapes, tessellation; no AccessKit), printed.
//!
//! ```sh
//! cargo bench --bench arm_view
//! ```

mod view_frames;

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use xsel_pendant::render::paint_png::PngPainter;
use xsel_pendant::render::{
    Ghost, GhostCheck, Marker, Mm, OverlayFrame, Palette, SceneInput, SelectedFrame, View,
    build_scene, paint_egui,
};
use xsel_pendant::robot::{
    CoordSystem, FrameKind, Joints, Move, PATH_SPACING_MM, Pose, PtpMove, PtpParams, RobotModel,
    Scara, ZoneBox, sweep,
};

/// A busy scene's inputs: a 10,000-point trail, frames, an overlay, 8 zones and a PTP
/// ghost with its whole path.
struct Inputs {
    kin: Scara,
    trail: Vec<Mm>,
    overlays: Vec<OverlayFrame>,
    ghost: Ghost,
    zones: Vec<ZoneBox>,
    markers: Vec<Marker>,
}

/// 8 zones of 80 x 60 mm around the reach.
fn zones() -> Vec<ZoneBox> {
    (0..8u8)
        .map(|i| {
            let c = Mm::ORIGIN.polar(380.0, -120.0 + 34.0 * f64::from(i));
            ZoneBox::from_corners(
                i + 1,
                [Some(c.x - 40.0), Some(c.y - 30.0), Some(0.0), None],
                [Some(c.x + 40.0), Some(c.y + 30.0), Some(120.0), None],
            )
        })
        .collect()
}

/// A long PTP move: J1 from -90 to 90, J2 from 30 to 120, Z down 100, J4 a half turn.
fn ptp_move(kin: &Scara) -> Move {
    let model = RobotModel::default_model();
    let params = PtpParams::from_command(&model, 30, 30, 30);
    Move::Ptp(
        PtpMove::joints(
            kin,
            Joints::new(-90.0, 30.0, 0.0, 0.0),
            Joints::new(90.0, 120.0, 100.0, 180.0),
            &params,
        )
        .expect("a move within the limits"),
    )
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
    let zones = zones();
    let tool = CoordSystem::from_wire([30_000, 0, 20_000, 0]);
    let path = sweep(&kin, &ptp_move(&kin), &tool, &zones, PATH_SPACING_MM);
    let mm = |p: &Pose| Mm::new(p.x, p.y);
    let mut ghost = Ghost::at(
        "No. 12",
        Pose::new(300.0, 300.0, 50.0, 100.0),
        Some(Joints::new(90.0, 120.0, 100.0, 180.0)),
        GhostCheck::Zone("enters zone 1: press twice".into()),
    );
    ghost.path = path.tips.iter().map(mm).collect();
    ghost.mark = path
        .first
        .as_ref()
        .map(|m| (mm(&m.tip), m.fault.to_string()));
    ghost.zones = path.zones.clone();
    // 200 taught positions over the reach, one selected.
    let markers = (0..200)
        .map(|i| Marker {
            at: Mm::ORIGIN.polar(
                160.0 + f64::from(i % 10) * 30.0,
                -110.0 + f64::from(i / 10) * 11.0,
            ),
            label: (i + 1).to_string(),
            selected: i == 57,
        })
        .collect();
    Inputs {
        kin,
        trail,
        overlays,
        ghost,
        zones,
        markers,
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
        zones: &i.zones,
        markers: &i.markers,
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

    let kin = i.kin;
    let mv = ptp_move(&kin);
    let tool = CoordSystem::from_wire([30_000, 0, 20_000, 0]);
    let zones = zones();
    let samples = sweep(&kin, &mv, &tool, &zones, PATH_SPACING_MM).tips.len();
    println!("arm_view/path_check_ptp_8_zones: {samples} samples");
    c.bench_function("arm_view/path_check_ptp_8_zones", |b| {
        b.iter(|| sweep(&kin, black_box(&mv), &tool, &zones, PATH_SPACING_MM))
    });

    // A whole frame as the window draws it: the scene built, painted and tessellated.
    let frames: Vec<_> = (0..400)
        .map(|_| {
            view_frames::frame(&ctx, false, |ui| {
                let scene = build_scene(black_box(&input));
                let rect = ui.max_rect();
                let view = View::fit(
                    &scene.bounds,
                    [rect.min.x, rect.min.y],
                    [rect.width(), rect.height()],
                    12.0,
                );
                paint_egui::paint(ui.painter(), &scene, &palette, &view);
            })
        })
        .collect();
    view_frames::stats("arm_view/frame_scene_paint_tessellate_1280x800", frames);

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
