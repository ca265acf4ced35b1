//! Builds the arm view's scene from the robot model and what is known of the arm and the
//! cell: the envelope and limits, the controller's zones, the frames, the trail, the ghost
//! of the next step with its whole path, the arm itself and the Z/R gauge. Imports only
//! `robot` of the project.

use super::envelope;
use super::gauge;
use super::scene::{Anchor, Bounds, Item, Mm, Role, Scene, Shape, fan_fill};
use crate::robot::{Arm, CoordSystem, FrameKind, IkError, Joints, Pose, Scara, ZoneBox};

/// An extra frame the operator switched on to be drawn over the arm (a row of the
/// coordinate-table editor): a work frame sits where it is defined in the base frame, a
/// tool frame at the tool tip it would give on the current flange.
#[derive(Clone, Debug, PartialEq)]
pub struct OverlayFrame {
    pub label: String,
    pub kind: FrameKind,
    pub system: CoordSystem,
}

/// The selected work or tool frame: its number and definition.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SelectedFrame {
    pub number: u8,
    pub system: CoordSystem,
}

/// The outcome of the checks on the next step, which colours its ghost.
#[derive(Clone, Debug, PartialEq)]
pub enum GhostCheck {
    Reachable,
    /// Reachable, but in the other arm system (the pendant asks for a second press).
    ArmFlip,
    /// Reachable, but the path enters interference zones: the words ("enters zone 2:
    /// press twice"; the pendant asks for a second press).
    Zone(String),
    /// Refused, with the reason shown to the operator.
    Refused(String),
}

impl GhostCheck {
    pub fn role(&self) -> Role {
        match self {
            GhostCheck::Reachable => Role::GhostReachable,
            GhostCheck::ArmFlip => Role::GhostFlip,
            GhostCheck::Refused(_) | GhostCheck::Zone(_) => Role::GhostRefused,
        }
    }
}

/// The next step's target: the pose the arm would take (when the planner found one) and
/// the tool tip it aims at, in the base frame.
#[derive(Clone, Debug, PartialEq)]
pub struct Ghost {
    /// What the step is, for its label ("X+ 10 mm", "target").
    pub label: String,
    pub joints: Option<Joints>,
    /// The tool tip the step aims at, base frame (x, y mm, z mm, r deg).
    pub tip: Pose,
    pub check: GhostCheck,
    /// A CP step's straight line, base frame (drawn when there is no `path`).
    pub line: Option<(Mm, Mm)>,
    /// The tool tip's whole path, base frame: PTP through joint interpolation, CP on its
    /// line (the samples the checks used).
    pub path: Vec<Mm>,
    /// The first point of the path that fails a check, and what fails there.
    pub mark: Option<(Mm, String)>,
    /// The zones the path enters.
    pub zones: Vec<u8>,
}

impl Ghost {
    /// A ghost of `label` at `tip` with nothing known of its path.
    pub fn at(
        label: impl Into<String>,
        tip: Pose,
        joints: Option<Joints>,
        check: GhostCheck,
    ) -> Self {
        Ghost {
            label: label.into(),
            joints,
            tip,
            check,
            line: None,
            path: Vec::new(),
            mark: None,
            zones: Vec::new(),
        }
    }
}

/// A taught position drawn over the arm: where its tool tip is (base frame), its short
/// label ("12", "T3") and whether it is the one selected in its table.
#[derive(Clone, Debug, PartialEq)]
pub struct Marker {
    pub at: Mm,
    pub label: String,
    pub selected: bool,
}

/// Everything the scene is built from.
#[derive(Clone, Copy, Debug)]
pub struct SceneInput<'a> {
    pub kin: &'a Scara,
    /// The polled joints, if known.
    pub joints: Option<Joints>,
    /// The position is out of date.
    pub stale: bool,
    pub work: Option<SelectedFrame>,
    pub tool: Option<SelectedFrame>,
    pub overlays: &'a [OverlayFrame],
    pub ghost: Option<&'a Ghost>,
    /// Past tool tip positions, base frame, oldest first.
    pub trail: &'a [Mm],
    /// The tool tip as the controller reports it (base frame, the readouts' sample): the
    /// Z bar and R dial read it, so they agree with the Position pane to 0.001. `None`:
    /// the forward kinematics of `joints`.
    pub reported_tip: Option<Pose>,
    /// The controller's interference zones, base frame.
    pub zones: &'a [ZoneBox],
    /// Taught positions (position table, teach list).
    pub markers: &'a [Marker],
}

