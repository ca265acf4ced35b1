//! Axis messages: 232H servo, 233H home, 234H/235H linear-axis moves, 236H jog/inching,
//! 238H stop, 262H speed change.

use crate::protocol::{AxisMove, Direction, Home, Jog, JogMotion, Servo, SpeedChange, Stop};
use crate::robot::G_MM_S2;
use crate::robot::Trapezoid;
use crate::robot_wire;
use crate::sim::controller::Controller;
use crate::sim::errors::SimError;
use crate::sim::motion::{Motion, MotionKind, Plan};
use crate::sim::state::{HomeProgress, Mode};

/// Axes 5-6: the linear axes (234H/235H move only these; the SCARA uses 2D4H/2D5H).
pub(crate) const LINEAR: u8 = 0x30;
/// Axes 1-4: the SCARA.
pub(crate) const SCARA: u8 = 0x0F;

/// Closer than this to a limit (mm or deg, far below the 0.001 wire unit) is at it: a
/// continuous jog towards it is refused (C74).
pub(crate) const AT_LIMIT: f64 = 1e-6;

/// Parameter values for a 0 in a linear move's fields.
const LINEAR_DEFAULT_SPEED: f64 = 100.0;
const LINEAR_DEFAULT_ACCEL_CG: f64 = 30.0;

impl Controller {
    /// Starts a motion owning `axes`; their "completed normally" bits drop.
    pub(crate) fn start_motion(
        &mut self,
        kind: MotionKind,
        axes: u8,
        plan: Plan,
        speed_changeable: bool,
    ) {
        for i in 0..8 {
            if axes & (1 << i) != 0 {
                self.axes[i].completed = false;
            }
        }
        self.motions.push(Motion {
            kind,
            axes,
            plan,
            t0: self.now,
            speed_changeable,
        });
    }

    /// 232H servo ON/OFF (PROTOCOL.md 3.6); the switch takes `servo_switch_time`.
    pub(crate) fn msg_servo(&mut self, s: &Servo) -> Result<(), SimError> {
        let (pattern, on) = (s.axes.0, s.on);
        self.check_pattern(pattern)?;
        if on {
            self.check_can_act()?;
        } else if self.mode == Mode::Manual {
            return Err(SimError::ManualMode);
        }
        if self.busy_axes() & pattern != 0 {
            return Err(SimError::AxisBusy);
        }
        self.counters.servo_commands += 1;
        self.start_servo_switch(pattern, on);
        Ok(())
    }

    /// 233H home return (PROTOCOL.md 3.7): home state 1 while it runs, 2 when done.
    pub(crate) fn msg_home(&mut self, h: &Home) -> Result<(), SimError> {
        let pattern = h.axes.0;
        self.check_pattern(pattern)?;
        self.check_can_act()?;
        let in_use = self.busy_axes();
        for i in 0..8 {
            if pattern & (1 << i) != 0 {
                if in_use & (1 << i) != 0 {
                    return Err(SimError::AxisBusy);
                }
                if !self.axes[i].servo {
                    return Err(SimError::ServoOff);
                }
            }
        }
        let from = self.values;
        let mut to = from;
        for (i, slot) in to.iter_mut().enumerate() {
            if pattern & (1 << i) != 0 {
                *slot = self.home_value(i);
            }
        }
        let until = self.now + self.cfg.homing_time;
        for i in 0..8 {
            if pattern & (1 << i) != 0 {
                self.axes[i].home = HomeProgress::Homing {
                    since: self.now,
                    until,
                };
            }
        }
        let secs = self.cfg.homing_time.as_secs_f64().max(1e-3);
        let profile = Trapezoid::timed(1.0, secs).map_err(|_| SimError::BadValue)?;
        let plan = Plan::Axes {
            from,
            to,
            length: 1.0,
            profile,
        };
        self.start_motion(MotionKind::Home, pattern, plan, false);
        Ok(())
    }

    /// Speed (mm/s) and accelerations (mm/s²) of a linear-axis move from its fields.
    pub(crate) fn linear_rates(&self, speed: u16, accel: u16, decel: u16) -> (f64, f64, f64) {
        let v = if speed == 0 {
            LINEAR_DEFAULT_SPEED
        } else {
            f64::from(speed)
        };
        let cg = |c: u16| if c == 0 { LINEAR_DEFAULT_ACCEL_CG } else { f64::from(c) } / 100.0 * G_MM_S2;
        (v.min(self.cfg.linear_max_speed), cg(accel), cg(decel))
    }

    /// Starts a straight move of linear axes to `to` (each-axis values), refused beyond
    /// the stroke.
    pub(crate) fn linear_move(
        &mut self,
        pattern: u8,
        to: [f64; 8],
        rates: (f64, f64, f64),
        kind: MotionKind,
    ) -> Result<(), SimError> {
        for i in 0..8 {
            if pattern & (1 << i) != 0 {
                let (lo, hi) = self.axis_range(i);
                if !(lo..=hi).contains(&to[i]) {
                    return Err(SimError::SoftLimit);
                }
            }
        }
        let from = self.values;
        let length = (0..8)
            .filter(|i| pattern & (1 << i) != 0)
            .map(|i| (to[i] - from[i]).powi(2))
            .sum::<f64>()
            .sqrt();
        let profile =
            Trapezoid::new(length, rates.0, rates.1, rates.2).map_err(|_| SimError::BadValue)?;
        let plan = Plan::Axes {
            from,
            to,
            length,
            profile,
        };
        self.start_motion(kind, pattern, plan, true);
        Ok(())
    }

