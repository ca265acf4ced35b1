//! The reduced jog speed: a cap on the speed at the tool applied to every step, continuous
//! jog, taught-point Go and Go to target. Format B works only in AUTO mode, where the
//! controller applies no safety speed of its own (PROTOCOL.md), so the pendant does.

use super::plan::{Interpolation, JogMode, JogSettings, SpeedSource};
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

/// The speed field a jog of one kind carries on the line, under the cap: what the jog
/// panel's "sends" lines say, from the same settings the planners are given.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SentSpeed {
    /// The field and its unit.
    pub source: SpeedSource,
    /// The value set in the panel (0 = the controller's parameter value).
    pub asked: u16,
    /// The value on the line, and whether the cap lowered it.
    pub capped: Capped,
}

impl SentSpeed {
    /// The number in the command's speed field.
    pub fn field(&self) -> u16 {
        self.capped.sent
    }

    /// "3 % (20 % capped)", "50 mm/s", "0 (the controller's parameter, in mm/s)".
    pub fn text(&self) -> String {
        let unit = self.source.unit();
        let sent = match self.field() {
            0 => format!("0 (the controller's parameter, in {unit})"),
            n => format!("{n} {unit}"),
        };
        if !self.capped.lowered {
            return sent;
        }
        match self.asked {
            0 => format!("{sent} (the parameter's speed, capped)"),
            asked => format!("{sent} ({asked} {unit} capped)"),
        }
    }
}

/// The speed a jog of a joint (`joint`) or a Cartesian axis sends in `settings`' mode,
/// under `cap_mm_s`.
pub fn sent_speed(
    settings: &JogSettings,
    model: &RobotModel,
    cap_mm_s: f64,
    joint: bool,
) -> SentSpeed {
    let source = SpeedSource::of(settings, joint);
    let capped = match source {
        SpeedSource::Percent => ptp_speed(settings, model, cap_mm_s),
        SpeedSource::MmPerSec => cp_speed(settings, model, cap_mm_s),
    };
    SentSpeed {
        source,
        asked: settings.speed(source),
        capped,
    }
}

