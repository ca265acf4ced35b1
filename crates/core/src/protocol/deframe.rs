//! Splitting a byte stream into runs (candidate frames, noise, cut or overlong runs), for
//! both roles: the client's [`StreamDecoder`](super::StreamDecoder) and the simulated
//! controller's receiver. The accepted headers and the length limit are parameters.

/// Consumed bytes are dropped from the buffer's front once this many have accumulated.
const COMPACT_AT: usize = 32 * 1024;

/// What a run is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RunKind {
    /// From a header to its LF, within the limit: a frame to parse.
    Candidate,
    /// Bytes without a header, up to and with an LF, up to the next header, or `limit`
    /// bytes of a longer stretch.
    Noise,
    /// From a header up to the next header, without an LF (only when headers cut runs).
    Cut,
    /// The first `limit` bytes of a run from a header that has no LF within the limit;
    /// the rest of it follows as noise.
    Overlong,
}

/// What ended a run.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum End {
    /// Its own LF (the last byte of the run).
    LineEnd,
    /// A header byte, which starts the next run.
    Header,
    /// The length limit: the stretch goes on in the next run.
    Limit,
}

/// One run of the stream, borrowed from the deframer until the next call.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Run<'a> {
    pub kind: RunKind,
    pub bytes: &'a [u8],
    pub end: End,
}

/// Position of the first LF in `s`, eight bytes at a time.
#[inline]
pub(crate) fn find_lf(s: &[u8]) -> Option<usize> {
    const ONES: u64 = 0x0101_0101_0101_0101;
    const HIGH: u64 = 0x8080_8080_8080_8080;
    let mut chunks = s.chunks_exact(8);
    let mut base = 0;
    for c in &mut chunks {
        let w = u64::from_le_bytes(<[u8; 8]>::try_from(c).unwrap_or([0; 8]))
            ^ (ONES * u64::from(b'\n'));
        // Nonzero iff some byte of `w` is zero (the classic has-zero-byte test).
        let z = w.wrapping_sub(ONES) & !w & HIGH;
        if z != 0 {
            return Some(base + (z.trailing_zeros() / 8) as usize);
        }
        base += 8;
    }
    chunks
        .remainder()
        .iter()
        .position(|&b| b == b'\n')
        .map(|p| base + p)
}

/// Splits a byte stream into [`Run`]s. Feed bytes with [`push`](Self::push) in any split;
/// take runs with [`pull`](Self::pull) until it returns `None`. Never panics; after
/// every `pull` has returned `None`, fewer than `limit` bytes are held.
#[derive(Debug, Clone)]
pub struct Deframer {
    buf: Vec<u8>,
    /// Start of the unconsumed bytes.
    start: usize,
    /// Bytes in `start..scanned` hold nothing that ends the current run.
    scanned: usize,
    header: [bool; 256],
    limit: usize,
    cut_at_header: bool,
}

impl Deframer {
    /// A deframer whose runs start at any byte of `headers` and hold at most `limit`
    /// bytes (CR LF included). With `cut_at_header`, a header byte always ends the run
    /// before it (a receiver that restarts on every header); without, only an LF ends a
    /// run from a header, since frame data may hold header characters (text), and the
    /// caller decides with [`rewind`](Self::rewind) whether to restart inside it.
    pub fn new(headers: &[u8], limit: usize, cut_at_header: bool) -> Self {
        let mut header = [false; 256];
        for &h in headers {
            header[usize::from(h)] = true;
        }
        Self {
            buf: Vec::new(),
            start: 0,
            scanned: 0,
            header,
            limit: limit.max(1),
            cut_at_header,
        }
    }

    /// Whether `b` starts a run.
    #[inline]
    pub fn is_header(&self, b: u8) -> bool {
        self.header[usize::from(b)]
    }

    /// Adds received bytes.
    #[inline]
    pub fn push(&mut self, bytes: &[u8]) {
        if self.start == self.buf.len() {
            self.buf.clear();
            self.start = 0;
            self.scanned = 0;
        } else if self.start >= COMPACT_AT {
            self.buf.drain(..self.start);
            self.scanned -= self.start.min(self.scanned);
            self.start = 0;
            if self.buf.capacity() > 4 * (COMPACT_AT + self.limit) {
                self.buf.shrink_to(2 * (COMPACT_AT + self.limit));
            }
        }
        self.buf.extend_from_slice(bytes);
    }

    /// Bytes received but not yet handed out in a run.
    pub fn pending(&self) -> usize {
        self.buf.len() - self.start
    }

    /// Drops the pending bytes and returns them.
    pub fn take_pending(&mut self) -> Vec<u8> {
        let rest = self.buf.get(self.start..).unwrap_or(&[]).to_vec();
        self.buf.clear();
        self.start = 0;
        self.scanned = 0;
        rest
    }

    /// Gives back the last `n` bytes of the run just pulled: they are split again.
    pub fn rewind(&mut self, n: usize) {
        self.start -= n.min(self.start);
        self.scanned = self.start;
    }

