//! Where the scene's labels go: each inside the view and clear of every other, the most
//! important placed first; when there is no room without overlap a label is hidden, the
//! least important first. Both painters place text through here, so the window and the
//! PNG agree.

use super::scene::{Item, Role, Shape};
use super::view::{View, text_top_left};

/// Space kept between two labels, in pixels.
const GAP_PX: f32 = 2.0;

/// One label to place: where its anchor is on the screen, where the anchor sits on the
/// label's box, the box's size and the label's rank (0 = the most important).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LabelBox {
    pub anchor_pos: [f32; 2],
    pub fractions: (f32, f32),
    pub size: [f32; 2],
    pub rank: u8,
}

/// How much a label of this role matters: what the operator must notice first, then the
/// next step, the frames and gauges, names, and last the scenery.
pub fn rank(role: Role) -> u8 {
    match role {
        Role::Warning => 0,
        Role::GhostRefused
        | Role::GhostFlip
        | Role::GhostReachable
        | Role::CpLine
        | Role::ZoneEntered => 1,
        Role::Zone | Role::MarkerSelected => 2,
        Role::Tool | Role::FrameTool | Role::FrameWork | Role::FrameBase | Role::FrameOverlay => 2,
        Role::Gauge | Role::GaugeValue => 3,
        Role::Label | Role::Base | Role::Link | Role::Joint | Role::Trail => 4,
        Role::Marker => 5,
        Role::EnvelopeRight
        | Role::EnvelopeLeft
        | Role::EnvelopeEdge
        | Role::Singular
        | Role::LimitSector
        | Role::Grid => 5,
    }
}

/// The text items of a scene in order, with their role.
pub fn texts(items: &[Item]) -> impl Iterator<Item = (usize, &Item)> {
    items
        .iter()
        .enumerate()
        .filter(|(_, i)| matches!(i.shape, Shape::Text { .. }))
}

/// The top-left corner of each label (in the order given), or `None` for a label hidden
/// because no place clear of the more important ones is left. A label tries its own
/// place first, then places nudged up, down and sideways, each kept inside the view.
pub fn place(view: &View, labels: &[LabelBox]) -> Vec<Option<[f32; 2]>> {
    let mut order: Vec<usize> = (0..labels.len()).collect();
    // The stable sort keeps the scene's order among labels of one rank.
    order.sort_by_key(|&i| labels[i].rank);
    let mut placed: Vec<[f32; 4]> = Vec::with_capacity(labels.len());
    let mut out = vec![None; labels.len()];
    for i in order {
        let label = labels[i];
        let [w, h] = label.size;
        let nudges = [
            [0.0, 0.0],
            [0.0, -(h + GAP_PX)],
            [0.0, h + GAP_PX],
            [w * 0.5 + GAP_PX, 0.0],
            [-(w * 0.5 + GAP_PX), 0.0],
            [0.0, -2.0 * (h + GAP_PX)],
            [0.0, 2.0 * (h + GAP_PX)],
        ];
        let spot = nudges.iter().find_map(|d| {
            let pos = [label.anchor_pos[0] + d[0], label.anchor_pos[1] + d[1]];
            let [x, y] = text_top_left(view, pos, label.fractions, label.size);
            let rect = [x, y, x + w, y + h];
            let fits = inside(view, rect) && !placed.iter().any(|p| overlaps(*p, rect));
            fits.then_some([x, y])
        });
        if let Some([x, y]) = spot {
            placed.push([x, y, x + w, y + h]);
            out[i] = Some([x, y]);
        }
    }
    out
}

/// Whether a box lies inside the view's area.
fn inside(view: &View, [x0, y0, x1, y1]: [f32; 4]) -> bool {
    let (ox, oy) = (view.origin[0], view.origin[1]);
    x0 >= ox - 0.5
        && y0 >= oy - 0.5
        && x1 <= ox + view.size[0] + 0.5
        && y1 <= oy + view.size[1] + 0.5
}

/// Whether two boxes come closer than the gap.
fn overlaps(a: [f32; 4], b: [f32; 4]) -> bool {
    a[0] < b[2] + GAP_PX && b[0] < a[2] + GAP_PX && a[1] < b[3] + GAP_PX && b[1] < a[3] + GAP_PX
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::scene::{Bounds, Mm};

    fn view(w: f32, h: f32) -> View {
        let b = Bounds {
            min: Mm::new(-100.0, -100.0),
            max: Mm::new(100.0, 100.0),
        };
        View::fit(&b, [0.0, 0.0], [w, h], 0.0)
    }

    fn label(x: f32, y: f32, rank: u8) -> LabelBox {
        LabelBox {
            anchor_pos: [x, y],
            fractions: (0.5, 0.5),
            size: [60.0, 14.0],
            rank,
        }
    }

    #[test]
    fn two_labels_on_one_spot_are_moved_apart() {
        let v = view(400.0, 300.0);
        let placed = place(&v, &[label(200.0, 150.0, 4), label(200.0, 150.0, 4)]);
        let [Some(a), Some(b)] = placed[..] else {
            panic!("both fit: {placed:?}")
        };
        let ra = [a[0], a[1], a[0] + 60.0, a[1] + 14.0];
        let rb = [b[0], b[1], b[0] + 60.0, b[1] + 14.0];
        assert!(!overlaps(ra, rb), "{a:?} {b:?}");
        assert_eq!(a, [170.0, 143.0], "the first keeps its own place");
    }

    #[test]
    fn when_room_is_short_the_less_important_hide_first() {
        // A view with room for one line of labels only.
        let v = view(70.0, 20.0);
        let placed = place(
            &v,
            &[
                label(35.0, 10.0, 5),
                label(35.0, 10.0, 0),
                label(35.0, 10.0, 3),
            ],
        );
        assert_eq!(
            placed.iter().map(Option::is_some).collect::<Vec<_>>(),
            [false, true, false],
            "only the warning is shown: {placed:?}"
        );
    }
}
