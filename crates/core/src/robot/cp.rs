//! CP moves: the tool tip on a straight Cartesian line, checked by IK along all of it first.
//!
//! The tip moves from its current pose to the target on a straight line in X, Y, Z, with
//! R interpolated linearly by the same fraction (the target R is taken as given, not
//! wrapped: a target 360° away turns a full turn). The arm system never changes (CP keeps
//! the current arm, PROTOCOL.md 3.20). Before the move is accepted, check points every
//! `spacing_mm` along the line (and at both ends) are solved; the first that is out of
//! reach, inside the singular band or beyond a joint limit refuses the whole move, naming
//! its index, its distance along the line and the tip pose there.
//!
//! J1 is followed continuously along the line: it is the start J1 plus the angle the
//! flange has swept about the J1 axis, minus the change of the elbow's share. So it
//! never jumps by 360°, and the same formula serves the checks and the sampling.

use super::frames::CoordSystem;
use super::kinematics::{Arm, ArmSystem, IkError, Joint, Scara, check};
use super::motion::{CpParams, MoveError, MoveSample};
use super::profile::{Phase, ProfileError, Trapezoid};
use super::units::{Joints, Pose};

/// Default distance between CP check points, mm.
pub const DEFAULT_CHECK_SPACING_MM: f64 = 0.1;

/// Most check points one line may take; longer lines get a wider spacing.
pub const MAX_CHECK_POINTS: usize = 2_000_000;

/// Check points for a path of `length` at `spacing`: at least 1, at most the maximum.
fn check_points(length: f64, spacing: f64) -> usize {
    (length / spacing)
        .ceil()
        .clamp(1.0, MAX_CHECK_POINTS as f64) as usize
}

/// A planned, fully checked CP move.
#[derive(Debug, Clone, PartialEq)]
pub struct CpMove {
    k: Scara,
    arm: Arm,
    /// Tool offset, mm and deg.
    tool: Pose,
    tool_turns: bool,
    start_tip: Pose,
    end_tip: Pose,
    start: Joints,
    /// Command position: the planned target, or the stop point after a stop.
    end: Joints,
    /// Flange XY at the start, for the swept angle.
    f0: (f64, f64),
    /// Elbow share of J1 at the start (deg).
    beta0: f64,
    length_mm: f64,
    profile: Trapezoid,
}

impl CpMove {
    /// Plans a straight line of the tool tip from where `start` puts it to `target_tip`
    /// (base frame), with tool `tool`, and checks it every `spacing_mm`.
    pub fn plan(
        k: &Scara,
        start: Joints,
        target_tip: &Pose,
        tool: &CoordSystem,
        params: &CpParams,
        spacing_mm: f64,
    ) -> Result<Self, MoveError> {
        params.check()?;
        let tool_off = tool.offset();
        let flange0 = k.forward(&start);
        let start_tip = tool.flange_to_tip(&flange0);
        let arm = match k.arm_system(&start) {
            ArmSystem::Right => Arm::Right,
            ArmSystem::Left => Arm::Left,
            ArmSystem::Undetermined => {
                return Err(MoveError::CpLine {
                    index: 0,
                    distance_mm: 0.0,
                    position: start_tip,
                    reason: if start.j2.is_finite() {
                        IkError::Singular {
                            j2_deg: start.j2,
                            band_deg: k.band_deg,
                        }
                    } else {
                        IkError::NotFinite
                    },
                });
            }
        };
        if !target_tip.is_finite() || !start.is_finite() {
            return Err(MoveError::Unreachable(IkError::NotFinite));
        }
        let d = *target_tip - start_tip;
        let length_mm = (d.x * d.x + d.y * d.y + d.z * d.z).sqrt();
        let turn = d.r.abs();
        let (mut v, mut a, mut dec) = (f64::INFINITY, f64::INFINITY, f64::INFINITY);
        if length_mm > 0.0 {
            v = params.speed_mm_s / length_mm;
            a = params.accel_mm_s2 / length_mm;
            dec = params.decel_mm_s2 / length_mm;
        }
        if turn > 0.0 {
            v = v.min(k.r.max_speed / turn);
            a = a.min(k.r.max_accel / turn);
            dec = dec.min(k.r.max_accel / turn);
        }
        let profile = if v.is_infinite() {
            Trapezoid::new(
                0.0,
                params.speed_mm_s,
                params.accel_mm_s2,
                params.decel_mm_s2,
            )?
        } else {
            Trapezoid::new(1.0, v, a, dec)?
        };
        let (s2, c2) = start.j2.to_radians().sin_cos();
        let mut m = CpMove {
            k: *k,
            arm,
            tool: tool_off,
            tool_turns: tool_off.x != 0.0 || tool_off.y != 0.0,
            start_tip,
            end_tip: *target_tip,
            start,
            end: start,
            f0: (flange0.x, flange0.y),
            beta0: (k.l2 * s2).atan2(k.l1 + k.l2 * c2).to_degrees(),
            length_mm,
            profile,
        };
        if !(spacing_mm > 0.0 && spacing_mm.is_finite()) {
            return Err(MoveError::Profile(
                super::profile::ProfileError::NotPositive {
                    what: "the check spacing",
                    value: spacing_mm,
                },
            ));
        }
        // Path length of the flange, which also turns about the tip when R changes.
        let swing = tool_off.x.hypot(tool_off.y) * turn.to_radians();
        m.end = m.check_line(check_points(length_mm + swing, spacing_mm))?;
        Ok(m)
    }

