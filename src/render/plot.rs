//! A plot painted with tiny-skia to a PNG, as the window's Plots pane shows it: one panel
//! per unit (its own value axis), the bits and phases as steps on lanes beneath, cursors,
//! a legend and a title. No window and no GPU (the pane's export, `--plot-png`).

use tiny_skia::{Paint, PathBuilder, Pixmap, Rect, Stroke, Transform};

use super::glyphs::Glyphs;
use super::paint_png::{MAX_SIDE, RenderError, encode};
use super::style::Rgba;

/// The colours of traces 1, 2, ...: the window uses them too.
pub const TRACE_COLOURS: [[u8; 3]; 8] = [
    [80, 160, 255],
    [255, 140, 60],
    [90, 200, 110],
    [230, 80, 200],
    [240, 210, 70],
    [120, 220, 230],
    [200, 120, 90],
    [170, 170, 250],
];

/// One trace to paint.
#[derive(Clone, Copy, Debug)]
pub struct PlotLine<'a> {
    pub label: &'a str,
    /// Empty for a level.
    pub unit: &'a str,
    /// A bit or a phase: a step trace on a lane of its own.
    pub step: bool,
    /// A level's largest value.
    pub top: f64,
    /// (x, value) in x order; per pixel column a min and a max when decimated.
    pub points: &'a [[f64; 2]],
    /// Index into [`TRACE_COLOURS`].
    pub colour: usize,
}

/// What to paint.
#[derive(Clone, Debug)]
pub struct PlotPicture<'a> {
    pub title: String,
    /// `seconds since start`, `seconds from the trigger`.
    pub x_label: &'a str,
    pub x_range: (f64, f64),
    pub lines: Vec<PlotLine<'a>>,
    pub cursors: Vec<f64>,
    pub light: bool,
}

const MARGIN_LEFT: f32 = 70.0;
const MARGIN_RIGHT: f32 = 16.0;
const TITLE: f32 = 26.0;
const X_AXIS: f32 = 34.0;
const LANE: f32 = 22.0;
const TEXT: f32 = 12.0;

/// Where everything goes in a picture: the time axis's pixels, and per unit a panel with
/// its value range.
#[derive(Clone, Debug, PartialEq)]
pub struct Layout<'a> {
    pub left: f32,
    pub right: f32,
    /// The bottom of the lanes (the time axis's labels are below).
    pub bottom: f32,
    pub lanes_top: f32,
    pub x_range: (f64, f64),
    pub panels: Vec<Panel<'a>>,
}

/// One unit's panel: where it is and the values it spans.
#[derive(Clone, Debug, PartialEq)]
pub struct Panel<'a> {
    pub unit: &'a str,
    pub top: f32,
    pub height: f32,
    pub lo: f64,
    pub hi: f64,
}

impl Panel<'_> {
    /// The pixel row of `value`.
    pub fn y(&self, value: f64) -> f32 {
        self.top + 4.0 + ((self.hi - value) / (self.hi - self.lo)) as f32 * (self.height - 8.0)
    }
}

impl<'a> Layout<'a> {
    pub fn of(p: &'a PlotPicture<'a>, width: u32, height: u32) -> Self {
        let (w, h) = (width as f32, height as f32);
        let levels = p.lines.iter().filter(|l| l.step).count();
        let mut units: Vec<&str> = Vec::new();
        for l in p.lines.iter().filter(|l| !l.step) {
            if !units.contains(&l.unit) {
                units.push(l.unit);
            }
        }
        let lanes_h = LANE * levels as f32;
        let panels_h = (h - TITLE - X_AXIS - lanes_h).max(20.0);
        let panel_h = panels_h / units.len().max(1) as f32;
        let panels = units
            .iter()
            .enumerate()
            .map(|(k, unit)| {
                let lines: Vec<&PlotLine<'_>> = p
                    .lines
                    .iter()
                    .filter(|l| !l.step && l.unit == *unit)
                    .collect();
                let (lo, hi) = value_range(&lines);
                Panel {
                    unit,
                    top: TITLE + k as f32 * panel_h,
                    height: panel_h,
                    lo,
                    hi,
                }
            })
            .collect();
        Layout {
            left: MARGIN_LEFT,
            right: (w - MARGIN_RIGHT).max(MARGIN_LEFT + 1.0),
            bottom: TITLE + panels_h + lanes_h,
            lanes_top: TITLE + panels_h,
            x_range: p.x_range,
            panels,
        }
    }

    /// The pixel column of time `x`.
    pub fn x(&self, x: f64) -> f32 {
        let (x0, x1) = self.x_range;
        let span = if x1 > x0 { x1 - x0 } else { 1.0 };
        self.left + ((x - x0) / span) as f32 * (self.right - self.left)
    }
}