impl<'a> SceneInput<'a> {
    /// An arm with nothing else known: no frames, ghost or trail.
    pub fn pose(kin: &'a Scara, joints: Option<Joints>) -> Self {
        SceneInput {
            kin,
            joints,
            stale: false,
            work: None,
            tool: None,
            overlays: &[],
            ghost: None,
            trail: &[],
            reported_tip: None,
            zones: &[],
            markers: &[],
        }
    }
}

/// The flange and tool tip of a joint pose, base frame.
pub fn tip_of(kin: &Scara, j: &Joints, tool: &CoordSystem) -> Pose {
    tool.flange_to_tip(&kin.forward(j))
}

/// Whether the tool tip can be at `tip` (base frame, with Z and R as given) with each arm
/// system, J1 and R taken nearest `near`: the joints, or why not.
pub fn reach_at(
    kin: &Scara,
    tip: Mm,
    z: f64,
    r: f64,
    tool: &CoordSystem,
    near: &Joints,
) -> [(Arm, Result<Joints, IkError>); 2] {
    let flange = tool.tip_to_flange(&Pose::new(tip.x, tip.y, z, r));
    [Arm::Right, Arm::Left].map(|arm| (arm, kin.inverse(&flange, arm, near)))
}

/// Builds the scene.
pub fn build_scene(input: &SceneInput<'_>) -> Scene {
    let kin = input.kin;
    let reach = kin.l1 + kin.l2;
    let bounds = gauge::scene_bounds(kin);
    let mut items = Vec::with_capacity(160);
    envelope::grid(&mut items, &bounds, reach);
    envelope::envelope(&mut items, kin);
    envelope::j1_limit(&mut items, kin);
    let entered = input.ghost.map_or(&[][..], |g| &g.zones[..]);
    for z in input.zones.iter().filter(|z| z.is_defined()) {
        zone(&mut items, z, entered.contains(&z.number));
    }
    let tool = input.tool.map_or(CoordSystem::ZERO, |t| t.system);
    if let Some(w) = input.work.filter(|w| w.number != 0) {
        let o = w.system.offset();
        let label = format!("work {}", w.number);
        frame_axes(
            &mut items,
            Mm::new(o.x, o.y),
            o.r,
            0.16 * reach,
            Role::FrameWork,
            &label,
        );
    }
    for f in input.overlays {
        overlay(&mut items, kin, input.joints.as_ref(), f, reach);
    }
    if input.trail.len() >= 2 {
        items.push(Item {
            role: Role::Trail,
            shape: Shape::Trail {
                points: input.trail.to_vec(),
            },
        });
    }
    markers(&mut items, input.markers);
    if let Some(g) = input.ghost {
        ghost(&mut items, kin, g, &tool);
    }
    match input.joints {
        Some(j) => {
            envelope::j2_limit(&mut items, kin, &j);
            let roles = ArmRoles::ACTUAL;
            arm(&mut items, kin, &j, &tool, roles);
            base_frame(&mut items, reach);
            joint_labels(&mut items, kin, &j);
            let tip = tip_of(kin, &j, &tool);
            let label = match input.tool {
                Some(t) => format!("tool {}", t.number),
                None => "flange".to_string(),
            };
            frame_axes(
                &mut items,
                Mm::new(tip.x, tip.y),
                tip.r,
                0.12 * reach,
                Role::FrameTool,
                &label,
            );
            items.push(Item {
                role: Role::Tool,
                shape: Shape::Circle {
                    centre: Mm::new(tip.x, tip.y),
                    radius: 0.012 * reach,
                },
            });
        }
        None => {
            base_frame(&mut items, reach);
            items.push(Item {
                role: Role::Warning,
                shape: Shape::Text {
                    at: Mm::new(0.0, 0.55 * reach),
                    text: "no position yet: connect, or wait for the first poll".into(),
                    anchor: Anchor::Center,
                    offset_px: [0.0, 0.0],
                },
            });
        }
    }
    let ghost_pose = input.ghost.map(|g| g.tip);
    let ghost_role = input.ghost.map_or(Role::GhostReachable, |g| g.check.role());
    let actual = input
        .reported_tip
        .or_else(|| input.joints.map(|j| tip_of(kin, &j, &tool)));
    gauge::gauge(&mut items, kin, actual, ghost_pose.map(|p| (p, ghost_role)));
    if input.stale && input.joints.is_some() {
        items.push(Item {
            role: Role::Warning,
            shape: Shape::Text {
                at: Mm::new(bounds.min.x, bounds.max.y),
                text: "position out of date".into(),
                anchor: Anchor::LeftTop,
                offset_px: [8.0, 8.0],
            },
        });
    }
    // The ghost's labels over everything: a refusal's reason must stay readable.
    let is_ghost = |r: Role| {
        matches!(
            r,
            Role::GhostReachable | Role::GhostFlip | Role::GhostRefused
        )
    };
    let (labels, mut items): (Vec<Item>, Vec<Item>) = items
        .into_iter()
        .partition(|i| is_ghost(i.role) && matches!(i.shape, Shape::Text { .. }));
    items.extend(labels);
    Scene { items, bounds }
}

