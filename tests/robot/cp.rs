//! CP lines: followed exactly, and refused before they start at the first bad point.

use xsel_pendant::robot::{
    Arm, ArmSystem, CoordSystem, CpMove, CpParams, IkError, Joint, Joints, Move, MoveError, Phase,
    Pose, RobotModel, Scara,
};

const SPACING: f64 = 0.1;

fn setup() -> (RobotModel, Scara, CpParams) {
    let m = RobotModel::default_model();
    let k = Scara::new(&m);
    let p = CpParams {
        speed_mm_s: 200.0,
        accel_mm_s2: 0.3 * 9806.65,
        decel_mm_s2: 0.5 * 9806.65,
    };
    (m, k, p)
}

/// Right-arm joints putting the flange at (x, y, z) with R = r.
fn at(k: &Scara, x: f64, y: f64, z: f64, r: f64) -> Joints {
    k.inverse(&Pose::new(x, y, z, r), Arm::Right, &Joints::default())
        .unwrap()
}

/// Checks a refusal names the first offending point: its position is on the line at the
/// distance given, it fails with the reason given, and the check point before it passes.
fn assert_first_offender(
    err: &MoveError,
    start: &Pose,
    end: &Pose,
    k: &Scara,
    arm: Arm,
) -> IkError {
    let MoveError::CpLine {
        index,
        distance_mm,
        position,
        reason,
    } = err
    else {
        panic!("expected a CP line refusal, got {err:?}");
    };
    let d = *end - *start;
    let len = (d.x * d.x + d.y * d.y + d.z * d.z).sqrt();
    let u = distance_mm / len;
    let on_line = start.lerp(end, u);
    assert!((on_line.x - position.x).abs() < 1e-9 && (on_line.y - position.y).abs() < 1e-9);
    assert!(
        ((*index as f64) * SPACING - distance_mm).abs() < SPACING,
        "{index} {distance_mm}"
    );
    let near = Joints::new(0.0, 0.0, 0.0, 0.0);
    // The offending point fails IK with the same kind of reason; the one before passes.
    let here = k.inverse(position, arm, &near);
    assert!(here.is_err(), "{position:?} should fail");
    assert_eq!(
        std::mem::discriminant(&here.unwrap_err()),
        std::mem::discriminant(reason)
    );
    let before = start.lerp(end, (distance_mm - SPACING * 1.0001).max(0.0) / len);
    assert!(
        k.inverse(&before, arm, &near).is_ok(),
        "{before:?} should pass"
    );
    *reason
}

#[test]
fn a_good_line_is_followed_exactly() {
    let (_, k, p) = setup();
    let tool = CoordSystem::from_wire([30_000, 10_000, 25_000, 5_000]);
    let start = at(&k, 300.0, -100.0, 20.0, 10.0);
    let start_tip = tool.flange_to_tip(&k.forward(&start));
    let target = Pose::new(200.0, 250.0, 80.0, 70.0);
    let m = CpMove::plan(&k, start, &target, &tool, &p, SPACING).unwrap();
    assert_eq!(m.arm(), Arm::Right);
    let dur = m.profile().duration();
    let n = 3000;
    let mut prev_tip = start_tip;
    for i in 0..=n {
        let t = dur * i as f64 / n as f64;
        let s = m.sample(t);
        assert_eq!(k.arm_system(&s.joints), ArmSystem::Right);
        let tip = tool.flange_to_tip(&k.forward(&s.joints));
        // On the line, R in step with the position.
        let want = start_tip.lerp(&target, s.progress);
        for (a, b) in tip.to_wire().iter().zip(want.to_wire()) {
            assert!((a - b).abs() <= 1, "{tip:?} vs {want:?}");
        }
        // Tip speed within the CP speed.
        if i > 0 {
            let d = tip - prev_tip;
            let v = (d.x * d.x + d.y * d.y + d.z * d.z).sqrt() / (dur / n as f64);
            assert!(v <= p.speed_mm_s * 1.001, "{v} mm/s");
        }
        prev_tip = tip;
    }
    let end = tool.flange_to_tip(&k.forward(&m.joints_at(dur)));
    assert_eq!(end.to_wire(), target.to_wire());
    assert_eq!(m.sample(dur).phase, Phase::Complete);
}

