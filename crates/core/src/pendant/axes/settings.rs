//! The RMC151's settings kept between runs: where it is, how many axes, and the jog
//! choices of its axis panel.

use serde::{Deserialize, Serialize};

use crate::pendant::jog::JogMode;
use crate::rmc::{AxisId, MAX_AXES};
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
    /// The position units' name for axes without one of their own (set in RMCTools;
    /// "pu" unless named).
    pub units: String,
    /// Per axis (Axis 1 first): its units' name and soft travel limits. Axes beyond the
    /// list take the defaults.
    pub axis: Vec<RmcAxisSettings>,
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
            axis: Vec::new(),
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

    /// The name of `axis`'s position units.
    pub fn units(&self, axis: AxisId) -> &str {
        match self.axis.get(axis.index()).map(|a| a.units.trim()) {
            Some(own) if !own.is_empty() => own,
            _ => &self.units,
        }
    }

    /// `axis`'s soft travel limits (none unless set).
    pub fn limits(&self, axis: AxisId) -> SoftLimits {
        self.axis
            .get(axis.index())
            .map_or_else(SoftLimits::default, |a| a.limits)
    }

    /// `axis`'s own settings, added (with the defaults) when the list is shorter.
    pub fn axis_mut(&mut self, axis: AxisId) -> &mut RmcAxisSettings {
        if self.axis.len() <= axis.index() {
            self.axis
                .resize(axis.index() + 1, RmcAxisSettings::default());
        }
        &mut self.axis[axis.index()]
    }
}

/// One RMC axis's own settings.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct RmcAxisSettings {
    /// Its units' name (empty: the RMC's default name).
    pub units: String,
    pub limits: SoftLimits,
}

/// Travel limits the pendant keeps to on an axis, in its position units: the RMC's own
/// limits are set in RMCTools; these stop the pendant's moves short of them.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct SoftLimits {
    pub min: Option<f32>,
    pub max: Option<f32>,
}

impl SoftLimits {
    /// Why a move ending at `end` is refused, if it is.
    pub fn check_end(&self, end: f32, units: &str) -> Result<(), String> {
        if !end.is_finite() {
            return Err(format!("its end {end} is not a position"));
        }
        let beyond = [self.max.filter(|m| end > *m), self.min.filter(|m| end < *m)];
        match beyond.into_iter().flatten().next() {
            Some(limit) => Err(format!(
                "its end {end:.3} {units} is beyond the soft limit {limit:.3} {units}"
            )),
            None => Ok(()),
        }
    }

    /// The limit a motion in `sign`'s direction runs toward, if one is set.
    pub fn ahead(&self, sign: f32) -> Option<f32> {
        if sign > 0.0 { self.max } else { self.min }
    }

    /// Why the limits cannot be kept, if they cannot (min above max, not numbers).
    pub fn check(&self) -> Result<(), String> {
        for v in [self.min, self.max].into_iter().flatten() {
            if !v.is_finite() {
                return Err(format!("the soft limit {v} is not a number"));
            }
        }
        match (self.min, self.max) {
            (Some(min), Some(max)) if min >= max => Err(format!(
                "the soft limits are the wrong way round ({min} is not below {max})"
            )),
            _ => Ok(()),
        }
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