fn base_frame(items: &mut Vec<Item>, reach: f64) {
    frame_axes(items, Mm::ORIGIN, 0.0, 0.2 * reach, Role::FrameBase, "base");
}

/// Which roles draw an arm: the actual one, or a ghost in one colour.
#[derive(Clone, Copy)]
struct ArmRoles {
    base: Role,
    link: Role,
    joint: Role,
    tool: Role,
}

impl ArmRoles {
    const ACTUAL: ArmRoles = ArmRoles {
        base: Role::Base,
        link: Role::Link,
        joint: Role::Joint,
        tool: Role::Tool,
    };
    fn ghost(role: Role) -> ArmRoles {
        ArmRoles {
            base: role,
            link: role,
            joint: role,
            tool: role,
        }
    }
}

/// Base, arm 1, arm 2, the joints and the tool offset of one pose.
fn arm(items: &mut Vec<Item>, kin: &Scara, j: &Joints, tool: &CoordSystem, roles: ArmRoles) {
    let reach = kin.l1 + kin.l2;
    let elbow = Mm::ORIGIN.polar(kin.l1, j.j1);
    let f = kin.forward(j);
    let flange = Mm::new(f.x, f.y);
    let tip = tool.flange_to_tip(&f);
    let tip = Mm::new(tip.x, tip.y);
    if roles.base == Role::Base {
        circle(items, Role::Base, Mm::ORIGIN, 0.1 * reach);
    }
    capsule(items, roles.link, Mm::ORIGIN, elbow, 0.05 * reach);
    capsule(items, roles.link, elbow, flange, 0.04 * reach);
    circle(items, roles.joint, Mm::ORIGIN, 0.055 * reach);
    circle(items, roles.joint, elbow, 0.045 * reach);
    circle(items, roles.joint, flange, 0.03 * reach);
    if tip.distance(flange) > 1e-6 {
        items.push(Item {
            role: roles.tool,
            shape: Shape::Polyline {
                points: vec![flange, tip],
                closed: false,
            },
        });
    }
}

