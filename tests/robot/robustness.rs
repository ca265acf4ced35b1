//! No panics on any input: NaN, infinities, huge values, arbitrary model text.

use proptest::num::f64::ANY;
use proptest::prelude::*;
use xsel_pendant::robot::{
    Arm, ArmPolicy, CoordSystem, CpMove, CpParams, JogFrame, Joints, Pose, PtpMove, PtpParams,
    RobotModel, Scara, Trapezoid, jog_delta_to_work_wire, solve_arm_policy,
};

fn config() -> ProptestConfig {
    ProptestConfig {
        cases: 2000,
        failure_persistence: None,
        ..ProptestConfig::default()
    }
}

proptest! {
    #![proptest_config(config())]

    #[test]
    fn profiles(d in ANY, v in ANY, a in ANY, b in ANY, t in ANY, ts in ANY) {
        if let Ok(p) = Trapezoid::new(d, v, a, b) {
            let _ = p.sample(t);
            let _ = p.stopped_at(ts).sample(t);
        }
    }

    #[test]
    fn kinematics_and_moves(x in ANY, y in ANY, z in ANY, r in ANY, j in [ANY, ANY, ANY, ANY],
                            s in [ANY, ANY, ANY], code in any::<u8>(), w in any::<[i32; 4]>(),
                            t in ANY) {
        let k = Scara::new(&RobotModel::default_model());
        let p = Pose::new(x, y, z, r);
        let j = Joints::from_array(j);
        let _ = k.inverse(&p, Arm::Left, &j);
        let policy = [
            ArmPolicy::CurrentNoSwitch,
            ArmPolicy::CurrentMaySwitch,
            ArmPolicy::Right,
            ArmPolicy::Left,
        ][usize::from(code % 4)];
        let _ = solve_arm_policy(&k, &p, &j, policy);
        let pp = PtpParams { speed_pct: s[0], accel_pct: s[1], decel_pct: s[2] };
        if let Ok(mut m) = PtpMove::joints(&k, j, k.inverse(&p, Arm::Right, &j).unwrap_or(j), &pp) {
            let _ = m.joints_at(t);
            m.stop(t);
        }
        let cp = CpParams { speed_mm_s: s[0], accel_mm_s2: s[1], decel_mm_s2: s[2] };
        let tool = CoordSystem::from_wire(w);
        if let Ok(mut m) = CpMove::plan(&k, j, &p, &tool, &cp, 1.0) {
            let _ = m.sample(t);
            m.stop(t);
        }
        let _ = jog_delta_to_work_wire(w, JogFrame::Tool, &tool, &tool, x);
    }

    #[test]
    fn model_text(text in ".{0,400}") {
        let _ = RobotModel::from_toml_str(&text);
    }
}

#[test]
fn cp_with_sane_params_from_anywhere() {
    // Valid parameters, start joints and targets all over the place.
    let k = Scara::new(&RobotModel::default_model());
    let cp = CpParams {
        speed_mm_s: 100.0,
        accel_mm_s2: 1000.0,
        decel_mm_s2: 1000.0,
    };
    for i in 0..200 {
        let f = i as f64;
        let j = Joints::new(f * 7.0 - 700.0, f * 3.0 - 300.0, f, f * 11.0);
        let p = Pose::new(f * 5.0 - 500.0, 300.0 - f * 3.0, f - 50.0, f * 9.0);
        if let Ok(m) = CpMove::plan(&k, j, &p, &CoordSystem::ZERO, &cp, 0.5) {
            let _ = m.sample(m.profile().duration() / 2.0);
        }
    }
}