/// The jog panel's line for one kind of jog: what it is sent as, and its speed field
/// ("Cartesian jogs (236H) send 50 mm/s").
pub fn speed_line(
    settings: &JogSettings,
    model: &RobotModel,
    cap_mm_s: f64,
    joint: bool,
) -> String {
    let what = match (joint, settings.mode, settings.interpolation) {
        (true, JogMode::Step, _) => "Joint steps (236H)",
        (true, JogMode::Continuous, _) => "Joint jogs (236H)",
        (false, JogMode::Step, Interpolation::Ptp) => "X Y Z R steps (2D5H PTP)",
        (false, JogMode::Step, Interpolation::Cp) => "X Y Z R steps (2D5H CP)",
        (false, JogMode::Continuous, _) => "X Y Z R jogs (236H)",
    };
    let speed = sent_speed(settings, model, cap_mm_s, joint);
    format!("{what} send {}", speed.text())
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

    use crate::pendant::jog::plan::{
        ArmNow, Interpolation, JogAxis, JogMode, continuous_jog, plan_step,
    };
    use crate::protocol::{Command, Direction, ScMode, Station};
    use crate::robot::{CoordSystem, Joints, Scara};

    /// The speed field of a 2D5H or 236H frame (columns 17-20 of both), as a number.
    fn wire_speed(command: &Command) -> u16 {
        let bytes = command
            .to_bytes(Station::DEFAULT, ScMode::Computed)
            .expect("encodes");
        let frame = String::from_utf8(bytes).expect("ASCII");
        assert!(matches!(&frame[3..6], "2D5" | "236"), "{frame}");
        u16::from_str_radix(&frame[16..20], 16).expect("hex speed")
    }

    /// The command a press of `axis` X+ or J1+ sends under `settings` and `cap`, planned
    /// as the pendant plans it (capped settings, then the planner of the mode).
    fn planned(settings: &JogSettings, cap: f64, axis: JogAxis) -> Command {
        let model = RobotModel::default_model();
        let kin = Scara::new(&model);
        let sent = apply(settings, &model, cap);
        match settings.mode {
            JogMode::Continuous => continuous_jog(&sent, axis, Direction::Positive),
            JogMode::Step => {
                let now = ArmNow {
                    joints: Joints::new(30.0, 60.0, 50.0, 0.0),
                    command: None,
                    target: None,
                    work: CoordSystem::ZERO,
                    tool: CoordSystem::ZERO,
                    zones: &[],
                };
                plan_step(&model, &kin, &sent, axis, Direction::Positive, &now)
                    .expect("a 1 mm step from the middle of the reach")
                    .command
            }
        }
    }

    /// The panel's line's number: the first word that parses after "send".
    fn shown_number(line: &str) -> u16 {
        let (_, after) = line.split_once(" send ").expect("a send line");
        after
            .split_whitespace()
            .next()
            .and_then(|w| w.parse().ok())
            .unwrap_or_else(|| panic!("no number in {line:?}"))
    }

    #[test]
    fn the_speed_on_the_wire_is_the_number_the_panel_shows_in_every_mode() {
        let model = RobotModel::default_model();
        let modes = [
            (JogMode::Step, Interpolation::Ptp),
            (JogMode::Step, Interpolation::Cp),
            (JogMode::Continuous, Interpolation::Ptp),
            (JogMode::Continuous, Interpolation::Cp),
        ];
        // Slow, fast (capped) and parameter (0) speeds, under the reduced and a raised cap.
        let speeds = [(20, 50), (1, 400), (100, 10), (0, 0), (7, 2000)];
        for (mode, interpolation) in modes {
            for (pct, mm_s) in speeds {
                for cap in [REDUCED_SPEED_MM_S, 1500.0] {
                    let s = JogSettings {
                        mode,
                        interpolation,
                        ptp_speed_pct: pct,
                        cp_speed_mm_s: mm_s,
                        ..JogSettings::default()
                    };
                    for axis in [JogAxis::X, JogAxis::Z, JogAxis::R, JogAxis::J1, JogAxis::J3] {
                        let joint = axis.is_joint();
                        let line = speed_line(&s, &model, cap, joint);
                        let wire = wire_speed(&planned(&s, cap, axis));
                        let what = format!("{mode:?} {interpolation:?} {axis:?} cap {cap}");
                        assert_eq!(shown_number(&line), wire, "{what}: {line}");
                        let sent = sent_speed(&s, &model, cap, joint);
                        assert_eq!(sent.field(), wire, "{what}");
                        assert!(line.contains(sent.source.unit()), "{what}: {line}");
                    }
                }
            }
        }
    }

    #[test]
    fn a_continuous_cartesian_jog_in_ptp_sends_and_shows_the_mm_s_speed() {
        // The case: Motion PTP at 20 %, the CP field at 400 mm/s.
        let model = RobotModel::default_model();
        let s = JogSettings {
            mode: JogMode::Continuous,
            interpolation: Interpolation::Ptp,
            ptp_speed_pct: 20,
            cp_speed_mm_s: 400,
            ..JogSettings::default()
        };
        let line = speed_line(&s, &model, REDUCED_SPEED_MM_S, false);
        assert_eq!(line, "X Y Z R jogs (236H) send 250 mm/s (400 mm/s capped)");
        assert_eq!(
            wire_speed(&planned(&s, REDUCED_SPEED_MM_S, JogAxis::X)),
            250
        );
        let joints = speed_line(&s, &model, REDUCED_SPEED_MM_S, true);
        let pct = ptp_percent_cap(&model, REDUCED_SPEED_MM_S);
        assert_eq!(
            joints,
            format!("Joint jogs (236H) send {pct} % (20 % capped)")
        );
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