fn joint_labels(items: &mut Vec<Item>, kin: &Scara, j: &Joints) {
    let reach = kin.l1 + kin.l2;
    let elbow = Mm::ORIGIN.polar(kin.l1, j.j1);
    items.push(Item {
        role: Role::Label,
        shape: Shape::Text {
            at: Mm::new(0.0, -0.1 * reach),
            text: format!("J1 {:.3}", j.j1),
            anchor: Anchor::CenterTop,
            offset_px: [0.0, 4.0],
        },
    });
    // Outside the elbow: away from both links.
    let (a, b) = ((j.j1 + 180.0).to_radians(), (j.j1 + j.j2).to_radians());
    let (x, y) = (-(a.cos() + b.cos()), -(a.sin() + b.sin()));
    let out = if x.hypot(y) < 1e-6 {
        (j.j1 + 90.0).to_radians()
    } else {
        y.atan2(x)
    };
    let (s, c) = out.sin_cos();
    items.push(Item {
        role: Role::Label,
        shape: Shape::Text {
            at: elbow.polar(0.05 * reach, out.to_degrees()),
            text: format!("J2 {:.3}", j.j2),
            anchor: if c >= 0.0 {
                Anchor::LeftCenter
            } else {
                Anchor::RightCenter
            },
            offset_px: [(c * 4.0) as f32, (-s * 6.0) as f32],
        },
    });
}

/// Taught positions as dots with their numbers; the selected one larger, in its own
/// colour, drawn last (over the others).
fn markers(items: &mut Vec<Item>, markers: &[Marker]) {
    let (selected, plain): (Vec<&Marker>, Vec<&Marker>) = markers.iter().partition(|m| m.selected);
    for (m, role, radius_px) in plain
        .into_iter()
        .map(|m| (m, Role::Marker, 3.5))
        .chain(selected.into_iter().map(|m| (m, Role::MarkerSelected, 6.0)))
    {
        items.push(Item {
            role,
            shape: Shape::Dot {
                centre: m.at,
                radius_px,
            },
        });
        items.push(Item {
            role,
            shape: Shape::Text {
                at: m.at,
                text: m.label.clone(),
                anchor: Anchor::LeftBottom,
                offset_px: [radius_px + 1.0, -1.0],
            },
        });
    }
}

/// A zone in plan: its X-Y rectangle, filled, and "zone N Z a..b" at its corner; red
/// when the next step's path enters it. A zone that names no X or Y is not drawn.
fn zone(items: &mut Vec<Item>, z: &ZoneBox, entered: bool) {
    let Some(((x0, x1), (y0, y1))) = z.plan_rect() else {
        return;
    };
    let role = if entered {
        Role::ZoneEntered
    } else {
        Role::Zone
    };
    let corners = vec![
        Mm::new(x0, y0),
        Mm::new(x1, y0),
        Mm::new(x1, y1),
        Mm::new(x0, y1),
    ];
    items.push(Item {
        role,
        shape: fan_fill(corners.clone()),
    });
    items.push(Item {
        role,
        shape: Shape::Polyline {
            points: corners,
            closed: true,
        },
    });
    items.push(Item {
        role,
        shape: Shape::Text {
            at: Mm::new(x0, y1),
            text: z.label(),
            anchor: Anchor::LeftBottom,
            offset_px: [2.0, -3.0],
        },
    });
}

fn ghost(items: &mut Vec<Item>, kin: &Scara, g: &Ghost, tool: &CoordSystem) {
    let role = g.check.role();
    let path = match g.line {
        _ if g.path.len() >= 2 => Some(g.path.clone()),
        Some((a, b)) => Some(vec![a, b]),
        None => None,
    };
    if let Some(points) = path {
        items.push(Item {
            role: Role::CpLine,
            shape: Shape::Polyline {
                points,
                closed: false,
            },
        });
    }
    if let Some(j) = g.joints {
        arm(items, kin, &j, tool, ArmRoles::ghost(role));
    }
    let at = Mm::new(g.tip.x, g.tip.y);
    items.push(Item {
        role,
        shape: Shape::Cross {
            centre: at,
            half_px: 7.0,
        },
    });
    let verdict = match &g.check {
        GhostCheck::Reachable => "reachable".to_string(),
        GhostCheck::ArmFlip => "flips the arm system".to_string(),
        GhostCheck::Zone(why) => why.clone(),
        GhostCheck::Refused(why) => format!("refused: {why}"),
    };
    // Two lines, on the side of the target away from the gauge.
    let (anchor, dx) = if g.tip.x > 0.25 * (kin.l1 + kin.l2) {
        (Anchor::RightBottom, -10.0)
    } else {
        (Anchor::LeftBottom, 10.0)
    };
    for (text, dy) in [(g.label.clone(), -24.0), (verdict, -8.0)] {
        items.push(Item {
            role,
            shape: Shape::Text {
                at,
                text,
                anchor,
                offset_px: [dx, dy],
            },
        });
    }
    // The first failing point after the ghost's own lines: they are placed first.
    if let Some((at, why)) = &g.mark {
        items.push(Item {
            role: Role::GhostRefused,
            shape: Shape::Cross {
                centre: *at,
                half_px: 5.0,
            },
        });
        items.push(Item {
            role: Role::GhostRefused,
            shape: Shape::Text {
                at: *at,
                text: format!("{why} here"),
                // Below the point: the ghost's own two lines are above its target.
                anchor: Anchor::CenterTop,
                offset_px: [0.0, 8.0],
            },
        });
    }
}

