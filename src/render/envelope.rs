//! The reach envelope (right- and left-arm regions, inner and outer radius, the singular
//! band), the J1 and J2 limit sectors and the grid under them.

use super::scene::{Anchor, Bounds, Item, Mm, Role, Shape, arc_points, fan_fill};
use crate::robot::{Joints, Scara};

/// Samples of the envelope's grid over J1 (per degree) and J2.
const J1_STEP_DEG: f64 = 4.0;
const J2_SAMPLES: usize = 14;

/// Lines every 100 mm (50 mm for small robots) over the bounds.
pub(super) fn grid(items: &mut Vec<Item>, b: &Bounds, reach: f64) {
    let step = if reach > 300.0 { 100.0 } else { 50.0 };
    let line = |a: Mm, b: Mm| Item {
        role: Role::Grid,
        shape: Shape::Polyline {
            points: vec![a, b],
            closed: false,
        },
    };
    let mut x = (b.min.x / step).ceil() * step;
    while x <= b.max.x {
        items.push(line(Mm::new(x, b.min.y), Mm::new(x, b.max.y)));
        x += step;
    }
    let mut y = (b.min.y / step).ceil() * step;
    while y <= b.max.y {
        items.push(line(Mm::new(b.min.x, y), Mm::new(b.max.x, y)));
        y += step;
    }
}

/// Flange position of J1, J2 (deg).
fn fk(kin: &Scara, j1: f64, j2: f64) -> Mm {
    let f = kin.forward(&Joints::new(j1, j2, 0.0, 0.0));
    Mm::new(f.x, f.y)
}

/// The angle by which the flange direction leads J1 at elbow angle `j2`.
fn lead_deg(kin: &Scara, j2: f64) -> f64 {
    let (s, c) = j2.to_radians().sin_cos();
    (kin.l2 * s).atan2(kin.l1 + kin.l2 * c).to_degrees()
}

/// The regions each arm system reaches within the J1 and J2 limits (the image of the
/// joint-limit rectangle; one arm system maps it one to one), the inner and outer radius,
/// and the singular band.
pub(super) fn envelope(items: &mut Vec<Item>, kin: &Scara) {
    let (j1_lo, j1_hi) = (kin.j1.min, kin.j1.max.min(kin.j1.min + 360.0));
    let band = kin.band_deg;
    let right = (band, kin.j2.max.min(180.0));
    let left = (kin.j2.min.max(-180.0), -band);
    for ((lo, hi), role) in [(right, Role::EnvelopeRight), (left, Role::EnvelopeLeft)] {
        if lo < hi {
            region(items, kin, (j1_lo, j1_hi), (lo, hi), role);
        }
    }
    let outer = kin.l1 + kin.l2;
    let edge = |radius: f64, lead: f64| Item {
        role: Role::EnvelopeEdge,
        shape: Shape::Arc {
            centre: Mm::ORIGIN,
            radius,
            start_deg: j1_lo + lead,
            end_deg: j1_hi + lead,
        },
    };
    items.push(edge(outer, 0.0));
    if right.0 < right.1 {
        items.push(edge(
            kin.reach(crate::robot::Arm::Right).0,
            lead_deg(kin, right.1),
        ));
    }
    if left.0 < left.1 {
        items.push(edge(
            kin.reach(crate::robot::Arm::Left).0,
            lead_deg(kin, left.0),
        ));
    }
    // The band is a thin ring just inside the outer radius: marked as a dashed arc.
    let inner_band = fk(kin, 0.0, band).distance(Mm::ORIGIN);
    items.push(Item {
        role: Role::Singular,
        shape: Shape::Arc {
            centre: Mm::ORIGIN,
            radius: (inner_band + outer) / 2.0,
            start_deg: j1_lo,
            end_deg: j1_hi,
        },
    });
    let text = |role: Role, at: Mm, text: String, anchor: Anchor, offset_px: [f32; 2]| Item {
        role,
        shape: Shape::Text {
            at,
            text,
            anchor,
            offset_px,
        },
    };
    items.push(text(
        Role::Singular,
        Mm::ORIGIN.polar(outer, j1_hi),
        format!("singular band (J2 within +/-{band} deg)"),
        Anchor::LeftBottom,
        [4.0, -4.0],
    ));
    items.push(text(
        Role::Label,
        Mm::ORIGIN.polar(outer, -90.0),
        format!("reach {outer:.0} mm"),
        Anchor::CenterTop,
        [0.0, 4.0],
    ));
    if right.0 < right.1 {
        items.push(text(
            Role::EnvelopeRight,
            fk(kin, j1_hi, 0.5 * (right.0 + right.1)),
            "right arm".into(),
            Anchor::Center,
            [0.0, 0.0],
        ));
    }
    if left.0 < left.1 {
        items.push(text(
            Role::EnvelopeLeft,
            fk(kin, j1_lo, 0.5 * (left.0 + left.1)),
            "left arm".into(),
            Anchor::Center,
            [0.0, 0.0],
        ));
    }
}

