//! Paints a scene with egui shapes for the live window: vector shapes tessellated by
//! egui each frame, no texture upload.

use egui::epaint::{Mesh, PathShape, PathStroke};
use egui::{Color32, FontId, Painter, Pos2, Shape as EguiShape, Stroke, pos2};

use super::labels::{self, LabelBox, ShownLabel};
use super::scene::{Mm, Scene, Shape, arc_points};
use super::style::{Palette, Rgba, Style};
use super::view::{View, arrow_head, trail_runs};

/// Paints every item of `scene` seen through `view` (its area in the painter's points);
/// the labels last, placed clear of each other ([`labels::place`]). Returns every label
/// as placed (shortened or hidden ones too), for the hover and the tests.
pub fn paint(painter: &Painter, scene: &Scene, palette: &Palette, view: &View) -> Vec<ShownLabel> {
    let mut out = Vec::with_capacity(scene.items.len() + 16);
    out.push(EguiShape::rect_filled(
        painter.clip_rect(),
        0.0,
        colour(palette.background),
    ));
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
                let (c, size) = style.text;
                let layout =
                    |t: String| painter.layout_no_wrap(t, FontId::proportional(size), colour(c));
                let galley = layout(text.clone());
                let short = labels::short_text(text).map(layout);
                let s = view.to_screen(*at);
                let label = LabelBox {
                    anchor_pos: [s[0] + offset_px[0], s[1] + offset_px[1]],
                    fractions: anchor.fractions(),
                    size: [galley.size().x, galley.size().y],
                    short: short.as_ref().map(|g| [g.size().x, g.size().y]),
                    rank: labels::rank(item.role),
                };
                texts.push((galley, short, c, label, text));
            }
            other => shape(&mut out, view, other, &style),
        }
    }
    let boxes: Vec<LabelBox> = texts.iter().map(|t| t.3).collect();
    let mut shown = Vec::with_capacity(texts.len());
    for ((galley, short, c, label, text), spot) in
        texts.into_iter().zip(labels::place(view, &boxes))
    {
        let mut rect = None;
        if let Some(p) = spot {
            let g = match short {
                Some(g) if p.short => g,
                _ => galley,
            };
            let [x, y] = p.top_left;
            rect = Some([x, y, x + g.size().x, y + g.size().y]);
            out.push(EguiShape::galley(pos(p.top_left), g, colour(c)));
        }
        shown.push(ShownLabel {
            text: text.clone(),
            anchor: label.anchor_pos,
            rect,
            short: spot.is_some_and(|p| p.short),
        });
    }
    painter.extend(out);
    shown
}

fn colour(c: Rgba) -> Color32 {
    let [r, g, b, a] = c.0;
    Color32::from_rgba_unmultiplied(r, g, b, a)
}

fn pos(s: [f32; 2]) -> Pos2 {
    pos2(s[0], s[1])
}

fn stroke_of(style: &Style) -> Option<Stroke> {
    style.stroke.map(|(c, w)| Stroke::new(w, colour(c)))
}

fn line(out: &mut Vec<EguiShape>, points: Vec<Pos2>, closed: bool, style: &Style) {
    let Some(stroke) = stroke_of(style) else {
        return;
    };
    if points.len() < 2 {
        return;
    }
    if style.dashed {
        let mut points = points;
        if closed && let Some(first) = points.first().copied() {
            points.push(first);
        }
        out.extend(EguiShape::dashed_line(&points, stroke, 7.0, 5.0));
    } else if closed {
        out.push(EguiShape::Path(PathShape::closed_line(points, stroke)));
    } else {
        out.push(EguiShape::Path(PathShape::line(
            points,
            PathStroke::from(stroke),
        )));
    }
}