fn overlay(
    items: &mut Vec<Item>,
    kin: &Scara,
    joints: Option<&Joints>,
    f: &OverlayFrame,
    reach: f64,
) {
    let (at, r) = match f.kind {
        FrameKind::Work => {
            let o = f.system.offset();
            (Mm::new(o.x, o.y), o.r)
        }
        FrameKind::Tool => {
            let Some(j) = joints else { return };
            let tip = tip_of(kin, j, &f.system);
            (Mm::new(tip.x, tip.y), tip.r)
        }
    };
    frame_axes(items, at, r, 0.14 * reach, Role::FrameOverlay, &f.label);
}

/// A frame's X and Y axes as labelled arrows, and its name at the origin.
pub(super) fn frame_axes(
    items: &mut Vec<Item>,
    origin: Mm,
    r_deg: f64,
    len: f64,
    role: Role,
    label: &str,
) {
    for (angle, name) in [(r_deg, "X"), (r_deg + 90.0, "Y")] {
        let to = origin.polar(len, angle);
        items.push(Item {
            role,
            shape: Shape::Arrow { from: origin, to },
        });
        let (s, c) = angle.to_radians().sin_cos();
        items.push(Item {
            role,
            shape: Shape::Text {
                at: to,
                text: name.into(),
                anchor: Anchor::Center,
                offset_px: [(c * 10.0) as f32, (-s * 10.0) as f32],
            },
        });
    }
    // The name on the side away from both axes.
    let (s, c) = (r_deg + 225.0).to_radians().sin_cos();
    items.push(Item {
        role,
        shape: Shape::Text {
            at: origin,
            text: label.into(),
            anchor: if c >= 0.0 {
                Anchor::LeftCenter
            } else {
                Anchor::RightCenter
            },
            offset_px: [(c * 12.0) as f32, (-s * 12.0) as f32],
        },
    });
}

pub(super) fn circle(items: &mut Vec<Item>, role: Role, centre: Mm, radius: f64) {
    items.push(Item {
        role,
        shape: Shape::Circle { centre, radius },
    });
}

/// A link: a filled rounded bar from `a` to `b`, `half` mm wide each side.
fn capsule(items: &mut Vec<Item>, role: Role, a: Mm, b: Mm, half: f64) {
    let dir = (b.y - a.y).atan2(b.x - a.x).to_degrees();
    let mut points = super::scene::arc_points(b, half, dir - 90.0, dir + 90.0, 15.0);
    points.extend(super::scene::arc_points(
        a,
        half,
        dir + 90.0,
        dir + 270.0,
        15.0,
    ));
    items.push(Item {
        role,
        shape: fan_fill(points.clone()),
    });
    items.push(Item {
        role,
        shape: Shape::Polyline {
            points,
            closed: true,
        },
    });
}

/// The bounds of a scene of this robot (what "fit" shows).
pub fn bounds(kin: &Scara) -> Bounds {
    gauge::scene_bounds(kin)
}
