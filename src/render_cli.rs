//! `xsel-pendant --render-png FILE`: the arm view of a pose drawn by tiny-skia into a PNG,
//! with no window, GPU or line (documentation, tests), over the built-in simulator's cell
//! (its zones); and `--plot-png FILE --capture CSV`:
//! a capture the Plots pane saved, painted as the pane draws it.

use std::io::Write;
use std::process::ExitCode;

use crate::cli::Args;
use crate::pendant::samples::view::capture_trace;
use crate::render::paint_png::PngPainter;
use crate::render::plot::plot_png;
use crate::render::{Ghost, GhostCheck, Mm, Palette, SceneInput, build_scene};
use crate::robot::{
    Arm, CoordSystem, Joints, Move, PATH_SPACING_MM, Pose, PtpMove, PtpParams, RobotModel, Scara,
    ZoneBox, sweep,
};

/// A flag value that cannot be used, named.
#[derive(Debug, thiserror::Error)]
#[error("{flag}: {reason}")]
pub struct RenderArgError {
    pub flag: &'static str,
    pub reason: String,
}

fn bad(flag: &'static str, reason: impl Into<String>) -> RenderArgError {
    RenderArgError {
        flag,
        reason: reason.into(),
    }
}

/// `n` comma-separated finite numbers.
pub fn numbers<const N: usize>(flag: &'static str, text: &str) -> Result<[f64; N], RenderArgError> {
    let parts: Vec<&str> = text.split(',').map(str::trim).collect();
    if parts.len() != N {
        return Err(bad(
            flag,
            format!("`{text}`: expected {N} numbers separated by commas"),
        ));
    }
    let mut out = [0.0; N];
    for (slot, p) in out.iter_mut().zip(&parts) {
        *slot = p
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| bad(flag, format!("`{p}` is not a number")))?;
    }
    Ok(out)
}

/// `WIDTHxHEIGHT`.
pub fn size(text: &str) -> Result<[u32; 2], RenderArgError> {
    let (w, h) = text.split_once(['x', 'X']).ok_or_else(|| {
        bad(
            "--size",
            format!("`{text}`: expected WIDTHxHEIGHT, e.g. 1920x1080"),
        )
    })?;
    let side = |s: &str| {
        s.trim()
            .parse::<u32>()
            .ok()
            .filter(|v| (16..=crate::render::paint_png::MAX_SIDE).contains(v))
            .ok_or_else(|| {
                bad(
                    "--size",
                    format!("`{s}`: each side must be 16 to 16384 pixels"),
                )
            })
    };
    Ok([side(w)?, side(h)?])
}

fn arm(text: &str) -> Result<Arm, RenderArgError> {
    match text.trim().to_ascii_lowercase().as_str() {
        "right" => Ok(Arm::Right),
        "left" => Ok(Arm::Left),
        other => Err(bad("--arm", format!("`{other}`: expected right or left"))),
    }
}

/// The joints the flags name, checked against the model's limits.
fn joints(args: &Args, kin: &Scara, home: Joints) -> Result<Joints, RenderArgError> {
    let j = if let Some(text) = &args.joints {
        Joints::from_array(numbers::<4>("--joints", text)?)
    } else if let Some(text) = &args.pose {
        let p = Pose::from_array(numbers::<4>("--pose", text)?);
        kin.inverse(&p, arm(&args.arm)?, &home)
            .map_err(|e| bad("--pose", e.to_string()))?
    } else {
        home
    };
    kin.check_joints(&j)
        .map_err(|e| bad("--joints", e.to_string()))?;
    Ok(j)
}

/// The ghost of a PTP move to `--target`, coloured by the reach check and the zones its
/// whole path enters (the window's checks: [`sweep`]).
fn ghost(
    args: &Args,
    model: &RobotModel,
    kin: &Scara,
    j: &Joints,
    zones: &[ZoneBox],
) -> Result<Option<Ghost>, RenderArgError> {
    let Some(text) = &args.target else {
        return Ok(None);
    };
    let [x, y] = numbers::<2>("--target", text)?;
    let now = kin.forward(j);
    let tip = Pose::new(x, y, now.z, now.r);
    let arm = arm(&args.arm)?;
    let label = format!("target ({arm} arm)");
    let end = match kin.inverse(&tip, arm, j) {
        Ok(end) => end,
        Err(e) => {
            return Ok(Some(Ghost::at(
                label,
                tip,
                None,
                GhostCheck::Refused(e.to_string()),
            )));
        }
    };
    let flips = kin.arm_system(&end) != kin.arm_system(j);
    let params = PtpParams::from_command(model, 30, 30, 30);
    let mut g = Ghost::at(label, tip, Some(end), GhostCheck::Reachable);
    if let Ok(m) = PtpMove::joints(kin, *j, end, &params) {
        let path = sweep(
            kin,
            &Move::Ptp(m),
            &CoordSystem::ZERO,
            zones,
            PATH_SPACING_MM,
        );
        let mm = |p: &Pose| Mm::new(p.x, p.y);
        g.path = path.tips.iter().map(mm).collect();
        g.mark = path
            .first
            .as_ref()
            .map(|m| (mm(&m.tip), m.fault.to_string()));
        g.zones.clone_from(&path.zones);
        if let [n, ..] = path.zones[..] {
            g.check = GhostCheck::Zone(format!("enters zone {n}: press twice"));
        }
    }
    if flips && g.zones.is_empty() {
        g.check = GhostCheck::ArmFlip;
    }
    Ok(Some(g))
}

