//! Streaming decoder: bytes in any split in, frames or typed errors out, with resync.

use std::fmt;

use super::frame::{Frame, FrameError, FrameErrorKind, MAX_FRAME_LEN, OwnedFrame};

/// Consumed bytes are dropped from the buffer's front once this many have accumulated.
const COMPACT_AT: usize = 32 * 1024;

/// Something in the byte stream that is not a valid frame, with its raw bytes.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub enum DecodeError {
    /// Bytes before a header (`!`, `#`, `&`), or a line without one.
    Garbage {
        /// The bytes skipped.
        raw: Vec<u8>,
    },
    /// A header followed by bytes up to LF (or up to the next header) that do not form a
    /// valid frame: bad checksum, missing CR LF, bad station, ...
    Frame(FrameError),
    /// A header followed by more than [`MAX_FRAME_LEN`] bytes without LF.
    Overlong {
        /// The bytes dropped (the header and the following `MAX_FRAME_LEN` bytes).
        raw: Vec<u8>,
    },
}

impl DecodeError {
    /// The bytes this error covers.
    pub fn raw(&self) -> &[u8] {
        match self {
            DecodeError::Garbage { raw } | DecodeError::Overlong { raw } => raw,
            DecodeError::Frame(e) => &e.raw,
        }
    }
}

impl fmt::Display for DecodeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            DecodeError::Garbage { raw } => write!(
                f,
                "{} byte(s) that are not part of a frame (no '!', '#' or '&' header)",
                raw.len()
            ),
            DecodeError::Frame(e) => e.fmt(f),
            DecodeError::Overlong { raw } => write!(
                f,
                "no line end within {} bytes after a header: dropped {} bytes",
                MAX_FRAME_LEN,
                raw.len()
            ),
        }
    }
}

impl std::error::Error for DecodeError {}

/// Position of the first LF in `s`, eight bytes at a time.
#[inline]
fn find_lf(s: &[u8]) -> Option<usize> {
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

#[inline]
fn is_header(b: u8) -> bool {
    matches!(b, b'!' | b'#' | b'&')
}

/// Splits a byte stream into frames. Feed bytes with [`push`](Self::push) in any split;
/// take results with [`pull`](Self::pull) until it returns `None`.
///
/// Resynchronises on the next header after any error. Never panics. After every
/// `pull` has returned `None`, at most [`MAX_FRAME_LEN`] + 1 bytes are held.
#[derive(Debug, Default)]
pub struct StreamDecoder {
    buf: Vec<u8>,
    /// Start of the unconsumed bytes.
    start: usize,
    /// Bytes in `start..scanned` have been searched already (for LF when `buf[start]` is a
    /// header; for a header or LF otherwise).
    scanned: usize,
}

impl StreamDecoder {
    /// An empty decoder.
    pub fn new() -> Self {
        Self::default()
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
            if self.buf.capacity() > 4 * (COMPACT_AT + MAX_FRAME_LEN) {
                self.buf.shrink_to(2 * (COMPACT_AT + MAX_FRAME_LEN));
            }
        }
        self.buf.extend_from_slice(bytes);
    }

    /// Bytes received but not yet returned as a frame or an error.
    pub fn pending(&self) -> usize {
        self.buf.len() - self.start
    }

    /// Drops the pending bytes and returns them (e.g. after a reply time-out).
    pub fn take_pending(&mut self) -> Vec<u8> {
        let rest = self.buf.get(self.start..).unwrap_or(&[]).to_vec();
        self.buf.clear();
        self.start = 0;
        self.scanned = 0;
        rest
    }

    fn emit_bytes(&mut self, end: usize) -> Vec<u8> {
        let raw = self.buf.get(self.start..end).unwrap_or(&[]).to_vec();
        self.start = end;
        self.scanned = end;
        raw
    }

    /// The next complete frame or error, or `None` when more bytes are needed.
    pub fn pull(&mut self) -> Option<Result<OwnedFrame, DecodeError>> {
        let first = *self.buf.get(self.start)?;
        if !is_header(first) {
            return self.pull_garbage();
        }
        let from = self.scanned.max(self.start + 1);
        let tail = self.buf.get(from..).unwrap_or(&[]);
        let Some(off) = find_lf(tail) else {
            self.scanned = self.buf.len();
            if self.buf.len() - self.start > MAX_FRAME_LEN {
                return Some(Err(self.overlong()));
            }
            return None;
        };
        let end = from + off + 1;
        let cand = self.buf.get(self.start..end).unwrap_or(&[]);
        match Frame::parse(cand) {
            Ok(frame) => {
                let frame = frame.into_owned();
                self.start = end;
                self.scanned = end;
                Some(Ok(frame))
            }
            Err(e) => {
                // A header inside means an earlier frame was cut short: report the
                // piece before it and restart there (the rest is searched again).
                if let Some(k) = cand
                    .get(1..)
                    .and_then(|c| c.iter().position(|&b| is_header(b)))
                {
                    return Some(Err(self.cut_short(self.start + 1 + k)));
                }
                self.start = end;
                self.scanned = end;
                Some(Err(DecodeError::Frame(e)))
            }
        }
    }

    /// Bytes from `start` up to the header at `k`, which lack a line end.
    fn cut_short(&mut self, k: usize) -> DecodeError {
        let raw = self.buf.get(self.start..k).unwrap_or(&[]).to_vec();
        self.start = k;
        // `scanned` still holds: no LF was seen before it, and it is >= k.
        let kind = match Frame::parse(&raw) {
            Err(e) => e.kind,
            Ok(_) => FrameErrorKind::MissingLineEnd {
                column: raw.len() + 1,
            },
        };
        DecodeError::Frame(FrameError { raw, kind })
    }

    fn overlong(&mut self) -> DecodeError {
        let limit = self.start + MAX_FRAME_LEN + 1;
        let inner = self
            .buf
            .get(self.start + 1..limit)
            .and_then(|c| c.iter().position(|&b| is_header(b)));
        match inner {
            Some(k) => self.cut_short(self.start + 1 + k),
            None => DecodeError::Overlong {
                raw: self.emit_bytes(limit),
            },
        }
    }

    fn pull_garbage(&mut self) -> Option<Result<OwnedFrame, DecodeError>> {
        let from = self.scanned.max(self.start);
        let tail = self.buf.get(from..).unwrap_or(&[]);
        match tail.iter().position(|&b| is_header(b) || b == b'\n') {
            Some(off) => {
                let at = from + off;
                let is_lf = self.buf.get(at) == Some(&b'\n');
                let end = if is_lf { at + 1 } else { at };
                Some(Err(DecodeError::Garbage {
                    raw: self.emit_bytes(end),
                }))
            }
            None => {
                self.scanned = self.buf.len();
                if self.buf.len() - self.start > MAX_FRAME_LEN {
                    let end = self.buf.len();
                    return Some(Err(DecodeError::Garbage {
                        raw: self.emit_bytes(end),
                    }));
                }
                None
            }
        }
    }
}

