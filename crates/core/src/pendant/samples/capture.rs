//! Captures triggered by moves, as RMCTools' plots are: each move starts one, with a
//! pre-trigger share; when its length has been polled it is copied out of the store with
//! a summary (duration, final error, overshoot, settling time to In Position). Sans-IO:
//! the trigger's time comes in, and captures complete as samples arrive.

use std::collections::VecDeque;
use std::time::{Duration, Instant};

use serde::{Deserialize, Serialize};

use super::{Channel, Encoding, SampleStore, SeriesId};

/// Captures kept in the list (the oldest go first).
pub const KEEP_CAPTURES: usize = 50;

/// How long a capture is and how much of it comes before its trigger.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct CaptureSettings {
    /// Capture moves at all.
    pub on: bool,
    /// Seconds in all.
    pub length_s: f32,
    /// The share of the length before the trigger, 0 to 0.9.
    pub pre_share: f32,
}

impl Default for CaptureSettings {
    fn default() -> Self {
        Self {
            on: true,
            length_s: 4.0,
            pre_share: 0.2,
        }
    }
}

impl CaptureSettings {
    /// The span before and after the trigger, with the settings kept within bounds.
    pub fn spans(&self) -> (Duration, Duration) {
        let length = if self.length_s.is_finite() {
            self.length_s.clamp(0.1, 600.0)
        } else {
            4.0
        };
        let share = if self.pre_share.is_finite() {
            self.pre_share.clamp(0.0, 0.9)
        } else {
            0.2
        };
        let pre = Duration::from_secs_f32(length * share);
        (pre, Duration::from_secs_f32(length) - pre)
    }
}

/// Which channels of a series the summary reads.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Roles {
    /// Where the axis is: its Actual Position (or the X-SEL's moved coordinate).
    pub actual: usize,
    /// Where it was sent (Command Position), when the device reports it.
    pub command: Option<usize>,
    /// The In Position bit.
    pub in_position: Option<usize>,
    /// The target generator's phase (0 complete).
    pub phase: Option<usize>,
}

/// What started a capture.
#[derive(Clone, Debug, PartialEq)]
pub struct Trigger {
    pub at: Instant,
    /// `Axis 1: Move Relative 10 relative to command`.
    pub label: String,
    pub series: SeriesId,
    pub roles: Roles,
}

/// How a move went, read from its capture.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Summary {
    /// Where the axis was at the trigger and at the end.
    pub start: f64,
    pub end: f64,
    /// Trigger to the target generator's end (the last sample still moving, for a device
    /// without one).
    pub duration: Option<f64>,
    /// Command − Actual at the end.
    pub final_error: Option<f64>,
    /// How far the axis went past its end, in the move's direction (0 when it did not).
    pub overshoot: Option<f64>,
    /// The target generator's end to In Position (set from then to the end).
    pub settling: Option<f64>,
}

/// A move's samples from before its trigger to the capture's end.
#[derive(Clone, Debug, PartialEq)]
pub struct Capture {
    /// 1, 2, ... in the order taken (0 for one read from a file).
    pub number: u64,
    pub label: String,
    /// The series it was copied from (`Axis 1`, `X-SEL work position`).
    pub series: String,
    pub channels: Vec<Channel>,
    pub encoding: Encoding,
    /// The trigger's time since the store's origin, s.
    pub trigger_s: f64,
    /// Each sample's time from the trigger, s (negative before it).
    pub times: Vec<f64>,
    /// Per channel, one value per sample, exactly as polled.
    pub values: Vec<Vec<f64>>,
    pub roles: Roles,
    pub summary: Summary,
}

impl Capture {
    /// Copies `trigger`'s span out of the series, with each of `companions` (plotted
    /// signals) as further channels: at each sample, the companion's last value read at
    /// or before it (a companion never read before the capture starts is left out).
    fn take(
        store: &SampleStore,
        trigger: &Trigger,
        pre: Duration,
        post: Duration,
        companions: &[SeriesId],
    ) -> Option<Self> {
        let origin = store.origin()?;
        let series = store.series(trigger.series)?;
        let t0 = trigger.at.saturating_duration_since(origin);
        let rows = series.rows_between(t0.saturating_sub(pre), t0 + post);
        let trigger_s = t0.as_secs_f64();
        let times: Vec<f64> = rows
            .clone()
            .filter_map(|r| series.time(r))
            .map(|t| t.as_secs_f64() - trigger_s)
            .collect();
        let mut values: Vec<Vec<f64>> = (0..series.channels.len())
            .map(|c| rows.clone().filter_map(|r| series.value(r, c)).collect())
            .collect();
        let mut channels = series.channels.clone();
        for id in companions.iter().filter(|id| **id != trigger.series) {
            if let Some((channel, held)) = held_values(store, *id, trigger_s, &times) {
                channels.push(channel);
                values.push(held);
            }
        }
        let mut capture = Capture {
            number: 0,
            label: trigger.label.clone(),
            series: series.name.clone(),
            channels,
            encoding: series.encoding,
            trigger_s,
            times,
            values,
            roles: trigger.roles,
            summary: Summary::default(),
        };
        capture.summary = capture.summarise();
        Some(capture)
    }

    /// The values of a channel by its name, or by `series channel` for a companion.
    pub fn channel_named(&self, name: &str) -> Option<usize> {
        self.channels.iter().position(|c| c.name == name)
    }

