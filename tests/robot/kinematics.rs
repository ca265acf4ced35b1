//! Kinematics: FK(IK(p)) = p over thousands of random poses, and every refusal's reason.

use proptest::prelude::*;
use xsel_pendant::robot::{Arm, ArmSystem, IkError, Joint, Joints, Pose, RobotModel, Scara};

fn models() -> Vec<Scara> {
    ["scara-500", "scara-250"]
        .iter()
        .map(|n| Scara::new(&RobotModel::builtin(n).unwrap()))
        .collect()
}

/// Difference of two angles folded into -180..180.
fn angle_diff(a: f64, b: f64) -> f64 {
    (a - b + 180.0).rem_euclid(360.0) - 180.0
}

fn assert_same_pose(a: &Pose, b: &Pose) {
    let d = ((a.x - b.x).powi(2) + (a.y - b.y).powi(2) + (a.z - b.z).powi(2)).sqrt();
    assert!(d < 1e-3, "{a:?} vs {b:?}: {d} mm apart");
    assert!(
        angle_diff(a.r, b.r).abs() < 1e-3,
        "{a:?} vs {b:?}: R differs"
    );
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 4000, failure_persistence: None, ..ProptestConfig::default() })]

    /// Joints drawn inside the limits (outside the singular band), both arm systems.
    #[test]
    fn fk_ik_round_trip(
        which in 0usize..2,
        f1 in 0.0f64..=1.0, f2 in 0.0f64..=1.0, fz in 0.0f64..=1.0, f4 in 0.0f64..=1.0,
        left in any::<bool>(),
        near_j4 in -360.0f64..360.0,
    ) {
        let k = models()[which];
        let lerp = |s: &xsel_pendant::robot::JointSpec, f: f64| s.min + (s.max - s.min) * f;
        let mag = k.band_deg + 1e-6 + (k.j2.max - k.band_deg - 2e-6) * f2;
        let j = Joints::new(lerp(&k.j1, f1), if left { -mag } else { mag }, lerp(&k.z, fz), lerp(&k.r, f4));
        let arm = if left { Arm::Left } else { Arm::Right };
        prop_assert_eq!(k.arm_system(&j), ArmSystem::from(arm));
        let p = k.forward(&j);
        // Nearest the original joints: the original comes back.
        let back = k.inverse(&p, arm, &j).unwrap();
        assert_same_pose(&k.forward(&back), &p);
        prop_assert!((back.j1 - j.j1).abs() < 1e-6 && (back.j2 - j.j2).abs() < 1e-6);
        prop_assert!((back.j4 - j.j4).abs() < 1e-6);
        // Nearest some other R angle: the same pose, J4 inside the limits.
        let other = k.inverse(&p, arm, &Joints::new(0.0, 0.0, 0.0, near_j4)).unwrap();
        assert_same_pose(&k.forward(&other), &p);
        prop_assert!(k.check_joints(&other).is_ok());
        // ... and no other 360° multiple inside the limits is nearer the asked-for angle.
        for alt in [other.j4 - 360.0, other.j4 + 360.0] {
            prop_assert!(!k.r.contains(alt) || (alt - near_j4).abs() >= (other.j4 - near_j4).abs() - 1e-9);
        }
    }

    /// Cartesian targets anywhere around the robot: either reached exactly, or refused
    /// with the reason the geometry predicts.
    #[test]
    fn ik_reaches_or_says_why(
        which in 0usize..2,
        x in -600.0f64..600.0, y in -600.0f64..600.0, z in -50.0f64..250.0, r in -400.0f64..400.0,
        left in any::<bool>(),
    ) {
        let k = models()[which];
        let arm = if left { Arm::Left } else { Arm::Right };
        let p = Pose::new(x, y, z, r);
        let d = x.hypot(y);
        let (inner, outer) = k.reach(arm);
        match k.inverse(&p, arm, &Joints::default()) {
            Ok(j) => {
                assert_same_pose(&k.forward(&j), &p);
                prop_assert!(k.check_joints(&j).is_ok());
                prop_assert_eq!(k.arm_system(&j), ArmSystem::from(arm));
            }
            Err(IkError::TooFar { distance_mm, .. }) => prop_assert!(d > outer && (distance_mm - d).abs() < 1e-9),
            Err(IkError::TooNear { distance_mm, .. }) => prop_assert!(d < inner && (distance_mm - d).abs() < 1e-9),
            Err(IkError::Singular { j2_deg, .. }) => prop_assert!(j2_deg.abs() < k.band_deg),
            Err(IkError::JointLimit { joint: Joint::Z, .. }) => prop_assert!(!k.z.contains(z)),
            Err(IkError::JointLimit { joint: Joint::J1, value, .. }) => prop_assert!(!k.j1.contains(value)),
            Err(e) => prop_assert!(false, "unexpected refusal {e}"),
        }
    }
}