impl Iterator for StreamDecoder {
    type Item = Result<OwnedFrame, DecodeError>;

    /// Same as [`StreamDecoder::pull`].
    fn next(&mut self) -> Option<Self::Item> {
        self.pull()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::protocol::ids::MessageId;

    fn drain(d: &mut StreamDecoder) -> Vec<Result<OwnedFrame, DecodeError>> {
        std::iter::from_fn(|| d.pull()).collect()
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
    fn frames_split_anywhere_come_out_whole() {
        let bytes = b"#992322C\r\n#99212021C00000000002715AF\r\n";
        for split in 0..bytes.len() {
            let mut d = StreamDecoder::new();
            let (a, b) = bytes.split_at(split);
            d.push(a);
            let mut out = drain(&mut d);
            d.push(b);
            out.extend(drain(&mut d));
            let ids: Vec<_> = out.into_iter().map(|r| r.unwrap().id()).collect();
            assert_eq!(ids, [Some(MessageId::SERVO), Some(MessageId::AXIS_STATUS)]);
            assert_eq!(d.pending(), 0);
        }
    }

    #[test]
    fn garbage_then_frame() {
        let mut d = StreamDecoder::new();
        d.push(b"xx\x00yy#992322C\r\n");
        let out = drain(&mut d);
        assert_eq!(
            out[0],
            Err(DecodeError::Garbage {
                raw: b"xx\x00yy".to_vec()
            })
        );
        assert!(out[1].is_ok());
    }

    #[test]
    fn garbage_line_is_reported_at_its_line_end() {
        let mut d = StreamDecoder::new();
        d.push(b"hello\r\n");
        assert_eq!(
            d.pull(),
            Some(Err(DecodeError::Garbage {
                raw: b"hello\r\n".to_vec()
            }))
        );
        assert_eq!(d.pull(), None);
    }

    #[test]
    fn bad_checksum_is_an_error_and_the_next_frame_survives() {
        let mut d = StreamDecoder::new();
        d.push(b"#9921202040000000000270EAF\r\n#992322C\r\n");
        let out = drain(&mut d);
        match &out[0] {
            Err(DecodeError::Frame(e)) => {
                assert!(matches!(
                    e.kind,
                    FrameErrorKind::Checksum {
                        found: 0xAF,
                        computed: 0xAE,
                        ..
                    }
                ))
            }
            other => panic!("{other:?}"),
        }
        assert_eq!(out[1].as_ref().unwrap().id(), Some(MessageId::SERVO));
    }

    #[test]
    fn a_frame_cut_short_is_reported_and_the_next_recovered() {
        let mut d = StreamDecoder::new();
        d.push(b"#99212021C000#992322C\r\n");
        let out = drain(&mut d);
        match &out[0] {
            Err(DecodeError::Frame(e)) => {
                assert_eq!(e.raw, b"#99212021C000");
                assert!(matches!(
                    e.kind,
                    FrameErrorKind::MissingLineEnd { column: 14 }
                ));
            }
            other => panic!("{other:?}"),
        }
        assert_eq!(out[1].as_ref().unwrap().id(), Some(MessageId::SERVO));
    }

    #[test]
    fn overlong_frames_are_dropped_and_memory_stays_bounded() {
        let mut d = StreamDecoder::new();
        d.push(b"#");
        let chunk = [b'0'; 1000];
        let mut errors = 0;
        for _ in 0..40 {
            d.push(&chunk);
            for r in drain(&mut d) {
                assert!(r.is_err());
                errors += 1;
            }
            assert!(d.pending() <= MAX_FRAME_LEN + 1);
        }
        assert!(errors >= 2);
        d.push(b"\r\n#992322C\r\n");
        let out = drain(&mut d);
        assert!(out.last().unwrap().is_ok());
    }
}