    #[inline]
    fn emit(&mut self, kind: RunKind, end_at: usize, end: End) -> Option<Run<'_>> {
        let from = self.start;
        self.start = end_at;
        self.scanned = end_at;
        Some(Run {
            kind,
            bytes: self.buf.get(from..end_at).unwrap_or(&[]),
            end,
        })
    }

    /// The next complete run, or `None` when more bytes are needed.
    #[inline]
    pub fn pull(&mut self) -> Option<Run<'_>> {
        let first = *self.buf.get(self.start)?;
        if !self.is_header(first) {
            return self.pull_noise();
        }
        let from = self.scanned.max(self.start + 1);
        let overlong = self.start + self.limit;
        // Never past the length limit: a long stretch without LF is cut there, and a
        // search to the end of a large buffer for every cut would take quadratic time.
        let end = self.buf.len().min(overlong + 1);
        let tail = self.buf.get(from..end).unwrap_or(&[]);
        let found = if self.cut_at_header {
            tail.iter().position(|&b| b == b'\n' || self.is_header(b))
        } else {
            find_lf(tail)
        };
        match found.map(|off| from + off) {
            Some(at) if at >= overlong => self.emit(RunKind::Overlong, overlong, End::Limit),
            Some(at) if self.buf.get(at) == Some(&b'\n') => {
                self.emit(RunKind::Candidate, at + 1, End::LineEnd)
            }
            Some(at) => self.emit(RunKind::Cut, at, End::Header),
            None => {
                self.scanned = end.max(from);
                if self.buf.len() >= overlong {
                    return self.emit(RunKind::Overlong, overlong, End::Limit);
                }
                None
            }
        }
    }

    fn pull_noise(&mut self) -> Option<Run<'_>> {
        let from = self.scanned.max(self.start);
        let limit = self.start + self.limit;
        let end = self.buf.len().min(limit + 1);
        let tail = self.buf.get(from..end).unwrap_or(&[]);
        match tail
            .iter()
            .position(|&b| b == b'\n' || self.is_header(b))
            .map(|off| from + off)
        {
            Some(at) if at >= limit => self.emit(RunKind::Noise, limit, End::Limit),
            Some(at) if self.buf.get(at) == Some(&b'\n') => {
                self.emit(RunKind::Noise, at + 1, End::LineEnd)
            }
            Some(at) => self.emit(RunKind::Noise, at, End::Header),
            None => {
                self.scanned = end.max(from);
                if self.buf.len() >= limit {
                    return self.emit(RunKind::Noise, limit, End::Limit);
                }
                None
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn runs(d: &mut Deframer, input: &[u8]) -> Vec<(RunKind, Vec<u8>, End)> {
        d.push(input);
        std::iter::from_fn(|| d.pull().map(|r| (r.kind, r.bytes.to_vec(), r.end))).collect()
    }

    #[test]
    fn lf_search_finds_the_first_lf_anywhere() {
        for len in 0..40 {
            for at in 0..=len {
                let mut v = vec![b'A'; len];
                if at < len {
                    v[at] = b'\n';
                    if at + 3 < len {
                        v[at + 3] = b'\n';
                    }
                }
                let want = v.iter().position(|&b| b == b'\n');
                assert_eq!(find_lf(&v), want, "{len} {at}");
            }
        }
        assert_eq!(find_lf(&[0x8A, 0x0B, 0x0A]), Some(2));
    }

    #[test]
    fn a_receiver_restarts_on_every_header() {
        let mut d = Deframer::new(b"!", 64, true);
        let got = runs(&mut d, b"#99\r\nzz!99215!992152B\r\n!9");
        use {End::*, RunKind::*};
        assert_eq!(
            got,
            vec![
                (Noise, b"#99\r\n".to_vec(), LineEnd),
                (Noise, b"zz".to_vec(), Header),
                (Cut, b"!99215".to_vec(), Header),
                (Candidate, b"!992152B\r\n".to_vec(), LineEnd),
            ]
        );
        assert_eq!(d.pending(), 2);
    }

    #[test]
    fn without_cutting_only_lf_ends_a_run_and_rewind_resplits() {
        let mut d = Deframer::new(b"!#&", 64, false);
        d.push(b"#99!x\r\n");
        let run = d.pull().unwrap();
        assert_eq!(
            (run.kind, run.bytes),
            (RunKind::Candidate, &b"#99!x\r\n"[..])
        );
        d.rewind(4);
        let run = d.pull().unwrap();
        assert_eq!((run.kind, run.bytes), (RunKind::Candidate, &b"!x\r\n"[..]));
    }

    #[test]
    fn the_limit_bounds_runs_and_memory() {
        let mut d = Deframer::new(b"!", 8, true);
        use {End::*, RunKind::*};
        assert_eq!(
            runs(&mut d, b"!2345678"),
            vec![(Overlong, b"!2345678".to_vec(), Limit)]
        );
        assert_eq!(
            runs(&mut d, b"9\r\n!234567\n"),
            vec![
                (Noise, b"9\r\n".to_vec(), LineEnd),
                (Candidate, b"!234567\n".to_vec(), LineEnd)
            ]
        );
        assert_eq!(
            runs(&mut d, b"abcdefghij"),
            vec![(Noise, b"abcdefgh".to_vec(), Limit)]
        );
        assert!(d.pending() < 8);
    }

    /// A large batch of headers and junk without one LF (a flood) is cut at the limit
    /// run after run, every byte accounted for; each cut looks no further than the limit.
    #[test]
    fn a_flood_without_lf_is_cut_at_the_limit_every_byte_accounted() {
        let mut d = Deframer::new(b"!#&", 64, false);
        let junk: Vec<u8> = (0..100_000u32)
            .map(|i| b"#abc!&xyz"[(i % 9) as usize])
            .collect();
        d.push(&junk);
        let mut total = 0;
        while let Some(r) = d.pull() {
            assert!(r.bytes.len() <= 64);
            total += r.bytes.len();
        }
        assert!(junk.len() - total < 64, "{total} of {}", junk.len());
    }
}
