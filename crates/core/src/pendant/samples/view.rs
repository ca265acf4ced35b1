//! What a plot shows, apart from how it is painted: the channels chosen, each turned into
//! a trace decimated to one min/max pair per pixel column, the bits and phases on lanes of
//! their own, and the exact sample under a cursor. The window's plot and the PNG painter
//! both draw these.

use std::time::Duration;

use serde::{Deserialize, Serialize};

use super::capture::Capture;
use super::{Channel, Encoding, SampleStore, Series};

/// A channel chosen for a trace: its series and channel, by name (names outlive a
/// restart; indices need not).
#[derive(Clone, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct TraceChoice {
    pub series: String,
    pub channel: String,
}

impl TraceChoice {
    pub fn new(series: impl Into<String>, channel: impl Into<String>) -> Self {
        Self {
            series: series.into(),
            channel: channel.into(),
        }
    }

    /// `Axis 1 Actual Position`.
    pub fn label(&self) -> String {
        format!("{} {}", self.series, self.channel)
    }
}

/// A trace ready to draw.
#[derive(Clone, Debug, PartialEq)]
pub struct Trace {
    pub label: String,
    /// Empty for a bit or a phase.
    pub unit: String,
    /// A bit or a phase: drawn as steps on a lane under the curves.
    pub step: bool,
    /// Its largest level (1 for a bit, 3 for the target generator's phase).
    pub top: f64,
    /// (seconds, value): per pixel column its min and max, in time order.
    pub points: Vec<[f64; 2]>,
}

impl Trace {
    fn new(label: String, channel: &Channel) -> Self {
        Self {
            label,
            unit: channel.unit.clone(),
            step: channel.step,
            top: f64::from(channel.top),
            points: Vec::new(),
        }
    }

    /// Where a level sits on lane `lane` (lanes are 1.0 apart, levels fill 0.8 of one).
    pub fn on_lane(&self, lane: usize, value: f64) -> f64 {
        lane as f64 + 0.8 * value / self.top.max(1.0)
    }
}

impl SampleStore {
    /// The series and channel `choice` names.
    pub fn find(&self, choice: &TraceChoice) -> Option<(&Series, usize)> {
        let series = self.all().iter().find(|s| s.name == choice.series)?;
        let channel = series
            .channels
            .iter()
            .position(|c| c.name == choice.channel)?;
        Some((series, channel))
    }

    /// Every channel there is, as choices.
    pub fn choices(&self) -> Vec<TraceChoice> {
        self.all()
            .iter()
            .flat_map(|s| {
                s.channels
                    .iter()
                    .map(|c| TraceChoice::new(&s.name, &c.name))
            })
            .collect()
    }
}

/// `choice` over `from..to` seconds since the store's origin, one min/max pair per
/// column of `columns`.
pub fn live_trace(
    store: &SampleStore,
    choice: &TraceChoice,
    from: f64,
    to: f64,
    columns: usize,
) -> Option<Trace> {
    TraceCache::default().trace(store, choice, from, to, columns)
}

/// The decimated columns of one trace kept between frames: while the span and the
/// columns stay the same and rows only come in at the end, only the columns the new
/// rows fall in are worked out again (a live plot whose span moves a column at a time
/// costs a column a frame, however long the span).
#[derive(Clone, Debug, Default)]
pub struct TraceCache {
    entries: Vec<Cached>,
}

#[derive(Clone, Debug)]
struct Cached {
    choice: TraceChoice,
    from: f64,
    to: f64,
    columns: usize,
    /// Rows dropped and kept when worked out.
    dropped: u64,
    len: usize,
    spans: Vec<Option<(f64, f64)>>,
}

