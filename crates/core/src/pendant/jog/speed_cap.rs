//! The reduced jog speed: a cap on the speed at the tool applied to every step, continuous
//! jog, taught-point Go and Go to target. Format B works only in AUTO mode, where the
//! controller applies no safety speed of its own (PROTOCOL.md), so the pendant does.

use super::plan::JogSettings;
use crate::robot::RobotModel;

/// The default cap, mm/s at the tool centre point: ISO 10218-1's reduced speed.
pub const REDUCED_SPEED_MM_S: f64 = 250.0;

/// The most a cap may be raised to, mm/s.
pub const MAX_CAP_MM_S: f64 = 2000.0;

/// The highest tool speed a PTP move or joint jog at 100 % can reach, mm/s: every joint
/// at its maximum speed at once, J1 swinging the whole reach, J2 the second link, Z added
/// square. [inferred] PTP % scales each joint's maximum speed (PROTOCOL.md 3.20 names the
/// field "speed ratio"); an upper bound, so a cap through it is never exceeded.
pub fn full_ptp_tool_speed(model: &RobotModel) -> f64 {
    let planar = model.j1.max_speed.to_radians() * (model.arm1_mm + model.arm2_mm)
        + model.j2.max_speed.to_radians() * model.arm2_mm;
    planar.hypot(model.z.max_speed)
}

/// The largest PTP % whose tool speed stays within `cap_mm_s` (at least 1 %).
pub fn ptp_percent_cap(model: &RobotModel, cap_mm_s: f64) -> u16 {
    let pct = (100.0 * cap_mm_s / full_ptp_tool_speed(model)).floor();
    pct.clamp(1.0, 100.0) as u16
}

/// What the cap does to one speed field: the value sent and whether it was lowered.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Capped {
    pub sent: u16,
    pub lowered: bool,
}

fn cap_field(asked: u16, parameter_value: f64, limit: u16) -> Capped {
    // 0 asks for the controller's parameter value: capped as that value.
    let effective = if asked == 0 {
        parameter_value
    } else {
        f64::from(asked)
    };
    if effective > f64::from(limit) {
        Capped {
            sent: limit,
            lowered: true,
        }
    } else {
        Capped {
            sent: asked,
            lowered: false,
        }
    }
}

/// The PTP (and joint) speed % sent under the cap.
pub fn ptp_speed(settings: &JogSettings, model: &RobotModel, cap_mm_s: f64) -> Capped {
    cap_field(
        settings.ptp_speed_pct,
        model.defaults.ptp_speed_pct,
        ptp_percent_cap(model, cap_mm_s),
    )
}

/// The CP (and Cartesian jog) speed in mm/s sent under the cap.
pub fn cp_speed(settings: &JogSettings, model: &RobotModel, cap_mm_s: f64) -> Capped {
    let limit = cap_mm_s.floor().clamp(1.0, f64::from(u16::MAX)) as u16;
    cap_field(settings.cp_speed_mm_s, model.defaults.cp_speed_mm_s, limit)
}

/// The settings as they go on the line: both speeds within the cap.
pub fn apply(settings: &JogSettings, model: &RobotModel, cap_mm_s: f64) -> JogSettings {
    JogSettings {
        ptp_speed_pct: ptp_speed(settings, model, cap_mm_s).sent,
        cp_speed_mm_s: cp_speed(settings, model, cap_mm_s).sent,
        ..settings.clone()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_default_cap_lowers_fast_speeds_and_keeps_slow_ones() {
        let model = RobotModel::default_model();
        let mut s = JogSettings {
            cp_speed_mm_s: 800,
            ptp_speed_pct: 50,
            ..JogSettings::default()
        };
        let sent = apply(&s, &model, REDUCED_SPEED_MM_S);
        assert_eq!(sent.cp_speed_mm_s, 250);
        let pct = ptp_percent_cap(&model, REDUCED_SPEED_MM_S);
        assert_eq!(sent.ptp_speed_pct, pct);
        // The % cap never lets the tool exceed the cap.
        assert!(full_ptp_tool_speed(&model) * f64::from(pct) / 100.0 <= REDUCED_SPEED_MM_S);
        s.cp_speed_mm_s = 40;
        s.ptp_speed_pct = 1;
        let sent = apply(&s, &model, REDUCED_SPEED_MM_S);
        assert_eq!((sent.cp_speed_mm_s, sent.ptp_speed_pct), (40, 1));
    }

    #[test]
    fn a_zero_asks_for_the_parameter_value_and_is_capped_as_that() {
        let model = RobotModel::default_model();
        let s = JogSettings {
            cp_speed_mm_s: 0,
            ptp_speed_pct: 0,
            ..JogSettings::default()
        };
        // The model's parameter CP speed is 250 mm/s: a cap of 100 lowers it.
        assert_eq!(
            cp_speed(&s, &model, 100.0),
            Capped {
                sent: 100,
                lowered: true
            }
        );
        assert_eq!(cp_speed(&s, &model, 300.0).sent, 0);
        assert!(ptp_speed(&s, &model, REDUCED_SPEED_MM_S).lowered);
    }
}
