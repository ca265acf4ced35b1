//! SCARA moves: 2D4H absolute, 2D5H relative (work frame), 2D6H position number, and the
//! SCARA side of 236H jog/inching (base, work, tool or each-axis system).

use super::axis::{LINEAR, SCARA};
use crate::protocol::{ScaraMotion, ScaraMove, ScaraPositionMove};
use crate::robot::{Arm, ArmSystem, G_MM_S2, IkError, JogFrame, Joints, Pose, jog_delta_to_work};
use crate::sim::controller::Controller;
use crate::sim::errors::SimError;
use crate::sim::motion::{MotionKind, Path};

/// Longest straight line a continuous Cartesian jog plans ahead (mm or deg).
const JOG_REACH: f64 = 2000.0;

/// Maps a kinematics refusal to the table: joint limit = C74, anything else unreachable.
fn ik_error(e: IkError) -> SimError {
    match e {
        IkError::JointLimit { .. } => SimError::SoftLimit,
        _ => SimError::Unreachable,
    }
}

/// A SCARA move's kind and rates: CP in mm/s and 0.01 G, PTP in % with an arm policy
/// (PROTOCOL.md 3.20).
struct OpType {
    cp: bool,
    policy: u8,
}

fn op_type(m: &ScaraMotion) -> (OpType, [u16; 3]) {
    match *m {
        ScaraMotion::Cp { acc, dec, speed } => (
            OpType {
                cp: true,
                policy: 0,
            },
            [speed.0, acc.0, dec.0],
        ),
        ScaraMotion::Ptp {
            acc,
            dec,
            speed,
            arm,
        } => (
            OpType {
                cp: false,
                policy: arm.code(),
            },
            [speed.0, acc.0, dec.0],
        ),
    }
}

impl Controller {
    /// The arm the SCARA is in now; on the singular line, the side J2 leans to.
    fn current_arm(&self) -> Arm {
        match self.kin.arm_system(&self.joints()) {
            ArmSystem::Right => Arm::Right,
            ArmSystem::Left => Arm::Left,
            ArmSystem::Undetermined if self.values[1] >= 0.0 => Arm::Right,
            ArmSystem::Undetermined => Arm::Left,
        }
    }

    /// Joints putting the selected tool's tip at `tip` (base frame) with `arm`.
    fn ik(&self, tip: &Pose, arm: Arm, near: &Joints) -> Result<Joints, IkError> {
        self.kin.inverse(&self.tool().tip_to_flange(tip), arm, near)
    }

    /// PTP target joints under an arm policy (PROTOCOL.md 5, erratum 5 `[inferred]`):
    /// 0 current arm only, 1 current arm then the other, 2 right, 3 left.
    fn ptp_target(&self, tip: &Pose, policy: u8) -> Result<Joints, SimError> {
        let near = self.joints();
        let current = self.current_arm();
        match policy {
            0 => self.ik(tip, current, &near).map_err(|e| {
                if self.ik(tip, current.other(), &near).is_ok() {
                    SimError::ArmSystem
                } else {
                    ik_error(e)
                }
            }),
            1 => self.ik(tip, current, &near).or_else(|e| {
                self.ik(tip, current.other(), &near)
                    .map_err(|_| ik_error(e))
            }),
            2 => self.ik(tip, Arm::Right, &near).map_err(ik_error),
            _ => self.ik(tip, Arm::Left, &near).map_err(ik_error),
        }
    }

    /// Starts a joint-synchronised PTP move to `target` at `speed`/`accel`/`decel` % of
    /// each joint's maxima (0 = the model's defaults).
    fn start_ptp(
        &mut self,
        target: Joints,
        axes: u8,
        speed: u16,
        accel: u16,
        decel: u16,
        kind: MotionKind,
    ) {
        let d = &self.model.defaults;
        let pct =
            |v: u16, def: f64| (if v == 0 { def } else { f64::from(v) }).clamp(1.0, 100.0) / 100.0;
        let (sp, ap, dp) = (
            pct(speed, d.ptp_speed_pct),
            pct(accel, d.ptp_accel_pct),
            pct(decel, d.ptp_accel_pct),
        );
        let from = self.values;
        let mut to = from;
        to[..4].copy_from_slice(&target.to_array());
        let specs = [self.model.j1, self.model.j2, self.model.z, self.model.r];
        let (mut v, mut a, mut dd) = (f64::INFINITY, f64::INFINITY, f64::INFINITY);
        for (i, s) in specs.iter().enumerate() {
            let dist = (to[i] - from[i]).abs();
            if axes & (1 << i) != 0 && dist > 1e-9 {
                v = v.min(s.max_speed * sp / dist);
                a = a.min(s.max_accel * ap / dist);
                dd = dd.min(s.max_accel * dp / dist);
            }
        }
        if !v.is_finite() {
            (v, a, dd) = (1e9, 1e9, 1e9);
        }
        self.start_motion(kind, axes, Path::Joint { from, to }, 1.0, v, a, dd, false);
    }

