//! The frame log: every frame and garbage run on the line, in a capped ring of compact
//! chunks (times, kinds, verdicts, request/reply pairs; the exact bytes in one buffer per
//! chunk). Sans-IO: times come in with the events; rows are decoded only when shown.

pub mod file;
pub mod filter;
mod row;

use std::collections::VecDeque;
use std::sync::Arc;
use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};

pub use row::{Dir, Row, Verdict};
use row::{Entry, NO_ID};

const _: () = assert!(std::mem::size_of::<Entry>() == 24);

/// Rows per chunk. Full chunks are frozen (shared with savers, never changed).
const CHUNK: usize = 4096;
/// The default cap on rows kept.
pub const DEFAULT_CAP: usize = 1_000_000;
/// How far after a request its reply is looked for (rows).
const REPLY_REACH: u64 = 64;

/// Rows and the bytes they point into.
#[derive(Clone, Debug, Default)]
pub struct Chunk {
    entries: Vec<Entry>,
    bytes: Vec<u8>,
}

impl Chunk {
    fn with_capacity() -> Self {
        Self {
            entries: Vec::with_capacity(CHUNK),
            bytes: Vec::with_capacity(CHUNK * 24),
        }
    }
}

/// The log of one line (or one opened file).
#[derive(Clone, Debug)]
pub struct FrameLog {
    cap: usize,
    /// Frozen full chunks; `frozen[0]` starts at sequence number `base`.
    frozen: VecDeque<Arc<Chunk>>,
    open: Chunk,
    /// Sequence number of the first entry of `frozen[0]` (or of `open`).
    base: u64,
    /// First row still kept (rows before it were dropped from the head).
    head: u64,
    /// Rows dropped from the head because of the cap.
    dropped_head: u64,
    /// Traffic events the link left out (its reader fell behind).
    dropped_link: u64,
    /// Where times count from (the first row's time unless set).
    origin: Option<Instant>,
    /// The wall-clock time of `origin` (the Unix epoch until set).
    origin_wall: SystemTime,
    /// The request that waits for its reply (its sequence number).
    outstanding: Option<u64>,
}

impl FrameLog {
    /// An empty log keeping at most `cap` rows; times count from the first row's.
    pub fn new(cap: usize) -> Self {
        Self {
            cap: cap.max(1),
            frozen: VecDeque::new(),
            open: Chunk::with_capacity(),
            base: 0,
            head: 0,
            dropped_head: 0,
            dropped_link: 0,
            origin: None,
            origin_wall: UNIX_EPOCH,
            outstanding: None,
        }
    }

    /// Where times count from, and its wall-clock time (opened files carry their own).
    pub fn set_origin(&mut self, origin: Option<Instant>, wall: SystemTime) {
        self.origin = origin;
        self.origin_wall = wall;
    }

    pub fn origin_wall(&self) -> SystemTime {
        self.origin_wall
    }

    pub fn cap(&self) -> usize {
        self.cap
    }

    /// A new cap; rows beyond it are dropped from the head at once.
    pub fn set_cap(&mut self, cap: usize) {
        self.cap = cap.max(1);
        self.trim();
    }