/// The built-in simulator's zones for `model` (the cell the window shows out of the box).
fn builtin_zones(model: &RobotModel) -> Vec<ZoneBox> {
    crate::files::coords_file::defaults(model)
        .zones
        .iter()
        .map(|(&n, rec)| crate::robot_wire::zone_box(n, rec))
        .filter(ZoneBox::is_defined)
        .collect()
}

fn render(args: &Args) -> Result<String, String> {
    let Some(path) = &args.render_png else {
        return Err("--render-png: no file named".into());
    };
    let model = args.model().map_err(|e| e.to_string())?;
    let kin = Scara::new(&model);
    let [w, h] = size(args.size.as_deref().unwrap_or("1280x800")).map_err(|e| e.to_string())?;
    let j = joints(args, &kin, model.home).map_err(|e| e.to_string())?;
    let zones = builtin_zones(&model);
    let g = ghost(args, &model, &kin, &j, &zones).map_err(|e| e.to_string())?;
    let scene = build_scene(&SceneInput {
        ghost: g.as_ref(),
        zones: &zones,
        ..SceneInput::pose(&kin, Some(j))
    });
    let palette = if args.light {
        Palette::light()
    } else {
        Palette::dark()
    };
    let png = PngPainter::new()
        .render_png(&scene, &palette, w, h)
        .map_err(|e| e.to_string())?;
    crate::files::write_whole(path, &png).map_err(|e| format!("--render-png: {e}"))?;
    Ok(format!(
        "{}: {w}x{h}, {} J1 {:.3} J2 {:.3} Z {:.3} J4 {:.3}",
        path.display(),
        model.name,
        j.j1,
        j.j2,
        j.z,
        j.j4
    ))
}

/// Paints the capture of `--capture` into `--plot-png`'s file: every channel, positions
/// and velocities each on their own axis, bits and phases on lanes.
fn plot(args: &Args) -> Result<String, String> {
    let (Some(out), Some(input)) = (&args.plot_png, &args.capture) else {
        return Err("--plot-png needs --capture FILE".into());
    };
    let [w, h] = size(args.size.as_deref().unwrap_or("1600x900")).map_err(|e| e.to_string())?;
    let text =
        crate::files::read_text_bounded(input, 64 << 20).map_err(|e| format!("--capture: {e}"))?;
    let capture = crate::pendant::samples::csv::read_capture(text.as_bytes())
        .map_err(|e| format!("--capture {}: {e}", input.display()))?;
    let traces: Vec<_> = capture
        .channels
        .iter()
        .enumerate()
        .filter_map(|(i, c)| capture_trace(&capture, &c.name, c.name.clone()).map(|t| (i, t)))
        .collect();
    let x_range = (
        capture.times.first().copied().unwrap_or(0.0),
        capture.times.last().copied().unwrap_or(1.0),
    );
    let title = format!("{} ({})", capture.label, capture.series);
    // The picture as the Plots pane's export paints it.
    let picture = crate::ui::plots::picture(
        &title,
        "seconds from the trigger",
        x_range,
        &traces,
        Vec::new(),
        args.light,
    );
    let png = plot_png(&picture, w, h).map_err(|e| e.to_string())?;
    crate::files::write_whole(out, &png).map_err(|e| format!("--plot-png: {e}"))?;
    let s = capture.summary;
    let num = |v: Option<f64>| v.map_or("-".to_string(), |v| format!("{v:.4}"));
    Ok(format!(
        "{}: {w}x{h}, {} samples of {}; duration {} s, final error {}, overshoot {}, settling {} s",
        out.display(),
        capture.times.len(),
        capture.label,
        num(s.duration),
        num(s.final_error),
        num(s.overshoot),
        num(s.settling)
    ))
}

/// Runs `--render-png` or `--plot-png`: exit 0 and one line on stdout, or exit 2 and one
/// line on stderr.
pub fn run(args: &Args) -> ExitCode {
    let result = if args.plot_png.is_some() {
        plot(args)
    } else {
        render(args)
    };
    match result {
        Ok(line) => {
            let _ = writeln!(std::io::stdout(), "{line}");
            ExitCode::SUCCESS
        }
        Err(e) => {
            let _ = writeln!(std::io::stderr(), "xsel-pendant: {e}");
            ExitCode::from(2)
        }
    }
}
