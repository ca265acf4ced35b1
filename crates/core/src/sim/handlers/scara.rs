//! SCARA moves: 2D4H absolute, 2D5H relative (work frame), 2D6H position number, and the
//! SCARA side of 236H jog/inching (base, work, tool or each-axis system), planned and
//! checked by the robot layer's motion generator.

use super::axis::{AT_LIMIT, LINEAR, SCARA};
use crate::protocol::{Milli, ScaraMotion, ScaraMove, ScaraPositionMove};
use crate::robot::{
    ArmPolicy, CpMove, CpParams, DEFAULT_CHECK_SPACING_MM, IkError, JogFrame, Joints, MoveError,
    Pose, PtpMove, PtpParams, jog_delta_to_work,
};
use crate::robot_wire;
use crate::sim::controller::Controller;
use crate::sim::errors::SimError;
use crate::sim::motion::{MotionKind, Plan};

/// Longest straight line a continuous Cartesian jog plans ahead (mm or deg).
const JOG_REACH: f64 = 2000.0;

/// Maps a kinematics refusal to the table: joint limit = C74, anything else unreachable.
fn ik_error(e: IkError) -> SimError {
    match e {
        IkError::JointLimit { .. } => SimError::SoftLimit,
        _ => SimError::Unreachable,
    }
}

/// Maps a refused move to the table: the arm policy forbids the switch = B09, a joint
/// limit = C74, anything else out of reach (B08) or, for bad rates, A03.
fn move_error(e: MoveError) -> SimError {
    match e {
        MoveError::Unreachable(e)
        | MoveError::NotReachableWithArm { reason: e, .. }
        | MoveError::CpLine { reason: e, .. } => ik_error(e),
        MoveError::ArmSwitchNotAllowed { .. } => SimError::ArmSystem,
        MoveError::CpAroundBase { .. } => SimError::Unreachable,
        MoveError::Profile(_) => SimError::BadValue,
    }
}

/// A SCARA move's arm policy (PTP) or none (CP), and its rates (speed, accel, decel): CP
/// in mm/s and 0.01 G, PTP in % (PROTOCOL.md 3.20).
fn op_type(m: &ScaraMotion) -> (Option<ArmPolicy>, [u16; 3]) {
    let rates = match *m {
        ScaraMotion::Cp { acc, dec, speed } => [speed.0, acc.0, dec.0],
        ScaraMotion::Ptp {
            acc, dec, speed, ..
        } => [speed.0, acc.0, dec.0],
    };
    (robot_wire::arm_policy(m), rates)
}

impl Controller {
    /// Starts a PTP move of the joints to `target` at `speed`/`accel`/`decel` % of each
    /// joint's maxima (0 = the model's defaults). Like every SCARA motion it owns axes 1-4:
    /// the arm's motion writes all four joints, and completion is read on all of them.
    fn start_ptp(
        &mut self,
        target: Joints,
        [speed, accel, decel]: [u16; 3],
        kind: MotionKind,
    ) -> Result<(), SimError> {
        let params = PtpParams::from_command(&self.model, accel, decel, speed);
        let m = PtpMove::joints(&self.kin, self.joints(), target, &params).map_err(move_error)?;
        self.start_motion(kind, SCARA, Plan::Arm(m.into()), false);
        Ok(())
    }

    /// Starts a CP move of the tool tip to `to` (base frame) on the current arm, at
    /// `speed` mm/s and `accel`/`decel` 0.01 G (0 = the model's defaults), checked along
    /// the whole line; `to_limit` cuts the line at the edge of the workspace instead.
    fn start_cp(
        &mut self,
        to: Pose,
        [speed, accel, decel]: [u16; 3],
        kind: MotionKind,
        to_limit: bool,
    ) -> Result<(), SimError> {
        let params = CpParams::from_command(&self.model, accel, decel, speed);
        let plan = if to_limit {
            CpMove::plan_to_limit
        } else {
            CpMove::plan
        };
        let (k, tool) = (&self.kin, &self.tool());
        let m = plan(
            k,
            self.joints(),
            &to,
            tool,
            &params,
            DEFAULT_CHECK_SPACING_MM,
        )
        .map_err(move_error)?;
        self.start_motion(kind, SCARA, Plan::Arm(m.into()), true);
        Ok(())
    }

    /// 2D4H absolute (layout as 2D5H `[inferred, PROTOCOL.md 3.19]`) and 2D5H relative
    /// (PROTOCOL.md 3.20) SCARA moves in the selected work frame.
    pub(crate) fn msg_scara_move(&mut self, m: &ScaraMove, relative: bool) -> Result<(), SimError> {
        let pattern = m.targets.pattern().0;
        self.check_pattern(pattern)?;
        let mut values = [0i32; 8];
        for (axis, v) in m.targets.iter() {
            values[axis.index()] = v.0;
        }
        let (policy, rates) = op_type(&m.motion);
        self.scara_or_linear_move(pattern, &values, relative, policy, rates)
    }

