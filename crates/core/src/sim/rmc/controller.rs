//! The simulated RMC151E, sans-IO: every axis, the loop run up to the time passed in, and
//! the commands each axis receives.

use std::time::{Duration, Instant};

use super::axis::Axis;
use super::profile::LOOP_S;
use crate::rmc::{AxisId, AxisStatus, Command, MAX_AXES};

/// The loop time as a Duration (1 ms).
pub const LOOP: Duration = Duration::from_micros((LOOP_S * 1e6) as u64);

/// What the simulated controller has.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RmcConfig {
    /// Axes, 1..=8 (values outside are brought inside).
    pub axes: usize,
    /// Soft travel limits (negative, positive), pu, the same for every axis.
    pub travel: (f32, f32),
}

impl Default for RmcConfig {
    fn default() -> Self {
        Self {
            axes: 2,
            travel: (-1000.0, 1000.0),
        }
    }
}

/// Every axis and the controller's registers; time comes in as `now` arguments.
#[derive(Clone, Debug)]
pub struct RmcController {
    pub(super) axes: Vec<Axis>,
    /// PROGRAM mode (Controller Status bit 0 clear): motion commands are refused.
    pub(super) program_mode: bool,
    /// When the last loop ran (loops run on a 1 ms grid from `new`'s `now`).
    last: Instant,
}

impl RmcController {
    pub fn new(config: RmcConfig, now: Instant) -> Self {
        let count = config.axes.clamp(1, MAX_AXES);
        let (a, b) = config.travel;
        let travel = if a <= b { (a, b) } else { (b, a) };
        Self {
            axes: (0..count).map(|_| Axis::new(travel)).collect(),
            program_mode: false,
            last: now,
        }
    }

    pub fn axis_count(&self) -> usize {
        self.axes.len()
    }

    /// Runs the loop (1 ms loop time) up to `now`; an earlier `now` does nothing. Loops in
    /// which nothing can change are skipped at once, so a long idle gap costs nothing.
    pub fn advance(&mut self, now: Instant) {
        while now.saturating_duration_since(self.last) >= LOOP {
            if !self.axes.iter().any(Axis::active) {
                let behind = now.saturating_duration_since(self.last);
                let loops = behind.as_nanos() / LOOP.as_nanos();
                self.last += LOOP * u32::try_from(loops).unwrap_or(u32::MAX);
                return;
            }
            self.last += LOOP;
            for axis in &mut self.axes {
                axis.step();
            }
        }
    }

    /// An axis's status file, ACK clear (ACK is per connection); `None` beyond the count.
    pub fn status(&self, axis: AxisId) -> Option<AxisStatus> {
        self.axes.get(axis.index()).map(Axis::status)
    }

    /// When the next loop will change something by itself (a move or a stop runs, Actual
    /// still settles); `None` when every axis is still.
    pub fn next_change(&self) -> Option<Instant> {
        self.axes
            .iter()
            .any(Axis::active)
            .then_some(self.last + LOOP)
    }

    /// Runs a command on an axis now (at the last loop [`advance`](Self::advance) ran);
    /// false when the axis is beyond the count.
    pub fn command(&mut self, axis: AxisId, command: Command) -> bool {
        let program = self.program_mode;
        match self.axes.get_mut(axis.index()) {
            Some(a) if program && command.moves() => {
                a.last_error = super::axis::ERROR_PROGRAM_MODE;
                true
            }
            Some(a) => {
                a.run(command);
                true
            }
            None => false,
        }
    }

    /// What an operator does at the simulated controller (its console): false when the
    /// axis is beyond the count.
    pub fn operate(&mut self, action: RmcAction) -> bool {
        match action {
            RmcAction::FaultInput(axis, on) => self
                .axes
                .get_mut(axis.index())
                .map(|a| a.set_fault_input(on))
                .is_some(),
            RmcAction::FollowingError(axis) => self
                .axes
                .get_mut(axis.index())
                .map(Axis::following_error)
                .is_some(),
            RmcAction::Program(on) => {
                self.program_mode = on;
                true
            }
        }
    }

    /// Controller Status Bits: RUN (bit 0) unless in PROGRAM mode, Controller Enabled (bit 1).
    pub fn controller_status(&self) -> u32 {
        if self.program_mode { 0b10 } else { 0b11 }
    }
}

/// An operator's action at the simulated RMC151.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum RmcAction {
    /// The axis's Fault Input on or off.
    FaultInput(AxisId, bool),
    /// A following error on the axis.
    FollowingError(AxisId),
    /// PROGRAM mode (true) or RUN (false).
    Program(bool),
}

impl RmcAction {
    /// Reads a console line: `fault AXIS on|off`, `ferror AXIS`, `program`, `run` (axes
    /// numbered from 1, as people count them).
    pub fn parse(line: &str) -> Result<RmcAction, String> {
        let words: Vec<&str> = line.split_whitespace().collect();
        let axis = |w: Option<&&str>| -> Result<AxisId, String> {
            let w = w.ok_or("name the axis (1-8)")?;
            w.parse::<usize>()
                .ok()
                .and_then(|n| n.checked_sub(1))
                .and_then(AxisId::new)
                .ok_or_else(|| format!("`{w}` is not an axis (1-8)"))
        };
        match words.first().copied() {
            Some("fault") => {
                let a = axis(words.get(1))?;
                match words.get(2).copied() {
                    Some("on") => Ok(RmcAction::FaultInput(a, true)),
                    Some("off") => Ok(RmcAction::FaultInput(a, false)),
                    _ => Err("fault AXIS on|off".into()),
                }
            }
            Some("ferror") => Ok(RmcAction::FollowingError(axis(words.get(1))?)),
            Some("program") => Ok(RmcAction::Program(true)),
            Some("run") => Ok(RmcAction::Program(false)),
            Some(other) => Err(format!(
                "`{other}` is not a console command (help lists them)"
            )),
            None => Err("an empty line".into()),
        }
    }
}
