//! The pendant's own series: the X-SEL's work position (and the tool tip's speed from
//! successive polls) from each 2A1H, and each RMC axis's status from each poll, an hour of
//! each at the polling rate; and the captures its moves trigger.

use std::time::Instant;

use super::capture::{Captures, Roles, Trigger};
use super::{Channel, Encoding, Sample, SampleStore, SeriesId};
use crate::rmc::{AxisId, AxisStatus, Command, StatusBits, TgPhase};

/// The channels of an RMC axis's series, in order.
pub mod rmc_channel {
    pub const COMMAND_POSITION: usize = 0;
    pub const TARGET_POSITION: usize = 1;
    pub const ACTUAL_POSITION: usize = 2;
    pub const TARGET_VELOCITY: usize = 3;
    pub const ACTUAL_VELOCITY: usize = 4;
    pub const FOLLOWING_ERROR: usize = 5;
    pub const IN_POSITION: usize = 6;
    pub const TG_PHASE: usize = 7;
    pub const ACK: usize = 8;
}

/// The X-SEL work series' channels after X, Y, Z, R.
pub mod xsel_channel {
    pub const SPEED: usize = 4;
    pub const IN_POSITION: usize = 5;
    pub const MOTION_PHASE: usize = 6;
}

/// The pendant's motion phase of the X-SEL's move as a level: 0 idle, 1 accelerating,
/// 2 constant, 3 decelerating, 4 done, 5 jogging, 6 stopped [I: from the move's planned
/// profile and the controller's answers; the controller reports no phase].
pub fn phase_level(phase: crate::pendant::MotionPhase) -> u8 {
    use crate::pendant::MotionPhase::*;
    match phase {
        Idle => 0,
        Accelerating => 1,
        Constant => 2,
        Decelerating => 3,
        Done => 4,
        Jogging => 5,
        Stopped => 6,
    }
}

/// Rows kept per series: an hour at 50 polls a second (the RMC's round is 20 ms; the
/// X-SEL's work position comes less often).
pub const HOUR_ROWS: usize = 3600 * 50;

/// The store and where each device's samples go.
#[derive(Clone, Debug)]
pub struct Polled {
    pub store: SampleStore,
    pub captures: Captures,
    xsel: SeriesId,
    joints: SeriesId,
    rmc: Vec<SeriesId>,
    /// The last work pose and its time, for the tool tip's speed.
    last_pose: Option<(Instant, [i32; 4])>,
    /// A series per plotted signal, made at its first sample.
    signals: std::collections::HashMap<crate::pendant::signals::Signal, SeriesId>,
}

/// Rows kept per plotted signal: an hour of reads at 10 rounds a second (the signals'
/// round starts at most every [`crate::pendant::signals::MIN_ROUND`]).
pub const SIGNAL_ROWS: usize = 3600 * 10;

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
                Channel::new("Tool-tip speed", "mm/s"),
                Channel::level("In position"),
                Channel::levels("Motion phase", 6),
            ],
            Encoding::Milli,
            HOUR_ROWS,
        );
        let joints = store.add(
            "X-SEL joints",
            vec![
                Channel::new("J1", "deg"),
                Channel::new("J2", "deg"),
                Channel::new("J3", "mm"),
                Channel::new("J4", "deg"),
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
                        Channel::levels("TG phase", 3),
                        Channel::level("ACK"),
                    ],
                    Encoding::Real,
                    HOUR_ROWS,
                )
            })
            .collect();
        Self {
            store,
            captures: Captures::default(),
            xsel,
            joints,
            rmc,
            last_pose: None,
            signals: Default::default(),
        }
    }

    /// A 2A1H reply in the work system: X, Y, Z, R in thousandths. The tool tip's speed
    /// is the XYZ distance from the last poll over the time between them [I: polled
    /// positions, so a move shorter than a poll interval reads slower than it ran].
    pub fn xsel_work(&mut self, at: Instant, pose: [i32; 4], in_position: bool, phase: u8) {
        let speed = self.last_pose.map_or(0, |(t, last)| {
            let dt = at.saturating_duration_since(t).as_secs_f64();
            let d = (0..3)
                .map(|i| f64::from(pose[i] - last[i]).powi(2))
                .sum::<f64>()
                .sqrt();
            if dt > 0.0 { (d / dt).round() as i32 } else { 0 }
        });
        self.last_pose = Some((at, pose));
        let [x, y, z, r] = pose.map(Sample::Milli);
        let levels = [Sample::Level(u8::from(in_position)), Sample::Level(phase)];
        let values = [x, y, z, r, Sample::Milli(speed), levels[0], levels[1]];
        self.store.push(self.xsel, at, &values);
    }

    /// Values of plotted signals as read: a series each, named by its row (a bit a
    /// level, a number a value), on the same clock as the positions.
    pub fn signal_samples(&mut self, samples: Vec<crate::pendant::signals::SignalSample>) {
        for s in samples {
            let store = &mut self.store;
            let id = *self.signals.entry(s.signal).or_insert_with(|| {
                let channel = if s.bit {
                    Channel::level("state")
                } else {
                    Channel::new("value", "")
                };
                store.add(s.label.clone(), vec![channel], Encoding::Real, SIGNAL_ROWS)
            });
            let value = if s.bit {
                Sample::Level(u8::from(s.value != 0.0))
            } else {
                Sample::Real(s.value as f32)
            };
            self.store.push(id, s.at, &[value]);
        }
    }

    /// A 2A1H reply in the joint system: J1, J2, J3, J4 in thousandths.
    pub fn xsel_joints(&mut self, at: Instant, joints: [i32; 4]) {
        self.store.push(self.joints, at, &joints.map(Sample::Milli));
    }

    /// The X-SEL accepted a move at `at`: a capture of the work position, read on
    /// `channel` (0-3: X, Y, Z, R, the coordinate the move changes most).
    pub fn xsel_moved(&mut self, at: Instant, label: String, channel: usize) {
        self.captures.trigger(Trigger {
            at,
            label,
            series: self.xsel,
            roles: Roles {
                actual: channel.min(3),
                in_position: Some(xsel_channel::IN_POSITION),
                ..Roles::default()
            },
        });
    }

    /// A motion command went out to an RMC axis at `at`: a capture of its status.
    pub fn rmc_moved(&mut self, at: Instant, axis: AxisId, command: &Command) {
        let Some(series) = self.rmc_series(axis) else {
            return;
        };
        let what = match command {
            Command::MoveRelative(m) => format!(
                "Move Relative {} relative to {}",
                m.distance,
                m.relative_to.name()
            ),
            Command::MoveAbsolute(m) => format!("Move Absolute to {}", m.position),
            other => other.name().to_string(),
        };
        use rmc_channel::*;
        self.captures.trigger(Trigger {
            at,
            label: format!("{axis}: {what}"),
            series,
            roles: Roles {
                actual: ACTUAL_POSITION,
                command: Some(COMMAND_POSITION),
                in_position: Some(IN_POSITION),
                phase: Some(TG_PHASE),
            },
        });
    }

    /// Takes the captures whose samples are in.
    pub fn poll_captures(&mut self, now: Instant) {
        if self.captures.waiting() {
            let companions: Vec<SeriesId> = self.signals.values().copied().collect();
            self.captures.poll(&self.store, now, &companions);
        }
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
