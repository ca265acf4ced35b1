//! Motions the simulator runs, on the robot layer's motion generator: SCARA moves are
//! robot [`Move`]s (PTP or checked CP lines); homing and the linear axes 5-6 interpolate
//! axis values along a robot [`Trapezoid`]. Stop (238H) and speed change (262H) re-plan
//! the profile mid-move (262H reaches only the linear axes 5-6).

use std::time::Duration;

use crate::robot::{Move, ProfileError, Trapezoid};

/// How the axes get from start to end.
#[derive(Debug, Clone, PartialEq)]
pub enum Plan {
    /// The SCARA (axes 1-4).
    Arm(Move),
    /// Axis values (8 slots, each-axis units) interpolated along `profile`, which runs
    /// over `length` (mm for linear moves, 1 for homing).
    Axes {
        from: [f64; 8],
        to: [f64; 8],
        length: f64,
        profile: Trapezoid,
    },
}

/// Why a motion runs, for status and counters.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MotionKind {
    Home,
    Move,
    Jog,
}

/// A motion in progress on a set of axes.
#[derive(Debug, Clone, PartialEq)]
pub struct Motion {
    pub kind: MotionKind,
    /// Axis pattern the motion owns (bit n = axis n+1).
    pub axes: u8,
    pub plan: Plan,
    /// When the move started.
    pub t0: Duration,
    /// PTP moves in % and homing cannot change speed (262H answers CC1).
    pub speed_changeable: bool,
}

impl Motion {
    /// Seconds since the move started.
    fn t(&self, now: Duration) -> f64 {
        now.saturating_sub(self.t0).as_secs_f64()
    }

    pub fn profile(&self) -> &Trapezoid {
        match &self.plan {
            Plan::Arm(m) => m.profile(),
            Plan::Axes { profile, .. } => profile,
        }
    }

    /// True once the profile has run out.
    pub fn finished(&self, now: Duration) -> bool {
        self.t(now) >= self.profile().duration()
    }

    /// Stopped by 238H: it ends short and is not "completed normally".
    pub fn cancelled(&self) -> bool {
        self.profile().is_stopped()
    }

    /// Brakes to a stop from where it is now (238H).
    pub fn stop(&mut self, now: Duration) {
        let t = self.t(now);
        match &mut self.plan {
            Plan::Arm(m) => m.stop(t),
            Plan::Axes { profile, .. } => *profile = profile.stopped_at(t),
        }
    }

    /// Re-plans the rest of the move at a new top speed in mm/s (262H).
    pub fn change_speed(&mut self, now: Duration, speed: f64) -> Result<(), ProfileError> {
        let t = self.t(now);
        match &mut self.plan {
            Plan::Arm(Move::Cp(m)) => m.change_speed(t, speed),
            Plan::Arm(Move::Ptp(_)) => Ok(()),
            Plan::Axes { profile, .. } => {
                *profile = profile.with_speed_at(t, speed)?;
                Ok(())
            }
        }
    }

    /// The axis values (8 slots) at `now`, starting from `current` for the axes the
    /// motion does not own.
    pub fn values_at(&self, now: Duration, current: &[f64; 8]) -> [f64; 8] {
        let t = self.t(now);
        let mut out = *current;
        match &self.plan {
            Plan::Arm(m) => out[..4].copy_from_slice(&m.joints_at(t).to_array()),
            Plan::Axes {
                from,
                to,
                length,
                profile,
            } => {
                let s = profile.sample(t).s;
                let u = if *length > 0.0 { s / length } else { 1.0 };
                for (i, slot) in out.iter_mut().enumerate() {
                    if self.axes & (1 << i) != 0 {
                        *slot = from[i] + (to[i] - from[i]) * u;
                    }
                }
            }
        }
        out
    }
}
