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
        match self.axes.get_mut(axis.index()) {
            Some(a) => {
                a.run(command);
                true
            }
            None => false,
        }
    }
}
