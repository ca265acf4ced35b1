//! The frame log: every frame and garbage run on the lines (the X-SEL's Format B and the
//! RMC151's Modbus/TCP, in the order they happened), in a capped ring of compact chunks
//! (16 bytes a row for times, protocols, kinds, verdicts and request/reply pairs; the
//! exact bytes in one buffer per chunk, Format B frames packed as hex nibbles, a frame
//! seen before in the chunk stored once). Sans-IO: times come in with the events; rows
//! are decoded only when shown.

mod chunk;
mod entry;
pub mod file;
pub mod filter;
mod packed;
pub mod raw_send;
mod row;

use std::collections::VecDeque;
use std::sync::Arc;
use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};

pub use chunk::Chunk;
use chunk::OpenIndex;
use entry::{Entry, MAX_NOTE_BYTES, MAX_ROW_BYTES};
pub use row::{Dir, Protocol, Row, Verdict, hex_pairs};

/// Rows per chunk. Full chunks are frozen (shared with savers, never changed).
const CHUNK: usize = 4096;
/// The default cap on rows kept.
pub const DEFAULT_CAP: usize = 1_000_000;
/// The default cap on the memory the rows take: whole chunks of the oldest rows go
/// when it is passed, whatever the row cap says (a line of junk fills it in bytes, not
/// rows).
pub const DEFAULT_BUDGET_BYTES: usize = 64 * 1024 * 1024;
/// The most of one garbage run a row keeps (what the link's event carries); the rest is
/// counted in its note.
pub use crate::link::event::GARBAGE_KEEP;
/// The most rows of the other line between a request and its answer for the two to be
/// paired (each line has one request outstanding; the other line's rows come between).
const PAIR_REACH: u64 = 1024;

/// The log of one line (or one opened file).
#[derive(Clone, Debug)]
pub struct FrameLog {
    cap: usize,
    /// The most memory the rows may take (see [`DEFAULT_BUDGET_BYTES`]).
    budget: usize,
    /// Memory the frozen chunks take.
    frozen_bytes: usize,
    /// Rows dropped from the head to keep the memory budget.
    dropped_budget: u64,
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
    /// Per protocol, the request that waits for its reply (its sequence number).
    outstanding: [Option<u64>; 2],
    /// What the open chunk holds, for sharing repeated bytes.
    index: OpenIndex,
}

