//! The plots' sample store (DESIGN.md "The window"): every polled value with its poll's
//! time, one series per polled record (an RMC axis's status, the X-SEL's position), each a
//! bounded ring. Values read back exactly as polled; for drawing, a time span is decimated
//! to each pixel column's min and max, whole blocks of rows taken from their kept min and
//! max so that an hour draws as fast as a minute. Sans-IO: times come in with the
//! samples.

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
    /// A level's largest value (1 for a bit).
    pub top: u8,
}

impl Channel {
    pub fn new(name: impl Into<String>, unit: impl Into<String>) -> Self {
        Self {
            name: name.into(),
            unit: unit.into(),
            step: false,
            top: 1,
        }
    }

    /// A bit.
    pub fn level(name: impl Into<String>) -> Self {
        Self::levels(name, 1)
    }

    /// A phase or state numbered 0 to `top`.
    pub fn levels(name: impl Into<String>, top: u8) -> Self {
        Self {
            name: name.into(),
            unit: String::new(),
            step: true,
            top: top.max(1),
        }
    }
}

/// Rows per block of kept minima and maxima.
const BLOCK: u64 = 16;

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
    /// Per block of [`BLOCK`] rows (counted from the first row ever pushed) and channel,
    /// the block's (min, max), rounded outwards to f32; `blocks[0]` is block
    /// `dropped / BLOCK` (it may still hold rows dropped since).
    blocks: VecDeque<(f32, f32)>,
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
    /// wide still shows: rows at a span's edges are read one by one, whole blocks between
    /// them by their kept min and max (exact to f32; a thousandths count beyond 2^24 is
    /// widened by at most one f32 step).
    pub fn min_max(
        &self,
        channel: usize,
        from: Duration,
        to: Duration,
        columns: usize,
    ) -> Vec<Option<(f64, f64)>> {
        self.min_max_from(channel, from, to, columns, 0)
    }

    /// As [`min_max`](Self::min_max), only the columns from `first` on (the same
    /// columns, worked out the same way).
    pub fn min_max_from(
        &self,
        channel: usize,
        from: Duration,
        to: Duration,
        columns: usize,
        first: usize,
    ) -> Vec<Option<(f64, f64)>> {
        let first = first.min(columns);
        let mut out = vec![None; columns - first];
        if columns == 0 || to <= from || channel >= self.channels.len() {
            return out;
        }
        let (start, span) = (nanos(from), nanos(to) - nanos(from));
        // A column's start time, and the first row at or after it.
        let edge =
            |column: usize| start + ((u128::from(span) * column as u128) / columns as u128) as u64;
        let all = self.rows_between(from, to);
        let mut row = self
            .times
            .partition_point(|t| *t < edge(first))
            .clamp(all.start, all.end);
        for (column, slot) in (first..columns).zip(out.iter_mut()) {
            let end = if column + 1 == columns {
                all.end
            } else {
                self.times
                    .partition_point(|t| *t < edge(column + 1))
                    .clamp(row, all.end)
            };
            *slot = self.span_min_max(channel, row..end);
            row = end;
        }
        out
    }

    /// The (min, max) of `channel` over `rows`, whole blocks by their kept values.
    fn span_min_max(&self, channel: usize, rows: Range<usize>) -> Option<(f64, f64)> {
        if rows.is_empty() {
            return None;
        }
        let n = self.channels.len();
        let mut acc: Option<(f64, f64)> = None;
        let mut take = |lo: f64, hi: f64| {
            acc = Some(match acc {
                Some((a, b)) => (a.min(lo), b.max(hi)),
                None => (lo, hi),
            });
        };
        let first_block = self.dropped / BLOCK;
        let mut r = rows.start;
        while r < rows.end {
            let absolute = self.dropped + r as u64;
            let block_end = ((absolute / BLOCK + 1) * BLOCK - self.dropped) as usize;
            // A whole block, all of it kept: its min and max.
            if absolute.is_multiple_of(BLOCK) && block_end <= rows.end {
                let i = ((absolute / BLOCK - first_block) as usize) * n + channel;
                if let Some(&(lo, hi)) = self.blocks.get(i) {
                    take(f64::from(lo), f64::from(hi));
                    r = block_end;
                    continue;
                }
            }
            if let Some(v) = self.value(r, channel) {
                take(v, v);
            }
            r += 1;
        }
        acc
    }

    /// Bytes its samples take (times, values and the blocks' minima and maxima).
    pub fn bytes(&self) -> usize {
        self.times.len() * 8 + self.values.len() * 4 + self.blocks.len() * 8
    }
}

/// The f32s just below and above `v` (both `v` when it is an f32).
fn f32_around(v: f64) -> (f32, f32) {
    let f = v as f32;
    let lo = if f64::from(f) > v { f.next_down() } else { f };
    let hi = if f64::from(f) < v { f.next_up() } else { f };
    (lo, hi)
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
            blocks: VecDeque::new(),
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
        let n = s.channels.len();
        if s.times.len() == s.cap {
            s.times.pop_front();
            s.values.drain(..n);
            s.dropped += 1;
            // The first block's rows are all gone.
            if s.dropped.is_multiple_of(BLOCK) {
                s.blocks.drain(..n.min(s.blocks.len()));
            }
        }
        let absolute = s.dropped + s.times.len() as u64;
        s.times.push_back(t);
        s.values
            .extend((0..n).map(|i| values.get(i).map_or(0, |v| v.bits())));
        let row = s.times.len() - 1;
        let new_block = absolute.is_multiple_of(BLOCK);
        let base = s.blocks.len().saturating_sub(n);
        for c in 0..n {
            let v = s.value(row, c).unwrap_or(0.0);
            let (lo, hi) = f32_around(v);
            if new_block {
                s.blocks.push_back((lo, hi));
            } else if let Some(b) = s.blocks.get_mut(base + c) {
                *b = (b.0.min(lo), b.1.max(hi));
            }
        }
    }

    /// Bytes all samples take.
    pub fn bytes(&self) -> usize {
        self.series.iter().map(Series::bytes).sum()
    }
}