    /// 234H absolute / 235H relative move (PROTOCOL.md 3.8, 3.9) of linear axes 5-6.
    /// SCARA axes are refused with BadAxis: they move with 2D4H/2D5H `[inferred]`.
    pub(crate) fn msg_linear_move(&mut self, m: &AxisMove, relative: bool) -> Result<(), SimError> {
        let pattern = m.targets.pattern().0;
        self.check_pattern(pattern)?;
        if pattern & !LINEAR != 0 {
            return Err(SimError::BadAxis);
        }
        let mut to = self.values;
        for (axis, v) in m.targets.iter() {
            let slot = &mut to[axis.index()];
            *slot = if relative {
                *slot + v.units()
            } else {
                v.units()
            };
        }
        self.check_ready_to_move(pattern)?;
        let rates = self.linear_rates(m.speed.0, m.acc.0, m.dec.0);
        self.linear_move(pattern, to, rates, MotionKind::Move)
    }

    /// 236H jog (distance 0: until 238H) or inching (PROTOCOL.md 3.10). In the each-axis
    /// system (and on linear axes) allowed before homing; Cartesian jogs need it (B02).
    pub(crate) fn msg_jog(&mut self, j: &Jog) -> Result<(), SimError> {
        let pattern = j.axes.0;
        self.check_pattern(pattern)?;
        if j.axes.count() != 1 {
            return Err(SimError::BadAxis);
        }
        let inching = (!j.is_continuous()).then(|| j.distance.0.unsigned_abs());
        let positive = j.direction == Direction::Positive;
        let (accel, decel, speed) = match j.motion {
            JogMotion::Cartesian {
                acc, dec, speed, ..
            } => (acc.0, dec.0, speed.0),
            JogMotion::Joint { acc, dec, speed } => (acc.0, dec.0, speed.0),
        };
        if pattern & SCARA != 0 {
            let frame = robot_wire::jog_frame(&j.motion);
            self.scara_jog(pattern, [speed, accel, decel], inching, positive, frame)?;
        } else {
            // A linear axis jogs in its own (each-axis) system: no homing needed.
            self.check_ready_to_jog_joint(pattern)?;
            let i = pattern.trailing_zeros() as usize;
            let (lo, hi) = self.axis_range(i);
            let mut to = self.values;
            let sign = if positive { 1.0 } else { -1.0 };
            let (target, kind) = match inching {
                None => {
                    let limit = if positive { hi } else { lo };
                    // Already at the limit it would jog to: refused like a SCARA joint jog.
                    if (to[i] - limit).abs() < AT_LIMIT {
                        return Err(SimError::SoftLimit);
                    }
                    (limit, MotionKind::Jog)
                }
                Some(distance) => (
                    to[i] + sign * f64::from(distance) / 1000.0,
                    MotionKind::Move,
                ),
            };
            to[i] = target;
            let rates = self.linear_rates(speed, accel, decel);
            self.linear_move(pattern, to, rates, kind)?;
        }
        Ok(())
    }

    /// 238H operation stop & cancel (PROTOCOL.md 3.11): every motion that owns one of the
    /// axes brakes to a stop and ends not completed; appended byte bit 0 also drops the
    /// output changes the I/O interlock holds. Always answered, in any mode.
    pub(crate) fn msg_stop(&mut self, s: &Stop) -> Result<(), SimError> {
        let pattern = s.axes.0;
        self.counters.stops += 1;
        // Appended byte bit 0: drop the output changes the I/O interlock holds (3.11).
        if s.cancel_held_outputs {
            self.signals.cancel_held();
        }
        let now = self.now;
        for m in self.motions.iter_mut() {
            if m.axes & pattern != 0 && !m.cancelled() {
                m.stop(now);
            }
        }
        Ok(())
    }

    /// 262H speed change (PROTOCOL.md 3.14): new top speed (mm/s) for the linear-axis
    /// move in progress on these axes; CC1 when there is none. SCARA axes must not be
    /// selected on a SCARA controller (A04).
    pub(crate) fn msg_speed_change(&mut self, c: &SpeedChange) -> Result<(), SimError> {
        let (pattern, speed) = (c.axes.0, c.speed.0);
        self.check_pattern(pattern)?;
        if pattern & SCARA != 0 {
            return Err(SimError::BadAxis);
        }
        self.check_can_act()?;
        if speed == 0 {
            return Err(SimError::BadValue);
        }
        let affected: Vec<usize> = (0..self.motions.len())
            .filter(|&k| self.motions[k].axes & pattern != 0)
            .collect();
        if affected.is_empty()
            || affected
                .iter()
                .any(|&k| !self.motions[k].speed_changeable || self.motions[k].cancelled())
        {
            return Err(SimError::SpeedChange);
        }
        let now = self.now;
        let max = self.cfg.linear_max_speed;
        for k in affected {
            self.motions[k]
                .change_speed(now, f64::from(speed).min(max))
                .map_err(|_| SimError::BadValue)?;
        }
        Ok(())
    }
}
