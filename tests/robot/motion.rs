//! Profiles, PTP moves, stop, status, arm policies and "relative to".

use proptest::prelude::*;
use xsel_pendant::robot::{
    Arm, ArmPolicy, Joints, Move, MoveError, Phase, Pose, Positions, PtpMove, PtpParams,
    RelativeTo, RobotModel, Scara, Trapezoid, relative_move, solve_arm_policy,
};

fn config() -> ProptestConfig {
    ProptestConfig {
        cases: 2000,
        failure_persistence: None,
        ..ProptestConfig::default()
    }
}

const ORDER: [Phase; 4] = [
    Phase::Accel,
    Phase::ConstantVelocity,
    Phase::Decel,
    Phase::Complete,
];

fn rank(p: Phase) -> usize {
    ORDER.iter().position(|q| *q == p).unwrap()
}

/// Samples `p` densely from before the start to after the end; checks the phase order,
/// the speed and acceleration bounds, continuity, and returns the phases seen in order.
fn walk(p: &Trapezoid, speed: f64, accel: f64, decel: f64) -> Vec<Phase> {
    let n = 4000;
    let dt = p.duration() / n as f64;
    let mut seen = vec![];
    let mut prev = p.sample(-1.0);
    assert_eq!((prev.s, prev.v), (0.0, 0.0));
    for i in 0..=n + 10 {
        let t = i as f64 * dt;
        let s = p.sample(t);
        if seen.last() != Some(&s.phase) {
            seen.push(s.phase);
        }
        assert!(
            rank(s.phase) >= rank(prev.phase),
            "phase went back at t={t}"
        );
        assert!(
            s.v <= speed * (1.0 + 1e-9) && s.v >= 0.0,
            "speed {} at t={t}",
            s.v
        );
        assert!(s.s >= prev.s - 1e-12, "went backwards at t={t}");
        if i > 0 && dt > 0.0 {
            let a = (s.v - prev.v) / dt;
            assert!(a <= accel * (1.0 + 1e-6) + 1e-9, "accel {a} at t={t}");
            assert!(a >= -decel * (1.0 + 1e-6) - 1e-9, "decel {a} at t={t}");
            // Distance is the integral of speed: the trapezoid rule is exact where v is
            // linear, off by at most (accel + decel) dt^2 / 2 across a phase boundary.
            let ds = 0.5 * (s.v + prev.v) * dt;
            let tol = 0.5 * (accel + decel) * dt * dt + 1e-9 * (1.0 + p.distance());
            assert!((s.s - prev.s - ds).abs() <= tol, "jump at t={t}");
        }
        prev = s;
    }
    assert_eq!(prev.phase, Phase::Complete);
    seen
}

proptest! {
    #![proptest_config(config())]

    #[test]
    fn profile_covers_exactly_its_distance_in_phase_order(
        distance in 0.001f64..1000.0, speed in 1.0f64..2000.0,
        accel in 10.0f64..20_000.0, decel in 10.0f64..20_000.0,
    ) {
        let p = Trapezoid::new(distance, speed, accel, decel).unwrap();
        let end = p.sample(p.duration());
        prop_assert_eq!(end.s, distance);
        prop_assert_eq!(end.phase, Phase::Complete);
        prop_assert_eq!(p.sample(p.duration() + 5.0).s, distance);
        let [t1, t2, t3] = p.phase_ends();
        // Each phase holds in the middle of its interval.
        prop_assert_eq!(p.sample(t1 / 2.0).phase, Phase::Accel);
        prop_assert_eq!(p.sample((t2 + t3) / 2.0).phase, Phase::Decel);
        let ramps = speed * speed / (2.0 * accel) + speed * speed / (2.0 * decel);
        if ramps < distance {
            prop_assert!(!p.is_triangular());
            prop_assert_eq!(p.sample((t1 + t2) / 2.0).phase, Phase::ConstantVelocity);
            prop_assert_eq!(p.peak_speed(), speed);
        } else {
            prop_assert!(p.is_triangular());
            prop_assert!(p.peak_speed() <= speed);
        }
        let seen = walk(&p, speed, accel, decel);
        if p.is_triangular() {
            prop_assert!(!seen.contains(&Phase::ConstantVelocity), "{seen:?}");
        }
        prop_assert_eq!(seen.first(), Some(&Phase::Accel));
    }

    #[test]
    fn stop_ends_short_within_the_decel_rate(
        distance in 1.0f64..1000.0, speed in 1.0f64..2000.0,
        accel in 10.0f64..20_000.0, decel in 10.0f64..20_000.0, at in 0.01f64..0.99,
    ) {
        let p = Trapezoid::new(distance, speed, accel, decel).unwrap();
        let [_, t2, t3] = p.phase_ends();
        let ts = at * t3;
        let q = p.stopped_at(ts);
        prop_assert!(q.is_stopped() && !p.is_stopped());
        // Identical up to the stop.
        let (a, b) = (p.sample(ts * 0.999), q.sample(ts * 0.999));
        prop_assert!((a.s - b.s).abs() < 1e-9 && (a.v - b.v).abs() < 1e-9);
        prop_assert!(q.distance() <= distance);
        if ts < t2 {
            prop_assert!(q.distance() < distance, "a stop before the deceleration ends short");
            prop_assert!(q.duration() < t3);
            // From the stop on: decelerating (never accelerating, never cruising).
            prop_assert_eq!(q.sample(ts + 1e-9 * t3).phase, Phase::Decel);
        }
        prop_assert_eq!(q.sample(q.duration()).s, q.distance());
        walk(&q, speed, accel, decel);
        // Stopping a stopped or finished profile changes nothing.
        prop_assert_eq!(q.stopped_at(ts * 0.5), q);
        prop_assert_eq!(p.stopped_at(t3 + 1.0), p);
    }
}