    /// Checks a straight tool-tip line (base frame) point by point, at most 1 mm (or 1 deg)
    /// apart, with `arm`; returns the joints at its end.
    fn check_line(&self, from: &Pose, to: &Pose, arm: Arm) -> Result<Joints, SimError> {
        let d = *to - *from;
        let len = (d.x * d.x + d.y * d.y + d.z * d.z).sqrt().max(d.r.abs());
        let steps = (len.ceil() as usize).clamp(16, 8192);
        let mut near = self.joints();
        for k in 1..=steps {
            let p = from.lerp(to, k as f64 / steps as f64);
            near = self.ik(&p, arm, &near).map_err(ik_error)?;
        }
        Ok(near)
    }

    /// Starts a CP move of the tool tip to `to` (base frame) on the current arm, at
    /// `speed` mm/s and `accel`/`decel` 0.01 G (0 = the model's defaults).
    fn start_cp(
        &mut self,
        to: Pose,
        speed: u16,
        accel: u16,
        decel: u16,
        kind: MotionKind,
    ) -> Result<(), SimError> {
        let from = self.tip_base();
        let arm = self.current_arm();
        self.check_line(&from, &to, arm)?;
        let m = &self.model;
        let v = (if speed == 0 {
            m.defaults.cp_speed_mm_s
        } else {
            f64::from(speed)
        })
        .min(m.cp_max_speed_mm_s);
        let g = |c: u16| {
            ((if c == 0 {
                m.defaults.cp_accel_cg
            } else {
                f64::from(c)
            }) / 100.0
                * G_MM_S2)
                .min(m.cp_max_accel_mm_s2)
        };
        let (a, d) = (g(accel), g(decel));
        let delta = to - from;
        let xyz = (delta.x * delta.x + delta.y * delta.y + delta.z * delta.z).sqrt();
        let length = if xyz > 1e-6 { xyz } else { delta.r.abs() };
        let tool = self.tool();
        self.start_motion(
            kind,
            SCARA,
            Path::Line {
                from,
                to,
                arm,
                tool,
            },
            length,
            v,
            a,
            d,
            true,
        );
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
        let (op, rates) = op_type(&m.motion);
        self.scara_or_linear_move(pattern, &values, relative, op, rates)
    }

    /// Runs a 2D4H/2D5H/2D6H move once decoded: `values` are wire units per axis.
    fn scara_or_linear_move(
        &mut self,
        pattern: u8,
        values: &[i32; 8],
        relative: bool,
        op: OpType,
        [speed, accel, decel]: [u16; 3],
    ) -> Result<(), SimError> {
        if pattern & SCARA != 0 && pattern & LINEAR != 0 {
            return Err(SimError::BadAxis);
        }
        if pattern & SCARA == 0 {
            // Linear axes alone: an each-axis move in mm, mm/s, 0.01 G.
            self.check_ready_to_move(pattern)?;
            let mut to = self.values;
            for (i, slot) in to.iter_mut().enumerate() {
                if pattern & (1 << i) != 0 {
                    let v = f64::from(values[i]) / 1000.0;
                    *slot = if relative { *slot + v } else { v };
                }
            }
            for i in 4..6 {
                if pattern & (1 << i) != 0 && !(0.0..=self.cfg.linear_stroke_mm).contains(&to[i]) {
                    return Err(SimError::SoftLimit);
                }
            }
            return self.linear_axes_move(pattern, to, speed, accel, decel);
        }
        self.check_ready_to_move(SCARA)?;
        let mut target = self.tip_work().to_wire().map(f64::from);
        let current = self.tip_work();
        let cur = [current.x, current.y, current.z, current.r];
        for i in 0..4 {
            target[i] = if pattern & (1 << i) == 0 {
                cur[i]
            } else if relative {
                cur[i] + f64::from(values[i]) / 1000.0
            } else {
                f64::from(values[i]) / 1000.0
            };
        }
        let tip = self
            .work()
            .work_to_base(&Pose::new(target[0], target[1], target[2], target[3]));
        if op.cp {
            self.start_cp(tip, speed, accel, decel, MotionKind::Move)
        } else {
            let joints = self.ptp_target(&tip, op.policy)?;
            self.start_ptp(joints, SCARA, speed, accel, decel, MotionKind::Move);
            Ok(())
        }
    }

