//! Message handlers, one file per family, taking the protocol's typed commands; shared
//! precondition checks.

// Axis loops index several per-axis arrays by the axis number: clearer than zips.
#![allow(clippy::needless_range_loop)]

mod axis;
mod coords;
mod scara;
mod status;
mod system;

use super::controller::Controller;
use super::errors::SimError;
use super::state::Mode;

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

    /// Axes about to move: servo on, homed, not in use.
    pub(crate) fn check_ready_to_move(&self, pattern: u8) -> Result<(), SimError> {
        self.check_can_act()?;
        let in_use = self.in_use();
        for i in 0..8 {
            if pattern & (1 << i) == 0 {
                continue;
            }
            let a = &self.axes[i];
            if in_use & (1 << i) != 0 {
                return Err(SimError::AxisBusy);
            }
            if !a.servo {
                return Err(SimError::ServoOff);
            }
            if !a.is_homed() {
                return Err(SimError::NotHomed);
            }
        }
        Ok(())
    }
}
