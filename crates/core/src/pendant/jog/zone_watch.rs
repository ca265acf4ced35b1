//! Continuous jogs and the interference zones: a held 236H has no end to check, so the
//! way it may still travel before a STOP takes hold is checked from where the arm is,
//! at the press and on every frame it runs, and a zone ahead stops it.

use super::hold::JogTarget;
use super::plan::{ArmNow, Interpolation, JogMode, JogSettings, PlannedStep, plan_step};
use crate::robot::{CpParams, PtpParams, RelativeTo, RobotModel, Scara};

/// How long a held jog runs on, at its speed, before the pendant can have seen it and
/// its STOP taken hold, in seconds. `[inferred]` The status cycle polls the position
/// every 100 ms; its reply, a frame of the window and STOP's own line time come on top,
/// and a late poll doubles it: 0.25 s. The controller's deceleration is added apart
/// (the jog's own, as the controller's STOP deceleration is a parameter a host cannot
/// read).
pub const SEEN_LATE_S: f64 = 0.25;

/// The shortest look ahead, mm or deg: a jog at a crawl still sees a zone at its edge.
const MIN_AHEAD: f64 = 1.0;

/// How far a continuous jog of `target` with the speeds on the line (`sent`, within the
/// cap) may still go before it stands: its travel while it is seen late and its
/// braking, in the axis's unit (mm for X Y Z and Z, deg for R and the joints).
pub fn stopping_reach(model: &RobotModel, sent: &JogSettings, target: JogTarget) -> f64 {
    let (speed, decel) = if target.axis.is_joint() {
        let p = PtpParams::from_command(
            model,
            sent.ptp_accel_pct,
            sent.ptp_decel_pct,
            sent.ptp_speed_pct,
        );
        let spec = [model.j1, model.j2, model.z, model.r][target.axis.index()];
        (
            spec.max_speed * p.speed_pct / 100.0,
            spec.max_accel * p.decel_pct / 100.0,
        )
    } else {
        // [inferred] The Cartesian jog's speed and deceleration in mm/s and 0.01 G apply
        // to R in deg/s and deg/s^2 alike (PROTOCOL.md 3.10 names one unit).
        let p = CpParams::from_command(
            model,
            sent.cp_accel_cg,
            sent.cp_decel_cg,
            sent.cp_speed_mm_s,
        );
        (p.speed_mm_s, p.decel_mm_s2)
    };
    let braking = if decel > 0.0 && decel.is_finite() {
        speed * speed / (2.0 * decel)
    } else {
        0.0
    };
    (speed * SEEN_LATE_S + braking).max(MIN_AHEAD)
}

/// The way a held jog of `target` may still go from `now`'s polled joints, planned as a
/// step of [`stopping_reach`] relative to the arm (CP on the frame's axis for X Y Z R,
/// the joint alone for joints) and checked as a step is. Where that step cannot be
/// planned (beyond reach or a joint's limit, where the controller ends the jog itself),
/// half and then a quarter of it; `None` when none can.
pub fn way_ahead(
    model: &RobotModel,
    kin: &Scara,
    sent: &JogSettings,
    target: JogTarget,
    now: &ArmNow,
) -> Option<PlannedStep> {
    let reach = stopping_reach(model, sent, target);
    [1.0, 0.5, 0.25].into_iter().find_map(|part| {
        let settings = JogSettings {
            mode: JogMode::Step,
            step: (reach * part).min(super::plan::MAX_STEP),
            interpolation: Interpolation::Cp,
            relative_to: RelativeTo::Actual,
            ..sent.clone()
        };
        plan_step(model, kin, &settings, target.axis, target.direction, now).ok()
    })
}

/// The zones that way enters which the tool is not inside already (a jog that starts in
/// a zone may move in it), in the order it enters them.
pub fn zones_entered(way: &PlannedStep, now: &ArmNow) -> Vec<u8> {
    let Some(start) = way.path.tips.first() else {
        return Vec::new();
    };
    way.path
        .zones
        .iter()
        .copied()
        .filter(|n| {
            !now.zones
                .iter()
                .any(|z| z.number == *n && z.contains(start))
        })
        .collect()
}