    /// As [`CpMove::plan`], but a line that leaves the workspace or a joint range is cut
    /// at the last check point before the first refused one instead of being refused: a
    /// continuous jog that runs to the edge. Check points are also at most `spacing_mm`
    /// degrees apart in R, so a turn stops at the J4 limit. Refused only when not even
    /// the first check point after the start can be reached.
    pub fn plan_to_limit(
        k: &Scara,
        start: Joints,
        target_tip: &Pose,
        tool: &CoordSystem,
        params: &CpParams,
        spacing_mm: f64,
    ) -> Result<Self, MoveError> {
        let refusal = match Self::plan(k, start, target_tip, tool, params, spacing_mm) {
            Err(e @ (MoveError::CpLine { index: 1.., .. } | MoveError::CpAroundBase { .. })) => e,
            other => return other,
        };
        let full = Self::unchecked(k, start, target_tip, tool, params)?;
        let turn = (full.end_tip.r - full.start_tip.r).abs();
        let n = check_points(full.length_mm.max(turn), spacing_mm);
        let mut last_good = match full.check_line(n) {
            Err(MoveError::CpLine { index, .. } | MoveError::CpAroundBase { index, .. }) => {
                index.saturating_sub(1)
            }
            _ => n,
        };
        // The cut line is checked again at its own spacing; step back a little if a check
        // point between the scan's points fails.
        for _ in 0..8 {
            if last_good == 0 {
                break;
            }
            let u = last_good as f64 / n as f64;
            match Self::plan(k, start, &full.tip_at_progress(u), tool, params, spacing_mm) {
                Err(MoveError::CpLine { .. } | MoveError::CpAroundBase { .. }) => last_good -= 1,
                other => return other,
            }
        }
        Err(refusal)
    }

    /// The plan of [`CpMove::plan`] with a huge spacing: the line and profile, checked
    /// only at its ends (for [`CpMove::plan_to_limit`], which checks it itself).
    fn unchecked(
        k: &Scara,
        start: Joints,
        target_tip: &Pose,
        tool: &CoordSystem,
        params: &CpParams,
    ) -> Result<Self, MoveError> {
        let here = tool.flange_to_tip(&k.forward(&start));
        let mut m = Self::plan(k, start, &here, tool, params, f64::MAX)?;
        m.end_tip = *target_tip;
        let d = *target_tip - m.start_tip;
        m.length_mm = (d.x * d.x + d.y * d.y + d.z * d.z).sqrt();
        Ok(m)
    }

    /// Re-plans the rest of the line at a new tip speed in mm/s (262H): the same
    /// accelerations, the same end; R's own speed limit still applies.
    pub fn change_speed(&mut self, t: f64, speed_mm_s: f64) -> Result<(), ProfileError> {
        let turn = (self.end_tip.r - self.start_tip.r).abs();
        let mut v = f64::INFINITY;
        if self.length_mm > 0.0 {
            v = speed_mm_s / self.length_mm;
        }
        if turn > 0.0 {
            v = v.min(self.k.r.max_speed / turn);
        }
        if v.is_finite() {
            self.profile = self.profile.with_speed_at(t, v)?;
        }
        Ok(())
    }

    /// Solves `n + 1` evenly spaced points; the joints at the end, or the first refusal.
    fn check_line(&self, n: usize) -> Result<Joints, MoveError> {
        let mut last = self.start;
        let mut prev_sweep = 0.0;
        let step = 1.0 / n as f64;
        for i in 0..=n {
            let u = if i == n { 1.0 } else { i as f64 * step };
            match self.solve(u) {
                Ok((j, sweep)) => {
                    if (sweep - prev_sweep).abs() > 90.0 {
                        return Err(MoveError::CpAroundBase {
                            index: i,
                            distance_mm: u * self.length_mm,
                            position: self.tip_at_progress(u),
                        });
                    }
                    prev_sweep = sweep;
                    last = j;
                }
                Err(reason) => {
                    return Err(MoveError::CpLine {
                        index: i,
                        distance_mm: u * self.length_mm,
                        position: self.tip_at_progress(u),
                        reason,
                    });
                }
            }
        }
        Ok(last)
    }

    /// The tool tip pose (base frame) at path fraction `u`.
    pub fn tip_at_progress(&self, u: f64) -> Pose {
        self.start_tip.lerp(&self.end_tip, u)
    }

