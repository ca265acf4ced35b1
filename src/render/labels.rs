//! Where the scene's labels go: each inside the view and clear of every other, the most
//! important placed first; when there is no room without overlap a label is shortened
//! (its head, "…") and then hidden, the least important first; the window shows the
//! whole text of a shortened or hidden label on hover. Both painters place text through
//! here, so the window and the PNG agree.

use super::scene::{Item, Role, Shape};
use super::view::{View, text_top_left};

/// Space kept between two labels, in pixels.
const GAP_PX: f32 = 2.0;

/// One label to place: where its anchor is on the screen, where the anchor sits on the
/// label's box, the box's size, the size of its short form ([`short_text`]) if it has
/// one, and the label's rank (0 = the most important).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LabelBox {
    pub anchor_pos: [f32; 2],
    pub fractions: (f32, f32),
    pub size: [f32; 2],
    pub short: Option<[f32; 2]>,
    pub rank: u8,
}

/// Where a label went: its top-left corner, and whether its short form is shown.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Placement {
    pub top_left: [f32; 2],
    pub short: bool,
}

/// A label as painted, for the hover and the size tests: its whole text, its box on the
/// screen (`None`: hidden, no room) and whether it was shortened.
#[derive(Clone, Debug, PartialEq)]
pub struct ShownLabel {
    pub text: String,
    pub anchor: [f32; 2],
    pub rect: Option<[f32; 4]>,
    pub short: bool,
}

/// Labels no longer than this are never shortened.
const SHORT_MIN: usize = 8;

/// The short form of a label: the part before ": " ("enters zone 1: press twice" ->
/// "enters zone 1…"), else its first two words ("zone 1 Z 0..150" -> "zone 1…"); `None`
/// when the label is short already.
pub fn short_text(text: &str) -> Option<String> {
    if text.chars().count() <= SHORT_MIN {
        return None;
    }
    let head = match text.split_once(": ") {
        Some((head, _)) if !head.is_empty() => head.to_owned(),
        _ => {
            let words: Vec<&str> = text.split_whitespace().take(2).collect();
            words.join(" ")
        }
    };
    (head.chars().count() + 1 < text.chars().count()).then(|| format!("{head}…"))
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

/// Where each label goes (in the order given), or `None` for a label hidden because no
/// place clear of the more important ones is left. A label tries its own place first,
/// then places nudged up, down and sideways, each kept inside the view; then the same
/// with its short form.
pub fn place(view: &View, labels: &[LabelBox]) -> Vec<Option<Placement>> {
    let mut order: Vec<usize> = (0..labels.len()).collect();
    // The stable sort keeps the scene's order among labels of one rank.
    order.sort_by_key(|&i| labels[i].rank);
    let mut placed: Vec<[f32; 4]> = Vec::with_capacity(labels.len());
    let mut out = vec![None; labels.len()];
    for i in order {
        let label = labels[i];
        let sizes = [Some(label.size), label.short];
        let spot = sizes.iter().enumerate().find_map(|(k, size)| {
            let size = (*size)?;
            spot_for(view, &label, size, &placed).map(|at| (at, size, k == 1))
        });
        if let Some(([x, y], [w, h], short)) = spot {
            placed.push([x, y, x + w, y + h]);
            out[i] = Some(Placement {
                top_left: [x, y],
                short,
            });
        }
    }
    out
}

/// The first place for a box of `size` around the label's anchor that lies inside the
/// view and clear of every box `placed`.
fn spot_for(
    view: &View,
    label: &LabelBox,
    size: [f32; 2],
    placed: &[[f32; 4]],
) -> Option<[f32; 2]> {
    let [w, h] = size;
    let nudges = [
        [0.0, 0.0],
        [0.0, -(h + GAP_PX)],
        [0.0, h + GAP_PX],
        [w * 0.5 + GAP_PX, 0.0],
        [-(w * 0.5 + GAP_PX), 0.0],
        [0.0, -2.0 * (h + GAP_PX)],
        [0.0, 2.0 * (h + GAP_PX)],
    ];
    nudges.iter().find_map(|d| {
        let pos = [label.anchor_pos[0] + d[0], label.anchor_pos[1] + d[1]];
        let [x, y] = text_top_left(view, pos, label.fractions, size);
        let rect = [x, y, x + w, y + h];
        let fits = inside(view, rect) && !placed.iter().any(|p| overlaps(*p, rect));
        fits.then_some([x, y])
    })
}

/// Whether two painted label boxes overlap (touching is fine), for the size tests.
pub fn boxes_overlap(a: [f32; 4], b: [f32; 4]) -> bool {
    a[0] < b[2] - 0.01 && b[0] < a[2] - 0.01 && a[1] < b[3] - 0.01 && b[1] < a[3] - 0.01
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
            short: None,
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
        let (a, b) = (a.top_left, b.top_left);
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

    #[test]
    fn a_label_without_room_is_shortened_before_it_is_hidden() {
        assert_eq!(
            short_text("enters zone 1: press twice").as_deref(),
            Some("enters zone 1…")
        );
        assert_eq!(short_text("zone 2 Z 0..200").as_deref(), Some("zone 2…"));
        assert_eq!(short_text("T12"), None);
        assert_eq!(short_text("zone 1 Z"), None, "short already");
        // Room for 40 px beside a placed label: the long one shows its short form.
        let v = view(200.0, 20.0);
        let mut long = label(150.0, 10.0, 3);
        long.size = [120.0, 14.0];
        long.short = Some([38.0, 14.0]);
        let placed = place(&v, &[label(60.0, 10.0, 0), long]);
        assert!(matches!(placed[0], Some(Placement { short: false, .. })));
        let Some(p) = placed[1] else {
            panic!("the short form fits: {placed:?}")
        };
        assert!(p.short);
        let a = placed[0].map(|p| p.top_left).unwrap();
        assert!(!boxes_overlap(
            [a[0], a[1], a[0] + 60.0, a[1] + 14.0],
            [
                p.top_left[0],
                p.top_left[1],
                p.top_left[0] + 38.0,
                p.top_left[1] + 14.0
            ]
        ));
    }
}
