//! The plots' sample store (DESIGN.md "The window"): every polled value with its poll's
//! time, one series per polled record (an RMC axis's status, the X-SEL's position), each a
//! bounded ring. Values read back exactly as polled; for drawing, a time span is decimated
//! to each pixel column's min and max. Sans-IO: times come in with the samples.

pub mod capture;
#[cfg(test)]
mod capture_tests;
pub mod csv;
pub mod polled;
#[cfg(test)]
mod tests;
pub mod view;

use std::collections::VecDeque;
use std::ops::Range;
use std::time::{Duration, Instant};

/// How a series keeps its values: 4 bytes each, exact either way.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Encoding {
    /// An f32 as polled (RMC REALs).
    Real,
    /// A whole number of thousandths (X-SEL positions in 0.001 mm or deg).
    Milli,
}

/// One value as polled.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Sample {
    Real(f32),
    Milli(i32),
    /// A bit or a phase, drawn as a step trace.
    Level(u8),
}

impl Sample {
    fn bits(self) -> u32 {
        match self {
            Sample::Real(v) => v.to_bits(),
            Sample::Milli(v) => v as u32,
            Sample::Level(v) => u32::from(v),
        }
    }
}

/// What a channel is: its name, its unit, whether it is a step trace.
#[derive(Clone, Debug, PartialEq)]
pub struct Channel {
    pub name: String,
    pub unit: String,
    /// Bits and phases (drawn as steps under the curves).
    pub step: bool,
}

impl Channel {
    pub fn new(name: impl Into<String>, unit: impl Into<String>) -> Self {
        Self {
            name: name.into(),
            unit: unit.into(),
            step: false,
        }
    }

    pub fn level(name: impl Into<String>) -> Self {
        Self {
            name: name.into(),
            unit: String::new(),
            step: true,
        }
    }
}

/// Identifies a series in its store.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct SeriesId(usize);

/// One polled record's samples: a time per row, a value per channel per row.
#[derive(Clone, Debug)]
pub struct Series {
    pub name: String,
    pub channels: Vec<Channel>,
    encoding: Encoding,
    cap: usize,
    /// Nanoseconds since the store's origin, one per row, never decreasing.
    times: VecDeque<u64>,
    /// Row-major: `channels.len()` values a row.
    values: VecDeque<u32>,
    /// Rows dropped from the head to keep the bound.
    pub dropped: u64,
}

impl Series {
    pub fn len(&self) -> usize {
        self.times.len()
    }

    pub fn is_empty(&self) -> bool {
        self.times.is_empty()
    }

    /// Row `row`'s time since the store's origin.
    pub fn time(&self, row: usize) -> Option<Duration> {
        self.times.get(row).map(|t| Duration::from_nanos(*t))
    }

    /// Row `row`'s value of `channel`, as polled (f64 holds an f32 or a thousandths
    /// count exactly; a thousandths count is divided by 1000).
    pub fn value(&self, row: usize, channel: usize) -> Option<f64> {
        if channel >= self.channels.len() {
            return None;
        }
        let bits = *self.values.get(row * self.channels.len() + channel)?;
        Some(self.decode(channel, bits))
    }

    /// The raw value (an f32's bits, a thousandths count, a level), for exact comparison.
    pub fn raw(&self, row: usize, channel: usize) -> Option<u32> {
        (channel < self.channels.len())
            .then(|| {
                self.values
                    .get(row * self.channels.len() + channel)
                    .copied()
            })
            .flatten()
    }

    fn decode(&self, channel: usize, bits: u32) -> f64 {
        if self.channels.get(channel).is_some_and(|c| c.step) {
            return f64::from(bits);
        }
        match self.encoding {
            Encoding::Real => f64::from(f32::from_bits(bits)),
            Encoding::Milli => f64::from(bits as i32) / 1000.0,
        }
    }

    /// The rows whose times lie in `from..=to` (since the origin).
    pub fn rows_between(&self, from: Duration, to: Duration) -> Range<usize> {
        let (from, to) = (nanos(from), nanos(to));
        let start = self.times.partition_point(|t| *t < from);
        let end = self.times.partition_point(|t| *t <= to);
        start..end.max(start)
    }

    /// `channel` over `from..to` cut into `columns` equal spans: each span's (min, max),
    /// `None` where a span holds no sample. Every sample counts, so a spike one sample
    /// wide still shows.
    pub fn min_max(
        &self,
        channel: usize,
        from: Duration,
        to: Duration,
        columns: usize,
    ) -> Vec<Option<(f64, f64)>> {
        let mut out = vec![None; columns];
        if columns == 0 || to <= from || channel >= self.channels.len() {
            return out;
        }
        let (start, span) = (nanos(from), nanos(to) - nanos(from));
        for row in self.rows_between(from, to) {
            let (Some(t), Some(v)) = (self.times.get(row), self.value(row, channel)) else {
                continue;
            };
            let column = ((u128::from(t - start) * columns as u128) / u128::from(span)) as usize;
            let Some(slot) = out.get_mut(column.min(columns - 1)) else {
                continue;
            };
            *slot = Some(match *slot {
                Some((lo, hi)) => (lo.min(v), hi.max(v)),
                None => (v, v),
            });
        }
        out
    }

    /// Bytes its samples take (times and values).
    pub fn bytes(&self) -> usize {
        self.times.len() * 8 + self.values.len() * 4
    }
}

fn nanos(d: Duration) -> u64 {
    u64::try_from(d.as_nanos()).unwrap_or(u64::MAX)
}

/// Every series of the pendant's polls.
#[derive(Clone, Debug, Default)]
pub struct SampleStore {
    origin: Option<Instant>,
    series: Vec<Series>,
}

impl SampleStore {
    /// Adds a series of `channels` keeping at most `cap` rows.
    pub fn add(
        &mut self,
        name: impl Into<String>,
        channels: Vec<Channel>,
        encoding: Encoding,
        cap: usize,
    ) -> SeriesId {
        self.series.push(Series {
            name: name.into(),
            channels,
            encoding,
            cap: cap.max(1),
            times: VecDeque::new(),
            values: VecDeque::new(),
            dropped: 0,
        });
        SeriesId(self.series.len() - 1)
    }

    pub fn series(&self, id: SeriesId) -> Option<&Series> {
        self.series.get(id.0)
    }

    pub fn all(&self) -> &[Series] {
        &self.series
    }

    /// Where times count from (the first sample's time unless set).
    pub fn origin(&self) -> Option<Instant> {
        self.origin
    }

    /// One polled row at `at`: a value per channel (missing ones are 0, extra ones left
    /// out). A time before the last row's is taken as the last row's (times never go back).
    pub fn push(&mut self, id: SeriesId, at: Instant, values: &[Sample]) {
        let origin = *self.origin.get_or_insert(at);
        let Some(s) = self.series.get_mut(id.0) else {
            return;
        };
        let t = nanos(at.saturating_duration_since(origin));
        let t = s.times.back().map_or(t, |last| t.max(*last));
        if s.times.len() == s.cap {
            s.times.pop_front();
            s.values.drain(..s.channels.len());
            s.dropped += 1;
        }
        s.times.push_back(t);
        let n = s.channels.len();
        s.values
            .extend((0..n).map(|i| values.get(i).map_or(0, |v| v.bits())));
    }

    /// Bytes all samples take.
    pub fn bytes(&self) -> usize {
        self.series.iter().map(Series::bytes).sum()
    }
}
