//! Where the scene sits on a screen or picture: the mm point at the centre of the
//! drawing area and the scale. Zoom about a point, pan by pixels, fit to bounds.

use super::scene::{Bounds, Mm};

/// Closest and farthest zoom, pixels per mm.
const MIN_SCALE: f64 = 0.02;
const MAX_SCALE: f64 = 200.0;

/// A view of the scene on an area of `size` pixels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct View {
    /// The scene point at the middle of the area.
    pub centre: Mm,
    /// Pixels per mm.
    pub scale: f64,
    /// The area's top left corner and size, in pixels.
    pub origin: [f32; 2],
    pub size: [f32; 2],
}

impl View {
    /// The view that shows all of `bounds` in the area, with a margin of `margin_px`.
    pub fn fit(
        bounds: &super::scene::Bounds,
        origin: [f32; 2],
        size: [f32; 2],
        margin_px: f32,
    ) -> View {
        let w = f64::from((size[0] - 2.0 * margin_px).max(1.0));
        let h = f64::from((size[1] - 2.0 * margin_px).max(1.0));
        let scale = (w / bounds.width().max(1e-6))
            .min(h / bounds.height().max(1e-6))
            .clamp(MIN_SCALE, MAX_SCALE);
        View {
            centre: bounds.centre(),
            scale,
            origin,
            size,
        }
    }

    /// Same scale and centre, on another area (the pane was resized).
    pub fn on_area(self, origin: [f32; 2], size: [f32; 2]) -> View {
        View {
            origin,
            size,
            ..self
        }
    }

    /// Screen position (pixels) of a scene point; +y is down on screen, up in the scene.
    pub fn to_screen(&self, p: Mm) -> [f32; 2] {
        let cx = f64::from(self.origin[0]) + f64::from(self.size[0]) / 2.0;
        let cy = f64::from(self.origin[1]) + f64::from(self.size[1]) / 2.0;
        [
            (cx + (p.x - self.centre.x) * self.scale) as f32,
            (cy - (p.y - self.centre.y) * self.scale) as f32,
        ]
    }

    /// The scene point under a screen position.
    pub fn to_scene(&self, s: [f32; 2]) -> Mm {
        let cx = f64::from(self.origin[0]) + f64::from(self.size[0]) / 2.0;
        let cy = f64::from(self.origin[1]) + f64::from(self.size[1]) / 2.0;
        Mm::new(
            self.centre.x + (f64::from(s[0]) - cx) / self.scale,
            self.centre.y - (f64::from(s[1]) - cy) / self.scale,
        )
    }

    /// Zooms by `factor` keeping the scene point under `screen` where it is.
    pub fn zoom_about(&mut self, screen: [f32; 2], factor: f64) {
        if !factor.is_finite() || factor <= 0.0 {
            return;
        }
        let before = self.to_scene(screen);
        self.scale = (self.scale * factor).clamp(MIN_SCALE, MAX_SCALE);
        let after = self.to_scene(screen);
        self.centre.x += before.x - after.x;
        self.centre.y += before.y - after.y;
    }

    /// Moves the picture by a screen distance (a drag).
    pub fn pan(&mut self, delta_px: [f32; 2]) {
        self.centre.x -= f64::from(delta_px[0]) / self.scale;
        self.centre.y += f64::from(delta_px[1]) / self.scale;
    }

    /// The scene bounds visible in the area.
    pub fn visible(&self) -> Bounds {
        let a = self.to_scene(self.origin);
        let b = self.to_scene([self.origin[0] + self.size[0], self.origin[1] + self.size[1]]);
        Bounds {
            min: Mm::new(a.x.min(b.x), a.y.min(b.y)),
            max: Mm::new(a.x.max(b.x), a.y.max(b.y)),
        }
    }
}

/// Trail points closer than this (pixels, |dx| + |dy|) to the last one kept are left
/// out: a 2 px line shows no difference, and painting stays cheap at 10,000 points.
pub const TRAIL_MIN_STEP_PX: f32 = 2.5;

/// How many steps of fading a trail is painted in.
pub const TRAIL_FADE_STEPS: usize = 16;

