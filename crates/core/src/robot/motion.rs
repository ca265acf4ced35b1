//! Moves with Delta RMC semantics: PTP in joint space, arm policies, status, stop, "relative to".
//!
//! A move is planned once (all checks and the profile precomputed) and then sampled at
//! any time `t` (seconds since the move started); nothing here reads a clock. PTP moves
//! interpolate the joints with one shared profile, so all axes start, accelerate, cruise,
//! decelerate and stop together; the profile's limits are the tightest of the axes'
//! (each axis' max speed/accel × the command's %, divided by its share of the travel),
//! so the slowest axis sets the duration and no axis exceeds its own limits.

use std::ops::Add;

use thiserror::Error;

use super::cp::CpMove;
use super::kinematics::{Arm, ArmSystem, IkError, Scara};
use super::model::{G_MM_S2, InPositionBand, RobotModel};
use super::profile::{Phase, ProfileError, Trapezoid};
use super::units::{Joints, Pose};

/// Why a move was refused before it started. Display text is for the operator.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum MoveError {
    #[error("{0}")]
    Unreachable(IkError),
    #[error(
        "not reachable with the current {arm} arm ({reason}); the {other} arm could, but this move may not switch arms",
        other = .arm.other()
    )]
    ArmSwitchNotAllowed { arm: Arm, reason: IkError },
    #[error("not reachable with the {arm} arm: {reason}")]
    NotReachableWithArm { arm: Arm, reason: IkError },
    #[error(
        "the straight line is refused {distance_mm:.3} mm along it (check point {index}, X {x:.3} Y {y:.3} Z {z:.3} R {r:.3}): {reason}",
        x = .position.x, y = .position.y, z = .position.z, r = .position.r
    )]
    CpLine {
        /// Check point number from 0 (the start).
        index: usize,
        /// Distance of the tool tip along the line from the start, mm.
        distance_mm: f64,
        /// The tool tip pose there, base frame.
        position: Pose,
        reason: IkError,
    },
    #[error(
        "the straight line would swing the arm around the base {distance_mm:.3} mm along it (check point {index})"
    )]
    CpAroundBase {
        index: usize,
        distance_mm: f64,
        position: Pose,
    },
    #[error("{0}")]
    Profile(#[from] ProfileError),
}

/// PTP target arm (on the wire: 2D4H-2D6H operation type bits 3-4, converted in
/// `crate::robot_wire`). The printed spec is ambiguous for the right/left policies; this
/// follows PROTOCOL.md section 5 erratum 5 `[inferred]`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ArmPolicy {
    /// 0: keep the current arm; refuse if it cannot reach.
    CurrentNoSwitch,
    /// 1: keep the current arm; switch to the other if only that one reaches.
    CurrentMaySwitch,
    /// 2: the right arm.
    Right,
    /// 3: the left arm.
    Left,
}

/// The joints for a PTP move's flange target (base frame) under an arm policy. J1 is
/// chosen nearest the current joints; J4 puts the flange at exactly the target's R
/// ([`Scara::inverse_exact_r`]): a move turns R the way and distance it names, or is
/// refused at the R joint's limits, never wrapped by 360°. With the current arm undetermined (J2 inside
/// the singular band), policies 0 and 1 take whichever arm reaches with the smaller J1+J2
/// travel `[inferred: the spec does not say]`.
pub fn solve_arm_policy(
    k: &Scara,
    flange_target: &Pose,
    current: &Joints,
    policy: ArmPolicy,
) -> Result<Joints, MoveError> {
    let fixed = |arm: Arm| {
        k.inverse_exact_r(flange_target, arm, current)
            .map_err(|reason| MoveError::NotReachableWithArm { arm, reason })
    };
    let arm = match (policy, k.arm_system(current)) {
        (ArmPolicy::Right, _) => return fixed(Arm::Right),
        (ArmPolicy::Left, _) => return fixed(Arm::Left),
        (_, ArmSystem::Right) => Arm::Right,
        (_, ArmSystem::Left) => Arm::Left,
        (_, ArmSystem::Undetermined) => {
            let travel = |j: &Joints| (j.j1 - current.j1).abs() + (j.j2 - current.j2).abs();
            return match (
                k.inverse_exact_r(flange_target, Arm::Right, current),
                k.inverse_exact_r(flange_target, Arm::Left, current),
            ) {
                (Ok(r), Ok(l)) => Ok(if travel(&l) < travel(&r) { l } else { r }),
                (Ok(j), Err(_)) | (Err(_), Ok(j)) => Ok(j),
                (Err(e), Err(_)) => Err(MoveError::Unreachable(e)),
            };
        }
    };
    match k.inverse_exact_r(flange_target, arm, current) {
        Ok(j) => Ok(j),
        Err(reason) => match k.inverse_exact_r(flange_target, arm.other(), current) {
            Ok(j) if policy == ArmPolicy::CurrentMaySwitch => Ok(j),
            Ok(_) => Err(MoveError::ArmSwitchNotAllowed { arm, reason }),
            Err(_) => Err(MoveError::Unreachable(reason)),
        },
    }
}