fn k() -> Scara {
    Scara::new(&RobotModel::default_model())
}

fn full() -> PtpParams {
    PtpParams {
        speed_pct: 100.0,
        accel_pct: 100.0,
        decel_pct: 100.0,
    }
}

#[test]
fn ptp_axes_are_synchronised_and_the_slowest_sets_the_duration() {
    let k = k();
    let start = Joints::new(-30.0, 60.0, 10.0, 0.0);
    let target = Joints::new(90.0, -45.0, 150.0, 200.0);
    let params = PtpParams {
        speed_pct: 50.0,
        accel_pct: 40.0,
        decel_pct: 80.0,
    };
    let m = PtpMove::joints(&k, start, target, &params).unwrap();
    assert_eq!(m.joints_at(m.profile().duration()), target);
    // Each axis alone, with its own limits.
    let specs = [k.j1, k.j2, k.z, k.r];
    let delta = (target - start).to_array();
    let mut slowest = 0.0f64;
    for (spec, d) in specs.iter().zip(delta) {
        let solo = Trapezoid::new(
            d,
            spec.max_speed * 0.5,
            spec.max_accel * 0.4,
            spec.max_accel * 0.8,
        )
        .unwrap();
        slowest = slowest.max(solo.duration());
    }
    assert!(m.profile().duration() >= slowest - 1e-9);
    // All axes at the same fraction of their travel, and within their own limits.
    let n = 2000;
    let dt = m.profile().duration() / n as f64;
    let mut prev = start;
    for i in 1..=n {
        let j = m.joints_at(i as f64 * dt);
        let f = (j - start).to_array();
        let u = f[0] / delta[0];
        for (fi, di) in f.iter().zip(delta) {
            assert!((fi / di - u).abs() < 1e-9);
        }
        for ((spec, a), b) in specs.iter().zip(j.to_array()).zip(prev.to_array()) {
            assert!((a - b).abs() / dt <= spec.max_speed * 0.5 * (1.0 + 1e-6));
        }
        prev = j;
    }
}

#[test]
fn a_single_axis_move_takes_exactly_its_own_profile() {
    let k = k();
    let start = Joints::new(0.0, 90.0, 0.0, 0.0);
    let target = Joints::new(0.0, 90.0, 120.0, 0.0);
    let m = PtpMove::joints(&k, start, target, &full()).unwrap();
    let solo = Trapezoid::new(120.0, k.z.max_speed, k.z.max_accel, k.z.max_accel).unwrap();
    assert!((m.profile().duration() - solo.duration()).abs() < 1e-12);
}

#[test]
fn ptp_refuses_targets_beyond_limits_and_bad_parameters() {
    let k = k();
    let start = Joints::new(0.0, 90.0, 0.0, 0.0);
    let err = PtpMove::joints(&k, start, Joints::new(0.0, 150.0, 0.0, 0.0), &full()).unwrap_err();
    assert_eq!(
        err.to_string(),
        "J2 would be at 150.000°, 5.000° beyond its limit of 145.000°"
    );
    let zero = PtpParams {
        speed_pct: 0.0,
        ..full()
    };
    assert!(matches!(
        PtpMove::joints(&k, start, Joints::new(1.0, 90.0, 0.0, 0.0), &zero),
        Err(MoveError::Profile(_))
    ));
    let nan = PtpParams {
        accel_pct: f64::NAN,
        ..full()
    };
    assert!(matches!(
        PtpMove::joints(&k, start, Joints::new(1.0, 90.0, 0.0, 0.0), &nan),
        Err(MoveError::Profile(_))
    ));
}

