//! Paints a scene with tiny-skia into a pixmap, and to a PNG of any size: no window and
//! no GPU (exports, `--render-png`, image tests).

use tiny_skia::{
    Color, FillRule, LineCap, LineJoin, Paint, Path, PathBuilder, Pixmap, Stroke, StrokeDash,
    Transform,
};

use super::glyphs::Glyphs;
use super::labels::{self, LabelBox};
use super::scene::{Mm, Scene, Shape, arc_points};
use super::style::{Palette, Rgba, Style};
use super::view::{View, trail_runs};

/// The largest picture side, pixels.
pub const MAX_SIDE: u32 = 16_384;

/// Why a picture could not be made.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    #[error(
        "a picture of {width}x{height} pixels cannot be made: each side must be 16 to {MAX_SIDE}"
    )]
    Size { width: u32, height: u32 },
    #[error("PNG encoding failed: {0}")]
    Encode(String),
}

/// The tiny-skia painter; keeps egui's fonts between pictures.
pub struct PngPainter {
    glyphs: Glyphs,
}

impl Default for PngPainter {
    fn default() -> Self {
        Self::new()
    }
}

impl PngPainter {
    pub fn new() -> Self {
        PngPainter {
            glyphs: Glyphs::new(),
        }
    }

    /// The scene fitted into a new pixmap of `width` x `height`.
    pub fn render(
        &mut self,
        scene: &Scene,
        palette: &Palette,
        width: u32,
        height: u32,
    ) -> Result<Pixmap, RenderError> {
        let view = View::fit(
            &scene.bounds,
            [0.0, 0.0],
            [width as f32, height as f32],
            16.0,
        );
        self.render_view(scene, palette, &view, width, height)
    }

    /// The scene seen through `view` (its origin and size are replaced by the picture's).
    pub fn render_view(
        &mut self,
        scene: &Scene,
        palette: &Palette,
        view: &View,
        width: u32,
        height: u32,
    ) -> Result<Pixmap, RenderError> {
        let ok = |s: u32| (16..=MAX_SIDE).contains(&s);
        let mut pixmap = match (ok(width) && ok(height), Pixmap::new(width, height)) {
            (true, Some(p)) => p,
            _ => return Err(RenderError::Size { width, height }),
        };
        let view = view.on_area([0.0, 0.0], [width as f32, height as f32]);
        self.paint(scene, palette, &view, &mut pixmap);
        Ok(pixmap)
    }

    /// The scene fitted into a PNG of `width` x `height`.
    pub fn render_png(
        &mut self,
        scene: &Scene,
        palette: &Palette,
        width: u32,
        height: u32,
    ) -> Result<Vec<u8>, RenderError> {
        encode(&self.render(scene, palette, width, height)?)
    }

    /// Paints the background and every item onto `pixmap`; the labels last, placed clear
    /// of each other ([`labels::place`]), as the window does.
    pub fn paint(&mut self, scene: &Scene, palette: &Palette, view: &View, pixmap: &mut Pixmap) {
        pixmap.fill(color(palette.background));
        let mut texts = Vec::new();
        for item in &scene.items {
            let style = palette.style(item.role);
            match &item.shape {
                Shape::Text {
                    at,
                    text,
                    anchor,
                    offset_px,
                } => {
                    let (colour, size) = style.text;
                    let galley = self.glyphs.layout(text, size);
                    let short = labels::short_text(text).map(|t| self.glyphs.layout(&t, size));
                    let s = view.to_screen(*at);
                    let label = LabelBox {
                        anchor_pos: [s[0] + offset_px[0], s[1] + offset_px[1]],
                        fractions: anchor.fractions(),
                        size: [galley.rect.width(), galley.rect.height()],
                        short: short.as_ref().map(|g| [g.rect.width(), g.rect.height()]),
                        rank: labels::rank(item.role),
                    };
                    texts.push((galley, short, colour, label));
                }
                other => self.shape(pixmap, view, other, &style),
            }
        }
        let boxes: Vec<LabelBox> = texts.iter().map(|t| t.3).collect();
        for ((galley, short, colour, _), spot) in texts.into_iter().zip(labels::place(view, &boxes))
        {
            if let Some(p) = spot {
                let g = match short {
                    Some(g) if p.short => g,
                    _ => galley,
                };
                self.glyphs.draw(pixmap, &g, p.top_left, colour);
            }
        }
    }

