//! Coordinate frames: exact round trips to the wire unit, and jog deltas into the work frame.

use proptest::prelude::*;
use xsel_pendant::robot::{
    Arm, CoordSystem, JogFrame, Joints, Pose, RobotModel, Scara, inverse_in_work,
    jog_delta_to_work, jog_delta_to_work_wire, snap_to_wire, tip_in_work,
};

fn wire() -> impl Strategy<Value = [i32; 4]> {
    [
        -2_000_000i32..2_000_000,
        -2_000_000i32..2_000_000,
        -500_000i32..500_000,
        -720_000i32..720_000,
    ]
}

fn config() -> ProptestConfig {
    ProptestConfig {
        cases: 3000,
        failure_persistence: None,
        ..ProptestConfig::default()
    }
}

proptest! {
    #![proptest_config(config())]

    #[test]
    fn base_work_base_is_exact_to_the_wire_unit(p in wire(), w in wire()) {
        let work = CoordSystem::from_wire(w);
        let base = Pose::from_wire(p);
        prop_assert_eq!(work.work_to_base(&work.base_to_work(&base)).to_wire(), p);
        prop_assert_eq!(work.base_to_work(&work.work_to_base(&base)).to_wire(), p);
    }

    /// Rounding the work coordinates in between (a 2D4H target) costs at most 1 unit.
    #[test]
    fn rounding_in_between_costs_at_most_one_unit(p in wire(), w in wire()) {
        let work = CoordSystem::from_wire(w);
        let on_wire = snap_to_wire(&work.base_to_work(&Pose::from_wire(p)));
        let back = work.work_to_base(&on_wire).to_wire();
        for (a, b) in back.iter().zip(p) {
            prop_assert!((a - b).abs() <= 1, "{back:?} vs {p:?}");
        }
    }

    #[test]
    fn flange_tip_flange_is_exact_to_the_wire_unit(p in wire(), t in wire()) {
        let tool = CoordSystem::from_wire(t);
        let flange = Pose::from_wire(p);
        prop_assert_eq!(tool.tip_to_flange(&tool.flange_to_tip(&flange)).to_wire(), p);
    }

    #[test]
    fn tip_in_work_and_back(f1 in -120.0f64..120.0, f2 in 10.0f64..140.0, z in 0.0f64..200.0,
                            j4 in -300.0f64..300.0, w in wire(), t in wire()) {
        let k = Scara::new(&RobotModel::default_model());
        let work = CoordSystem::from_wire(w);
        // Small tools, so the flange stays in reach.
        let tool = CoordSystem::from_wire([t[0] / 100, t[1] / 100, 0, t[3]]);
        let j = Joints::new(f1, f2, z, j4);
        let tip = tip_in_work(&k, &j, &work, &tool);
        let back = inverse_in_work(&k, &tip, &work, &tool, Arm::Right, &j).unwrap();
        prop_assert!((back.j1 - j.j1).abs() < 1e-6 && (back.j2 - j.j2).abs() < 1e-6);
        prop_assert!((back.z - j.z).abs() < 1e-6 && (back.j4 - j.j4).abs() < 1e-6);
    }
}

#[test]
fn tool_frame_jog_matches_a_hand_computation() {
    // Work frame turned 30°, tool frame turned 15° on a flange at Cartesian R 45° (base).
    // The tool's X axis points along 45 + 15 = 60° in base, i.e. 60 - 30 = 30° in the
    // work frame. A step of +10 mm along tool X is therefore, in the work frame,
    //   X = 10 cos 30° = 8.660254 mm -> 8660 µm
    //   Y = 10 sin 30° = 5.000000 mm -> 5000 µm
    // and a step of +4 mm along tool Y (direction 120° in the work frame) is
    //   X = 4 cos 120° = -2.000000 mm -> -2000 µm
    //   Y = 4 sin 120° =  3.464102 mm ->  3464 µm
    // Z (+1.5 mm) and R (+2°) pass through unchanged.
    let work = CoordSystem::from_wire([100_000, 20_000, 0, 30_000]);
    let tool = CoordSystem::from_wire([0, 0, 35_000, 15_000]);
    let got = jog_delta_to_work_wire(
        [10_000, 0, 1_500, 2_000],
        JogFrame::Tool,
        &work,
        &tool,
        45.0,
    );
    assert_eq!(got, [8_660, 5_000, 1_500, 2_000]);
    let got = jog_delta_to_work_wire([0, 4_000, 0, 0], JogFrame::Tool, &work, &tool, 45.0);
    assert_eq!(got, [-2_000, 3_464, 0, 0]);
}

#[test]
fn base_frame_jog_turns_by_minus_the_work_rotation() {
    // Work frame turned 90°: base +X is work -Y.
    let work = CoordSystem::from_wire([0, 0, 0, 90_000]);
    let tool = CoordSystem::ZERO;
    let got = jog_delta_to_work_wire([5_000, 0, 0, 0], JogFrame::Base, &work, &tool, 12.0);
    assert_eq!(got, [0, -5_000, 0, 0]);
    // A work-frame step passes through untouched.
    let d = Pose::new(1.0, 2.0, 3.0, 4.0);
    assert_eq!(jog_delta_to_work(&d, JogFrame::Work, &work, &tool, 12.0), d);
}

#[test]
fn a_converted_step_moves_the_tip_as_asked() {
    // Apply a tool-frame step through the work frame and check, in base coordinates, that
    // the tip moved along the tool's X axis.
    let k = Scara::new(&RobotModel::default_model());
    let work = CoordSystem::from_wire([50_000, -30_000, 5_000, -20_000]);
    let tool = CoordSystem::from_wire([40_000, 10_000, 30_000, 25_000]);
    let j = Joints::new(10.0, 70.0, 50.0, 30.0);
    let flange = k.forward(&j);
    let step = jog_delta_to_work(
        &Pose::new(3.0, 0.0, 0.0, 0.0),
        JogFrame::Tool,
        &work,
        &tool,
        flange.r,
    );
    let tip_work = tip_in_work(&k, &j, &work, &tool);
    let moved_base = work.work_to_base(&(tip_work + step));
    let tip_base = tool.flange_to_tip(&flange);
    let dir = (flange.r + 25.0).to_radians();
    assert!((moved_base.x - tip_base.x - 3.0 * dir.cos()).abs() < 1e-9);
    assert!((moved_base.y - tip_base.y - 3.0 * dir.sin()).abs() < 1e-9);
}