#[test]
fn stop_mid_move_ends_short_and_is_marked_cancelled() {
    let model = RobotModel::default_model();
    let k = Scara::new(&model);
    let start = Joints::new(-100.0, 90.0, 0.0, 0.0);
    let target = Joints::new(100.0, 90.0, 0.0, 0.0);
    let mut m = Move::Ptp(PtpMove::joints(&k, start, target, &full()).unwrap());
    let [t1, t2, _] = m.profile().phase_ends();
    let ts = (t1 + t2) / 2.0;
    let before = m.joints_at(ts);
    m.stop(ts);
    assert!(m.is_cancelled());
    let end = m.end();
    assert!(end.j1 < target.j1 - 1.0 && end.j1 > before.j1, "{end:?}");
    // Stop distance at J1's max accel from its cruise speed.
    let v = k.j1.max_speed;
    assert!((end.j1 - before.j1 - v * v / (2.0 * k.j1.max_accel)).abs() < 1e-6);
    let done = m.status(m.duration(), &end, &model.in_position);
    assert!(done.generator_done && done.cancelled && done.in_position);
    assert_eq!(done.phase, Phase::Complete);
    let mid = m.status(ts + 0.01, &before, &model.in_position);
    assert!(!mid.generator_done && !mid.in_position && mid.phase == Phase::Decel);
}

#[test]
fn status_follows_the_phases_and_the_positioning_band() {
    let model = RobotModel::default_model();
    let k = Scara::new(&model);
    let start = Joints::new(0.0, 90.0, 0.0, 0.0);
    let target = Joints::new(120.0, 90.0, 0.0, 0.0);
    let m = Move::Ptp(PtpMove::joints(&k, start, target, &full()).unwrap());
    let [t1, t2, t3] = m.profile().phase_ends();
    let band = &model.in_position;
    let phases: Vec<Phase> = [t1 / 2.0, (t1 + t2) / 2.0, (t2 + t3) / 2.0, t3]
        .iter()
        .map(|t| m.status(*t, &m.joints_at(*t), band).phase)
        .collect();
    assert_eq!(phases, ORDER);
    assert!(!m.status(t3, &m.joints_at(t3), band).cancelled);
    // In position: within 0.01° of the command position, not beyond.
    let near = Joints::new(120.0 - 0.009, 90.0, 0.0, 0.0);
    let off = Joints::new(120.0 - 0.011, 90.0, 0.0, 0.0);
    assert!(m.status(t3, &near, band).in_position);
    assert!(!m.status(t3, &off, band).in_position);
    assert!(m.status(t3, &off, band).generator_done);
}

#[test]
fn arm_policies() {
    let k = k();
    let current = Joints::new(0.0, 90.0, 0.0, 0.0); // right arm
    // Behind on the right (polar angle -150°, 300 mm): the right arm would need J1 ≈ -203°
    // (157°), beyond ±125°; the left arm reaches with J1 ≈ -96.9°.
    let a = (-150.0f64).to_radians();
    let p = Pose::new(300.0 * a.cos(), 300.0 * a.sin(), 0.0, 0.0);
    let err = solve_arm_policy(&k, &p, &current, ArmPolicy::CurrentNoSwitch).unwrap_err();
    assert!(matches!(
        err,
        MoveError::ArmSwitchNotAllowed {
            arm: Arm::Right,
            ..
        }
    ));
    assert!(err.to_string().contains("left arm could"), "{err}");
    let j = solve_arm_policy(&k, &p, &current, ArmPolicy::CurrentMaySwitch).unwrap();
    assert!(j.j2 < 0.0 && (j.j1 + 96.87).abs() < 0.01, "{j:?}");
    assert!(matches!(
        solve_arm_policy(&k, &p, &current, ArmPolicy::Right),
        Err(MoveError::NotReachableWithArm {
            arm: Arm::Right,
            ..
        })
    ));
    assert_eq!(solve_arm_policy(&k, &p, &current, ArmPolicy::Left), Ok(j));
    // Reachable by both: policy 0 keeps the current arm, 3 switches.
    let q = Pose::new(300.0, 100.0, 0.0, 0.0);
    assert!(
        solve_arm_policy(&k, &q, &current, ArmPolicy::CurrentNoSwitch)
            .unwrap()
            .j2
            > 0.0
    );
    assert!(
        solve_arm_policy(&k, &q, &current, ArmPolicy::Left)
            .unwrap()
            .j2
            < 0.0
    );
    // Unreachable by both: the current arm's reason.
    let far = Pose::new(700.0, 0.0, 0.0, 0.0);
    assert!(matches!(
        solve_arm_policy(&k, &far, &current, ArmPolicy::CurrentMaySwitch),
        Err(MoveError::Unreachable(_))
    ));
    // Undetermined current arm (J2 = 0.5°): the smaller travel wins, here the right arm.
    let straight = Joints::new(0.0, 0.5, 0.0, 0.0);
    let r = solve_arm_policy(
        &k,
        &Pose::new(400.0, 50.0, 0.0, 0.0),
        &straight,
        ArmPolicy::CurrentNoSwitch,
    );
    assert!(r.is_ok());
}