/// A second press armed for a continuous jog into zones: the same control, pressed
/// again within [`crate::pendant::CONFIRM_FOR`], may jog into them.
#[derive(Clone, Debug, PartialEq)]
pub struct ZonePass {
    pub target: JogTarget,
    pub zones: Vec<u8>,
    pub at: std::time::Instant,
}

impl ZonePass {
    /// Whether it lets a press of `target` at `now` enter `zones`.
    pub fn lets(&self, target: JogTarget, zones: &[u8], now: std::time::Instant) -> bool {
        self.target == target
            && now.saturating_duration_since(self.at) < crate::pendant::CONFIRM_FOR
            && zones.iter().all(|z| self.zones.contains(z))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pendant::Intent;
    use crate::pendant::jog::JogAxis;
    use crate::pendant::jog::hold::{JogInput, Press};
    use crate::pendant::sim_bench::{Bench, Fault};
    use crate::protocol::{Command, Direction};
    use crate::sim::SimSetup;

    #[test]
    fn the_reach_grows_with_the_speed_and_shrinks_with_the_deceleration() {
        let model = RobotModel::default_model();
        let x = JogTarget::new(JogAxis::X, Direction::Positive);
        let slow = JogSettings {
            cp_speed_mm_s: 50,
            cp_decel_cg: 30,
            ..JogSettings::default()
        };
        // 50 mm/s: 12.5 mm seen late, 50^2 / (2 * 0.3 G) = 0.42 mm braking.
        let r = stopping_reach(&model, &slow, x);
        let g = 9806.65;
        assert!((r - (12.5 + 2500.0 / (2.0 * 0.3 * g))).abs() < 1e-6, "{r}");
        let fast = JogSettings {
            cp_speed_mm_s: 250,
            ..slow.clone()
        };
        assert!(stopping_reach(&model, &fast, x) > 5.0 * r);
        let gentle = JogSettings {
            cp_decel_cg: 5,
            ..fast.clone()
        };
        assert!(stopping_reach(&model, &gentle, x) > stopping_reach(&model, &fast, x));
        // A joint: its own maximum speed at the % speed.
        let j1 = JogTarget::new(JogAxis::J1, Direction::Negative);
        let pct = JogSettings {
            ptp_speed_pct: 10,
            ..JogSettings::default()
        };
        let expect = model.j1.max_speed * 0.1 * SEEN_LATE_S;
        assert!(stopping_reach(&model, &pct, j1) > expect);
        assert!(stopping_reach(&model, &pct, j1) < expect * 1.5);
    }

    /// The bench's arm and pendant one frame on (20 ms): the simulator moves, the status
    /// polls answer, the jog input is reported, the frame's tick runs, and the requests
    /// go through the simulator.
    fn frame(b: &mut Bench, press: Press) {
        b.t += std::time::Duration::from_millis(20);
        let t = b.t;
        b.sim.advance(t);
        b.poll();
        b.apply(Intent::Jog(JogInput::Pointer, press));
        let now = b.now();
        b.p.tick(now);
        b.pump(|_| Fault::Pass);
    }

    fn tip(b: &Bench) -> crate::robot::Pose {
        Scara::new(&b.p.model).forward(&b.sim.joints())
    }

    fn said(b: &Bench) -> String {
        b.p.jog
            .feedback
            .as_ref()
            .map(|m| m.text.clone())
            .unwrap_or_default()
    }

    #[test]
    fn a_continuous_jog_toward_a_zone_stops_before_it_and_goes_in_on_a_second_press() {
        let mut b = Bench::new(SimSetup::default());
        b.apply(Intent::ReadZones);
        b.pump(|_| Fault::Pass);
        let zone = b.p.zones.boxes()[0];
        assert_eq!(zone.number, 1);
        let settings = JogSettings {
            mode: JogMode::Continuous,
            cp_speed_mm_s: 100,
            ..b.p.settings.jog.clone()
        };
        b.apply(Intent::JogSettings(settings));
        // Home: the tip at X 250, Y 250; zone 1 spans X 330-420 across it.
        let start = tip(&b);
        assert!((start.x - 250.0).abs() < 0.01 && !zone.contains(&start));
        let x = Press::On(JogTarget::new(JogAxis::X, Direction::Positive));

        // Held: it goes, and is stopped before the zone.
        frame(&mut b, x);
        assert!(b.p.held_jog().is_some(), "{}", said(&b));
        for _ in 0..500 {
            frame(&mut b, x);
            if b.p.held_jog().is_none() {
                break;
            }
        }
        assert!(
            b.p.stop_latch().is_some_and(|l| l.contains("zone 1 ahead")),
            "{:?}",
            b.p.stop_latch()
        );
        assert!(
            said(&b).starts_with("X+ stopped before zone 1 (the controller's zone")
                && said(&b).ends_with("press X+ again within 5 s to jog into it"),
            "{}",
            said(&b)
        );
        for _ in 0..50 {
            frame(&mut b, x);
        }
        let stood = tip(&b);
        assert!(b.sim.at_rest() && !zone.contains(&stood), "{stood:?}");
        assert!(stood.x > 300.0, "it went most of the way: {stood:?}");

        // Released and pressed again within the time: into the zone.
        frame(&mut b, Press::Up);
        frame(&mut b, x);
        assert!(b.p.held_jog().is_some(), "{}", said(&b));
        for _ in 0..100 {
            frame(&mut b, x);
            if zone.contains(&tip(&b)) {
                break;
            }
        }
        assert!(zone.contains(&tip(&b)), "{:?}", tip(&b));
        for _ in 0..5 {
            frame(&mut b, x);
        }
        assert!(
            b.p.held_jog().is_some(),
            "not stopped inside the zone it was let into"
        );
        frame(&mut b, Press::Up);
    }

    #[test]
    fn a_press_at_the_edge_of_a_zone_asks_first_and_a_stop_takes_the_question_back() {
        let mut b = Bench::new(SimSetup::default());
        b.apply(Intent::ReadZones);
        b.pump(|_| Fault::Pass);
        let settings = JogSettings {
            mode: JogMode::Continuous,
            step: 70.0,
            ..b.p.settings.jog.clone()
        };
        // A 70 mm step toward the zone (X 320: 10 mm short of it), then continuous.
        b.apply(Intent::JogSettings(JogSettings {
            mode: JogMode::Step,
            interpolation: Interpolation::Cp,
            ..settings.clone()
        }));
        frame(
            &mut b,
            Press::On(JogTarget::new(JogAxis::X, Direction::Positive)),
        );
        frame(&mut b, Press::Up);
        for _ in 0..200 {
            frame(&mut b, Press::Up);
        }
        assert!((tip(&b).x - 320.0).abs() < 0.01, "{:?}", tip(&b));
        b.apply(Intent::JogSettings(settings));
        let x = Press::On(JogTarget::new(JogAxis::X, Direction::Positive));
        let sent = b.sent.len();
        frame(&mut b, x);
        assert!(b.p.held_jog().is_none());
        assert!(
            !b.sent[sent..].iter().any(Command::is_continuous_jog),
            "nothing sent on the first press"
        );
        assert!(
            said(&b).starts_with("X+ would enter zone 1 within its stopping distance"),
            "{}",
            said(&b)
        );
        // Away from the zone it goes at once.
        frame(&mut b, Press::Up);
        let back = Press::On(JogTarget::new(JogAxis::X, Direction::Negative));
        frame(&mut b, back);
        assert!(b.p.held_jog().is_some(), "{}", said(&b));
        frame(&mut b, Press::Up);
        // STOP takes the question back: asked again, then the second press goes.
        frame(&mut b, x);
        assert!(b.p.held_jog().is_none());
        b.apply(Intent::Stop(crate::pendant::jog::hold::StopCause::Button));
        frame(&mut b, Press::Up);
        frame(&mut b, x);
        assert!(b.p.held_jog().is_none(), "asked again after STOP");
        frame(&mut b, Press::Up);
        frame(&mut b, x);
        assert!(b.p.held_jog().is_some(), "{}", said(&b));
    }
}
