//! Axis messages: 232H servo, 233H home, 234H/235H linear-axis moves, 236H jog/inching,
//! 238H stop, 262H speed change.

use super::{Fields, bits, expect_len};
use crate::robot::G_MM_S2;
use crate::sim::controller::Controller;
use crate::sim::errors::SimError;
use crate::sim::motion::{Motion, MotionKind, Path, Profile};
use crate::sim::state::{HomeState, Mode};

/// Axes 5-6: the linear axes (234H/235H move only these; the SCARA uses 2D4H/2D5H).
pub(crate) const LINEAR: u8 = 0x30;
/// Axes 1-4: the SCARA.
pub(crate) const SCARA: u8 = 0x0F;

/// Parameter values for a 0 in a linear move's fields.
const LINEAR_DEFAULT_SPEED: f64 = 100.0;
const LINEAR_DEFAULT_ACCEL_CG: f64 = 30.0;

impl Controller {
    /// Starts a motion owning `axes`. `length` is the path length in the unit speeds are
    /// given in; `v`, `a`, `d` in that unit per second (squared).
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn start_motion(
        &mut self,
        kind: MotionKind,
        axes: u8,
        path: Path,
        length: f64,
        v: f64,
        a: f64,
        d: f64,
        speed_changeable: bool,
    ) {
        let length = if length.is_finite() && length > 1e-9 {
            length
        } else {
            1e-9
        };
        let profile = Profile::plan(0.0, 0.0, 1.0, v / length, a / length, d / length);
        for i in 0..8 {
            if axes & (1 << i) != 0 {
                self.axes[i].completed = false;
            }
        }
        self.motions.push(Motion {
            kind,
            axes,
            path,
            profile,
            t0: self.now,
            cancelled: false,
            speed_changeable,
            length,
            accel: a / length,
            decel: d / length,
        });
    }

    /// 232H servo ON/OFF (PROTOCOL.md 3.6); the switch takes `servo_switch_time`.
    pub(crate) fn msg_servo(
        &mut self,
        id: [u8; 3],
        data: &[u8],
        out: &mut Vec<u8>,
    ) -> Result<(), SimError> {
        expect_len(data, 3)?;
        let mut f = Fields::new(data);
        let pattern = f.u8(2)?;
        let op = f.u8(1)?;
        self.check_pattern(pattern)?;
        if op & !1 != 0 {
            return Err(SimError::BadValue);
        }
        let on = op & 1 == 1;
        if on {
            self.check_can_act()?;
        } else if self.mode == Mode::Manual {
            return Err(SimError::ManualMode);
        }
        if self.in_use() & pattern != 0 {
            return Err(SimError::AxisBusy);
        }
        self.counters.servo_commands += 1;
        self.start_servo_switch(pattern, on);
        self.ack(id, out);
        Ok(())
    }

