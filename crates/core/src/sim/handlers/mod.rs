//! Message handlers, one file per family, taking the protocol's typed commands; shared
//! precondition checks.

// Axis loops index several per-axis arrays by the axis number: clearer than zips.
#![allow(clippy::needless_range_loop)]

mod axis;
mod coords;
mod positions;
mod programs;
mod scara;
mod signals;
mod status;
mod system;
mod zones;

use super::controller::Controller;
use super::errors::SimError;
use super::state::Mode;
use axis::SCARA;

pub use positions::{MAX_POSITIONS_3_DIGIT, MAX_POSITIONS_4_DIGIT};

impl Controller {
    /// Refusals shared by every command that acts (moves, servo, home, speed change):
    /// mode, emergency stop, drive cut-off, pending alarm.
    pub(crate) fn check_can_act(&self) -> Result<(), SimError> {
        if self.mode == Mode::Manual {
            return Err(SimError::ManualMode);
        }
        if self.estop {
            return Err(SimError::EmergencyStop);
        }
        if self.drive_cut {
            return Err(SimError::DriveCutOff);
        }
        if self.alarm.is_some() {
            return Err(SimError::AlarmPending);
        }
        Ok(())
    }

    /// The pattern names only axes this controller has, and at least one.
    pub(crate) fn check_pattern(&self, pattern: u8) -> Result<(), SimError> {
        if pattern == 0 || pattern & !self.present() != 0 {
            return Err(SimError::BadAxis);
        }
        Ok(())
    }

    /// Axes a new command may not take: those in use, and the whole SCARA (axes 1-4) while
    /// any of its axes is in use (moving, homing, switching servo). The arm's joints move
    /// together, so one SCARA axis is never commanded while another one works.
    pub(crate) fn busy_axes(&self) -> u8 {
        let in_use = self.in_use();
        if in_use & SCARA != 0 {
            in_use | SCARA
        } else {
            in_use
        }
    }

    /// Axes about to move: servo on, homed, not busy.
    pub(crate) fn check_ready_to_move(&self, pattern: u8) -> Result<(), SimError> {
        self.check_ready(pattern, true)
    }

    /// Axes about to jog or inch in the each-axis system: servo on, not busy. A relative
    /// joint move needs no reference, so no homing `[inferred, PROTOCOL.md 3.7]`.
    pub(crate) fn check_ready_to_jog_joint(&self, pattern: u8) -> Result<(), SimError> {
        self.check_ready(pattern, false)
    }

    fn check_ready(&self, pattern: u8, homed: bool) -> Result<(), SimError> {
        self.check_can_act()?;
        let in_use = self.busy_axes();
        for i in 0..8 {
            if pattern & (1 << i) == 0 {
                continue;
            }
            let a = &self.axes[i];
            if in_use & (1 << i) != 0 {
                return Err(SimError::AxisBusy);
            }
            // Axes a started program holds are its own (the program's moves pass).
            if self.programs.held_by_others(self.acting) & (1 << i) != 0 {
                return Err(SimError::AxisBusy);
            }
            if !a.servo {
                return Err(SimError::ServoOff);
            }
            if homed && !a.is_homed() {
                return Err(SimError::NotHomed);
            }
        }
        Ok(())
    }
}