/// One arm system's region: a filled grid over (J1, J2) and its outline.
fn region(items: &mut Vec<Item>, kin: &Scara, j1: (f64, f64), j2: (f64, f64), role: Role) {
    let n1 = ((j1.1 - j1.0) / J1_STEP_DEG).ceil().max(2.0) as usize;
    let n2 = J2_SAMPLES;
    let a = |i: usize| j1.0 + (j1.1 - j1.0) * i as f64 / n1 as f64;
    let b = |k: usize| j2.0 + (j2.1 - j2.0) * k as f64 / n2 as f64;
    // FK(J1, J2) = rot(J1) (l1 + l2 cos J2, l2 sin J2): one sin/cos per sample of each.
    let elbow: Vec<(f64, f64)> = (0..=n2)
        .map(|k| {
            let (s, c) = b(k).to_radians().sin_cos();
            (kin.l1 + kin.l2 * c, kin.l2 * s)
        })
        .collect();
    let mut points = Vec::with_capacity((n1 + 1) * (n2 + 1));
    for i in 0..=n1 {
        let (s, c) = a(i).to_radians().sin_cos();
        points.extend(
            elbow
                .iter()
                .map(|(x, y)| Mm::new(c * x - s * y, s * x + c * y)),
        );
    }
    let at = |i: usize, k: usize| (i * (n2 + 1) + k) as u32;
    let mut triangles = Vec::with_capacity(2 * n1 * n2);
    for i in 0..n1 {
        for k in 0..n2 {
            triangles.push([at(i, k), at(i + 1, k), at(i + 1, k + 1)]);
            triangles.push([at(i, k), at(i + 1, k + 1), at(i, k + 1)]);
        }
    }
    let mut outline = Vec::with_capacity(2 * (n1 + n2));
    outline.extend((0..n1).map(|i| at(i, 0)));
    outline.extend((0..n2).map(|k| at(n1, k)));
    outline.extend((1..=n1).rev().map(|i| at(i, n2)));
    outline.extend((1..=n2).rev().map(|k| at(0, k)));
    let boundary = outline.iter().map(|&i| points[i as usize]).collect();
    items.push(Item {
        role,
        shape: Shape::Fill {
            points,
            triangles,
            outline,
        },
    });
    items.push(Item {
        role,
        shape: Shape::Polyline {
            points: boundary,
            closed: true,
        },
    });
}

/// A pie from `start` to `end` degrees: fill, outline and a label.
fn sector(
    items: &mut Vec<Item>,
    centre: Mm,
    radius: f64,
    start: f64,
    end: f64,
    label: Option<&str>,
) {
    let mut points = vec![centre];
    points.extend(arc_points(centre, radius, start, end, 5.0));
    items.push(Item {
        role: Role::LimitSector,
        shape: fan_fill(points.clone()),
    });
    items.push(Item {
        role: Role::LimitSector,
        shape: Shape::Polyline {
            points,
            closed: true,
        },
    });
    if let Some(label) = label {
        items.push(Item {
            role: Role::LimitSector,
            shape: Shape::Text {
                at: centre.polar(radius * 1.2, (start + end) / 2.0),
                text: label.into(),
                anchor: Anchor::Center,
                offset_px: [0.0, 0.0],
            },
        });
    }
}

/// The J1 angles beyond its limits, at the base.
pub(super) fn j1_limit(items: &mut Vec<Item>, kin: &Scara) {
    let free = kin.j1.max - kin.j1.min;
    if free < 360.0 {
        let r = 0.17 * (kin.l1 + kin.l2);
        sector(
            items,
            Mm::ORIGIN,
            r,
            kin.j1.max,
            kin.j1.min + 360.0,
            Some("J1 limit"),
        );
    }
}

/// The directions of arm 2 beyond the J2 limits, at the elbow of pose `j`.
pub(super) fn j2_limit(items: &mut Vec<Item>, kin: &Scara, j: &Joints) {
    let free = kin.j2.max - kin.j2.min;
    if free < 360.0 {
        let elbow = Mm::ORIGIN.polar(kin.l1, j.j1);
        let r = 0.11 * (kin.l1 + kin.l2);
        let start = j.j1 + kin.j2.max;
        sector(items, elbow, r, start, j.j1 + kin.j2.min + 360.0, None);
    }
}
