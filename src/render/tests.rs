//! Scene tests: where the builder puts the arm, the envelope and the ghost.

use super::*;
use crate::robot::{Arm, CoordSystem, FrameKind, Joints, Pose, RobotModel, Scara, ZoneBox};

fn kin() -> Scara {
    Scara::new(&RobotModel::default_model())
}

fn tool_tips(scene: &Scene) -> Vec<Mm> {
    scene
        .with_role(Role::Tool)
        .filter_map(|s| match s {
            Shape::Circle { centre, .. } => Some(*centre),
            _ => None,
        })
        .collect()
}

#[test]
fn the_tool_tip_sits_at_forward_kinematics_for_both_arm_systems() {
    let k = kin();
    let tool = CoordSystem::from_wire([40_000, -15_000, 20_000, 30_000]);
    for j in [
        Joints::new(30.0, 60.0, 50.0, 10.0),
        Joints::new(-100.0, -135.5, 0.0, -200.0),
        Joints::new(117.25, 12.5, 150.0, 45.0),
    ] {
        for selected in [
            None,
            Some(SelectedFrame {
                number: 3,
                system: tool,
            }),
        ] {
            let input = SceneInput {
                tool: selected,
                ..SceneInput::pose(&k, Some(j))
            };
            let scene = build_scene(&input);
            let expected = selected
                .map_or(CoordSystem::ZERO, |t| t.system)
                .flange_to_tip(&k.forward(&j));
            let tips = tool_tips(&scene);
            assert_eq!(tips.len(), 1, "one tool tip for {j:?}");
            assert!(
                (tips[0].x - expected.x).abs() < 0.001 && (tips[0].y - expected.y).abs() < 0.001,
                "tip {:?} for {j:?}, FK says {expected:?}",
                tips[0]
            );
        }
    }
}

#[test]
fn the_envelope_radii_are_the_models() {
    for name in ["scara-500", "scara-250"] {
        let Ok(model) = RobotModel::builtin(name) else {
            panic!("builtin {name}")
        };
        let k = Scara::new(&model);
        let scene = build_scene(&SceneInput::pose(&k, None));
        let mut radii: Vec<f64> = scene
            .with_role(Role::EnvelopeEdge)
            .filter_map(|s| match s {
                Shape::Arc { centre, radius, .. } if *centre == Mm::ORIGIN => Some(*radius),
                _ => None,
            })
            .collect();
        radii.sort_by(f64::total_cmp);
        let mut expected = vec![
            k.reach(Arm::Right).1,
            k.reach(Arm::Right).0,
            k.reach(Arm::Left).0,
        ];
        expected.sort_by(f64::total_cmp);
        assert_eq!(radii.len(), 3, "{name}: {radii:?}");
        for (r, e) in radii.iter().zip(&expected) {
            assert!(
                (r - e).abs() < 1e-9,
                "{name}: radius {r} vs the model's {e}"
            );
        }
        assert!((expected[2] - (model.arm1_mm + model.arm2_mm)).abs() < 1e-9);
        // Every point of each arm's region lies within the model's reach.
        for role in [Role::EnvelopeRight, Role::EnvelopeLeft] {
            let points: Vec<&Mm> = scene
                .with_role(role)
                .flat_map(|s| match s {
                    Shape::Fill { points, .. } => points.iter().collect(),
                    _ => Vec::new(),
                })
                .collect();
            assert!(!points.is_empty(), "{name}: {role:?} is drawn");
            let arm = if role == Role::EnvelopeRight {
                Arm::Right
            } else {
                Arm::Left
            };
            let (inner, outer) = k.reach(arm);
            for p in points {
                let d = p.distance(Mm::ORIGIN);
                assert!(
                    d <= outer + 1e-6 && d >= inner - 1e-6,
                    "{name} {role:?}: {d}"
                );
            }
        }
    }
}

#[test]
fn a_refused_ghost_carries_the_refused_role_and_its_reason() {
    let k = kin();
    let ghost = Ghost::at(
        "X+ 50 mm",
        Pose::new(520.0, 0.0, 0.0, 0.0),
        None,
        GhostCheck::Refused("out of reach: 520.000 mm from the J1 axis".into()),
    );
    let input = SceneInput {
        ghost: Some(&ghost),
        ..SceneInput::pose(&k, Some(Joints::new(0.0, 20.0, 0.0, 0.0)))
    };
    let scene = build_scene(&input);
    let refused: Vec<&Shape> = scene.with_role(Role::GhostRefused).collect();
    assert!(
        refused
            .iter()
            .any(|s| matches!(s, Shape::Cross { centre, .. } if (centre.x - 520.0).abs() < 1e-9))
    );
    assert!(
        refused.iter().any(
            |s| matches!(s, Shape::Text { text, .. } if text.contains("refused: out of reach"))
        )
    );
    assert_eq!(scene.with_role(Role::GhostReachable).count(), 0);
    // A reachable ghost draws the target pose's arm in its own role.
    let ok = Ghost {
        check: GhostCheck::Reachable,
        joints: Some(Joints::new(10.0, 30.0, 0.0, 0.0)),
        line: Some((Mm::new(0.0, 0.0), Mm::new(1.0, 1.0))),
        ..ghost.clone()
    };
    let scene = build_scene(&SceneInput {
        ghost: Some(&ok),
        ..input
    });
    assert!(
        scene
            .with_role(Role::GhostReachable)
            .filter(|s| matches!(s, Shape::Fill { .. }))
            .count()
            >= 2
    );
    assert_eq!(scene.with_role(Role::GhostRefused).count(), 0);
    assert_eq!(scene.with_role(Role::CpLine).count(), 1);
}

