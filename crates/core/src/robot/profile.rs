//! Trapezoidal (triangular when short) motion profiles, sampled in closed form at time t.

use thiserror::Error;

/// Where a profile is, as the Delta RMC status bits report it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Phase {
    Accel,
    ConstantVelocity,
    Decel,
    Complete,
}

/// A profile's state at one instant: distance covered and speed (units of the profile).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProfileSample {
    pub s: f64,
    pub v: f64,
    pub phase: Phase,
}

/// A speed, acceleration or distance that cannot make a profile.
#[derive(Debug, Clone, Copy, PartialEq, Error)]
pub enum ProfileError {
    #[error("{what} must be a positive number, got {value}")]
    NotPositive { what: &'static str, value: f64 },
    #[error("the distance must be a finite number, got {0}")]
    BadDistance(f64),
    #[error(
        "the move would never end (distance {distance}, speed {speed}, acceleration {accel}, deceleration {decel})"
    )]
    Endless {
        distance: f64,
        speed: f64,
        accel: f64,
        decel: f64,
    },
}

/// A 1-D trapezoidal profile from rest to rest over `distance` (>= 0): accelerate at
/// `accel` to the peak speed, cruise, decelerate at `decel`. When the distance is too
/// short to reach `speed`, the cruise vanishes and the peak is lower (a triangle).
/// Everything is precomputed; [`Trapezoid::sample`] is a few multiplications.
/// Time 0 is the start of the move; time is always an argument, never read from a clock.
/// A re-planned profile ([`Trapezoid::with_speed_at`]) starts its first phase later, from
/// the distance and speed the move had then.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Trapezoid {
    distance: f64,
    accel: f64,
    decel: f64,
    v_peak: f64,
    /// Start of the first phase: 0, or the time of a re-plan.
    t0: f64,
    /// Distance and speed at `t0` (0 and 0 from rest).
    s0: f64,
    v0: f64,
    /// Rate of the first phase: `accel`, or `-decel` when a re-plan slows to a lower peak.
    a1: f64,
    /// End of the first phase (acceleration).
    t1: f64,
    /// End of constant velocity (= t1 for a triangle).
    t2: f64,
    /// End of the move.
    t3: f64,
    /// Distance at t1.
    s1: f64,
    stopped: bool,
}

fn positive(what: &'static str, value: f64) -> Result<f64, ProfileError> {
    if value > 0.0 && value.is_finite() {
        Ok(value)
    } else {
        Err(ProfileError::NotPositive { what, value })
    }
}

impl Trapezoid {
    /// A profile covering `distance` (negative is taken as its magnitude) with the given
    /// maximum speed, acceleration and deceleration (all > 0, finite).
    pub fn new(distance: f64, speed: f64, accel: f64, decel: f64) -> Result<Self, ProfileError> {
        if !distance.is_finite() {
            return Err(ProfileError::BadDistance(distance));
        }
        let speed = positive("the speed", speed)?;
        let accel = positive("the acceleration", accel)?;
        let decel = positive("the deceleration", decel)?;
        let distance = distance.abs();
        let ramps = speed * speed / (2.0 * accel) + speed * speed / (2.0 * decel);
        let (v_peak, cruise) = if ramps <= distance {
            (speed, (distance - ramps) / speed)
        } else {
            (
                (2.0 * distance * accel * decel / (accel + decel)).sqrt(),
                0.0,
            )
        };
        let profile = Self::from_parts(distance, accel, decel, v_peak, v_peak / accel, cruise);
        if !profile.duration().is_finite() {
            return Err(ProfileError::Endless {
                distance,
                speed,
                accel,
                decel,
            });
        }
        Ok(profile)
    }

    fn from_parts(
        distance: f64,
        accel: f64,
        decel: f64,
        v_peak: f64,
        t1: f64,
        cruise: f64,
    ) -> Self {
        let t2 = t1 + cruise;
        Trapezoid {
            distance,
            accel,
            decel,
            v_peak,
            t0: 0.0,
            s0: 0.0,
            v0: 0.0,
            a1: accel,
            t1,
            t2,
            t3: t2 + v_peak / decel,
            s1: 0.5 * accel * t1 * t1,
            stopped: false,
        }
    }

    /// A rest-to-rest profile over `distance` that takes exactly `duration` seconds: a
    /// third accelerating, a third cruising, a third decelerating (homing, timed moves).
    pub fn timed(distance: f64, duration: f64) -> Result<Self, ProfileError> {
        let t = positive("the duration", duration)?;
        let d = positive("the distance", distance.abs())?;
        Self::new(d, 1.5 * d / t, 4.5 * d / (t * t), 4.5 * d / (t * t))
    }