    /// 233H home return (PROTOCOL.md 3.7): home state 1 while it runs, 2 when done.
    pub(crate) fn msg_home(
        &mut self,
        id: [u8; 3],
        data: &[u8],
        out: &mut Vec<u8>,
    ) -> Result<(), SimError> {
        expect_len(data, 8)?;
        let mut f = Fields::new(data);
        let pattern = f.u8(2)?;
        let _search = f.hex(3)?;
        let _creep = f.hex(3)?;
        self.check_pattern(pattern)?;
        self.check_can_act()?;
        let in_use = self.in_use();
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
                self.axes[i].home = HomeState::Homing {
                    since: self.now,
                    until,
                };
                self.axes[i].completed = false;
            }
        }
        self.motions.push(Motion {
            kind: MotionKind::Home,
            axes: pattern,
            path: Path::Joint { from, to },
            profile: Profile::timed(self.cfg.homing_time),
            t0: self.now,
            cancelled: false,
            speed_changeable: false,
            length: 1.0,
            accel: 1e3,
            decel: 4.5 / self.cfg.homing_time.as_secs_f64().max(1e-3).powi(2),
        });
        self.ack(id, out);
        Ok(())
    }

    /// Speed (mm/s) and accelerations (mm/s²) of a linear-axis move from its fields.
    fn linear_rates(&self, speed: u16, accel: u16, decel: u16) -> (f64, f64, f64) {
        let v = if speed == 0 {
            LINEAR_DEFAULT_SPEED
        } else {
            f64::from(speed)
        };
        let cg = |c: u16| if c == 0 { LINEAR_DEFAULT_ACCEL_CG } else { f64::from(c) } / 100.0 * G_MM_S2;
        (v.min(self.cfg.linear_max_speed), cg(accel), cg(decel))
    }

    /// Starts a straight joint-space move of linear axes to `to`.
    fn linear_move(
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
        self.start_motion(
            kind,
            pattern,
            Path::Joint { from, to },
            length,
            rates.0,
            rates.1,
            rates.2,
            true,
        );
        Ok(())
    }

    /// 234H absolute / 235H relative move (PROTOCOL.md 3.8, 3.9) of linear axes 5-6.
    /// SCARA axes are refused with BadAxis: they move with 2D4H/2D5H `[inferred]`.
    pub(crate) fn msg_linear_move(
        &mut self,
        id: [u8; 3],
        data: &[u8],
        out: &mut Vec<u8>,
        relative: bool,
    ) -> Result<(), SimError> {
        if data.len() < 14 {
            return Err(SimError::WrongLength);
        }
        let mut f = Fields::new(data);
        let pattern = f.u8(2)?;
        let accel = f.u16(4)?;
        let decel = f.u16(4)?;
        let speed = f.u16(4)?;
        expect_len(data, 14 + 8 * bits(pattern))?;
        self.check_pattern(pattern)?;
        if pattern & !LINEAR != 0 {
            return Err(SimError::BadAxis);
        }
        let mut to = self.values;
        for (i, slot) in to.iter_mut().enumerate() {
            if pattern & (1 << i) != 0 {
                let v = f64::from(f.i32()?) / 1000.0;
                *slot = if relative { *slot + v } else { v };
            }
        }
        self.check_ready_to_move(pattern)?;
        let rates = self.linear_rates(speed, accel, decel);
        self.linear_move(pattern, to, rates, MotionKind::Move)?;
        self.ack(id, out);
        Ok(())
    }

    /// 236H jog (distance 0: until 238H) or inching (PROTOCOL.md 3.10).
    pub(crate) fn msg_jog(
        &mut self,
        id: [u8; 3],
        data: &[u8],
        out: &mut Vec<u8>,
    ) -> Result<(), SimError> {
        expect_len(data, 23)?;
        let mut f = Fields::new(data);
        let pattern = f.u8(2)?;
        let accel = f.u16(4)?;
        let decel = f.u16(4)?;
        let speed = f.u16(4)?;
        let distance = f.hex(8)?;
        let op = f.u8(1)?;
        self.check_pattern(pattern)?;
        if bits(pattern) != 1 || op & 0x8 != 0 || distance > i32::MAX as u32 {
            return Err(if bits(pattern) != 1 {
                SimError::BadAxis
            } else {
                SimError::BadValue
            });
        }
        let positive = op & 1 == 1;
        let system = (op >> 1) & 3;
        if pattern & SCARA != 0 {
            self.scara_jog(
                pattern,
                accel,
                decel,
                speed,
                distance as i32,
                positive,
                system,
            )?;
        } else {
            self.check_ready_to_move(pattern)?;
            let i = pattern.trailing_zeros() as usize;
            let (lo, hi) = self.axis_range(i);
            let mut to = self.values;
            let sign = if positive { 1.0 } else { -1.0 };
            let (target, kind) = if distance == 0 {
                (if positive { hi } else { lo }, MotionKind::Jog)
            } else {
                (
                    to[i] + sign * f64::from(distance) / 1000.0,
                    MotionKind::Move,
                )
            };
            to[i] = target;
            let rates = self.linear_rates(speed, accel, decel);
            self.linear_move(pattern, to, rates, kind)?;
        }
        self.ack(id, out);
        Ok(())
    }

    /// 238H operation stop & cancel (PROTOCOL.md 3.11): every motion that owns one of the
    /// axes brakes to a stop and ends not completed. Always answered, in any mode.
    pub(crate) fn msg_stop(
        &mut self,
        id: [u8; 3],
        data: &[u8],
        out: &mut Vec<u8>,
    ) -> Result<(), SimError> {
        expect_len(data, 4)?;
        let mut f = Fields::new(data);
        let pattern = f.u8(2)?;
        let _appended = f.u8(2)?;
        self.counters.stops += 1;
        let now = self.now;
        for m in self.motions.iter_mut() {
            if m.axes & pattern != 0 && !m.cancelled {
                m.stop(now);
            }
        }
        self.ack(id, out);
        Ok(())
    }

    /// 262H speed change (PROTOCOL.md 3.14): new top speed (mm/s) for the CP or linear
    /// move in progress on these axes; CC1 when there is none, or it is a PTP move in %.
    pub(crate) fn msg_speed_change(
        &mut self,
        id: [u8; 3],
        data: &[u8],
        out: &mut Vec<u8>,
    ) -> Result<(), SimError> {
        expect_len(data, 6)?;
        let mut f = Fields::new(data);
        let pattern = f.u8(2)?;
        let speed = f.u16(4)?;
        self.check_pattern(pattern)?;
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
                .any(|&k| !self.motions[k].speed_changeable || self.motions[k].cancelled)
        {
            return Err(SimError::SpeedChange);
        }
        let now = self.now;
        let cp_max = self.model.cp_max_speed_mm_s;
        let lin_max = self.cfg.linear_max_speed;
        for k in affected {
            let m = &mut self.motions[k];
            let max = if m.axes & SCARA != 0 { cp_max } else { lin_max };
            let v = f64::from(speed).min(max) / m.length;
            m.change_speed(now, v);
        }
        self.ack(id, out);
        Ok(())
    }
}