/// PTP speed and accelerations as % of each joint's maximum.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PtpParams {
    pub speed_pct: f64,
    pub accel_pct: f64,
    pub decel_pct: f64,
}

fn check_positive(what: &'static str, value: f64) -> Result<(), ProfileError> {
    if value > 0.0 && value.is_finite() {
        Ok(())
    } else {
        Err(ProfileError::NotPositive { what, value })
    }
}

impl PtpParams {
    /// All three positive and finite.
    pub fn check(&self) -> Result<(), ProfileError> {
        check_positive("the speed %", self.speed_pct)?;
        check_positive("the acceleration %", self.accel_pct)?;
        check_positive("the deceleration %", self.decel_pct)
    }

    /// From a move command's fields (2D4H/2D5H/2D6H PTP, 236H each-axis; PROTOCOL.md
    /// 3.10, 3.19-3.21): 0 means the model's default ("parameter value"); above 100 % is
    /// clamped to 100 `[inferred]`.
    pub fn from_command(model: &RobotModel, accel: u16, decel: u16, speed: u16) -> Self {
        let d = &model.defaults;
        let pct = |v: u16, default: f64| {
            if v == 0 {
                default
            } else {
                f64::from(v).min(100.0)
            }
        };
        PtpParams {
            speed_pct: pct(speed, d.ptp_speed_pct),
            accel_pct: pct(accel, d.ptp_accel_pct),
            decel_pct: pct(decel, d.ptp_accel_pct),
        }
    }
}

/// CP (straight line) speed in mm/s and accelerations in mm/s^2, of the tool tip.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CpParams {
    pub speed_mm_s: f64,
    pub accel_mm_s2: f64,
    pub decel_mm_s2: f64,
}

impl CpParams {
    /// All three positive and finite.
    pub fn check(&self) -> Result<(), ProfileError> {
        check_positive("the CP speed", self.speed_mm_s)?;
        check_positive("the CP acceleration", self.accel_mm_s2)?;
        check_positive("the CP deceleration", self.decel_mm_s2)
    }

    /// From a move command's fields (PROTOCOL.md 3.19-3.21): speed mm/s, accelerations in
    /// 0.01 G (98.0665 mm/s^2 each); 0 means the model's default; values above the model's
    /// CP maxima are clamped to them (the spec's "safety limit may apply"; clamping rather
    /// than refusing is `[inferred]`).
    pub fn from_command(model: &RobotModel, accel_cg: u16, decel_cg: u16, speed_mm_s: u16) -> Self {
        let d = &model.defaults;
        let or = |v: u16, default: f64| if v == 0 { default } else { f64::from(v) };
        let acc = |cg: u16| (or(cg, d.cp_accel_cg) * G_MM_S2 / 100.0).min(model.cp_max_accel_mm_s2);
        CpParams {
            speed_mm_s: or(speed_mm_s, d.cp_speed_mm_s).min(model.cp_max_speed_mm_s),
            accel_mm_s2: acc(accel_cg),
            decel_mm_s2: acc(decel_cg),
        }
    }
}

/// One instant of a move.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MoveSample {
    /// The target position: where the generator is now.
    pub joints: Joints,
    pub phase: Phase,
    /// Fraction of the path done, 0..=1 (of the planned path, also after a stop).
    pub progress: f64,
}

/// A planned PTP move in joint space.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PtpMove {
    start: Joints,
    delta: Joints,
    /// Command position: the planned target, or the stop point after a stop.
    end: Joints,
    profile: Trapezoid,
}

