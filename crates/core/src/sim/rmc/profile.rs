//! One axis's target generator, one loop at a time: a trapezoidal profile onto the
//! Command Position, a Stop (Closed Loop) ramp, and the first-order lag Actual follows.

use crate::rmc::TgPhase;

/// The loop time, seconds (an RMC150E runs 0.25-4 ms, RMC.md section 4; the simulator 1 ms).
pub const LOOP_S: f64 = 0.001;
/// Actual Position's lag behind Target, seconds (a first-order response).
pub const LAG_S: f64 = 0.010;
/// Velocities below this are equal (pu/s): phase changes ignore rounding.
const SAME_SPEED: f64 = 1e-9;
/// Actual within this of Target (pu) is taken as settled: it jumps there and stops.
const SETTLED: f64 = 1e-6;

/// What the generator is doing.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Drive {
    /// Not generating: Target holds still.
    Idle,
    /// Moving onto the Command Position with this speed, acceleration and deceleration.
    Move { speed: f64, accel: f64, decel: f64 },
    /// Stop (Closed Loop) (6): decelerating at this rate to a stop.
    Stop { decel: f64 },
}

/// Target and Actual of one axis, in f64 inside (reported as REALs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Profile {
    pub drive: Drive,
    pub command: f64,
    pub target: f64,
    pub velocity: f64,
    pub acceleration: f64,
    pub phase: TgPhase,
    pub actual: f64,
    pub actual_velocity: f64,
}

/// What one loop did that the axis must know of.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Event {
    None,
    /// A Stop (6) ramp ended: Command Position is now the Target.
    Stopped,
}

impl Profile {
    pub fn at(position: f64) -> Self {
        Self {
            drive: Drive::Idle,
            command: position,
            target: position,
            velocity: 0.0,
            acceleration: 0.0,
            phase: TgPhase::Complete,
            actual: position,
            actual_velocity: 0.0,
        }
    }

    /// Whether a loop would change anything (the generator runs or Actual still lags).
    pub fn active(&self) -> bool {
        self.drive != Drive::Idle || self.actual != self.target || self.actual_velocity != 0.0
    }

    /// Target stops where it is, at once (a halt): velocity 0, phase complete.
    pub fn halt(&mut self) {
        self.drive = Drive::Idle;
        self.velocity = 0.0;
        self.acceleration = 0.0;
        self.phase = TgPhase::Complete;
    }

    /// One loop of the target generator, then of Actual's lag.
    pub fn step(&mut self) -> Event {
        let before = self.velocity;
        let event = match self.drive {
            Drive::Idle => Event::None,
            Drive::Move {
                speed,
                accel,
                decel,
            } => {
                self.step_move(speed, accel, decel);
                Event::None
            }
            Drive::Stop { decel } => self.step_stop(decel),
        };
        self.acceleration = (self.velocity - before) / LOOP_S;
        self.follow();
        event
    }

    /// Trapezoid onto `command`: accelerate to `speed`, cruise, and decelerate along the
    /// fastest speed from which a stop at `decel` still ends on it after this loop
    /// (v · dt + v² / (2 · decel) = remaining), landing on it exactly. A move that cannot
    /// stop in time, or that points back, decelerates first and comes back.
    fn step_move(&mut self, speed: f64, accel: f64, decel: f64) {
        let remaining = self.command - self.target;
        let dir = if remaining >= 0.0 { 1.0 } else { -1.0 };
        let rem = remaining.abs();
        let along = self.velocity * dir; // towards the command; negative when away
        let brake = decel * LOOP_S;
        let next = if along < 0.0 {
            (along + brake).min(0.0)
        } else {
            let up = if along <= speed {
                (along + accel * LOOP_S).min(speed)
            } else {
                (along - brake).max(speed)
            };
            let curve = decel * (-LOOP_S + (LOOP_S * LOOP_S + 2.0 * rem / decel).sqrt());
            up.min(curve).max(along - brake).max(0.0)
        };
        let slow = brake * (1.0 + 1e-9);
        // Reached in this loop without braking harder than `decel`; or the curve's tail,
        // which would only creep closer.
        let lands = along >= 0.0
            && ((next * LOOP_S >= rem && next <= slow)
                || (along <= slow
                    && (next < along || next == 0.0)
                    && rem <= 0.5 * brake * LOOP_S * (1.0 + 1e-6)));
        if lands {
            self.target = self.command;
            self.velocity = 0.0;
            self.drive = Drive::Idle;
            self.phase = TgPhase::Complete;
            return;
        }
        self.phase = if along < 0.0 || next < along - SAME_SPEED {
            TgPhase::Decelerating
        } else if next > along + SAME_SPEED {
            TgPhase::Accelerating
        } else if (next - speed).abs() <= SAME_SPEED {
            TgPhase::ConstantVelocity
        } else {
            self.phase
        };
        self.velocity = next * dir;
        self.target += self.velocity * LOOP_S;
    }

    /// Stop (Closed Loop) (6): velocity falls at `decel` to 0; then Command = Target [I].
    fn step_stop(&mut self, decel: f64) -> Event {
        let speed = (self.velocity.abs() - decel * LOOP_S).max(0.0);
        self.velocity = speed * self.velocity.signum();
        self.target += self.velocity * LOOP_S;
        if speed == 0.0 {
            self.velocity = 0.0;
            self.drive = Drive::Idle;
            self.phase = TgPhase::Complete;
            self.command = self.target;
            Event::Stopped
        } else {
            self.phase = TgPhase::Decelerating;
            Event::None
        }
    }

    /// Actual follows Target with a first-order lag of [`LAG_S`].
    fn follow(&mut self) {
        let gain = 1.0 - (-LOOP_S / LAG_S).exp();
        let before = self.actual;
        self.actual += (self.target - self.actual) * gain;
        if (self.target - self.actual).abs() < SETTLED && self.drive == Drive::Idle {
            self.actual = self.target;
        }
        self.actual_velocity = (self.actual - before) / LOOP_S;
    }
}