impl TraceCache {
    /// As [`live_trace`], from the columns kept where they still hold. Nothing lies
    /// before the origin: columns there are left out.
    pub fn trace(
        &mut self,
        store: &SampleStore,
        choice: &TraceChoice,
        from: f64,
        to: f64,
        columns: usize,
    ) -> Option<Trace> {
        let (series, channel) = store.find(choice)?;
        let mut trace = Trace::new(choice.label(), &series.channels[channel]);
        let start = from.max(0.0);
        if to <= start || columns == 0 {
            return Some(trace);
        }
        let width = (to - from) / columns as f64;
        let columns = ((to - start) / width).round().max(1.0) as usize;
        let width = (to - start) / columns as f64;
        let i = match self.entries.iter().position(|e| e.choice == *choice) {
            Some(i) => i,
            None => {
                self.entries.push(Cached {
                    choice: choice.clone(),
                    from: f64::NAN,
                    to: f64::NAN,
                    columns: 0,
                    dropped: 0,
                    len: 0,
                    spans: Vec::new(),
                });
                self.entries.len() - 1
            }
        };
        let e = &mut self.entries[i];
        let same = e.from == start
            && e.to == to
            && e.columns == columns
            && e.dropped == series.dropped
            && e.len <= series.len();
        if !same {
            e.spans = series.min_max(channel, secs(start), secs(to), columns);
        } else if e.len < series.len() {
            // The new rows' first column (one before it, lest rounding put a row on a
            // column's edge in the wrong one), and every column after it, again.
            let first_new = series
                .time(e.len)
                .map_or(columns, |t| {
                    ((t.as_secs_f64() - start) / width).floor().max(1.0) as usize - 1
                })
                .min(columns);
            if first_new < columns {
                let again = series.min_max_from(channel, secs(start), secs(to), columns, first_new);
                e.spans.truncate(first_new);
                e.spans.extend(again);
            }
        }
        (e.from, e.to, e.columns, e.dropped, e.len) =
            (start, to, columns, series.dropped, series.len());
        trace.points = points_of(&e.spans, start, width);
        Some(trace)
    }

    /// Forgets traces no longer chosen.
    pub fn keep_only(&mut self, chosen: &[TraceChoice]) {
        self.entries.retain(|e| chosen.contains(&e.choice));
    }
}

/// Each column's min and max as points at the column's middle.
fn points_of(spans: &[Option<(f64, f64)>], from: f64, width: f64) -> Vec<[f64; 2]> {
    let mut points = Vec::with_capacity(spans.len() * 2);
    for (i, span) in spans.iter().enumerate() {
        let Some((lo, hi)) = span else { continue };
        let x = from + (i as f64 + 0.5) * width;
        points.push([x, *lo]);
        if hi != lo {
            points.push([x, *hi]);
        }
    }
    points
}

/// The value of `choice` at `t` seconds since the origin: the last sample at or before
/// it, exactly as polled (a plot of polls holds each value until the next).
pub fn live_value_at(store: &SampleStore, choice: &TraceChoice, t: f64) -> Option<f64> {
    let (series, channel) = store.find(choice)?;
    let rows = series.rows_between(Duration::ZERO, secs(t.max(0.0)));
    series.value(rows.end.checked_sub(1)?, channel)
}

/// A capture's channel named `channel` as a trace, times from its trigger.
pub fn capture_trace(capture: &Capture, channel: &str, label: String) -> Option<Trace> {
    let c = capture.channels.iter().position(|ch| ch.name == channel)?;
    let mut trace = Trace::new(label, &capture.channels[c]);
    trace.points = capture
        .times
        .iter()
        .zip(&capture.values[c])
        .map(|(t, v)| [*t, *v])
        .collect();
    Some(trace)
}

/// The value of a capture's channel at `t` seconds from its trigger (the last sample at
/// or before it).
pub fn capture_value_at(capture: &Capture, channel: &str, t: f64) -> Option<f64> {
    let c = capture.channels.iter().position(|ch| ch.name == channel)?;
    let i = capture.times.partition_point(|x| *x <= t).checked_sub(1)?;
    capture.values.get(c)?.get(i).copied()
}

fn secs(s: f64) -> Duration {
    Duration::try_from_secs_f64(s.max(0.0)).unwrap_or(Duration::MAX)
}

/// A value as polled, in text that reads back to the same value: an f32 in its shortest
/// exact form, thousandths with three decimals, a level as a whole number.
pub fn exact_text(encoding: Encoding, channel: &Channel, value: f64) -> String {
    if channel.step {
        format!("{value:.0}")
    } else {
        match encoding {
            Encoding::Real => (value as f32).to_string(),
            Encoding::Milli => format!("{value:.3}"),
        }
    }
}
