//! One simulated RMC axis: the commands it runs (RMC.md section 4), its soft travel
//! limits and latched Error Bits, and its status file as a host reads it.

use super::profile::{Drive, Event, Profile};
use crate::rmc::{AxisStatus, Command, ErrorBits, MoveRelative, StatusBits, TgPhase};
use crate::robot::RelativeTo;

/// Last Error Number after a motion command to an axis that is not enabled. The
/// simulator's own code [U: the RMC's numbers for this are not documented here].
pub const ERROR_NOT_ENABLED: f32 = 101.0;
/// Last Error Number after a command with a speed, acceleration or deceleration that is
/// not a number > 0 (the command is ignored). The simulator's own code [U].
pub const ERROR_BAD_PARAMETER: f32 = 102.0;
/// Last Error Number after a motion command while the controller is in PROGRAM mode. The
/// simulator's own code and behaviour [U: what PROGRAM mode does to host commands is open,
/// RMC.md section 7].
pub const ERROR_PROGRAM_MODE: f32 = 103.0;
/// In Position Tolerance at power-up, pu (RMC.md section 2).
pub const DEFAULT_TOLERANCE: f32 = 0.05;

/// One axis's state.
#[derive(Clone, Debug, PartialEq)]
pub struct Axis {
    pub profile: Profile,
    pub enabled: bool,
    pub halted: bool,
    /// In Position stays clear after a Stop (6) or a halt until the next motion command
    /// (RMC.md section 3).
    pub no_in_position: bool,
    pub errors: ErrorBits,
    pub last_error: f32,
    /// The speed of the last motion command (Command Velocity).
    pub command_velocity: f32,
    pub scale: f32,
    pub offset: f32,
    pub tolerance: f32,
    /// Soft travel limits (negative, positive), pu.
    pub travel: (f32, f32),
    /// The Fault Input is active (an operator's fault on the simulator's console).
    pub fault_input: bool,
}

impl Axis {
    pub fn new(travel: (f32, f32)) -> Self {
        Self {
            profile: Profile::at(0.0),
            enabled: false,
            halted: false,
            no_in_position: false,
            errors: ErrorBits::default(),
            last_error: 0.0,
            command_velocity: 0.0,
            scale: 1.0,
            offset: 0.0,
            tolerance: DEFAULT_TOLERANCE,
            travel,
            fault_input: false,
        }
    }

    /// Runs a command the moment it is received (RMC.md section 4: "immediately").
    pub fn run(&mut self, command: Command) {
        match command {
            Command::NoOp | Command::Other(_) => {}
            Command::ClosedLoopHalt => self.halt(),
            Command::ClearFaults => self.clear_faults(),
            Command::HoldCurrentPosition { .. } => {
                let p = &mut self.profile;
                p.halt();
                p.target = p.actual;
                p.command = p.actual;
            }
            Command::Stop { decel } => {
                if !(decel.is_finite() && decel > 0.0) {
                    self.last_error = ERROR_BAD_PARAMETER;
                } else if self.profile.drive != Drive::Idle || self.profile.velocity != 0.0 {
                    self.profile.drive = Drive::Stop {
                        decel: f64::from(decel),
                    };
                    self.profile.phase = TgPhase::Decelerating;
                    self.no_in_position = true;
                } else {
                    // Already still: the stop has nothing to ramp down.
                    self.profile.command = self.profile.target;
                    self.no_in_position = true;
                }
            }
            Command::MoveRelative(m) => self.move_relative(m),
            // Move Absolute is Move Relative to the position from 0 (RMC.md section 4).
            Command::MoveAbsolute(m) => self.move_to(0.0, m.position, [m.speed, m.accel, m.decel]),
            Command::Enable(on) => {
                self.enabled = on;
                if !on {
                    self.profile.halt();
                }
            }
        }
    }

    fn move_relative(&mut self, m: MoveRelative) {
        // The chosen quantity's value as reported, when the command is received [V]; the
        // sum in f32 as a host computes it from what it reads.
        let from = match m.relative_to {
            RelativeTo::Command => self.profile.command,
            RelativeTo::Actual => self.profile.actual,
            RelativeTo::Target => self.profile.target,
        } as f32;
        self.move_to(from, m.distance, [m.speed, m.accel, m.decel]);
    }

    /// A move to `from + distance` at `[speed, accel, decel]`, if the axis may move.
    fn move_to(&mut self, from: f32, distance: f32, [speed, accel, decel]: [f32; 3]) {
        if !self.enabled {
            // Until enabled, an axis accepts no motion command (RMC.md section 4).
            self.last_error = ERROR_NOT_ENABLED;
            return;
        }
        let good = |v: f32| v.is_finite() && v > 0.0;
        if !(distance.is_finite() && good(speed) && good(accel) && good(decel)) {
            self.last_error = ERROR_BAD_PARAMETER;
            return;
        }
        self.clear_faults();
        self.no_in_position = false;
        self.command_velocity = speed;
        let p = &mut self.profile;
        p.command = f64::from(from + distance);
        p.drive = Drive::Move {
            speed: f64::from(speed),
            accel: f64::from(accel),
            decel: f64::from(decel),
        };
        if p.velocity == 0.0 && p.target != p.command {
            // From rest the first loop accelerates; a moving target keeps its phase.
            p.phase = TgPhase::Accelerating;
        }
    }