    /// The state at time `t` (seconds since the start). Before 0 it is at rest at 0
    /// (before a re-plan's time, as it was then); from the end on it is at rest at the
    /// full distance, phase `Complete`.
    #[inline]
    pub fn sample(&self, t: f64) -> ProfileSample {
        // Negative times and NaN: at rest at the start.
        let t = if t > self.t0 { t } else { self.t0 };
        if t >= self.t3 {
            ProfileSample {
                s: self.distance,
                v: 0.0,
                phase: Phase::Complete,
            }
        } else if t < self.t1 {
            let dt = t - self.t0;
            ProfileSample {
                s: self.s0 + self.v0 * dt + 0.5 * self.a1 * dt * dt,
                v: self.v0 + self.a1 * dt,
                phase: if self.a1 >= 0.0 {
                    Phase::Accel
                } else {
                    Phase::Decel
                },
            }
        } else if t < self.t2 {
            ProfileSample {
                s: self.s1 + self.v_peak * (t - self.t1),
                v: self.v_peak,
                phase: Phase::ConstantVelocity,
            }
        } else {
            // Measured back from the end, so the end lands exactly on the distance.
            let tau = self.t3 - t;
            ProfileSample {
                s: self.distance - 0.5 * self.decel * tau * tau,
                v: self.decel * tau,
                phase: Phase::Decel,
            }
        }
    }

    /// The same move told to stop at time `t` (238H): from the state at `t` it
    /// decelerates at the move's own deceleration and ends short of the distance. A stop
    /// already in the final deceleration changes nothing but the cancelled mark; a stop
    /// after the end changes nothing at all.
    pub fn stopped_at(&self, t: f64) -> Trapezoid {
        if t >= self.t3 || self.stopped {
            return *self;
        }
        let t = if t > self.t0 { t } else { self.t0 };
        let mut p = *self;
        if t < self.t2 {
            if t < self.t1 {
                // Cut the first phase short: peak = speed reached at t, no cruise.
                let now = self.sample(t);
                (p.t1, p.v_peak, p.s1) = (t, now.v, now.s);
            }
            // Cut the cruise short (or leave none).
            p.t2 = p.t1 + (t - p.t1);
            p.t3 = p.t2 + p.v_peak / p.decel;
            p.distance = p.s1 + p.v_peak * (p.t2 - p.t1) + p.v_peak * p.v_peak / (2.0 * p.decel);
        }
        p.distance = p.distance.min(self.distance);
        p.stopped = true;
        p
    }

    /// The same move re-planned at time `t` for a new top speed (262H speed change):
    /// from the distance and speed it has at `t` it accelerates (or brakes, at the
    /// deceleration) to `speed`, cruises, and decelerates to the same end; when the rest
    /// is too short for `speed` the peak is lower. Once in the final deceleration, stopped
    /// or done, nothing changes. Samples before `t` give the state at `t`.
    pub fn with_speed_at(&self, t: f64, speed: f64) -> Result<Trapezoid, ProfileError> {
        let speed = positive("the speed", speed)?;
        let t = if t > self.t0 { t } else { self.t0 };
        if self.stopped || t >= self.t2 {
            return Ok(*self);
        }
        let now = self.sample(t);
        let (s0, v0, a, d) = (now.s, now.v, self.accel, self.decel);
        let rest = (self.distance - s0).max(0.0);
        let a1 = if speed >= v0 { a } else { -d };
        let ramp = (speed * speed - v0 * v0).abs() / (2.0 * a1.abs());
        let (a1, v_peak, t_ramp, cruise) = if ramp + speed * speed / (2.0 * d) <= rest {
            let cruise = (rest - ramp - speed * speed / (2.0 * d)) / speed;
            (a1, speed, (speed - v0).abs() / a1.abs(), cruise)
        } else {
            // The highest peak from which it still stops at the end (never below v0).
            let vp = ((2.0 * a * d * rest + d * v0 * v0) / (a + d))
                .sqrt()
                .max(v0);
            (a, vp, (vp - v0) / a, 0.0)
        };
        let mut p = *self;
        (p.t0, p.s0, p.v0, p.a1, p.v_peak) = (t, s0, v0, a1, v_peak);
        p.t1 = t + t_ramp;
        p.t2 = p.t1 + cruise;
        p.t3 = p.t2 + v_peak / d;
        p.s1 = s0 + v0 * t_ramp + 0.5 * a1 * t_ramp * t_ramp;
        Ok(p)
    }