    /// Runs a 2D4H/2D5H/2D6H move once decoded: `values` are wire units per axis; a PTP
    /// move has an arm policy, a CP move none.
    pub(crate) fn scara_or_linear_move(
        &mut self,
        pattern: u8,
        values: &[i32; 8],
        relative: bool,
        policy: Option<ArmPolicy>,
        [speed, accel, decel]: [u16; 3],
    ) -> Result<(), SimError> {
        if pattern & SCARA != 0 && pattern & LINEAR != 0 {
            return Err(SimError::BadAxis);
        }
        let value = |current: f64, i: usize| {
            let v = Milli(values[i]).units();
            if relative { current + v } else { v }
        };
        if pattern & SCARA == 0 {
            // Linear axes alone: an each-axis move in mm, mm/s, 0.01 G.
            self.check_ready_to_move(pattern)?;
            let mut to = self.values;
            for (i, slot) in to.iter_mut().enumerate() {
                if pattern & (1 << i) != 0 {
                    *slot = value(*slot, i);
                }
            }
            let rates = self.linear_rates(speed, accel, decel);
            return self.linear_move(pattern, to, rates, MotionKind::Move);
        }
        self.check_ready_to_move(SCARA)?;
        let current = self.tip_work();
        let mut target = [current.x, current.y, current.z, current.r];
        for (i, slot) in target.iter_mut().enumerate() {
            if pattern & (1 << i) != 0 {
                *slot = value(*slot, i);
            }
        }
        let [x, y, z, r] = target;
        let tip = self.work().work_to_base(&Pose::new(x, y, z, r));
        let rates = [speed, accel, decel];
        match policy {
            None => self.start_cp(tip, rates, MotionKind::Move, false),
            Some(policy) => {
                let flange = self.tool().tip_to_flange(&tip);
                let params = PtpParams::from_command(&self.model, accel, decel, speed);
                let m = PtpMove::to_pose(&self.kin, self.joints(), &flange, policy, &params)
                    .map_err(move_error)?;
                self.start_motion(MotionKind::Move, SCARA, Plan::Arm(m.into()), false);
                Ok(())
            }
        }
    }

    /// 2D6H move to a position number (PROTOCOL.md 3.21; 4-digit number `[inferred]`).
    pub(crate) fn msg_scara_position(&mut self, m: &ScaraPositionMove) -> Result<(), SimError> {
        let (pattern, number) = (m.axes.0, m.position);
        self.check_pattern(pattern)?;
        let (policy, [speed, accel, decel]) = op_type(&m.motion);
        self.check_position_number(number)?;
        let (pattern, values, record) = self.position_target(pattern, number)?;
        let pick = |cmd: u16, rec: u16| if cmd != 0 { cmd } else { rec };
        let rates = [
            pick(speed, record.speed.0),
            pick(accel, record.accel.0),
            pick(decel, record.decel.0),
        ];
        self.scara_or_linear_move(pattern, &values, false, policy, rates)
    }

    /// The SCARA side of 236H: one axis of the base/work/tool `frame` (X, Y, Z, R) or, with
    /// no frame, one joint (each-axis system, speeds in % `[inferred, PROTOCOL.md 5 erratum 12]`).
    /// `inching` is the distance of one inching step; `None` jogs until 238H or the edge of
    /// the workspace (a joint: its limit).
    pub(crate) fn scara_jog(
        &mut self,
        pattern: u8,
        rates: [u16; 3],
        inching: Option<u32>,
        positive: bool,
        frame: Option<JogFrame>,
    ) -> Result<(), SimError> {
        // Each-axis jogs and inching need no homing; Cartesian ones do (B02).
        if frame.is_some() {
            self.check_ready_to_move(SCARA)?;
        } else {
            self.check_ready_to_jog_joint(SCARA)?;
        }
        // "Only while no servo axis is operating" (PROTOCOL.md 3.10): the linear axes too.
        if self.in_use() & LINEAR != 0 {
            return Err(SimError::AxisBusy);
        }
        let i = pattern.trailing_zeros() as usize;
        let sign = if positive { 1.0 } else { -1.0 };
        let continuous = inching.is_none();
        let step = sign * f64::from(inching.unwrap_or(0)) / 1000.0;
        let kind = if continuous {
            MotionKind::Jog
        } else {
            MotionKind::Move
        };
        let Some(frame) = frame else {
            let (lo, hi) = self.axis_range(i);
            let mut j = self.joints().to_array();
            j[i] = match inching {
                None if positive => hi,
                None => lo,
                Some(_) => j[i] + step,
            };
            if !(lo..=hi).contains(&j[i])
                || (continuous && (j[i] - self.values[i]).abs() < AT_LIMIT)
            {
                return Err(SimError::SoftLimit);
            }
            return self.start_ptp(Joints::from_array(j), rates, kind);
        };
        let mut unit = [0.0; 4];
        unit[i] = sign;
        let [x, y, z, r] = unit;
        let flange_r = self.kin.forward(&self.joints()).r;
        let (work, tool) = (self.work(), self.tool());
        let dir = jog_delta_to_work(&Pose::new(x, y, z, r), frame, &work, &tool, flange_r);
        let reach = if continuous { JOG_REACH } else { step.abs() };
        let start = self.tip_work();
        let target = work.work_to_base(&Pose::new(
            start.x + dir.x * reach,
            start.y + dir.y * reach,
            start.z + dir.z * reach,
            start.r + dir.r * reach,
        ));
        self.start_cp(target, rates, kind, continuous)
    }
}