impl PtpMove {
    /// A joint-space move from `start` to `target`; the target must be within the limits.
    pub fn joints(
        k: &Scara,
        start: Joints,
        target: Joints,
        params: &PtpParams,
    ) -> Result<Self, MoveError> {
        params.check()?;
        k.check_joints(&target).map_err(MoveError::Unreachable)?;
        if !start.is_finite() {
            return Err(MoveError::Unreachable(IkError::NotFinite));
        }
        let delta = target - start;
        let specs = [k.j1, k.j2, k.z, k.r];
        let (mut v, mut a, mut d) = (f64::INFINITY, f64::INFINITY, f64::INFINITY);
        for (spec, dq) in specs.iter().zip(delta.to_array()) {
            let dq = dq.abs();
            if dq > 0.0 {
                v = v.min(spec.max_speed * params.speed_pct / 100.0 / dq);
                a = a.min(spec.max_accel * params.accel_pct / 100.0 / dq);
                d = d.min(spec.max_accel * params.decel_pct / 100.0 / dq);
            }
        }
        let profile = if v.is_infinite() {
            // No travel: a move that is already done.
            Trapezoid::new(0.0, 1.0, 1.0, 1.0)?
        } else {
            Trapezoid::new(1.0, v, a, d)?
        };
        Ok(PtpMove {
            start,
            delta,
            end: target,
            profile,
        })
    }

    /// A move to a flange pose (base frame), its joints chosen by the arm policy.
    pub fn to_pose(
        k: &Scara,
        start: Joints,
        flange_target: &Pose,
        policy: ArmPolicy,
        params: &PtpParams,
    ) -> Result<Self, MoveError> {
        let target = solve_arm_policy(k, flange_target, &start, policy)?;
        Self::joints(k, start, target, params)
    }

    /// The joints at time `t`: arithmetic only, for the simulator's fast loop.
    #[inline]
    pub fn joints_at(&self, t: f64) -> Joints {
        let s = self.profile.sample(t);
        if s.phase == Phase::Complete {
            return self.end;
        }
        self.at_progress(s.s)
    }

    #[inline]
    fn at_progress(&self, u: f64) -> Joints {
        let (a, d) = (&self.start, &self.delta);
        Joints::new(
            a.j1 + d.j1 * u,
            a.j2 + d.j2 * u,
            a.z + d.z * u,
            a.j4 + d.j4 * u,
        )
    }

    pub fn sample(&self, t: f64) -> MoveSample {
        let s = self.profile.sample(t);
        MoveSample {
            joints: if s.phase == Phase::Complete {
                self.end
            } else {
                self.at_progress(s.s)
            },
            phase: s.phase,
            progress: s.s,
        }
    }

    /// Stops the move at time `t` with its own deceleration (238H).
    pub fn stop(&mut self, t: f64) {
        self.profile = self.profile.stopped_at(t);
        if self.profile.is_stopped() {
            self.end = self.at_progress(self.profile.distance());
        }
    }

    pub fn start(&self) -> Joints {
        self.start
    }
    /// The command position: the planned target, or the stop point after a stop.
    pub fn end(&self) -> Joints {
        self.end
    }
    /// The shared profile, over the fraction of the path (0..=1).
    pub fn profile(&self) -> &Trapezoid {
        &self.profile
    }
}

/// A planned move of either kind.
#[derive(Debug, Clone, PartialEq)]
pub enum Move {
    Ptp(PtpMove),
    /// Boxed: a CP move carries its robot's geometry and limits.
    Cp(Box<CpMove>),
}

impl From<PtpMove> for Move {
    fn from(m: PtpMove) -> Self {
        Move::Ptp(m)
    }
}

impl From<CpMove> for Move {
    fn from(m: CpMove) -> Self {
        Move::Cp(Box::new(m))
    }
}

/// The status bits a controller reports for a move (Delta RMC style).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct MotionStatus {
    /// The actual position is within the positioning band of the command position.
    pub in_position: bool,
    /// The target generator has reached the end of the (possibly stopped) profile.
    pub generator_done: bool,
    pub phase: Phase,
    /// The move was stopped (238H) before it ended: not completed normally.
    pub cancelled: bool,
}