#[test]
fn trail_overlays_and_frames_are_drawn() {
    let k = kin();
    let trail: Vec<Mm> = (0..10_000)
        .map(|i| Mm::new(f64::from(i) * 0.01, 250.0))
        .collect();
    let overlays = [
        OverlayFrame {
            label: "work 5".into(),
            kind: FrameKind::Work,
            system: CoordSystem::from_wire([200_000, 100_000, 0, 45_000]),
        },
        OverlayFrame {
            label: "tool 9".into(),
            kind: FrameKind::Tool,
            system: CoordSystem::from_wire([30_000, 0, 0, 0]),
        },
    ];
    let work = SelectedFrame {
        number: 2,
        system: CoordSystem::from_wire([100_000, -50_000, 0, 90_000]),
    };
    let scene = build_scene(&SceneInput {
        trail: &trail,
        overlays: &overlays,
        work: Some(work),
        ..SceneInput::pose(&k, Some(Joints::new(0.0, 90.0, 0.0, 0.0)))
    });
    let trails: Vec<&Shape> = scene.with_role(Role::Trail).collect();
    assert!(matches!(trails.as_slice(), [Shape::Trail { points }] if points.len() == 10_000));
    let labels = |role: Role| -> Vec<String> {
        scene
            .with_role(role)
            .filter_map(|s| match s {
                Shape::Text { text, .. } => Some(text.clone()),
                _ => None,
            })
            .collect()
    };
    assert!(labels(Role::FrameOverlay).contains(&"work 5".to_string()));
    assert!(labels(Role::FrameOverlay).contains(&"tool 9".to_string()));
    assert!(labels(Role::FrameWork).contains(&"work 2".to_string()));
    // The work frame's X axis points along its R (90 deg: base +Y).
    let x_axis = scene.with_role(Role::FrameWork).find_map(|s| match s {
        Shape::Arrow { from, to } => Some((*from, *to)),
        _ => None,
    });
    let Some((from, to)) = x_axis else {
        panic!("no work axes")
    };
    assert!((from.x - 100.0).abs() < 1e-9 && (to.x - 100.0).abs() < 1e-6 && to.y > from.y);
}

#[test]
fn reach_at_tells_each_arm_system() {
    let k = kin();
    let near = Joints::new(0.0, 90.0, 0.0, 0.0);
    let [(a1, r1), (a2, r2)] = reach_at(
        &k,
        Mm::new(300.0, 100.0),
        0.0,
        0.0,
        &CoordSystem::ZERO,
        &near,
    );
    assert_eq!((a1, a2), (Arm::Right, Arm::Left));
    assert!(r1.is_ok() && r2.is_ok());
    let far = reach_at(&k, Mm::new(600.0, 0.0), 0.0, 0.0, &CoordSystem::ZERO, &near);
    assert!(far.iter().all(|(_, r)| r.is_err()));
    // Behind the base, beyond J1's limits one way: only one arm system gets there.
    let behind = reach_at(
        &k,
        Mm::new(-250.0, 250.0),
        0.0,
        0.0,
        &CoordSystem::ZERO,
        &near,
    );
    assert_eq!(
        behind.iter().filter(|(_, r)| r.is_ok()).count(),
        1,
        "{behind:?}"
    );
}

#[test]
fn a_label_near_an_edge_is_moved_inside_the_view_and_never_cut() {
    use super::scene::Bounds;
    use super::view::{View, text_top_left};
    let bounds = Bounds {
        min: Mm::new(-300.0, -300.0),
        max: Mm::new(300.0, 300.0),
    };
    let view = View::fit(&bounds, [100.0, 50.0], [400.0, 300.0], 12.0);
    let size = [120.0, 14.0];
    // Right-anchored at 30 px into the view: it would start 90 px left of the view.
    let at = text_top_left(&view, [130.0, 200.0], (1.0, 1.0), size);
    assert!(at[0] >= 100.0, "cut at the left edge: {at:?}");
    // Left-anchored near the right edge: it would run 100 px past it.
    let at = text_top_left(&view, [480.0, 55.0], (0.0, 1.0), size);
    assert!(at[0] + size[0] <= 500.0, "cut at the right edge: {at:?}");
    assert!(at[1] >= 50.0, "cut at the top: {at:?}");
    // A label that fits is left where its anchor puts it.
    assert_eq!(
        text_top_left(&view, [300.0, 200.0], (0.0, 1.0), size),
        [300.0, 186.0]
    );
    // One wider than the view starts at its left edge.
    let at = text_top_left(&view, [300.0, 200.0], (0.5, 0.5), [900.0, 14.0]);
    assert!(at[0] >= 100.0 && at[0] < 110.0, "{at:?}");
}