impl FrameLog {
    /// An empty log keeping at most `cap` rows; times count from the first row's.
    pub fn new(cap: usize) -> Self {
        Self {
            cap: cap.max(1),
            budget: DEFAULT_BUDGET_BYTES,
            frozen_bytes: 0,
            dropped_budget: 0,
            frozen: VecDeque::new(),
            open: Chunk::new(),
            base: 0,
            head: 0,
            dropped_head: 0,
            dropped_link: 0,
            origin: None,
            origin_wall: UNIX_EPOCH,
            outstanding: [None; 2],
            index: OpenIndex::default(),
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

    /// The cap on the memory the rows take.
    pub fn budget(&self) -> usize {
        self.budget
    }

    /// A new memory budget (at least one chunk's worth is always kept); the oldest rows
    /// beyond it go at once.
    pub fn set_budget(&mut self, bytes: usize) {
        self.budget = bytes;
        self.trim();
    }

    /// Rows dropped from the head to keep the memory budget (also in
    /// [`FrameLog::dropped_head`]).
    pub fn dropped_budget(&self) -> u64 {
        self.dropped_budget
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

    /// Bytes of memory the rows take (entries and stored bytes, capacity counted).
    pub fn memory_bytes(&self) -> usize {
        self.frozen.iter().map(|c| c.memory_bytes()).sum::<usize>()
            + self.open.memory_bytes()
            + self.index.memory_bytes()
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
        let (cap, budget, origin, wall) = (self.cap, self.budget, self.origin, self.origin_wall);
        *self = Self::new(cap);
        self.budget = budget;
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

    /// The X-SEL's line was lost: the request waiting for its reply gets none.
    pub fn line_lost(&mut self) {
        self.outstanding[Protocol::FormatB.index()] = None;
    }

    /// A Modbus/TCP row of the RMC151's connection at `at` (a time-out has no bytes; a
    /// note says why garbage is garbage, or what timed out).
    pub fn modbus(&mut self, dir: Dir, bytes: &[u8], note: &str, at: Instant) {
        let t = self.nanos(at);
        self.push_row(Protocol::Modbus, dir, bytes, note, t);
    }

    /// The RMC151's connection was lost: its request waiting for a reply gets none.
    pub fn modbus_line_lost(&mut self) {
        self.outstanding[Protocol::Modbus.index()] = None;
    }

    /// The link left out `n` traffic events.
    pub fn link_dropped(&mut self, n: u64) {
        self.dropped_link += n;
    }

    /// Adds `n` rows of the window's status polling after the rows there are, as while
    /// the arm moves: each cycle asks 2A1H in three systems and 215H, and every 2A1H
    /// reply (82 bytes) carries a new position, so no two are alike (the worst case for
    /// the store); every 1000th reply is an `&` error; a request every 2 ms, its reply
    /// 0.9 ms later. For benches and the tests of scale. The frames follow PROTOCOL.md 3.17 and 10 [observed].
    pub fn fill_synthetic(&mut self, n: u64) {
        const MOVING_2A1: &str =
            "#992A10100000F1C000000000493E01C000000FFFDB6101C00000000004E201C000000";
        let framed = |body: &str| {
            let mut f = body.as_bytes().to_vec();
            let sc = crate::protocol::checksum(&f);
            f.extend_from_slice(format!("{sc:02X}\r\n").as_bytes());
            f
        };
        let queries = ["!992A10F0", "!99215", "!992A10F1", "!992A10F2"].map(framed);
        let status = framed("#992151000000000006000");
        let start = self
            .row(self.end().wrapping_sub(1))
            .map_or(0, |r| r.t_ns().saturating_add(1));
        for i in 0..n / 2 {
            let t = start.saturating_add(i.saturating_mul(2_000_000));
            let which = (i % 4) as usize;
            self.push_sent(&queries[which], t);
            let reply = if i % 1000 == 999 {
                b"&99C1F00\r\n".to_vec()
            } else if which == 1 {
                status.clone()
            } else {
                framed(&format!("{MOVING_2A1}{:08X}", (i as u32).wrapping_mul(37)))
            };
            self.push_received(&reply, t.saturating_add(900_000));
        }
    }

    /// A sent frame at `t_ns` after the start.
    pub fn push_sent(&mut self, bytes: &[u8], t_ns: u64) {
        self.push_row(Protocol::FormatB, Dir::Sent, bytes, "", t_ns);
    }

    /// A received frame at `t_ns` after the start; it answers the outstanding request.
    pub fn push_received(&mut self, bytes: &[u8], t_ns: u64) {
        self.push_row(Protocol::FormatB, Dir::Received, bytes, "", t_ns);
    }

    /// A garbage run at `t_ns`; when a request waits, it is taken as its (bad) answer.
    pub fn push_garbage(&mut self, bytes: &[u8], error: &str, t_ns: u64) {
        self.push_row(Protocol::FormatB, Dir::Garbage, bytes, error, t_ns);
    }

    /// A time-out row; it ends the outstanding request.
    pub fn push_timeout(&mut self, text: &str, t_ns: u64) {
        self.push_row(Protocol::FormatB, Dir::Timeout, b"", text, t_ns);
    }

    /// A row of either line at `t_ns`: a request becomes its line's outstanding one;
    /// anything else answers it.
    pub fn push_row(&mut self, protocol: Protocol, dir: Dir, bytes: &[u8], note: &str, t_ns: u64) {
        let bytes = if dir == Dir::Timeout { &[][..] } else { bytes };
        // A garbage run is kept up to a length; the rest is said, not stored.
        let cut;
        let (bytes, note) = if dir == Dir::Garbage && bytes.len() > GARBAGE_KEEP {
            cut = format!("{note} (+{} bytes not kept)", bytes.len() - GARBAGE_KEEP);
            (&bytes[..GARBAGE_KEEP], cut.as_str())
        } else {
            (bytes, note)
        };
        let mut e = match protocol {
            Protocol::FormatB => Entry::new(dir, t_ns, bytes),
            Protocol::Modbus => Entry::modbus(dir, t_ns, bytes),
        };
        let seq = self.end();
        if dir == Dir::Sent {
            self.outstanding[protocol.index()] = Some(seq);
        } else {
            self.pair(&mut e, protocol, bytes);
        }
        self.push(e, bytes, note);
    }

    /// Pairs an answer with the request waiting for it on its line (a Modbus reply only
    /// with the request of its transaction).
    fn pair(&mut self, e: &mut Entry, protocol: Protocol, bytes: &[u8]) {
        let Some(seq) = self.outstanding[protocol.index()].take() else {
            return;
        };
        if self.end() - seq > PAIR_REACH {
            return;
        }
        let Some(request) = self.row(seq) else {
            return;
        };
        if protocol == Protocol::Modbus
            && bytes.len() >= 2
            && request.bytes().get(..2) != bytes.get(..2)
        {
            return;
        }
        let id = self.entry(seq).and_then(Entry::id);
        e.set_answers();
        // An `&` reply has no ID: it answers the request's. (A Modbus row's ID is its own
        // function code, or none.)
        if protocol == Protocol::FormatB {
            e.take_id(id);
        }
    }

    fn push(&mut self, mut e: Entry, bytes: &[u8], note: &str) {
        // Longer rows come only from files, which refuse them (`file::read_jsonl`).
        let bytes = &bytes[..bytes.len().min(MAX_ROW_BYTES)];
        let note = &note.as_bytes()[..floor_char_boundary(note, MAX_NOTE_BYTES)];
        let (start, len, packed) = if note.is_empty() {
            self.index.store(&mut self.open, bytes, &e)
        } else {
            self.open.store_alone(bytes, e.protocol())
        };
        e.set_stored(start, len, packed, !note.is_empty());
        if !note.is_empty() {
            self.open
                .bytes
                .extend_from_slice(&(note.len() as u16).to_le_bytes());
            self.open.bytes.extend_from_slice(note);
        }
        self.open.entries.push(e);
        if self.open.entries.len() == CHUNK {
            let mut full = std::mem::replace(&mut self.open, Chunk::new());
            full.bytes.shrink_to_fit();
            self.frozen_bytes += full.memory_bytes();
            self.frozen.push_back(Arc::new(full));
            self.index = OpenIndex::default();
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
        // The memory budget: the oldest chunk goes whole while the rows take more.
        while !self.frozen.is_empty() && self.frozen_bytes + self.open.memory_bytes() > self.budget
        {
            let first_end = self.base + CHUNK as u64;
            let gone = first_end.saturating_sub(self.head);
            self.head = self.head.max(first_end);
            self.dropped_head += gone;
            self.dropped_budget += gone;
            if let Some(c) = self.frozen.pop_front() {
                self.frozen_bytes -= c.memory_bytes();
            }
            self.base += CHUNK as u64;
        }
        while !self.frozen.is_empty() && self.head >= self.base + CHUNK as u64 {
            if let Some(c) = self.frozen.pop_front() {
                self.frozen_bytes -= c.memory_bytes();
            }
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
        Some(Row::new(seq, e, &chunk.bytes, || {
            request_before(seq, e.protocol(), self.head, |s| {
                self.locate(s).map(|(c, o)| (&c.entries[o], &c.bytes[..]))
            })
        }))
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
        if !r.answers() {
            return None;
        }
        let protocol = r.protocol();
        (seq.saturating_sub(PAIR_REACH).max(self.head)..seq)
            .rev()
            .find(|&s| {
                self.entry(s)
                    .is_some_and(|e| e.protocol() == protocol && e.dir() == Dir::Sent)
            })
    }

    /// The reply (or garbage, or time-out) that answers the request `seq`.
    pub fn reply_of(&self, seq: u64) -> Option<u64> {
        let r = self.row(seq)?;
        if r.dir() != Dir::Sent {
            return None;
        }
        let protocol = r.protocol();
        let next = (seq + 1..self.end().min(seq + 1 + PAIR_REACH))
            .find(|&s| self.entry(s).is_some_and(|e| e.protocol() == protocol))?;
        (self.request_of(next) == Some(seq)).then_some(next)
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
        Some(Row::new(seq, e, &chunk.bytes, || {
            request_before(seq, e.protocol(), self.head, |s| {
                let i = (s - self.base) as usize;
                let chunk = self.chunks.get(i / CHUNK)?;
                Some((chunk.entries.get(i % CHUNK)?, &chunk.bytes[..]))
            })
        }))
    }
}

/// The request row `seq` answers: the last request of its protocol before it, within
/// [`PAIR_REACH`] rows and not before `head`; `at` finds a kept row's entry and bytes.
fn request_before<'a>(
    seq: u64,
    protocol: Protocol,
    head: u64,
    at: impl Fn(u64) -> Option<(&'a Entry, &'a [u8])>,
) -> Option<(&'a Entry, &'a [u8])> {
    (seq.saturating_sub(PAIR_REACH).max(head)..seq)
        .rev()
        .filter_map(at)
        .find(|(e, _)| e.protocol() == protocol && e.dir() == Dir::Sent)
}

/// The longest prefix of `text` of at most `max` bytes that ends on a character boundary.
fn floor_char_boundary(text: &str, max: usize) -> usize {
    (0..=max.min(text.len()))
        .rev()
        .find(|&i| text.is_char_boundary(i))
        .unwrap_or(0)
}

#[cfg(test)]
mod tests;