/// A trail on screen: its points at least [`TRAIL_MIN_STEP_PX`] apart, cut into runs of equal age, each
/// with its opacity (oldest run faintest). Both painters draw these runs.
pub fn trail_runs(view: &View, points: &[Mm]) -> Vec<(f32, Vec<[f32; 2]>)> {
    let n = points.len();
    if n < 2 {
        return Vec::new();
    }
    let per_run = n.div_ceil(TRAIL_FADE_STEPS).max(1);
    let mut runs = Vec::with_capacity(TRAIL_FADE_STEPS);
    for (k, chunk_start) in (0..n).step_by(per_run).enumerate() {
        // Each run starts at the previous run's last point, so the trail has no gaps.
        let from = chunk_start.saturating_sub(1);
        let to = (chunk_start + per_run).min(n);
        let mut screen: Vec<[f32; 2]> = Vec::with_capacity(to - from);
        for p in &points[from..to] {
            let s = view.to_screen(*p);
            let far = screen
                .last()
                .is_none_or(|l| (l[0] - s[0]).abs() + (l[1] - s[1]).abs() >= TRAIL_MIN_STEP_PX);
            if far {
                screen.push(s);
            }
        }
        if let Some(last) = points.get(to - 1).map(|p| view.to_screen(*p))
            && screen.last() != Some(&last)
        {
            screen.push(last);
        }
        if screen.len() >= 2 {
            let age = (k + 1) as f32 / n.div_ceil(per_run) as f32;
            runs.push((0.15 + 0.85 * age, screen));
        }
    }
    runs
}

/// An arrow head's corners (tip, left, right) on screen for a line from `a` to `b`:
/// 10 px long, or a third of a short line.
pub fn arrow_head(a: [f32; 2], b: [f32; 2]) -> Option<[[f32; 2]; 3]> {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let len = dx.hypot(dy);
    if len < 1.0 {
        return None;
    }
    let (ux, uy) = (dx / len, dy / len);
    let l = (len / 3.0).min(10.0);
    let w = l * 0.45;
    let base = [b[0] - ux * l, b[1] - uy * l];
    Some([
        b,
        [base[0] - uy * w, base[1] + ux * w],
        [base[0] + uy * w, base[1] - ux * w],
    ])
}

/// Space kept between a label and the edge of the view, in pixels.
const LABEL_MARGIN_PX: f32 = 4.0;

/// Where a text of `size` pixels goes: its top-left corner for the anchor's `fractions`
/// at `anchor_pos`, moved inside the view's area (a label near an edge is never cut; one
/// wider than the view starts at its left edge). Both painters place text with this.
pub fn text_top_left(
    view: &View,
    anchor_pos: [f32; 2],
    fractions: (f32, f32),
    size: [f32; 2],
) -> [f32; 2] {
    let place = |axis: usize, fraction: f32| {
        let start = anchor_pos[axis] - fraction * size[axis];
        let low = view.origin[axis] + LABEL_MARGIN_PX;
        let high = view.origin[axis] + view.size[axis] - LABEL_MARGIN_PX - size[axis];
        start.min(high).max(low)
    };
    [place(0, fractions.0), place(1, fractions.1)]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn screen_and_scene_round_trip_and_zoom_keeps_the_point_under_the_cursor() {
        let b = Bounds {
            min: Mm::new(-500.0, -500.0),
            max: Mm::new(500.0, 500.0),
        };
        let mut v = View::fit(&b, [10.0, 20.0], [800.0, 600.0], 0.0);
        assert!((v.scale - 0.6).abs() < 1e-9);
        assert_eq!(v.to_screen(Mm::ORIGIN), [410.0, 320.0]);
        // +Y of the scene is up on the screen.
        assert!(v.to_screen(Mm::new(0.0, 100.0))[1] < 320.0);
        let p = Mm::new(123.0, -45.0);
        let s = v.to_screen(p);
        v.zoom_about(s, 3.0);
        let back = v.to_scene(s);
        assert!(back.distance(p) < 1e-3, "{back:?}");
        v.pan([30.0, 0.0]);
        assert!((v.to_screen(p)[0] - s[0] - 30.0).abs() < 1e-3);
    }
}