    /// Distance covered at the end (shorter than asked for after a stop).
    pub fn distance(&self) -> f64 {
        self.distance
    }
    /// Time from start to rest.
    pub fn duration(&self) -> f64 {
        self.t3
    }
    /// Highest speed reached.
    pub fn peak_speed(&self) -> f64 {
        self.v_peak
    }
    pub fn accel(&self) -> f64 {
        self.accel
    }
    pub fn decel(&self) -> f64 {
        self.decel
    }
    /// Ends of the acceleration, constant-velocity and deceleration phases.
    pub fn phase_ends(&self) -> [f64; 3] {
        [self.t1, self.t2, self.t3]
    }
    /// No constant-velocity phase.
    pub fn is_triangular(&self) -> bool {
        self.t2 <= self.t1
    }
    /// Cut short by [`Trapezoid::stopped_at`] (cancelled, not completed normally).
    pub fn is_stopped(&self) -> bool {
        self.stopped
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn trapezoid_and_triangle_shapes() {
        let p = Trapezoid::new(100.0, 50.0, 100.0, 200.0).unwrap();
        // 12.5 mm to accelerate, 6.25 mm to decelerate, 81.25 mm at 50 mm/s.
        assert_eq!(
            p.phase_ends(),
            [0.5, 0.5 + 81.25 / 50.0, 0.5 + 81.25 / 50.0 + 0.25]
        );
        assert!(!p.is_triangular());
        let q = Trapezoid::new(1.0, 50.0, 100.0, 100.0).unwrap();
        assert!(q.is_triangular() && (q.peak_speed() - 10.0).abs() < 1e-12);
        assert_eq!(q.sample(q.duration()).s, 1.0);
    }

    #[test]
    fn timed_profiles_take_their_time() {
        let p = Trapezoid::timed(1.0, 0.6).unwrap();
        assert!((p.duration() - 0.6).abs() < 1e-12);
        assert!((p.phase_ends()[0] - 0.2).abs() < 1e-12);
        assert_eq!(p.sample(0.6).s, 1.0);
        assert!(Trapezoid::timed(1.0, 0.0).is_err() && Trapezoid::timed(0.0, 1.0).is_err());
    }

    #[test]
    fn speed_change_replans_from_the_current_state_to_the_same_end() {
        let p = Trapezoid::new(100.0, 50.0, 100.0, 100.0).unwrap();
        let before = p.sample(1.0);
        for speed in [10.0, 50.0, 80.0, 1000.0] {
            let q = p.with_speed_at(1.0, speed).unwrap();
            let at = q.sample(1.0);
            assert!((at.s - before.s).abs() < 1e-12 && (at.v - before.v).abs() < 1e-12);
            assert_eq!(q.sample(q.duration()).s, 100.0);
            let (mut last, mut t) = (at.s, 1.0);
            while t < q.duration() {
                let x = q.sample(t);
                assert!(x.s >= last - 1e-9 && x.s <= 100.0 + 1e-9, "{speed}: {x:?}");
                assert!(x.v <= speed.max(50.0) + 1e-9);
                last = x.s;
                t += 0.01;
            }
        }
        // Slower: brakes to the new speed, so the move takes longer; faster: shorter.
        assert!(p.with_speed_at(1.0, 10.0).unwrap().duration() > p.duration());
        assert!(p.with_speed_at(1.0, 80.0).unwrap().duration() < p.duration());
        assert_eq!(
            p.with_speed_at(1.0, 10.0).unwrap().sample(1.2).phase,
            Phase::Decel
        );
        // A re-planned move still stops short when told to.
        let q = p.with_speed_at(1.0, 10.0).unwrap().stopped_at(2.0);
        assert!(q.is_stopped() && q.distance() < 100.0);
        assert!(p.with_speed_at(1.0, 0.0).is_err());
    }

    #[test]
    fn bad_parameters_are_refused() {
        assert!(Trapezoid::new(1.0, 0.0, 1.0, 1.0).is_err());
        assert!(Trapezoid::new(1.0, 1.0, f64::NAN, 1.0).is_err());
        assert!(Trapezoid::new(f64::INFINITY, 1.0, 1.0, 1.0).is_err());
        let z = Trapezoid::new(0.0, 1.0, 1.0, 1.0).unwrap();
        assert_eq!(z.duration(), 0.0);
        assert_eq!(z.sample(0.0).phase, Phase::Complete);
        assert_eq!(z.sample(f64::NAN).s, 0.0);
        let p = Trapezoid::new(10.0, 1.0, 1.0, 1.0).unwrap();
        let s = p.sample(f64::NAN);
        assert_eq!((s.s, s.v, s.phase), (0.0, 0.0, Phase::Accel));
    }
}