fn shape(out: &mut Vec<EguiShape>, view: &View, shape: &Shape, style: &Style) {
    let at = |p: &Mm| pos(view.to_screen(*p));
    match shape {
        Shape::Polyline { points, closed } => {
            line(out, points.iter().map(at).collect(), *closed, style);
        }
        Shape::Arc {
            centre,
            radius,
            start_deg,
            end_deg,
        } => {
            let pts = arc_points(*centre, *radius, *start_deg, *end_deg, 1.0);
            line(out, pts.iter().map(at).collect(), false, style);
        }
        Shape::Circle { centre, radius } => {
            let r = (*radius * view.scale) as f32;
            let fill = style.fill.map_or(Color32::TRANSPARENT, colour);
            let stroke = stroke_of(style).unwrap_or(Stroke::NONE);
            out.push(EguiShape::circle_filled(at(centre), r.max(0.5), fill));
            out.push(EguiShape::circle_stroke(at(centre), r.max(0.5), stroke));
        }
        Shape::Dot { centre, radius_px } => {
            if let Some(s) = stroke_of(style) {
                out.push(EguiShape::circle_filled(at(centre), *radius_px, s.color));
            }
        }
        Shape::Cross { centre, half_px } => {
            if let Some((c, _)) = style.stroke {
                let s = Stroke::new(2.5, colour(c));
                let p = at(centre);
                let h = *half_px;
                out.push(EguiShape::line_segment(
                    [p + egui::vec2(-h, -h), p + egui::vec2(h, h)],
                    s,
                ));
                out.push(EguiShape::line_segment(
                    [p + egui::vec2(-h, h), p + egui::vec2(h, -h)],
                    s,
                ));
            }
        }
        Shape::Fill {
            points, triangles, ..
        } => {
            let Some(c) = style.fill else { return };
            let c = colour(c);
            let mut mesh = Mesh::default();
            mesh.reserve_vertices(points.len());
            mesh.reserve_triangles(triangles.len());
            for p in points {
                mesh.colored_vertex(at(p), c);
            }
            let n = points.len() as u32;
            for t in triangles.iter().filter(|t| t.iter().all(|&i| i < n)) {
                mesh.add_triangle(t[0], t[1], t[2]);
            }
            out.push(EguiShape::mesh(mesh));
        }
        Shape::Arrow { from, to } => {
            let (a, b) = (view.to_screen(*from), view.to_screen(*to));
            line(out, vec![pos(a), pos(b)], false, style);
            if let (Some(head), Some((c, _))) = (arrow_head(a, b), style.stroke) {
                out.push(EguiShape::convex_polygon(
                    head.iter().map(|p| pos(*p)).collect(),
                    colour(c),
                    Stroke::NONE,
                ));
            }
        }
        // Labels are placed together, in `paint`.
        Shape::Text { .. } => {}
        Shape::Trail { points } => {
            if let Some((c, w)) = style.stroke {
                out.push(EguiShape::mesh(trail_mesh(view, points, c, w)));
            }
        }
    }
}

/// The trail as one mesh of quads, one per segment, shaded by age: thousands of points
/// cost no more than a few shapes (egui's path tessellation would feather each point).
fn trail_mesh(view: &View, points: &[Mm], c: Rgba, width: f32) -> Mesh {
    let runs = trail_runs(view, points);
    let mut mesh = Mesh::default();
    let segments: usize = runs.iter().map(|(_, r)| r.len().saturating_sub(1)).sum();
    mesh.reserve_vertices(4 * segments);
    mesh.reserve_triangles(2 * segments);
    let half = width / 2.0;
    for (alpha, run) in &runs {
        let colour = colour(c.fade(*alpha));
        for pair in run.windows(2) {
            let (a, b) = (pos(pair[0]), pos(pair[1]));
            let d = b - a;
            let len = d.length();
            if len <= f32::EPSILON {
                continue;
            }
            // Half a width along and across the segment, so neighbours overlap at joins.
            let along = d / len * half;
            let n = egui::vec2(-along.y, along.x);
            let i = mesh.vertices.len() as u32;
            mesh.colored_vertex(a - along + n, colour);
            mesh.colored_vertex(a - along - n, colour);
            mesh.colored_vertex(b + along - n, colour);
            mesh.colored_vertex(b + along + n, colour);
            mesh.add_triangle(i, i + 1, i + 2);
            mesh.add_triangle(i, i + 2, i + 3);
        }
    }
    mesh
}