#[test]
fn refusals_carry_the_right_reason() {
    let k = models()[0];
    let near = Joints::new(0.0, 90.0, 0.0, 0.0);
    match k.inverse(&Pose::new(600.0, 0.0, 0.0, 0.0), Arm::Right, &near) {
        Err(IkError::TooFar {
            distance_mm,
            max_mm,
        }) => assert_eq!((distance_mm, max_mm), (600.0, 500.0)),
        other => panic!("{other:?}"),
    }
    match k.inverse(&Pose::new(0.0, 20.0, 0.0, 0.0), Arm::Left, &near) {
        Err(IkError::TooNear {
            distance_mm,
            min_mm,
            arm: Arm::Left,
        }) => {
            assert_eq!(distance_mm, 20.0);
            // Arm 2 folded to the J2 limit of 145°: sqrt(2 * 250^2 * (1 + cos 145°)).
            assert!((min_mm - 150.35).abs() < 0.01, "{min_mm}");
        }
        other => panic!("{other:?}"),
    }
    assert!(matches!(
        k.inverse(&Pose::new(499.99, 0.0, 0.0, 0.0), Arm::Right, &near),
        Err(IkError::Singular { .. })
    ));
    // Behind the base: J1 would be near 180°, beyond its limit of 125°.
    match k.inverse(&Pose::new(-300.0, 0.0, 0.0, 0.0), Arm::Right, &near) {
        Err(IkError::JointLimit {
            joint: Joint::J1,
            limit,
            excess,
            ..
        }) => assert!(limit == 125.0 && excess > 0.0, "{limit} {excess}"),
        other => panic!("{other:?}"),
    }
    match k.inverse(&Pose::new(300.0, 0.0, 250.0, 0.0), Arm::Right, &near) {
        Err(
            e @ IkError::JointLimit {
                joint: Joint::Z, ..
            },
        ) => assert_eq!(
            e.to_string(),
            "Z would be at 250.000 mm, 50.000 mm beyond its limit of 200.000 mm"
        ),
        other => panic!("{other:?}"),
    }
    assert_eq!(
        k.inverse(&Pose::new(f64::NAN, 0.0, 0.0, 0.0), Arm::Right, &near),
        Err(IkError::NotFinite)
    );
}

#[test]
fn r_joint_beyond_a_narrow_limit_is_refused_by_the_least_excess() {
    let mut m = RobotModel::default_model();
    m.r.min = -100.0;
    m.r.max = 100.0;
    let k = Scara::new(&m);
    // (250, 250) with the right arm: J1 = 0, J2 = 90, so J4 = R - 90.
    let p = Pose::new(250.0, 250.0, 0.0, 90.0 + 200.0);
    match k.inverse(&p, Arm::Right, &Joints::default()) {
        Err(IkError::JointLimit {
            joint: Joint::R,
            value,
            limit,
            excess,
        }) => {
            // Candidates 200 (100 over) and -160 (60 under): the smaller miss is named.
            assert!(
                (value + 160.0).abs() < 1e-9 && limit == -100.0,
                "{value} {limit}"
            );
            assert!((excess - 60.0).abs() < 1e-9);
        }
        other => panic!("{other:?}"),
    }
}