#[test]
fn leaving_the_workspace_outward_is_refused_at_the_singular_rim() {
    let (_, k, p) = setup();
    let start = at(&k, 450.0, 0.0, 0.0, 0.0);
    let from = k.forward(&start);
    let target = Pose::new(520.0, 0.0, 0.0, 0.0);
    let err = CpMove::plan(&k, start, &target, &CoordSystem::ZERO, &p, SPACING).unwrap_err();
    // The band (|J2| < 2°) starts at 500 cos 1° = 499.924 mm: 49.92 mm along.
    let reason = assert_first_offender(&err, &from, &target, &k, Arm::Right);
    assert!(matches!(reason, IkError::Singular { .. }), "{reason:?}");
    let MoveError::CpLine { distance_mm, .. } = err else {
        unreachable!()
    };
    assert!((distance_mm - 49.924).abs() < 0.11, "{distance_mm}");
    // The band starts between check points 499 (49.9 mm, r = 499.9) and 500 (50.0 mm).
    assert!(
        err.to_string()
            .starts_with("the straight line is refused 50.000 mm along it (check point 500"),
        "{err}"
    );
}

#[test]
fn a_line_past_the_base_is_refused_too_near() {
    let (_, k, p) = setup();
    let start = at(&k, 300.0, 0.0, 0.0, 0.0);
    let from = k.forward(&start);
    let target = Pose::new(50.0, 0.0, 0.0, 0.0);
    let err = CpMove::plan(&k, start, &target, &CoordSystem::ZERO, &p, SPACING).unwrap_err();
    let reason = assert_first_offender(&err, &from, &target, &k, Arm::Right);
    match reason {
        IkError::TooNear { min_mm, .. } => assert!((min_mm - 150.35).abs() < 0.01),
        other => panic!("{other:?}"),
    }
}

#[test]
fn crossing_the_singular_band_is_refused() {
    // A straight line between two points inside the band's rim stays inside (distance from
    // the J1 axis is convex along a line), so the flange crosses the band only when the
    // tool swings it out: tip fixed at (470, 0), tool 50 mm behind the flange, R turning
    // from -90° to +90°. The flange runs on a 50 mm circle about the tip, out to 520 mm
    // at R = 0. Its distance is sqrt(470² + 50² + 2·470·50·cos R), which reaches the band
    // (500 cos 1° = 499.924 mm) where cos R = 0.5643, R = -55.64°.
    let (_, k, p) = setup();
    let tool = CoordSystem::from_wire([-50_000, 0, 0, 0]);
    let tip = Pose::new(470.0, 0.0, 0.0, -90.0);
    let start = k
        .inverse(&tool.tip_to_flange(&tip), Arm::Right, &Joints::default())
        .unwrap();
    let target = Pose::new(470.0, 0.0, 0.0, 90.0);
    let err = CpMove::plan(&k, start, &target, &tool, &p, SPACING).unwrap_err();
    let MoveError::CpLine {
        index,
        position,
        reason,
        ..
    } = err
    else {
        panic!("{err:?}");
    };
    assert!(matches!(reason, IkError::Singular { .. }), "{reason:?}");
    assert!((position.r + 55.64).abs() < 0.2, "{position:?}");
    assert!(index > 0);
    // The end point itself inside the band: refused as singular at the last point.
    let start = at(&k, 400.0, 0.0, 0.0, 0.0);
    let target = Pose::new(499.95, 0.0, 0.0, 0.0);
    match CpMove::plan(&k, start, &target, &CoordSystem::ZERO, &p, SPACING) {
        Err(MoveError::CpLine {
            index,
            reason: IkError::Singular { .. },
            ..
        }) => assert_eq!(index, 1000),
        other => panic!("{other:?}"),
    }
}

