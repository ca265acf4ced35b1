//! The RMC151's settings kept between runs: where it is, how many axes, and the jog
//! choices of its axis panel.

use serde::{Deserialize, Serialize};

use crate::pendant::jog::JogMode;
use crate::rmc::MAX_AXES;
use crate::robot::RelativeTo;

/// The largest step or jog speed the panel sends, in position units (a typo guard).
pub const MAX_STEP: f32 = 10_000.0;

/// The RMC151 beside the robot.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct RmcSettings {
    /// Drive an RMC151 at all.
    pub enabled: bool,
    /// `host:port` of the controller (port 502 [I, RMC.md section 1]); empty: the
    /// built-in simulated RMC151.
    pub address: String,
    /// Modbus unit ID (not documented [U]; 1 by default).
    pub unit: u8,
    /// Axes shown and polled, 1-8.
    pub axes: usize,
    /// The position units' name (set in RMCTools; "pu" unless named).
    pub units: String,
    /// Stop (Closed Loop) (6)'s deceleration for STOP and release, pu/s².
    pub stop_decel: f32,
    /// "Record" in the teach list takes the RMC axes' Command Positions too.
    pub teach_axes: bool,
    pub jog: RmcJogSettings,
}

impl Default for RmcSettings {
    fn default() -> Self {
        Self {
            enabled: true,
            address: String::new(),
            unit: 1,
            axes: 2,
            units: "pu".into(),
            stop_decel: 1000.0,
            teach_axes: false,
            jog: RmcJogSettings::default(),
        }
    }
}

impl RmcSettings {
    /// STOP's deceleration, a number above 0 whatever was saved.
    pub fn stop_decel(&self) -> f32 {
        if self.stop_decel.is_finite() && self.stop_decel > 0.0 {
            self.stop_decel
        } else {
            Self::default().stop_decel
        }
    }

    /// The axis count kept within 1-8.
    pub fn axis_count(&self) -> usize {
        self.axes.clamp(1, MAX_AXES)
    }
}

/// How the axis panel's − and + move an axis.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct RmcJogSettings {
    /// One Move Relative per press, or moves while held.
    pub mode: JogMode,
    /// A step's distance, position units.
    pub step: f32,
    /// pu/s.
    pub speed: f32,
    /// pu/s².
    pub accel: f32,
    /// pu/s².
    pub decel: f32,
    /// What a step is added to (Move Relative's fifth parameter).
    pub relative_to: RelativeTo,
}

impl Default for RmcJogSettings {
    fn default() -> Self {
        Self {
            mode: JogMode::Step,
            step: 10.0,
            speed: 50.0,
            accel: 500.0,
            decel: 500.0,
            relative_to: RelativeTo::Command,
        }
    }
}

impl RmcJogSettings {
    /// Why these choices cannot be sent, if they cannot.
    pub fn check(&self) -> Result<(), String> {
        let positive = |what: &str, v: f32| {
            if v.is_finite() && v > 0.0 && v <= MAX_STEP * 100.0 {
                Ok(())
            } else {
                Err(format!("{what} must be a number above 0 (it is {v})"))
            }
        };
        positive("the speed", self.speed)?;
        positive("the acceleration", self.accel)?;
        positive("the deceleration", self.decel)?;
        if !(self.step.is_finite() && self.step > 0.0 && self.step <= MAX_STEP) {
            return Err(format!(
                "the step must be above 0 and at most {MAX_STEP} (it is {})",
                self.step
            ));
        }
        Ok(())
    }
}