    fn shape(&mut self, pm: &mut Pixmap, view: &View, shape: &Shape, style: &Style) {
        let at = |p: &Mm| view.to_screen(*p);
        match shape {
            Shape::Polyline { points, closed } => {
                if let Some(path) = polyline(points.iter().map(at), *closed) {
                    stroke(pm, &path, style, None);
                }
            }
            Shape::Arc {
                centre,
                radius,
                start_deg,
                end_deg,
            } => {
                let pts = arc_points(*centre, *radius, *start_deg, *end_deg, 1.0);
                if let Some(path) = polyline(pts.iter().map(at), false) {
                    stroke(pm, &path, style, None);
                }
            }
            Shape::Circle { centre, radius } => {
                let c = at(centre);
                let r = (*radius * view.scale) as f32;
                if let Some(path) = PathBuilder::from_circle(c[0], c[1], r.max(0.5)) {
                    if let Some(f) = style.fill {
                        fill(pm, &path, f);
                    }
                    stroke(pm, &path, style, None);
                }
            }
            Shape::Dot { centre, radius_px } => {
                let c = at(centre);
                if let (Some(path), Some((colour, _))) = (
                    PathBuilder::from_circle(c[0], c[1], *radius_px),
                    style.stroke,
                ) {
                    fill(pm, &path, colour);
                }
            }
            Shape::Cross { centre, half_px } => {
                let [x, y] = at(centre);
                let h = *half_px;
                let mut pb = PathBuilder::new();
                pb.move_to(x - h, y - h);
                pb.line_to(x + h, y + h);
                pb.move_to(x - h, y + h);
                pb.line_to(x + h, y - h);
                if let Some(path) = pb.finish() {
                    stroke(pm, &path, style, Some(2.5));
                }
            }
            Shape::Fill {
                points, outline, ..
            } => {
                // The boundary as one path: no seams between triangles, few edges.
                let Some(colour) = style.fill else { return };
                let boundary = outline
                    .iter()
                    .filter_map(|&i| points.get(i as usize))
                    .map(at);
                if let Some(path) = polyline(boundary, true) {
                    fill(pm, &path, colour);
                }
            }
            Shape::Arrow { from, to } => {
                let (a, b) = (at(from), at(to));
                if let Some(path) = polyline([a, b].into_iter(), false) {
                    stroke(pm, &path, style, None);
                }
                if let (Some(head), Some((colour, _))) = (arrow_head(a, b), style.stroke) {
                    fill(pm, &head, colour);
                }
            }
            // Labels are placed together, in `paint`.
            Shape::Text { .. } => {}
            Shape::Trail { points } => {
                let Some((colour, width)) = style.stroke else {
                    return;
                };
                for (alpha, run) in trail_runs(view, points) {
                    if let Some(path) = polyline(run.into_iter(), false) {
                        let faded = Style {
                            stroke: Some((colour.fade(alpha), width)),
                            ..*style
                        };
                        stroke(pm, &path, &faded, None);
                    }
                }
            }
        }
    }
}

/// A pixmap as PNG bytes, with png's fast compression (about a third of the time of
/// tiny-skia's own encoder, files a little larger).
pub fn encode(pixmap: &Pixmap) -> Result<Vec<u8>, RenderError> {
    let err = |e: png::EncodingError| RenderError::Encode(e.to_string());
    // tiny-skia keeps premultiplied colour; only an opaque picture (ours: the background
    // covers it) is already straight RGBA.
    if pixmap.pixels().iter().any(|p| p.alpha() != 255) {
        return pixmap.encode_png().map_err(err);
    }
    let mut out = Vec::with_capacity(pixmap.data().len() / 8);
    let mut encoder = png::Encoder::new(&mut out, pixmap.width(), pixmap.height());
    encoder.set_color(png::ColorType::Rgba);
    encoder.set_depth(png::BitDepth::Eight);
    encoder.set_compression(png::Compression::Fast);
    let mut writer = encoder.write_header().map_err(err)?;
    writer.write_image_data(pixmap.data()).map_err(err)?;
    writer.finish().map_err(err)?;
    Ok(out)
}

fn color(c: Rgba) -> Color {
    let [r, g, b, a] = c.0;
    Color::from_rgba8(r, g, b, a)
}

fn paint_of(c: Rgba) -> Paint<'static> {
    let mut paint = Paint::default();
    paint.set_color(color(c));
    paint.anti_alias = true;
    paint
}

fn fill(pm: &mut Pixmap, path: &Path, c: Rgba) {
    pm.fill_path(
        path,
        &paint_of(c),
        FillRule::Winding,
        Transform::identity(),
        None,
    );
}

fn stroke(pm: &mut Pixmap, path: &Path, style: &Style, width: Option<f32>) {
    let Some((c, w)) = style.stroke else { return };
    let mut s = Stroke {
        width: width.unwrap_or(w),
        line_cap: LineCap::Round,
        line_join: LineJoin::Round,
        ..Stroke::default()
    };
    if style.dashed {
        s.dash = StrokeDash::new(vec![7.0, 5.0], 0.0);
    }
    pm.stroke_path(path, &paint_of(c), &s, Transform::identity(), None);
}

fn polyline(mut points: impl Iterator<Item = [f32; 2]>, closed: bool) -> Option<Path> {
    let first = points.next()?;
    let mut pb = PathBuilder::new();
    pb.move_to(first[0], first[1]);
    for p in points {
        pb.line_to(p[0], p[1]);
    }
    if closed {
        pb.close();
    }
    pb.finish()
}

/// A filled triangle at `b` pointing away from `a`.
fn arrow_head(a: [f32; 2], b: [f32; 2]) -> Option<Path> {
    let [tip, left, right] = super::view::arrow_head(a, b)?;
    let mut pb = PathBuilder::new();
    pb.move_to(tip[0], tip[1]);
    pb.line_to(left[0], left[1]);
    pb.line_to(right[0], right[1]);
    pb.close();
    pb.finish()
}
