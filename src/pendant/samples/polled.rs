//! The pendant's own series: the X-SEL's work position from each 2A1H, and each RMC
//! axis's status from each poll, an hour of each at the polling rate.

use std::time::Instant;

use super::{Channel, Encoding, Sample, SampleStore, SeriesId};
use crate::rmc::{AxisId, AxisStatus, StatusBits, TgPhase};

/// Rows kept per series: an hour at 50 polls a second (the RMC's round is 20 ms; the
/// X-SEL's work position comes less often).
pub const HOUR_ROWS: usize = 3600 * 50;

/// The store and where each device's samples go.
#[derive(Clone, Debug)]
pub struct Polled {
    pub store: SampleStore,
    xsel: SeriesId,
    rmc: Vec<SeriesId>,
}

impl Polled {
    pub fn new(rmc_axes: usize) -> Self {
        let mut store = SampleStore::default();
        let xsel = store.add(
            "X-SEL work position",
            vec![
                Channel::new("X", "mm"),
                Channel::new("Y", "mm"),
                Channel::new("Z", "mm"),
                Channel::new("R", "deg"),
            ],
            Encoding::Milli,
            HOUR_ROWS,
        );
        let rmc = AxisId::first(rmc_axes)
            .map(|axis| {
                store.add(
                    axis.to_string(),
                    vec![
                        Channel::new("Command Position", "pu"),
                        Channel::new("Target Position", "pu"),
                        Channel::new("Actual Position", "pu"),
                        Channel::new("Target Velocity", "pu/s"),
                        Channel::new("Actual Velocity", "pu/s"),
                        Channel::new("Following Error", "pu"),
                        Channel::level("In Position"),
                        Channel::level("TG phase"),
                        Channel::level("ACK"),
                    ],
                    Encoding::Real,
                    HOUR_ROWS,
                )
            })
            .collect();
        Self { store, xsel, rmc }
    }

    /// A 2A1H reply in the work system: X, Y, Z, R in thousandths.
    pub fn xsel_work(&mut self, at: Instant, pose: [i32; 4]) {
        let values = pose.map(Sample::Milli);
        self.store.push(self.xsel, at, &values);
    }

    /// An RMC axis's status as polled.
    pub fn rmc_status(&mut self, at: Instant, axis: AxisId, s: &AxisStatus) {
        let Some(id) = self.rmc.get(axis.index()).copied() else {
            return;
        };
        let phase = match s.bits.phase() {
            TgPhase::Complete => 0,
            TgPhase::Accelerating => 1,
            TgPhase::ConstantVelocity => 2,
            TgPhase::Decelerating => 3,
        };
        let values = [
            Sample::Real(s.command_position),
            Sample::Real(s.target_position),
            Sample::Real(s.actual_position),
            Sample::Real(s.target_velocity),
            Sample::Real(s.actual_velocity),
            Sample::Real(s.following_error()),
            Sample::Level(u8::from(s.bits.in_position())),
            Sample::Level(phase),
            Sample::Level(u8::from(s.bits.bit(StatusBits::ACK))),
        ];
        self.store.push(id, at, &values);
    }

    /// The series of an RMC axis, if it has one.
    pub fn rmc_series(&self, axis: AxisId) -> Option<SeriesId> {
        self.rmc.get(axis.index()).copied()
    }

    pub fn xsel_series(&self) -> SeriesId {
        self.xsel
    }
}
