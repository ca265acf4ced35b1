//! Taught positions over the arm view: the controller's position records (as read) and
//! the teach list's points as numbered markers, the one under the pointer, its row.

use crate::pendant::Pendant;
use crate::pendant::positions::Row;
use crate::render::{Marker, Mm, View};
use crate::robot::Pose;

/// Markers drawn at most (the position table holds up to 20000 records): the lowest
/// numbers first, then the teach list. A bound on the frame's work, not a safety limit.
pub const MAX_MARKERS: usize = 2_000;

/// How near the pointer must be to a marker to pick it, px.
const PICK_PX: f32 = 9.0;

/// Which row a marker stands for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MarkerKey {
    /// Position No. n of the controller's table (its record as read).
    Position(u16),
    /// Point i (0-based) of the teach list.
    Teach(usize),
}

impl MarkerKey {
    /// The short label on the view: "12" for position No. 12, "T3" for the third point.
    pub fn label(self) -> String {
        match self {
            MarkerKey::Position(n) => n.to_string(),
            MarkerKey::Teach(i) => format!("T{}", i + 1),
        }
    }
}

/// A marker and the row it stands for.
#[derive(Clone, Debug, PartialEq)]
pub struct Placed {
    pub key: MarkerKey,
    /// The tool tip it names, base frame.
    pub at: Mm,
}

/// Every taught position whose place is known: position records with X and Y in the
/// selected work frame (where 2D6H takes them), teach points in their own work frame.
pub fn taught(pendant: &Pendant) -> Vec<Placed> {
    let c = &pendant.controller;
    let mut out = Vec::new();
    if let Some(work) = c.work_frame() {
        use crate::protocol::Axis;
        for rec in pendant.positions.held() {
            if out.len() >= MAX_MARKERS {
                break;
            }
            let get = |a: Axis| rec.coords.get(a).map(|v| v.units());
            let (Some(x), Some(y)) = (get(Axis::A1), get(Axis::A2)) else {
                continue;
            };
            let tip = work.work_to_base(&Pose::new(x, y, 0.0, 0.0));
            out.push(Placed {
                key: MarkerKey::Position(rec.number),
                at: Mm::new(tip.x, tip.y),
            });
        }
    }
    for (i, p) in pendant.teach.list().iter().enumerate() {
        if out.len() >= MAX_MARKERS {
            break;
        }
        let Some(work) = c.work_frame_of(p.work) else {
            continue;
        };
        let tip = work.work_to_base(&Pose::from_wire(p.pose));
        out.push(Placed {
            key: MarkerKey::Teach(i),
            at: Mm::new(tip.x, tip.y),
        });
    }
    out
}

/// The markers to draw, the selected ones (`selected`) highlighted.
pub fn markers(placed: &[Placed], selected: &[MarkerKey]) -> Vec<Marker> {
    placed
        .iter()
        .map(|p| Marker {
            at: p.at,
            label: p.key.label(),
            selected: selected.contains(&p.key),
        })
        .collect()
}

/// The marker nearest the screen point `at`, within reach of the pointer.
pub fn pick(placed: &[Placed], view: &View, at: [f32; 2]) -> Option<MarkerKey> {
    placed
        .iter()
        .map(|p| {
            let s = view.to_screen(p.at);
            (p.key, (s[0] - at[0]).hypot(s[1] - at[1]))
        })
        .filter(|(_, d)| *d <= PICK_PX)
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(k, _)| k)
}

/// The marker's row in words, for the hover.
pub fn row_text(pendant: &Pendant, key: MarkerKey) -> String {
    match key {
        MarkerKey::Position(n) => match pendant.positions.row(n) {
            Row::Held(rec) => format!(
                "No. {n} (the controller's record, selected work frame): {}",
                super::positions::record_words(rec)
            ),
            _ => format!("No. {n}: not read"),
        },
        MarkerKey::Teach(i) => match pendant.teach.list().get(i) {
            Some(p) => {
                let [x, y, z, r] = p.pose.map(|v| crate::protocol::Milli(v).units());
                format!(
                    "T{} \"{}\": X {x:.3} Y {y:.3} Z {z:.3} R {r:.3} (work {} / tool {}), {} arm",
                    i + 1,
                    p.name,
                    p.work,
                    p.tool,
                    p.arm
                )
            }
            None => format!("T{}: no longer in the list", i + 1),
        },
    }
}

/// What "Go to" says for the marker.
pub fn go_label(pendant: &Pendant, key: MarkerKey) -> String {
    match key {
        MarkerKey::Position(n) => format!("Go to No. {n}"),
        MarkerKey::Teach(i) => match pendant.teach.list().get(i) {
            Some(p) => format!("Go to \"{}\"", p.name),
            None => format!("Go to T{}", i + 1),
        },
    }
}