/// The plot as PNG bytes, `width` x `height` pixels.
pub fn plot_png(p: &PlotPicture<'_>, width: u32, height: u32) -> Result<Vec<u8>, RenderError> {
    let pixmap = paint(p, width, height)?;
    encode(&pixmap)
}

/// The plot painted into a new pixmap.
pub fn paint(p: &PlotPicture<'_>, width: u32, height: u32) -> Result<Pixmap, RenderError> {
    let size_ok = |s: u32| (16..=MAX_SIDE).contains(&s);
    let mut pixmap = match Pixmap::new(width, height) {
        Some(p) if size_ok(width) && size_ok(height) => p,
        _ => return Err(RenderError::Size { width, height }),
    };
    let (bg, fg, grid) = if p.light {
        (
            Rgba::rgb(250, 250, 250),
            Rgba::rgb(30, 30, 30),
            Rgba::rgb(215, 215, 215),
        )
    } else {
        (
            Rgba::rgb(24, 24, 24),
            Rgba::rgb(220, 220, 220),
            Rgba::rgb(55, 55, 55),
        )
    };
    pixmap.fill(colour(bg));
    let mut glyphs = Glyphs::new();
    let mut text = |pm: &mut Pixmap, s: &str, at: [f32; 2], c: Rgba| {
        let g = glyphs.layout(s, TEXT);
        glyphs.draw(pm, &g, at, c);
        g.size().x
    };
    text(&mut pixmap, &p.title, [MARGIN_LEFT, 6.0], fg);

    let layout = Layout::of(p, width, height);
    let (left, right, bottom) = (layout.left, layout.right, layout.bottom);
    let px = |x: f64| layout.x(x);

    // Time grid and its labels.
    for tick in ticks(p.x_range.0, p.x_range.1, 6) {
        let x = px(tick);
        line(&mut pixmap, &[[x, TITLE], [x, bottom]], grid, 1.0);
        text(
            &mut pixmap,
            &format_tick(tick),
            [x - 10.0, bottom + 4.0],
            fg,
        );
    }
    text(&mut pixmap, p.x_label, [right - 140.0, bottom + 18.0], fg);

    for panel in &layout.panels {
        let (top, panel_h, unit) = (panel.top, panel.height, panel.unit);
        let lines: Vec<&PlotLine<'_>> = p
            .lines
            .iter()
            .filter(|l| !l.step && l.unit == unit)
            .collect();
        let (lo, hi) = (panel.lo, panel.hi);
        let py = |v: f64| panel.y(v);
        frame(&mut pixmap, left, top, right, top + panel_h, grid);
        for tick in ticks(lo, hi, 4) {
            let y = py(tick);
            line(&mut pixmap, &[[left, y], [right, y]], grid, 1.0);
            text(&mut pixmap, &format_tick(tick), [4.0, y - 7.0], fg);
        }
        text(&mut pixmap, unit, [4.0, top + 2.0], fg);
        let mut legend_x = left + 6.0;
        for l in &lines {
            let c = trace_colour(l.colour);
            let points: Vec<[f32; 2]> = l.points.iter().map(|[x, v]| [px(*x), py(*v)]).collect();
            line(&mut pixmap, &points, c, 1.5);
            legend_x += text(&mut pixmap, l.label, [legend_x, top + 4.0], c) + 14.0;
        }
    }
    for (lane, l) in p.lines.iter().filter(|l| l.step).enumerate() {
        let top = layout.lanes_top + lane as f32 * LANE;
        let c = trace_colour(l.colour);
        let py = |v: f64| top + LANE - 4.0 - (v / l.top.max(1.0)) as f32 * (LANE - 8.0);
        // Steps: each value held until the next.
        let mut points: Vec<[f32; 2]> = Vec::with_capacity(l.points.len() * 2);
        for pair in l.points.windows(2) {
            let ([xa, va], [xb, _]) = (pair[0], pair[1]);
            points.push([px(xa), py(va)]);
            points.push([px(xb), py(va)]);
        }
        if let Some([x, v]) = l.points.last() {
            points.push([px(*x), py(*v)]);
        }
        line(&mut pixmap, &points, c, 1.5);
        text(&mut pixmap, l.label, [4.0, top + 4.0], c);
    }
    for (i, x) in p.cursors.iter().enumerate() {
        let x = px(*x);
        line(&mut pixmap, &[[x, TITLE], [x, bottom]], fg, 1.0);
        let name = if i == 0 { "A" } else { "B" };
        text(&mut pixmap, name, [x + 3.0, TITLE + 2.0], fg);
    }
    Ok(pixmap)
}

fn trace_colour(i: usize) -> Rgba {
    let [r, g, b] = TRACE_COLOURS[i % TRACE_COLOURS.len()];
    Rgba::rgb(r, g, b)
}