    fn linear_axes_move(
        &mut self,
        pattern: u8,
        to: [f64; 8],
        speed: u16,
        accel: u16,
        decel: u16,
    ) -> Result<(), SimError> {
        let v = if speed == 0 { 100.0 } else { f64::from(speed) }.min(self.cfg.linear_max_speed);
        let g = |c: u16| if c == 0 { 30.0 } else { f64::from(c) } / 100.0 * G_MM_S2;
        let from = self.values;
        let length = (0..8)
            .filter(|i| pattern & (1 << i) != 0)
            .map(|i| (to[i] - from[i]).powi(2))
            .sum::<f64>()
            .sqrt();
        self.start_motion(
            MotionKind::Move,
            pattern,
            Path::Joint { from, to },
            length,
            v,
            g(accel),
            g(decel),
            true,
        );
        Ok(())
    }

    /// 2D6H move to a position number (PROTOCOL.md 3.21; 4-digit number `[inferred]`).
    pub(crate) fn msg_scara_position(&mut self, m: &ScaraPositionMove) -> Result<(), SimError> {
        let (pattern, number) = (m.axes.0, m.position);
        self.check_pattern(pattern)?;
        let (op, [speed, accel, decel]) = op_type(&m.motion);
        let record = *self.positions.get(&number).ok_or(SimError::NoPosition)?;
        let pattern = pattern & record.pattern();
        if pattern == 0 {
            return Err(SimError::NoPosition);
        }
        let mut values = [0i32; 8];
        for (i, v) in record.values.iter().enumerate() {
            values[i] = v.unwrap_or(0);
        }
        let pick = |cmd: u16, rec: u16| if cmd != 0 { cmd } else { rec };
        let rates = [
            pick(speed, record.speed),
            pick(accel, record.accel),
            pick(decel, record.decel),
        ];
        self.scara_or_linear_move(pattern, &values, false, op, rates)
    }

    /// The SCARA side of 236H: one axis of the base/work/tool frame (X, Y, Z, R) or one
    /// joint (each-axis system, speeds in % `[inferred, PROTOCOL.md 5 erratum 12]`).
    /// `distance` 0 = jog until 238H or the edge of the workspace.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn scara_jog(
        &mut self,
        pattern: u8,
        accel: u16,
        decel: u16,
        speed: u16,
        distance: i32,
        positive: bool,
        system: u8,
    ) -> Result<(), SimError> {
        self.check_ready_to_move(SCARA)?;
        let i = pattern.trailing_zeros() as usize;
        let sign = if positive { 1.0 } else { -1.0 };
        let kind = if distance == 0 {
            MotionKind::Jog
        } else {
            MotionKind::Move
        };
        if system == 3 {
            let (lo, hi) = self.axis_range(i);
            let mut j = self.joints().to_array();
            j[i] = if distance == 0 {
                if positive { hi } else { lo }
            } else {
                j[i] + sign * f64::from(distance) / 1000.0
            };
            if !(lo..=hi).contains(&j[i]) {
                return Err(SimError::SoftLimit);
            }
            if (j[i] - self.values[i]).abs() < 1e-9 && distance == 0 {
                return Err(SimError::SoftLimit);
            }
            self.start_ptp(Joints::from_array(j), 1 << i, speed, accel, decel, kind);
            return Ok(());
        }
        let frame = match system {
            0 => JogFrame::Base,
            1 => JogFrame::Work,
            _ => JogFrame::Tool,
        };
        let mut unit = [0.0; 4];
        unit[i] = sign;
        let flange_r = self.kin.forward(&self.joints()).r;
        let step_work = jog_delta_to_work(
            &Pose::new(unit[0], unit[1], unit[2], unit[3]),
            frame,
            &self.work(),
            &self.tool(),
            flange_r,
        );
        let work = self.work();
        let start = self.tip_work();
        let at = |k: f64| {
            work.work_to_base(&Pose::new(
                start.x + step_work.x * k,
                start.y + step_work.y * k,
                start.z + step_work.z * k,
                start.r + step_work.r * k,
            ))
        };
        let target = if distance == 0 {
            // Walk out in 1 mm (1 deg) steps while the line stays reachable.
            let arm = self.current_arm();
            let mut near = self.joints();
            let mut last = 0.0;
            let mut k = 1.0;
            while k <= JOG_REACH {
                match self.ik(&at(k), arm, &near) {
                    Ok(j) => {
                        near = j;
                        last = k;
                    }
                    Err(e) if last == 0.0 => return Err(ik_error(e)),
                    Err(_) => break,
                }
                k += 1.0;
            }
            at(last)
        } else {
            at(f64::from(distance) / 1000.0)
        };
        self.start_cp(target, speed, accel, decel, kind)
    }
}
