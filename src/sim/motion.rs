//! Motions the simulator runs: a path (joint interpolation or a straight tool-tip line)
//! driven by a trapezoidal profile that can be re-planned mid-move (speed change, stop).

use std::time::Duration;

use crate::robot::frames::CoordSystem;
use crate::robot::kinematics::{Arm, Scara};
use crate::robot::{Joints, Pose};

/// A 1-D trapezoidal profile of the path parameter `s` (0 at the start, 1 at the end),
/// starting at `s0` with speed `v0` at time 0: accelerate (or brake) to `vp`, cruise,
/// brake to a stop at `s_end`. Speeds in s/second.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Profile {
    s0: f64,
    v0: f64,
    a1: f64,
    t1: f64,
    vp: f64,
    t2: f64,
    d: f64,
    t3: f64,
}

impl Profile {
    /// From (`s0`, `v0`) to a stop at `s_end` (>= s0), speed at most `vmax`, accelerating
    /// at `a` and braking at `d` (all > 0). If the distance is too short to stop, it brakes
    /// harder so it never overshoots.
    pub fn plan(s0: f64, v0: f64, s_end: f64, vmax: f64, a: f64, d: f64) -> Profile {
        let dist = (s_end - s0).max(0.0);
        let (vmax, a, d) = (pos(vmax), pos(a), pos(d));
        let v0 = v0.max(0.0);
        let stop_dist = v0 * v0 / (2.0 * d);
        if stop_dist >= dist {
            // Brake now (harder if needed) to stop at s_end.
            let d_eff = if dist > 1e-12 {
                v0 * v0 / (2.0 * dist)
            } else {
                f64::INFINITY
            };
            let t3 = if d_eff.is_finite() && d_eff > 0.0 {
                v0 / d_eff
            } else {
                0.0
            };
            return Profile {
                s0,
                v0,
                a1: 0.0,
                t1: 0.0,
                vp: v0,
                t2: 0.0,
                d: d_eff.min(1e18),
                t3,
            };
        }
        let (a1, d1) = if vmax >= v0 {
            (a, (vmax * vmax - v0 * v0) / (2.0 * a))
        } else {
            (-d, (v0 * v0 - vmax * vmax) / (2.0 * d))
        };
        let d3 = vmax * vmax / (2.0 * d);
        if d1 + d3 <= dist {
            let t1 = (vmax - v0).abs() / a1.abs();
            let t2 = (dist - d1 - d3) / vmax;
            return Profile {
                s0,
                v0,
                a1,
                t1,
                vp: vmax,
                t2,
                d,
                t3: vmax / d,
            };
        }
        // Triangular: accelerate to vp < vmax, then brake.
        let vp = ((dist + v0 * v0 / (2.0 * a)) / (1.0 / (2.0 * a) + 1.0 / (2.0 * d)))
            .max(v0 * v0)
            .sqrt();
        Profile {
            s0,
            v0,
            a1: a,
            t1: (vp - v0) / a,
            vp,
            t2: 0.0,
            d,
            t3: vp / d,
        }
    }

    /// A start-to-end profile taking exactly `total` (accelerate a third, cruise a
    /// third, brake a third).
    pub fn timed(total: Duration) -> Profile {
        let t = total.as_secs_f64().max(1e-3);
        let v = 1.5 / t;
        let a = 4.5 / (t * t);
        Profile::plan(0.0, 0.0, 1.0, v, a, a)
    }

    /// Seconds from start to stop.
    pub fn duration(&self) -> f64 {
        self.t1 + self.t2 + self.t3
    }

    /// Position and speed `t` seconds after the start.
    pub fn at(&self, t: f64) -> (f64, f64) {
        let t = t.max(0.0);
        if t < self.t1 {
            return (
                self.s0 + self.v0 * t + 0.5 * self.a1 * t * t,
                self.v0 + self.a1 * t,
            );
        }
        let s1 = self.s0 + self.v0 * self.t1 + 0.5 * self.a1 * self.t1 * self.t1;
        let t = t - self.t1;
        if t < self.t2 {
            return (s1 + self.vp * t, self.vp);
        }
        let s2 = s1 + self.vp * self.t2;
        let t = (t - self.t2).min(self.t3);
        (
            s2 + self.vp * t - 0.5 * self.d * t * t,
            (self.vp - self.d * t).max(0.0),
        )
    }

    /// Where it stops.
    pub fn end(&self) -> f64 {
        self.at(self.duration()).0
    }
}

fn pos(v: f64) -> f64 {
    if v.is_finite() && v > 1e-12 { v } else { 1e-12 }
}