    /// Rows kept.
    pub fn len(&self) -> usize {
        (self.end() - self.head) as usize
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Sequence number of the first row kept.
    pub fn head(&self) -> u64 {
        self.head
    }

    /// Sequence number the next row will get.
    pub fn end(&self) -> u64 {
        self.base + (self.frozen.len() * CHUNK + self.open.entries.len()) as u64
    }

    /// Rows dropped from the head because of the cap.
    pub fn dropped_head(&self) -> u64 {
        self.dropped_head
    }

    /// Traffic events the link left out.
    pub fn dropped_link(&self) -> u64 {
        self.dropped_link
    }

    /// Forgets every row (counts too); new rows keep counting time from the same start.
    pub fn clear(&mut self) {
        let (cap, origin, wall) = (self.cap, self.origin, self.origin_wall);
        *self = Self::new(cap);
        self.set_origin(origin, wall);
    }

    fn nanos(&mut self, at: Instant) -> u64 {
        let origin = *self.origin.get_or_insert(at);
        at.saturating_duration_since(origin).as_nanos() as u64
    }

    /// A frame went out at `at`.
    pub fn sent(&mut self, bytes: &[u8], at: Instant) {
        let t = self.nanos(at);
        self.push_sent(bytes, t);
    }

    /// A frame came in (first byte at `first`).
    pub fn received(&mut self, bytes: &[u8], first: Instant) {
        let t = self.nanos(first);
        self.push_received(bytes, t);
    }

    /// Bytes that made no valid frame, with the link's reason.
    pub fn garbage(&mut self, bytes: &[u8], error: &str, at: Instant) {
        let t = self.nanos(at);
        self.push_garbage(bytes, error, t);
    }

    /// No reply came in time.
    pub fn timeout(&mut self, text: &str, at: Instant) {
        let t = self.nanos(at);
        self.push_timeout(text, t);
    }

    /// The line was lost: the request waiting for its reply gets none.
    pub fn line_lost(&mut self) {
        self.outstanding = None;
    }

    /// The link left out `n` traffic events.
    pub fn link_dropped(&mut self, n: u64) {
        self.dropped_link += n;
    }

    /// Adds `n` rows of status polling (212H queries and replies, 2 ms apart, every
    /// 1000th reply an `&` error) after the rows there are: for benches and the tests
    /// of scale.
    pub fn fill_synthetic(&mut self, n: u64) {
        let framed = |body: &str| {
            let mut f = body.as_bytes().to_vec();
            let sc = crate::protocol::checksum(&f);
            f.extend_from_slice(format!("{sc:02X}\r\n").as_bytes());
            f
        };
        let query = framed("!99212");
        let reply = framed("#9921200000000000000000000000000000000");
        let start = self
            .row(self.end().wrapping_sub(1))
            .map_or(0, |r| r.t_ns() + 1);
        for i in 0..n / 2 {
            let t = start + i * 2_000_000;
            self.push_sent(&query, t);
            if i % 1000 == 999 {
                self.push_received(b"&99C1F00\r\n", t + 900_000);
            } else {
                self.push_received(&reply, t + 900_000);
            }
        }
    }

    /// A sent frame at `t_ns` after the start.
    pub fn push_sent(&mut self, bytes: &[u8], t_ns: u64) {
        let seq = self.end();
        self.push(Entry::new(Dir::Sent, t_ns, bytes), bytes, b"");
        self.outstanding = Some(seq);
    }

    /// A received frame at `t_ns` after the start; it answers the outstanding request.
    pub fn push_received(&mut self, bytes: &[u8], t_ns: u64) {
        let mut e = Entry::new(Dir::Received, t_ns, bytes);
        self.pair(&mut e);
        self.push(e, bytes, b"");
    }

    /// A garbage run at `t_ns`; when a request waits, it is taken as its (bad) answer.
    pub fn push_garbage(&mut self, bytes: &[u8], error: &str, t_ns: u64) {
        let mut e = Entry::new(Dir::Garbage, t_ns, bytes);
        self.pair(&mut e);
        self.push(e, bytes, error.as_bytes());
    }

    /// A time-out row; it ends the outstanding request.
    pub fn push_timeout(&mut self, text: &str, t_ns: u64) {
        let mut e = Entry::new(Dir::Timeout, t_ns, b"");
        self.pair(&mut e);
        self.push(e, b"", text.as_bytes());
    }

    fn pair(&mut self, e: &mut Entry) {
        if let Some(seq) = self.outstanding.take() {
            // Farther back than a u16 reaches: no pair (never, with one outstanding).
            e.pair_back = u16::try_from(self.end() - seq).unwrap_or(0);
            if e.id == NO_ID
                && let Some(req) = self.entry(seq)
            {
                // An `&` reply has no ID: it answers the request's.
                e.id = req.id;
            }
        }
    }

    fn push(&mut self, mut e: Entry, bytes: &[u8], note: &[u8]) {
        e.start = self.open.bytes.len() as u32;
        e.len = bytes.len().min(u32::MAX as usize) as u32;
        e.note_len = note.len().min(u16::MAX as usize) as u16;
        self.open.bytes.extend_from_slice(bytes);
        self.open
            .bytes
            .extend_from_slice(&note[..e.note_len as usize]);
        self.open.entries.push(e);
        if self.open.entries.len() == CHUNK {
            let mut full = std::mem::replace(&mut self.open, Chunk::with_capacity());
            full.bytes.shrink_to_fit();
            self.frozen.push_back(Arc::new(full));
        }
        self.trim();
    }

    fn trim(&mut self) {
        let len = self.len() as u64;
        if len > self.cap as u64 {
            let over = len - self.cap as u64;
            self.head += over;
            self.dropped_head += over;
        }
        while !self.frozen.is_empty() && self.head >= self.base + CHUNK as u64 {
            self.frozen.pop_front();
            self.base += CHUNK as u64;
        }
        if self.frozen.is_empty() && self.head > self.base + self.open.entries.len() as u64 {
            self.head = self.base + self.open.entries.len() as u64;
        }
    }

    fn locate(&self, seq: u64) -> Option<(&Chunk, usize)> {
        if seq < self.head || seq >= self.end() {
            return None;
        }
        let i = (seq - self.base) as usize;
        let (c, o) = (i / CHUNK, i % CHUNK);
        match self.frozen.get(c) {
            Some(chunk) => Some((chunk, o)),
            None => Some((&self.open, o)),
        }
    }

    fn entry(&self, seq: u64) -> Option<&Entry> {
        self.locate(seq).map(|(c, o)| &c.entries[o])
    }

    /// The row with sequence number `seq`, if still kept.
    pub fn row(&self, seq: u64) -> Option<Row<'_>> {
        let (chunk, o) = self.locate(seq)?;
        let e = &chunk.entries[o];
        let request_t = (e.pair_back != 0)
            .then(|| self.entry(seq - u64::from(e.pair_back)))
            .flatten()
            .map(|r| r.t_ns);
        Some(Row::new(seq, e, &chunk.bytes, request_t))
    }