    /// The Fault Input comes on (Error Bit 3 latched and an Auto Stop) or goes off (the
    /// bit then clears at the next Clear Faults or motion command).
    pub fn set_fault_input(&mut self, on: bool) {
        self.fault_input = on;
        if on {
            self.errors = ErrorBits(self.errors.0 | (1 << ErrorBits::FAULT_INPUT));
            self.halt();
        }
    }

    /// A following error (Error Bit 0) as the servo loop would report it: an Auto Stop.
    pub fn following_error(&mut self) {
        self.errors = ErrorBits(self.errors.0 | (1 << ErrorBits::FOLLOWING_ERROR));
        self.halt();
    }

    /// Closed Loop Halt (1), or an Auto Stop: Target stops at once, Halted set.
    fn halt(&mut self) {
        self.profile.halt();
        self.halted = true;
        self.no_in_position = true;
    }

    /// Clears Halted and the error bits whose cause is gone (Clear Faults (4), or a
    /// motion command).
    fn clear_faults(&mut self) {
        self.halted = false;
        let mut still = 0;
        if self.errors.bit(ErrorBits::FAULT_INPUT) && self.fault_input {
            still |= 1 << ErrorBits::FAULT_INPUT;
            self.halted = true;
        }
        if self.errors.bit(ErrorBits::POSITIVE_LIMIT) && self.beyond_positive() {
            still |= 1 << ErrorBits::POSITIVE_LIMIT;
        }
        if self.errors.bit(ErrorBits::NEGATIVE_LIMIT) && self.beyond_negative() {
            still |= 1 << ErrorBits::NEGATIVE_LIMIT;
        }
        self.errors = ErrorBits(still);
    }

    fn beyond_positive(&self) -> bool {
        self.profile.target >= f64::from(self.travel.1)
    }

    fn beyond_negative(&self) -> bool {
        self.profile.target <= f64::from(self.travel.0)
    }

    /// Whether a loop would change anything.
    pub fn active(&self) -> bool {
        self.profile.active()
    }

    /// One loop: the generator steps; a Target past a soft limit halts there with the
    /// limit's error bit (an Auto Stop, RMC.md section 3).
    pub fn step(&mut self) {
        let was_moving = self.profile.drive != Drive::Idle;
        if self.profile.step() == Event::Stopped {
            self.no_in_position = true;
        }
        if !was_moving {
            return;
        }
        let (low, high) = (f64::from(self.travel.0), f64::from(self.travel.1));
        let bit = if self.profile.target > high {
            self.profile.target = high;
            ErrorBits::POSITIVE_LIMIT
        } else if self.profile.target < low {
            self.profile.target = low;
            ErrorBits::NEGATIVE_LIMIT
        } else {
            return;
        };
        self.errors = ErrorBits(self.errors.0 | (1 << bit));
        self.halt();
    }

    /// The status file as read, ACK clear (ACK is the reading connection's).
    pub fn status(&self) -> AxisStatus {
        let p = &self.profile;
        let tg_done = p.target == p.command;
        let in_position = tg_done
            && !self.no_in_position
            && !self.halted
            && (p.actual - p.command).abs() < f64::from(self.tolerance);
        let stopped = p.drive == Drive::Idle && p.velocity == 0.0 && p.actual_velocity == 0.0;
        let phase = if p.drive == Drive::Idle {
            TgPhase::Complete
        } else {
            p.phase
        };
        let bits = StatusBits(0)
            .with(StatusBits::IN_POSITION, in_position)
            .with(StatusBits::STOPPED, stopped)
            .with(StatusBits::ENABLE_OUTPUT, self.enabled)
            .with(StatusBits::TG_DONE, tg_done)
            .with(StatusBits::ENABLED, self.enabled)
            .with(StatusBits::HALTED, self.halted)
            .with(StatusBits::FAULT_INPUT, self.fault_input)
            .with_phase(phase);
        AxisStatus {
            bits,
            errors: self.errors,
            last_error: self.last_error,
            actual_position: p.actual as f32,
            actual_velocity: p.actual_velocity as f32,
            target_position: p.target as f32,
            target_velocity: p.velocity as f32,
            target_acceleration: p.acceleration as f32,
            command_position: p.command as f32,
            command_velocity: self.command_velocity,
        }
    }
}
