//! The arm view painted by tiny-skia, with no window and no GPU: pixels where the links,
//! joints and tool must be (and must not be), a committed image snapshot of a reference
//! pose, and `xsel-pendant --render-png`.

use std::process::Command;

use xsel_pendant::render::paint_png::PngPainter;
use xsel_pendant::render::{Ghost, GhostCheck, Mm, Palette, Role, SceneInput, View, build_scene};
use xsel_pendant::robot::{Joints, Pose, RobotModel, Scara};

const W: u32 = 800;
const H: u32 = 600;

fn kin() -> Scara {
    Scara::new(&RobotModel::default_model())
}

/// The picture of a pose, and the view that places scene points on it.
fn picture(j: Joints, palette: &Palette) -> (tiny_skia::Pixmap, View) {
    let k = kin();
    let scene = build_scene(&SceneInput::pose(&k, Some(j)));
    let view = View::fit(&scene.bounds, [0.0, 0.0], [W as f32, H as f32], 16.0);
    let pixmap = PngPainter::new()
        .render(&scene, palette, W, H)
        .unwrap_or_else(|e| panic!("render: {e}"));
    (pixmap, view)
}

/// The colour at a scene point (the pixmap is opaque: premultiplied = straight).
fn at(p: &tiny_skia::Pixmap, view: &View, mm: Mm) -> [u8; 3] {
    let [x, y] = view.to_screen(mm);
    let c = p
        .pixel(x.round() as u32, y.round() as u32)
        .unwrap_or_else(|| panic!("{mm:?} is outside the picture"));
    [c.red(), c.green(), c.blue()]
}

fn near(a: [u8; 3], b: [u8; 4]) -> bool {
    a.iter().zip(b).all(|(x, y)| x.abs_diff(y) <= 12)
}

fn fill(palette: &Palette, role: Role) -> [u8; 4] {
    palette
        .style(role)
        .fill
        .unwrap_or_else(|| panic!("{role:?} has a fill"))
        .0
}

#[test]
fn links_joints_and_tool_are_where_the_pose_puts_them_in_both_themes() {
    for palette in [Palette::dark(), Palette::light()] {
        let link = fill(&palette, Role::Link);
        let joint = fill(&palette, Role::Joint);
        let tool = fill(&palette, Role::Tool);
        // J1 0, J2 90: arm 1 along +X to (250, 0), arm 2 up to (250, 250).
        let (p, v) = picture(Joints::new(0.0, 90.0, 0.0, 0.0), &palette);
        assert!(
            near(at(&p, &v, Mm::new(125.0, 0.0)), link),
            "arm 1 at (125, 0)"
        );
        assert!(
            near(at(&p, &v, Mm::new(250.0, 125.0)), link),
            "arm 2 at (250, 125)"
        );
        assert!(
            near(at(&p, &v, Mm::new(250.0, 0.0)), joint),
            "J2 at (250, 0)"
        );
        assert!(
            near(at(&p, &v, Mm::new(250.0, 250.0)), tool),
            "tool tip at (250, 250)"
        );
        assert!(
            !near(at(&p, &v, Mm::new(0.0, 125.0)), link),
            "no link at (0, 125)"
        );
        // J1 90, J2 -90: arm 1 up to (0, 250), arm 2 along +X to (250, 250).
        let (p, v) = picture(Joints::new(90.0, -90.0, 0.0, 0.0), &palette);
        assert!(
            near(at(&p, &v, Mm::new(0.0, 125.0)), link),
            "arm 1 at (0, 125)"
        );
        assert!(
            near(at(&p, &v, Mm::new(125.0, 250.0)), link),
            "arm 2 at (125, 250)"
        );
        assert!(
            near(at(&p, &v, Mm::new(0.0, 250.0)), joint),
            "J2 at (0, 250)"
        );
        assert!(
            !near(at(&p, &v, Mm::new(125.0, 0.0)), link),
            "arm 1 left (125, 0)"
        );
        assert!(
            !near(at(&p, &v, Mm::new(250.0, 125.0)), link),
            "arm 2 left (250, 125)"
        );
        // Outside the reach, the background.
        let bg = palette.background.0;
        assert!(
            near(at(&p, &v, Mm::new(-530.0, -530.0)), bg),
            "background outside the reach"
        );
    }
}