fn colour(c: Rgba) -> tiny_skia::Color {
    let [r, g, b, a] = c.0;
    tiny_skia::Color::from_rgba8(r, g, b, a)
}

fn line(pm: &mut Pixmap, points: &[[f32; 2]], c: Rgba, width: f32) {
    let mut pb = PathBuilder::new();
    let mut any = false;
    for [x, y] in points
        .iter()
        .filter(|[x, y]| x.is_finite() && y.is_finite())
    {
        if any {
            pb.line_to(*x, *y);
        } else {
            pb.move_to(*x, *y);
            any = true;
        }
    }
    if points.len() == 1
        && let Some([x, y]) = points.first()
    {
        pb.line_to(x + 0.5, *y);
    }
    let Some(path) = pb.finish() else { return };
    let mut paint = Paint::default();
    paint.set_color(colour(c));
    paint.anti_alias = true;
    let stroke = Stroke {
        width,
        ..Stroke::default()
    };
    pm.stroke_path(&path, &paint, &stroke, Transform::identity(), None);
}

fn frame(pm: &mut Pixmap, l: f32, t: f32, r: f32, b: f32, c: Rgba) {
    if let Some(rect) = Rect::from_ltrb(l, t, r, b) {
        let path = PathBuilder::from_rect(rect);
        let mut paint = Paint::default();
        paint.set_color(colour(c));
        pm.stroke_path(
            &path,
            &paint,
            &Stroke::default(),
            Transform::identity(),
            None,
        );
    }
}

/// The values' range with a margin; a flat trace gets ±1.
fn value_range(lines: &[&PlotLine<'_>]) -> (f64, f64) {
    let values = lines.iter().flat_map(|l| l.points.iter().map(|p| p[1]));
    let (lo, hi) = values
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
    if !lo.is_finite() {
        return (-1.0, 1.0);
    }
    if hi - lo < 1e-9 {
        return (lo - 1.0, hi + 1.0);
    }
    let m = (hi - lo) * 0.05;
    (lo - m, hi + m)
}

/// About `n` round values between `lo` and `hi`.
pub fn ticks(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    if hi.partial_cmp(&lo) != Some(std::cmp::Ordering::Greater) || n == 0 {
        return Vec::new();
    }
    let raw = (hi - lo) / n as f64;
    let magnitude = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 5.0, 10.0]
        .iter()
        .map(|m| m * magnitude)
        .find(|s| *s >= raw)
        .unwrap_or(10.0 * magnitude);
    let first = (lo / step).ceil() as i64;
    let last = (hi / step).floor() as i64;
    (first..=last).map(|k| k as f64 * step).collect()
}

fn format_tick(v: f64) -> String {
    let t = format!("{v:.3}");
    let t = t.trim_end_matches('0').trim_end_matches('.');
    if t == "-0" { "0".into() } else { t.to_string() }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_trace_is_painted_where_its_values_are() {
        let points: Vec<[f64; 2]> = (0..=100).map(|i| [f64::from(i) / 10.0, 5.0]).collect();
        let picture = PlotPicture {
            title: "test".into(),
            x_label: "s",
            x_range: (0.0, 10.0),
            lines: vec![PlotLine {
                label: "flat",
                unit: "pu",
                step: false,
                top: 1.0,
                points: &points,
                colour: 0,
            }],
            cursors: vec![],
            light: false,
        };
        let pm = paint(&picture, 400, 300).unwrap();
        // A flat trace lies in the middle of its panel (range 4..6): the trace's colour
        // along that row, and not above it.
        let [r, g, b] = TRACE_COLOURS[0];
        let panel_mid = TITLE + (300.0 - TITLE - X_AXIS) / 2.0;
        // Pixels near the trace's colour (anti-aliasing blends its edges) on the row.
        let near = |x: u32, y: u32| {
            let p = pm.pixel(x, y).unwrap();
            let d = |a: u8, b: u8| i32::from(a).abs_diff(i32::from(b));
            d(p.red(), r) + d(p.green(), g) + d(p.blue(), b) < 120
        };
        let hit = |y: f32| {
            (100..380)
                .filter(|x| (y as u32 - 1..=y as u32 + 1).any(|y| near(*x, y)))
                .count()
        };
        assert!(
            hit(panel_mid) > 200,
            "{} pixels of the trace",
            hit(panel_mid)
        );
        assert_eq!(hit(panel_mid - 30.0), 0);
        assert!(matches!(
            paint(&picture, 8, 300),
            Err(RenderError::Size { .. })
        ));
        assert_eq!(ticks(0.0, 10.0, 5), vec![0.0, 2.0, 4.0, 6.0, 8.0, 10.0]);
    }
}