fn zone_box(n: u8, x: (f64, f64), y: (f64, f64)) -> ZoneBox {
    ZoneBox::from_corners(
        n,
        [Some(x.0), Some(y.0), Some(0.0), None],
        [Some(x.1), Some(y.1), Some(150.0), None],
    )
}

fn texts(scene: &Scene, role: Role) -> Vec<String> {
    scene
        .with_role(role)
        .filter_map(|s| match s {
            Shape::Text { text, .. } => Some(text.clone()),
            _ => None,
        })
        .collect()
}

#[test]
fn zones_are_boxes_with_their_z_range_and_the_one_a_path_enters_is_red_with_its_mark() {
    let k = kin();
    let zones = [
        zone_box(1, (330.0, 420.0), (180.0, 320.0)),
        zone_box(2, (-200.0, -80.0), (250.0, 400.0)),
        // Not defined (all zeros): never drawn.
        ZoneBox::from_corners(3, [Some(0.0); 4], [Some(0.0); 4]),
    ];
    let input = SceneInput {
        zones: &zones,
        ..SceneInput::pose(&k, Some(Joints::new(0.0, 90.0, 0.0, 0.0)))
    };
    let scene = build_scene(&input);
    let mut labels = texts(&scene, Role::Zone);
    labels.sort();
    assert_eq!(labels, ["zone 1 Z 0..150", "zone 2 Z 0..150"]);
    let outlines = scene
        .with_role(Role::Zone)
        .filter(|s| matches!(s, Shape::Polyline { closed: true, points } if points.len() == 4))
        .count();
    assert_eq!(outlines, 2);

    // A ghost whose path enters zone 1: that zone turns red, the path and its first
    // point in the zone are drawn.
    let mut ghost = Ghost::at(
        "X+ 100 mm",
        Pose::new(350.0, 250.0, 0.0, 90.0),
        Some(Joints::new(10.0, 80.0, 0.0, 0.0)),
        GhostCheck::Zone("enters zone 1: press twice".into()),
    );
    ghost.path = (0..=100)
        .map(|i| Mm::new(250.0 + f64::from(i), 250.0))
        .collect();
    ghost.mark = Some((Mm::new(330.0, 250.0), "enters zone 1".into()));
    ghost.zones = vec![1];
    let scene = build_scene(&SceneInput {
        ghost: Some(&ghost),
        ..input
    });
    assert_eq!(texts(&scene, Role::ZoneEntered), ["zone 1 Z 0..150"]);
    assert_eq!(texts(&scene, Role::Zone).len(), 1, "zone 2 stays as it is");
    assert!(
        scene
            .with_role(Role::CpLine)
            .any(|s| matches!(s, Shape::Polyline { points, .. } if points.len() == 101))
    );
    let refused = texts(&scene, Role::GhostRefused);
    assert!(
        refused.contains(&"enters zone 1 here".to_owned()),
        "{refused:?}"
    );
    assert!(
        refused.contains(&"enters zone 1: press twice".to_owned()),
        "{refused:?}"
    );
}

#[test]
fn taught_positions_are_numbered_dots_and_the_selected_one_stands_out() {
    let k = kin();
    let markers = [
        Marker {
            at: Mm::new(350.0, 0.0),
            label: "1".into(),
            selected: false,
        },
        Marker {
            at: Mm::new(250.0, -200.0),
            label: "T2".into(),
            selected: true,
        },
    ];
    let scene = build_scene(&SceneInput {
        markers: &markers,
        ..SceneInput::pose(&k, Some(Joints::new(0.0, 90.0, 0.0, 0.0)))
    });
    assert_eq!(texts(&scene, Role::Marker), ["1"]);
    assert_eq!(texts(&scene, Role::MarkerSelected), ["T2"]);
    let dot = |role| {
        scene
            .with_role(role)
            .find_map(|s| match s {
                Shape::Dot { centre, radius_px } => Some((*centre, *radius_px)),
                _ => None,
            })
            .unwrap()
    };
    assert_eq!(dot(Role::Marker).0, Mm::new(350.0, 0.0));
    assert!(dot(Role::MarkerSelected).1 > dot(Role::Marker).1);
    // The plain markers' numbers are the first labels to go when room is short.
    assert!(labels::rank(Role::Marker) > labels::rank(Role::Zone));
}