impl Move {
    pub fn sample(&self, t: f64) -> MoveSample {
        match self {
            Move::Ptp(m) => m.sample(t),
            Move::Cp(m) => m.sample(t),
        }
    }
    /// The joints at time `t`.
    pub fn joints_at(&self, t: f64) -> Joints {
        match self {
            Move::Ptp(m) => m.joints_at(t),
            Move::Cp(m) => m.joints_at(t),
        }
    }
    /// Stops the move at time `t` with its own deceleration (238H): it ends short and is
    /// marked cancelled. No effect once the move has ended.
    pub fn stop(&mut self, t: f64) {
        match self {
            Move::Ptp(m) => m.stop(t),
            Move::Cp(m) => m.stop(t),
        }
    }
    pub fn profile(&self) -> &Trapezoid {
        match self {
            Move::Ptp(m) => m.profile(),
            Move::Cp(m) => m.profile(),
        }
    }
    pub fn duration(&self) -> f64 {
        self.profile().duration()
    }
    pub fn start(&self) -> Joints {
        match self {
            Move::Ptp(m) => m.start(),
            Move::Cp(m) => m.start(),
        }
    }
    /// The command position: where the move ends (the stop point after a stop).
    pub fn end(&self) -> Joints {
        match self {
            Move::Ptp(m) => m.end(),
            Move::Cp(m) => m.end(),
        }
    }
    pub fn is_cancelled(&self) -> bool {
        self.profile().is_stopped()
    }
    /// The status at time `t`, with the actual (measured or simulated) joints.
    pub fn status(&self, t: f64, actual: &Joints, band: &InPositionBand) -> MotionStatus {
        let s = self.profile().sample(t);
        MotionStatus {
            in_position: in_position(actual, &self.end(), band),
            generator_done: s.phase == Phase::Complete,
            phase: s.phase,
            cancelled: self.is_cancelled(),
        }
    }
}

/// Every axis of `actual` within the positioning band of `command`.
pub fn in_position(actual: &Joints, command: &Joints, band: &InPositionBand) -> bool {
    (actual.j1 - command.j1).abs() <= band.deg
        && (actual.j2 - command.j2).abs() <= band.deg
        && (actual.z - command.z).abs() <= band.mm
        && (actual.j4 - command.j4).abs() <= band.deg
}

/// Which position a relative step is added to (Delta RMC Move Relative; DESIGN.md).
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Hash, Default, serde::Serialize, serde::Deserialize,
)]
pub enum RelativeTo {
    /// Where the last move ends: chained steps never drift.
    #[default]
    Command,
    /// The polled position: steps follow the real arm.
    Actual,
    /// Where the generator is now.
    Target,
}

impl RelativeTo {
    pub const ALL: [RelativeTo; 3] = [RelativeTo::Command, RelativeTo::Actual, RelativeTo::Target];

    /// "command", "actual", "target".
    pub fn name(self) -> &'static str {
        match self {
            RelativeTo::Command => "command",
            RelativeTo::Actual => "actual",
            RelativeTo::Target => "target",
        }
    }
}

/// The three positions a controller tracks, in any one representation (joints, poses).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Positions<T> {
    pub command: T,
    pub actual: T,
    pub target: T,
}

/// A relative step's `(start, final target)`: the target is `delta` added to the chosen
/// position; the move starts where the generator is now (the target position), so the
/// commanded path stays continuous whichever reference is chosen.
pub fn relative_move<T: Copy + Add<Output = T>>(
    relative_to: RelativeTo,
    at: &Positions<T>,
    delta: T,
) -> (T, T) {
    let base = match relative_to {
        RelativeTo::Command => at.command,
        RelativeTo::Actual => at.actual,
        RelativeTo::Target => at.target,
    };
    (at.target, base + delta)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn command_fields_resolve_defaults_and_clamp() {
        let m = RobotModel::default_model();
        let p = PtpParams::from_command(&m, 0, 50, 250);
        assert_eq!((p.speed_pct, p.accel_pct, p.decel_pct), (100.0, 30.0, 50.0));
        let c = CpParams::from_command(&m, 30, 0, 60_000);
        assert_eq!(c.speed_mm_s, m.cp_max_speed_mm_s);
        assert!((c.accel_mm_s2 - 30.0 * 98.0665).abs() < 1e-9);
        assert_eq!(c.accel_mm_s2, c.decel_mm_s2);
    }
}