/// The reference picture: a pose with a refused target, a trail and the light theme's
/// opposite, the dark one.
fn reference() -> tiny_skia::Pixmap {
    let k = kin();
    let j = Joints::new(30.0, 60.0, 50.0, 10.0);
    let ghost = Ghost::at(
        "X+ 50 mm",
        Pose::new(480.0, 200.0, 50.0, 100.0),
        None,
        GhostCheck::Refused("out of reach: 520.000 mm from the J1 axis".into()),
    );
    let trail: Vec<Mm> = (0..200)
        .map(|i| Mm::ORIGIN.polar(300.0, -40.0 + f64::from(i) * 0.35))
        .collect();
    let scene = build_scene(&SceneInput {
        ghost: Some(&ghost),
        trail: &trail,
        ..SceneInput::pose(&k, Some(j))
    });
    PngPainter::new()
        .render(&scene, &Palette::dark(), 960, 600)
        .unwrap_or_else(|e| panic!("render: {e}"))
}

#[test]
fn reference_pose_matches_the_committed_snapshot() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/snapshots/arm_view_reference.png"
    );
    let now = reference();
    if std::env::var_os("UPDATE_SNAPSHOTS").is_some() {
        now.save_png(path)
            .unwrap_or_else(|e| panic!("write {path}: {e}"));
        return;
    }
    let then = tiny_skia::Pixmap::load_png(path)
        .unwrap_or_else(|e| panic!("{path}: {e} (UPDATE_SNAPSHOTS=1 cargo test makes it)"));
    assert_eq!((then.width(), then.height()), (now.width(), now.height()));
    let differ = then
        .pixels()
        .iter()
        .zip(now.pixels())
        .filter(|(a, b)| {
            let d = |x: u8, y: u8| x.abs_diff(y) > 24;
            d(a.red(), b.red()) || d(a.green(), b.green()) || d(a.blue(), b.blue())
        })
        .count();
    let allowed = now.pixels().len() / 500;
    if differ > allowed {
        let new = path.replace(".png", ".new.png");
        let _ = now.save_png(&new);
        panic!("{differ} pixels differ from {path} (at most {allowed}); the new picture is {new}");
    }
}