/// The way the axes go from start to end as `s` runs from 0 to 1.
#[derive(Debug, Clone, PartialEq)]
pub enum Path {
    /// Every axis of `axes` (0-based index into the 8 axis values) interpolated linearly.
    Joint { from: [f64; 8], to: [f64; 8] },
    /// The tool tip on a straight line (base frame), joints by inverse kinematics on the
    /// given arm, J1/J4 kept continuous.
    Line {
        from: Pose,
        to: Pose,
        arm: Arm,
        tool: CoordSystem,
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
    pub path: Path,
    pub profile: Profile,
    /// When the current profile started.
    pub t0: Duration,
    /// Stopped by 238H (or an alarm): it ends short and is not "completed normally".
    pub cancelled: bool,
    /// PTP moves in % cannot change speed (262H answers CC1).
    pub speed_changeable: bool,
    /// Length of the path in its own unit (mm for lines and linear axes): converts
    /// mm/s into s/second for 262H.
    pub length: f64,
    /// Braking rate in s/second² (kept for 262H and 238H re-plans).
    pub accel: f64,
    pub decel: f64,
}

impl Motion {
    /// Path parameter and speed at `now`.
    pub fn state(&self, now: Duration) -> (f64, f64) {
        self.profile.at(now.saturating_sub(self.t0).as_secs_f64())
    }

    /// True once the profile has run out.
    pub fn finished(&self, now: Duration) -> bool {
        now.saturating_sub(self.t0).as_secs_f64() >= self.profile.duration()
    }

    /// Brakes to a stop from where it is now (238H): ends short, marked cancelled.
    pub fn stop(&mut self, now: Duration) {
        let (s, v) = self.state(now);
        let brake = self.decel;
        let end = (s + v * v / (2.0 * brake)).min(1.0);
        self.profile = Profile::plan(s, v, end, v.max(1e-9), brake, brake);
        self.t0 = now;
        self.cancelled = true;
    }

    /// Re-plans the rest of the move at a new top speed (s/second).
    pub fn change_speed(&mut self, now: Duration, vmax: f64) {
        let (s, v) = self.state(now);
        let end = self.profile.end();
        self.profile = Profile::plan(s, v, end, vmax, self.accel, self.decel);
        self.t0 = now;
    }

    /// The axis values (8 slots) at path parameter `s`, starting from `current` for the
    /// axes the path does not set. `None` if the line's IK fails there.
    pub fn values_at(&self, s: f64, kin: &Scara, current: &[f64; 8]) -> Option<[f64; 8]> {
        let s = s.clamp(0.0, 1.0);
        let mut out = *current;
        match &self.path {
            Path::Joint { from, to } => {
                for (i, slot) in out.iter_mut().enumerate() {
                    if self.axes & (1 << i) != 0 {
                        *slot = from[i] + (to[i] - from[i]) * s;
                    }
                }
            }
            Path::Line {
                from,
                to,
                arm,
                tool,
            } => {
                let tip = from.lerp(to, s);
                let near = Joints::new(current[0], current[1], current[2], current[3]);
                let j = kin.inverse(&tool.tip_to_flange(&tip), *arm, &near).ok()?;
                out[..4].copy_from_slice(&j.to_array());
            }
        }
        Some(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn trapezoid_reaches_the_end_and_never_overshoots() {
        for &(vmax, a) in &[(1.0, 1.0), (10.0, 2.0), (0.1, 50.0)] {
            let p = Profile::plan(0.0, 0.0, 1.0, vmax, a, a);
            let t = p.duration();
            assert!((p.at(t).0 - 1.0).abs() < 1e-9, "{p:?}");
            let mut last = 0.0;
            for i in 0..=1000 {
                let (s, v) = p.at(t * f64::from(i) / 1000.0);
                assert!(s >= last - 1e-12 && s <= 1.0 + 1e-9 && v >= 0.0 && v <= vmax + 1e-9);
                last = s;
            }
        }
    }

    #[test]
    fn replans_from_speed() {
        let p = Profile::plan(0.2, 2.0, 1.0, 0.5, 1.0, 10.0);
        assert!((p.end() - 1.0).abs() < 1e-9);
        let q = Profile::plan(0.9, 5.0, 1.0, 5.0, 1.0, 1.0); // must brake harder
        assert!((q.end() - 1.0).abs() < 1e-9);
        let r = Profile::timed(Duration::from_millis(600));
        assert!((r.duration() - 0.6).abs() < 1e-9);
    }
}
