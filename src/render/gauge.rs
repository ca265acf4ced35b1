//! The Z and R gauge beside the arm: a bar over the Z stroke with the actual (and the
//! ghost's) Z, and a dial with the tool's R in the base frame.

use super::scene::{Anchor, Bounds, Item, Mm, Role, Shape, fan_fill};
use crate::robot::{Pose, Scara};

/// Where the gauge sits: left edge, width, top and bottom of the Z bar, and the R dial.
struct Layout {
    x: f64,
    w: f64,
    top: f64,
    bottom: f64,
    dial: Mm,
    dial_r: f64,
}

fn layout(kin: &Scara) -> Layout {
    let reach = kin.l1 + kin.l2;
    let x = reach * 1.22;
    let w = reach * 0.07;
    Layout {
        x,
        w,
        top: reach * 0.85,
        bottom: reach * 0.05,
        dial: Mm::new(x + w / 2.0, -reach * 0.45),
        dial_r: reach * 0.14,
    }
}

/// The scene's bounds: the envelope, and the gauge with room for its labels.
pub(super) fn scene_bounds(kin: &Scara) -> Bounds {
    let reach = kin.l1 + kin.l2;
    let g = layout(kin);
    Bounds {
        min: Mm::new(-reach * 1.1, -reach * 1.1),
        max: Mm::new(g.x + g.w + reach * 0.32, reach * 1.1),
    }
}

/// The gauge, with the actual tool pose and the ghost's (pose and role), base frame.
pub(super) fn gauge(
    items: &mut Vec<Item>,
    kin: &Scara,
    actual: Option<Pose>,
    ghost: Option<(Pose, Role)>,
) {
    let g = layout(kin);
    let (zmin, zmax) = (kin.z.min, kin.z.max);
    let span = (zmax - zmin).max(1e-6);
    // [inferred] The bar's top is the Z stroke's low end, as the controller counts Z
    // (0 at the upper end on IAI SCARAs); the labels name both ends.
    let z_at = |z: f64| g.top - (z.clamp(zmin, zmax) - zmin) / span * (g.top - g.bottom);
    let rect = |y0: f64, y1: f64| {
        vec![
            Mm::new(g.x, y0),
            Mm::new(g.x + g.w, y0),
            Mm::new(g.x + g.w, y1),
            Mm::new(g.x, y1),
        ]
    };
    let fill = |role: Role, points: Vec<Mm>| Item {
        role,
        shape: fan_fill(points),
    };
    let text = |role: Role, at: Mm, text: String, anchor: Anchor, dx: f32| Item {
        role,
        shape: Shape::Text {
            at,
            text,
            anchor,
            offset_px: [dx, 0.0],
        },
    };
    items.push(fill(Role::Gauge, rect(g.top, g.bottom)));
    items.push(Item {
        role: Role::Gauge,
        shape: Shape::Polyline {
            points: rect(g.top, g.bottom),
            closed: true,
        },
    });
    items.push(text(
        Role::Gauge,
        Mm::new(g.x, g.top),
        format!("Z {zmin:.0}"),
        Anchor::RightCenter,
        -4.0,
    ));
    items.push(text(
        Role::Gauge,
        Mm::new(g.x, g.bottom),
        format!("Z {zmax:.0}"),
        Anchor::RightCenter,
        -4.0,
    ));
    items.push(Item {
        role: Role::Gauge,
        shape: Shape::Circle {
            centre: g.dial,
            radius: g.dial_r,
        },
    });
    items.push(Item {
        role: Role::Gauge,
        shape: Shape::Polyline {
            points: vec![
                g.dial.polar(g.dial_r * 0.8, 0.0),
                g.dial.polar(g.dial_r, 0.0),
            ],
            closed: false,
        },
    });
    items.push(text(
        Role::Gauge,
        g.dial.polar(g.dial_r, 0.0),
        "0".into(),
        Anchor::LeftCenter,
        4.0,
    ));
    let mut marks = |pose: &Pose, role: Role, label: bool| {
        let y = z_at(pose.z);
        if role == Role::GaugeValue {
            items.push(fill(role, rect(g.top, y)));
        }
        items.push(Item {
            role,
            shape: Shape::Polyline {
                points: vec![Mm::new(g.x - g.w * 0.3, y), Mm::new(g.x + g.w * 1.3, y)],
                closed: false,
            },
        });
        items.push(Item {
            role,
            shape: Shape::Arrow {
                from: g.dial,
                to: g.dial.polar(g.dial_r * 0.9, pose.r),
            },
        });
        if label {
            items.push(text(
                role,
                Mm::new(g.x + g.w, y),
                format!("Z {:.3}", pose.z),
                Anchor::LeftCenter,
                8.0,
            ));
            items.push(Item {
                role,
                shape: Shape::Text {
                    at: g.dial.polar(g.dial_r, -90.0),
                    text: format!("R {:.3}", pose.r),
                    anchor: Anchor::CenterTop,
                    offset_px: [0.0, 4.0],
                },
            });
        }
    };
    if let Some((pose, role)) = ghost {
        marks(&pose, role, false);
    }
    if let Some(pose) = actual {
        marks(&pose, Role::GaugeValue, true);
    }
}