    fn channel(&self, c: Option<usize>) -> Option<&[f64]> {
        c.and_then(|c| self.values.get(c)).map(Vec::as_slice)
    }

    /// The summary of the samples as they are.
    pub fn summarise(&self) -> Summary {
        let Some(actual) = self.channel(Some(self.roles.actual)) else {
            return Summary::default();
        };
        let (Some(&first), Some(&end)) = (actual.first(), actual.last()) else {
            return Summary::default();
        };
        // The last sample at or before the trigger (the first one when none is).
        let at_trigger = self.times.partition_point(|t| *t <= 0.0).saturating_sub(1);
        let start = actual.get(at_trigger).copied().unwrap_or(first);
        let after = |i: &usize| self.times.get(*i).is_some_and(|t| *t > 0.0);
        let command_end = self
            .channel(self.roles.command)
            .and_then(|c| c.last().copied());
        // The target generator's end: the first sample after the motion began whose phase
        // is complete again.
        let done = match self.channel(self.roles.phase) {
            Some(phase) => {
                let moving = (0..phase.len()).find(|i| after(i) && phase[*i] != 0.0);
                moving.and_then(|m| (m..phase.len()).find(|i| phase[*i] == 0.0))
            }
            // No phase to read: the last sample that still differs from the end.
            None => (0..actual.len())
                .rev()
                .find(|i| actual[*i] != end)
                .map(|i| i + 1)
                .filter(|i| *i < actual.len()),
        };
        let duration = done.and_then(|i| self.times.get(i)).map(|t| t.max(0.0));
        let settling = match (done, self.channel(self.roles.in_position)) {
            (Some(d), Some(in_pos)) => {
                // In Position from some sample on to the end.
                let set_from = (d..in_pos.len())
                    .rev()
                    .take_while(|i| in_pos[*i] != 0.0)
                    .last();
                set_from.and_then(|i| Some(self.times.get(i)? - self.times.get(d)?))
            }
            _ => None,
        };
        let final_error = command_end.map(|c| c - end);
        let overshoot = command_end.map(|c| {
            let direction = (c - start).signum();
            (0..actual.len())
                .filter(after)
                .map(|i| (actual[i] - c) * direction)
                .fold(0.0f64, f64::max)
        });
        Summary {
            start,
            end,
            duration,
            final_error,
            overshoot,
            settling,
        }
    }
}

/// The first channel of series `id` held at each of `times` (seconds from `trigger_s`):
/// the last value read at or before each; `None` when nothing was read before the first.
/// Its channel is named `series channel`, as the trace chooser names it.
fn held_values(
    store: &SampleStore,
    id: SeriesId,
    trigger_s: f64,
    times: &[f64],
) -> Option<(Channel, Vec<f64>)> {
    let s = store.series(id)?;
    let (first, last) = (*times.first()?, *times.last()?);
    let secs = |t: f64| Duration::try_from_secs_f64((trigger_s + t).max(0.0)).unwrap_or_default();
    let before = s.rows_between(Duration::ZERO, secs(first));
    let mut row = before.end.checked_sub(1)?;
    let rows = s.rows_between(secs(first), secs(last));
    let mut held = Vec::with_capacity(times.len());
    for &t in times {
        let at = secs(t);
        while row + 1 < rows.end && s.time(row + 1).is_some_and(|x| x <= at) {
            row += 1;
        }
        held.push(s.value(row, 0)?);
    }
    let mut channel = s.channels.first()?.clone();
    channel.name = format!("{} {}", s.name, channel.name);
    Some((channel, held))
}

/// Captures waiting for their samples, and those taken.
#[derive(Clone, Debug, Default)]
pub struct Captures {
    pub settings: CaptureSettings,
    pending: VecDeque<Trigger>,
    pub list: VecDeque<Capture>,
    /// Captures taken since the start (the list keeps the newest).
    pub taken: u64,
}

impl Captures {
    /// A move started: a capture begins unless one of the same series is still waiting
    /// (a held jog's chain of moves is one capture).
    pub fn trigger(&mut self, trigger: Trigger) {
        if !self.settings.on || self.pending.iter().any(|p| p.series == trigger.series) {
            return;
        }
        self.pending.push_back(trigger);
    }

    /// Whether a capture waits for samples.
    pub fn waiting(&self) -> bool {
        !self.pending.is_empty()
    }

    /// Takes the captures whose span the store now covers (or that `now` has passed by a
    /// second: a device that stopped answering gives what it has).
    pub fn poll(&mut self, store: &SampleStore, now: Instant, companions: &[SeriesId]) {
        let (pre, post) = self.settings.spans();
        let origin = store.origin();
        let mut still = VecDeque::new();
        while let Some(t) = self.pending.pop_front() {
            let end = t.at + post;
            let covered = origin
                .zip(store.series(t.series))
                .and_then(|(o, s)| s.time(s.len().checked_sub(1)?).map(|last| o + last))
                .is_some_and(|last| last >= end);
            if !covered && now < end + Duration::from_secs(1) {
                still.push_back(t);
                continue;
            }
            if let Some(mut c) = Capture::take(store, &t, pre, post, companions) {
                if self.list.len() == KEEP_CAPTURES {
                    self.list.pop_front();
                }
                self.taken += 1;
                c.number = self.taken;
                self.list.push_back(c);
            }
        }
        self.pending = still;
    }
}