#[test]
fn a_joint_limit_on_the_way_is_refused() {
    let (_, k, p) = setup();
    // J1 along a line from the front-left to behind-left runs past +125°.
    let start = at(&k, 0.0, 300.0, 0.0, 0.0);
    let from = k.forward(&start);
    let target = Pose::new(-300.0, -50.0, 0.0, 0.0);
    let err = CpMove::plan(&k, start, &target, &CoordSystem::ZERO, &p, SPACING).unwrap_err();
    let reason = assert_first_offender(&err, &from, &target, &k, Arm::Right);
    match reason {
        IkError::JointLimit {
            joint: Joint::J1,
            limit,
            excess,
            ..
        } => assert!(limit == 125.0 && excess > 0.0 && excess < 1.0, "{excess}"),
        other => panic!("{other:?}"),
    }
    // Z leaving its stroke half-way.
    let start = at(&k, 300.0, 0.0, 100.0, 0.0);
    let target = Pose::new(300.0, 100.0, 300.0, 0.0);
    let err = CpMove::plan(&k, start, &target, &CoordSystem::ZERO, &p, SPACING).unwrap_err();
    match err {
        MoveError::CpLine {
            reason: IkError::JointLimit {
                joint: Joint::Z, ..
            },
            distance_mm,
            ..
        } => {
            // Z reaches 200 after 100/200 of the rise: half the 223.6 mm line.
            let half = (100.0f64 * 100.0 + 200.0 * 200.0).sqrt() / 2.0;
            assert!((distance_mm - half).abs() < SPACING, "{distance_mm}");
        }
        other => panic!("{other:?}"),
    }
    // R turned past the J4 limit (±360°).
    let start = at(&k, 300.0, 0.0, 0.0, 0.0);
    let target = Pose::new(300.0, 0.0, 0.0, 800.0);
    match CpMove::plan(&k, start, &target, &CoordSystem::ZERO, &p, SPACING) {
        Err(MoveError::CpLine {
            reason: IkError::JointLimit {
                joint: Joint::R, ..
            },
            ..
        }) => {}
        other => panic!("{other:?}"),
    }
}

#[test]
fn an_undetermined_start_is_refused_at_point_zero() {
    let (_, k, p) = setup();
    let start = Joints::new(0.0, 0.5, 0.0, 0.0);
    match CpMove::plan(
        &k,
        start,
        &Pose::new(400.0, 0.0, 0.0, 0.0),
        &CoordSystem::ZERO,
        &p,
        SPACING,
    ) {
        Err(MoveError::CpLine {
            index: 0,
            reason: IkError::Singular { .. },
            ..
        }) => {}
        other => panic!("{other:?}"),
    }
}

#[test]
fn cp_stop_ends_short_on_the_line() {
    let (m, k, p) = setup();
    let start = at(&k, 300.0, -150.0, 0.0, 0.0);
    let from = k.forward(&start);
    let target = Pose::new(300.0, 150.0, 0.0, 0.0);
    let mut mv =
        Move::from(CpMove::plan(&k, start, &target, &CoordSystem::ZERO, &p, SPACING).unwrap());
    let [t1, t2, _] = mv.profile().phase_ends();
    let ts = (t1 + t2) / 2.0;
    mv.stop(ts);
    let end = k.forward(&mv.end());
    assert!(end.y < 150.0 - 1.0 && end.y > from.y);
    assert!((end.x - 300.0).abs() < 1e-6);
    let st = mv.status(mv.duration(), &mv.end(), &m.in_position);
    assert!(st.cancelled && st.generator_done && st.in_position);
}

#[test]
fn bad_spacing_and_nan_targets_are_refused_not_panicked() {
    let (_, k, p) = setup();
    let start = at(&k, 300.0, 0.0, 0.0, 0.0);
    let t = Pose::new(310.0, 0.0, 0.0, 0.0);
    assert!(CpMove::plan(&k, start, &t, &CoordSystem::ZERO, &p, 0.0).is_err());
    assert!(CpMove::plan(&k, start, &t, &CoordSystem::ZERO, &p, f64::NAN).is_err());
    let bad = CpParams {
        speed_mm_s: f64::NAN,
        ..p
    };
    let turn_and_move = Pose::new(310.0, 0.0, 0.0, 30.0);
    assert!(CpMove::plan(&k, start, &turn_and_move, &CoordSystem::ZERO, &bad, SPACING).is_err());
    let nan = Pose::new(f64::NAN, 0.0, 0.0, 0.0);
    assert!(CpMove::plan(&k, start, &nan, &CoordSystem::ZERO, &p, SPACING).is_err());
    // Pure R turn without a tool: allowed, the tip stays put.
    let turn = Pose::new(300.0, 0.0, 0.0, 90.0);
    let m = CpMove::plan(&k, start, &turn, &CoordSystem::ZERO, &p, SPACING).unwrap();
    assert!((m.end().j4 - start.j4 - 90.0).abs() < 1e-9);
}