#[test]
fn relative_steps_chain_without_drift_relative_to_the_command_position() {
    // A 10.000 mm step, three times, while the real arm lags 0.004 mm behind.
    let lag: f64 = 0.004;
    let mut at = Positions {
        command: 0.0,
        actual: 0.0,
        target: 0.0,
    };
    for _ in 0..3 {
        let (start, target) = relative_move(RelativeTo::Command, &at, 10.0);
        assert_eq!(start, at.target);
        at = Positions {
            command: target,
            actual: target - lag,
            target,
        };
    }
    assert_eq!(at.command, 30.0);
    // Relative to the actual position, each step inherits the lag.
    let mut at = Positions {
        command: 0.0,
        actual: 0.0,
        target: 0.0,
    };
    for _ in 0..3 {
        let (_, target) = relative_move(RelativeTo::Actual, &at, 10.0);
        at = Positions {
            command: target,
            actual: target - lag,
            target,
        };
    }
    assert!((at.command - (30.0 - 2.0 * lag)).abs() < 1e-12);
    // Relative to the target position mid-move: from where the generator is now.
    let at = Positions {
        command: Joints::new(50.0, 0.0, 0.0, 0.0),
        actual: Joints::new(19.0, 0.0, 0.0, 0.0),
        target: Joints::new(20.0, 0.0, 0.0, 0.0),
    };
    let step = Joints::new(5.0, 0.0, 0.0, 0.0);
    assert_eq!(relative_move(RelativeTo::Target, &at, step).1.j1, 25.0);
    assert_eq!(relative_move(RelativeTo::Command, &at, step).1.j1, 55.0);
    assert_eq!(
        relative_move(RelativeTo::Actual, &at, step),
        (at.target, Joints::new(24.0, 0.0, 0.0, 0.0))
    );
}

/// A PTP target's R is the Cartesian R the flange ends at: a step of R +300 deg from
/// J4 = 0 plans J4 = +300 (not -60), and one beyond the R joint's limits is refused;
/// base- and tool-frame steps pass R through unchanged.
#[test]
fn ptp_targets_turn_r_the_way_and_distance_named() {
    use xsel_pendant::robot::{CoordSystem, JogFrame, jog_delta_to_work};
    let m = RobotModel::default_model();
    let k = Scara::new(&m);
    let start = Joints::new(0.0, 90.0, 0.0, 0.0);
    let here = k.forward(&start);
    for turn in [179.0, -179.0, 181.0, -181.0, 300.0, -300.0, 360.0] {
        let target = Pose::new(here.x, here.y, here.z, here.r + turn);
        let j = solve_arm_policy(&k, &target, &start, ArmPolicy::CurrentNoSwitch).unwrap();
        assert!((j.j4 - turn).abs() < 1e-9, "R {turn:+}: J4 {}", j.j4);
    }
    for turn in [361.0, 1000.0] {
        let target = Pose::new(here.x, here.y, here.z, here.r + turn);
        assert!(
            solve_arm_policy(&k, &target, &start, ArmPolicy::CurrentNoSwitch).is_err(),
            "R {turn:+} is beyond the limit"
        );
    }
    let work = CoordSystem::from_wire([10_000, 0, 0, 30_000]);
    let tool = CoordSystem::from_wire([0, 50_000, 0, 90_000]);
    for frame in [JogFrame::Base, JogFrame::Work, JogFrame::Tool] {
        let d = jog_delta_to_work(&Pose::new(0.0, 0.0, 0.0, 300.0), frame, &work, &tool, 45.0);
        assert_eq!(d.r, 300.0, "{frame:?}");
    }
}