#[test]
fn render_png_flag_writes_a_picture_of_the_asked_size_and_names_bad_flags() {
    let dir = std::env::temp_dir().join(format!("xsel-render-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap_or_else(|e| panic!("{e}"));
    let file = dir.join("view.png");
    let out = Command::new(env!("CARGO_BIN_EXE_xsel-pendant"))
        .args(["--render-png"])
        .arg(&file)
        .args([
            "--joints",
            "-30,-60,20,0",
            "--size",
            "640x360",
            "--target",
            "100,-450",
            "--light",
        ])
        .output()
        .unwrap_or_else(|e| panic!("{e}"));
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let p = tiny_skia::Pixmap::load_png(&file).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!((p.width(), p.height()), (640, 360));
    assert!(String::from_utf8_lossy(&out.stdout).contains("J1 -30.000 J2 -60.000"));
    for (args, flag) in [
        (vec!["--size", "10x10"], "--size"),
        (vec!["--joints", "0,200,0,0"], "--joints"),
        (vec!["--pose", "600,0,0,0"], "--pose"),
        (vec!["--joints", "1,2,x,4"], "--joints"),
        (vec!["--arm", "up", "--target", "1,1"], "--arm"),
    ] {
        let out = Command::new(env!("CARGO_BIN_EXE_xsel-pendant"))
            .arg("--render-png")
            .arg(&file)
            .args(&args)
            .output()
            .unwrap_or_else(|e| panic!("{e}"));
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(
            err.contains(flag) && err.lines().count() == 1,
            "{args:?}: {err}"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// A capture as the Plots pane saves one: a step of 10 pu that ends in position.
fn capture_file() -> String {
    let mut text = String::from(
        "# xsel-pendant capture 1\n# label,Axis 1: Move Relative 10 relative to command\n\
         # series,Axis 1\n# trigger_s,3.5\n# encoding,real\n# roles,2,0,3,4\n\
         time_s,Command Position (pu),Target Position (pu),Actual Position (pu),In Position (level),TG phase (level)\n",
    );
    for i in -10..=40 {
        let t = f64::from(i) * 0.02;
        let moving = (0.0..0.5).contains(&t);
        let target = if t < 0.0 {
            0.0
        } else {
            (t / 0.5).min(1.0) * 10.0
        };
        let command = if t < 0.0 { 0.0 } else { 10.0 };
        let (in_pos, phase) = if moving { (0, 2) } else { (1, 0) };
        text.push_str(&format!(
            "{t:.9},{command},{target},{target},{in_pos},{phase}\n"
        ));
    }
    text
}

#[test]
fn plot_png_paints_a_saved_capture_and_names_what_is_wrong() {
    let dir = std::env::temp_dir().join(format!("xsel-plot-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap_or_else(|e| panic!("{e}"));
    let (csv, png) = (dir.join("step.csv"), dir.join("step.png"));
    std::fs::write(&csv, capture_file()).unwrap_or_else(|e| panic!("{e}"));
    let run = |args: &[&std::ffi::OsStr]| {
        Command::new(env!("CARGO_BIN_EXE_xsel-pendant"))
            .args(args)
            .output()
            .unwrap_or_else(|e| panic!("{e}"))
    };
    let out = run(&[
        "--plot-png".as_ref(),
        png.as_os_str(),
        "--capture".as_ref(),
        csv.as_os_str(),
    ]);
    let said = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let p = tiny_skia::Pixmap::load_png(&png).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!((p.width(), p.height()), (1600, 900));
    assert!(
        said.contains("51 samples of Axis 1: Move Relative 10"),
        "{said}"
    );
    assert!(said.contains("duration 0.5000 s"), "{said}");
    assert!(said.contains("final error 0.0000"), "{said}");
    // A file that is no capture, and no --capture at all: exit 2, one line naming it.
    std::fs::write(&csv, "time_s,x\n1,2\n").unwrap_or_else(|e| panic!("{e}"));
    for args in [
        vec![
            "--plot-png".as_ref(),
            png.as_os_str(),
            "--capture".as_ref(),
            csv.as_os_str(),
        ],
        vec!["--plot-png".as_ref(), png.as_os_str()],
    ] {
        let out = run(&args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{err}");
        assert!(
            err.contains("--capture") && err.lines().count() == 1,
            "{err}"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn zones_are_painted_and_the_entered_one_is_red_in_the_png() {
    use xsel_pendant::robot::ZoneBox;
    let k = kin();
    let palette = Palette::dark();
    let zones = [
        ZoneBox::from_corners(
            1,
            [Some(330.0), Some(180.0), Some(0.0), None],
            [Some(420.0), Some(320.0), Some(150.0), None],
        ),
        ZoneBox::from_corners(
            2,
            [Some(-200.0), Some(250.0), Some(0.0), None],
            [Some(-80.0), Some(400.0), Some(200.0), None],
        ),
    ];
    let mut ghost = Ghost::at(
        "X+ 100 mm",
        Pose::new(350.0, 250.0, 0.0, 90.0),
        None,
        GhostCheck::Zone("enters zone 1: press twice".into()),
    );
    ghost.zones = vec![1];
    let scene = build_scene(&SceneInput {
        zones: &zones,
        ghost: Some(&ghost),
        ..SceneInput::pose(&k, Some(Joints::new(0.0, 90.0, 0.0, 0.0)))
    });
    let view = View::fit(&scene.bounds, [0.0, 0.0], [W as f32, H as f32], 16.0);
    let p = PngPainter::new()
        .render(&scene, &palette, W, H)
        .unwrap_or_else(|e| panic!("render: {e}"));
    let bg = palette.background.0;
    let red = at(&p, &view, Mm::new(400.0, 200.0));
    let plain = at(&p, &view, Mm::new(-100.0, 270.0));
    assert!(!near(red, bg) && !near(plain, bg), "{red:?} {plain:?}");
    assert!(
        red[0] > red[1] + 20 && red[0] > plain[0],
        "the entered zone is tinted red: {red:?}, the other {plain:?}"
    );
}