    /// Joints at path fraction `u` and the flange's swept angle about J1 (deg).
    #[inline]
    fn solve(&self, u: f64) -> Result<(Joints, f64), IkError> {
        let tip = self.tip_at_progress(u);
        let fr = tip.r - self.tool.r;
        let (fx, fy) = if self.tool_turns {
            let (s, c) = fr.to_radians().sin_cos();
            (
                tip.x - (c * self.tool.x - s * self.tool.y),
                tip.y - (s * self.tool.x + c * self.tool.y),
            )
        } else {
            (tip.x, tip.y)
        };
        let k = &self.k;
        let (j2, c2, s2) = k.elbow(fx, fy, self.arm)?;
        let beta = (k.l2 * s2).atan2(k.l1 + k.l2 * c2).to_degrees();
        let (x0, y0) = self.f0;
        let sweep = (x0 * fy - y0 * fx).atan2(x0 * fx + y0 * fy).to_degrees();
        let j1 = check(
            self.start.j1 + sweep - (beta - self.beta0),
            &k.j1,
            Joint::J1,
        )?;
        let z = check(tip.z - self.tool.z, &k.z, Joint::Z)?;
        let j4 = check(fr - j1 - j2, &k.r, Joint::R)?;
        Ok((Joints::new(j1, j2, z, j4), sweep))
    }

    /// The joints at path fraction `u` (0..=1), as the checks computed them.
    pub fn joints_at_progress(&self, u: f64) -> Result<Joints, IkError> {
        self.solve(u).map(|(j, _)| j)
    }

    /// The joints at time `t`. The line was checked before it started; should a point
    /// between two check points still fail, the joints are interpolated instead.
    pub fn joints_at(&self, t: f64) -> Joints {
        self.sample(t).joints
    }

    pub fn sample(&self, t: f64) -> MoveSample {
        let s = self.profile.sample(t);
        let joints = if s.phase == Phase::Complete {
            self.end
        } else {
            self.joints_at_progress(s.s).unwrap_or_else(|_| {
                let (d, u) = (self.end - self.start, s.s);
                Joints::new(
                    self.start.j1 + d.j1 * u,
                    self.start.j2 + d.j2 * u,
                    self.start.z + d.z * u,
                    self.start.j4 + d.j4 * u,
                )
            })
        };
        MoveSample {
            joints,
            phase: s.phase,
            progress: s.s,
        }
    }

    /// Stops the move at time `t` with its own deceleration (238H): it ends short, on the
    /// line, and is marked cancelled.
    pub fn stop(&mut self, t: f64) {
        let before = self.end;
        self.profile = self.profile.stopped_at(t);
        if self.profile.is_stopped() {
            self.end = self
                .joints_at_progress(self.profile.distance())
                .unwrap_or(before);
        }
    }

    pub fn start(&self) -> Joints {
        self.start
    }
    /// The command position: the planned target, or the stop point after a stop.
    pub fn end(&self) -> Joints {
        self.end
    }
    pub fn profile(&self) -> &Trapezoid {
        &self.profile
    }
    /// The arm system the move keeps.
    pub fn arm(&self) -> Arm {
        self.arm
    }
    /// Length of the tip's line, mm.
    pub fn length_mm(&self) -> f64 {
        self.length_mm
    }
    /// Tool tip poses (base frame) at the start and the planned end.
    pub fn tip_line(&self) -> (Pose, Pose) {
        (self.start_tip, self.end_tip)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::robot::model::RobotModel;

    #[test]
    fn a_line_to_the_limit_stops_at_the_edge_and_can_change_speed() {
        let model = RobotModel::default_model();
        let k = Scara::new(&model);
        let start = model.home;
        let params = CpParams::from_command(&model, 0, 0, 0);
        let tool = CoordSystem::ZERO;
        let tip = k.forward(&start);
        let along = |dx: f64| Pose::new(tip.x + dx, tip.y, tip.z, tip.r);
        let far = along(5000.0);
        assert!(CpMove::plan(&k, start, &far, &tool, &params, 0.1).is_err());
        let cut = CpMove::plan_to_limit(&k, start, &far, &tool, &params, 0.1).unwrap();
        let (_, end) = cut.tip_line();
        assert!(end.x > tip.x + 1.0 && end.x < far.x, "{end:?}");
        let beyond = along(end.x - tip.x + 0.5);
        assert!(CpMove::plan(&k, start, &beyond, &tool, &params, 0.1).is_err());
        // A reachable line is planned as it is.
        let near = along(10.0);
        let whole = CpMove::plan(&k, start, &near, &tool, &params, 0.1).unwrap();
        let same = CpMove::plan_to_limit(&k, start, &near, &tool, &params, 0.1).unwrap();
        assert_eq!(whole, same);
        // 262H: slower from 10 ms on, same end.
        let mut slow = whole.clone();
        slow.change_speed(0.01, 1.0).unwrap();
        assert!(slow.profile().duration() > whole.profile().duration());
        assert_eq!(slow.sample(slow.profile().duration()).joints, whole.end());
    }
}