    /// The `index`-th row kept (0 = oldest).
    pub fn nth(&self, index: usize) -> Option<Row<'_>> {
        self.row(self.head + index as u64)
    }

    /// The row before `seq` (for the time since the previous row).
    pub fn previous(&self, seq: u64) -> Option<Row<'_>> {
        seq.checked_sub(1).and_then(|s| self.row(s))
    }

    /// The request a reply, garbage or time-out row answers.
    pub fn request_of(&self, seq: u64) -> Option<u64> {
        let r = self.row(seq)?;
        let back = r.pair_back()?;
        let req = seq.checked_sub(back as u64)?;
        self.row(req).map(|_| req)
    }

    /// The reply (or garbage, or time-out) that answers the request `seq`.
    pub fn reply_of(&self, seq: u64) -> Option<u64> {
        let r = self.row(seq)?;
        if r.dir() != Dir::Sent {
            return None;
        }
        (seq + 1..self.end().min(seq + 1 + REPLY_REACH)).find(|&s| self.request_of(s) == Some(seq))
    }

    /// Time of a row after the start.
    pub fn since_start(&self, row: &Row<'_>) -> Duration {
        Duration::from_nanos(row.t_ns())
    }

    /// Wall-clock time of a row.
    pub fn wall(&self, row: &Row<'_>) -> SystemTime {
        self.origin_wall + Duration::from_nanos(row.t_ns())
    }

    /// A cheap copy of the rows kept, for a saver or filter on another thread.
    pub fn snapshot(&self) -> Snapshot {
        let mut chunks: Vec<Arc<Chunk>> = self.frozen.iter().cloned().collect();
        chunks.push(Arc::new(self.open.clone()));
        Snapshot {
            chunks,
            base: self.base,
            head: self.head,
            end: self.end(),
            origin_wall: self.origin_wall,
        }
    }
}

/// The rows of a log at one moment, shared with another thread.
#[derive(Clone, Debug)]
pub struct Snapshot {
    chunks: Vec<Arc<Chunk>>,
    base: u64,
    head: u64,
    end: u64,
    pub origin_wall: SystemTime,
}

impl Snapshot {
    /// The rows, oldest first.
    pub fn rows(&self) -> impl Iterator<Item = Row<'_>> + '_ {
        (self.head..self.end).filter_map(move |seq| self.row(seq))
    }

    fn entry(&self, seq: u64) -> Option<&Entry> {
        if seq < self.head || seq >= self.end {
            return None;
        }
        let i = (seq - self.base) as usize;
        self.chunks.get(i / CHUNK)?.entries.get(i % CHUNK)
    }

    pub fn len(&self) -> usize {
        (self.end - self.head) as usize
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Sequence number after the last row.
    pub fn end(&self) -> u64 {
        self.end
    }

    /// The row `seq`, if the snapshot holds it.
    pub fn row(&self, seq: u64) -> Option<Row<'_>> {
        if seq < self.head || seq >= self.end {
            return None;
        }
        let i = (seq - self.base) as usize;
        let chunk = self.chunks.get(i / CHUNK)?;
        let e = chunk.entries.get(i % CHUNK)?;
        let request_t = (e.pair_back != 0)
            .then(|| self.entry(seq - u64::from(e.pair_back)))
            .flatten()
            .map(|r| r.t_ns);
        Some(Row::new(seq, e, &chunk.bytes, request_t))
    }
}

#[cfg(test)]
mod tests;
