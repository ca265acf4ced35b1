//! Message handlers, one file per family; shared field parsing and precondition checks.

// Axis loops index several per-axis arrays by the axis number: clearer than zips.
#![allow(clippy::needless_range_loop)]

mod axis;
mod coords;
mod scara;
mod status;
mod system;

use super::controller::Controller;
use super::errors::SimError;
use super::framing::hex_value;
use super::state::Mode;

/// Reads fixed-width hex fields from a command's data, left to right.
pub(crate) struct Fields<'a> {
    data: &'a [u8],
    pos: usize,
}

impl<'a> Fields<'a> {
    pub(crate) fn new(data: &'a [u8]) -> Self {
        Self { data, pos: 0 }
    }

    /// An unsigned field of `width` hex digits.
    pub(crate) fn hex(&mut self, width: usize) -> Result<u32, SimError> {
        let end = self.pos + width;
        let digits = self.data.get(self.pos..end).ok_or(SimError::WrongLength)?;
        self.pos = end;
        hex_value(digits).ok_or(SimError::BadValue)
    }

    pub(crate) fn u8(&mut self, width: usize) -> Result<u8, SimError> {
        Ok(self.hex(width)? as u8)
    }

    pub(crate) fn u16(&mut self, width: usize) -> Result<u16, SimError> {
        Ok(self.hex(width)? as u16)
    }

    /// A signed 32-bit value as 8 hex digits, two's complement (PROTOCOL.md 4).
    pub(crate) fn i32(&mut self) -> Result<i32, SimError> {
        Ok(self.hex(8)? as i32)
    }
}

/// Checks the data length exactly.
pub(crate) fn expect_len(data: &[u8], len: usize) -> Result<(), SimError> {
    if data.len() == len {
        Ok(())
    } else {
        Err(SimError::WrongLength)
    }
}

/// Number of set bits of an axis pattern.
pub(crate) fn bits(pattern: u8) -> usize {
    pattern.count_ones() as usize
}

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
