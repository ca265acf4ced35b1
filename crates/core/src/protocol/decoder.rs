//! Streaming decoder: bytes in any split in, frames or typed errors out, with resync.

use std::fmt;

use super::deframe::{Deframer, RunKind};
use super::frame::{Frame, FrameError, FrameErrorKind, MAX_FRAME_LEN, OwnedFrame};

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

/// The headers a client accepts: commands (in logs of both directions), replies, errors.
const HEADERS: &[u8] = b"!#&";

/// Splits a byte stream into frames. Feed bytes with [`push`](Self::push) in any split;
/// take results with [`pull`](Self::pull) until it returns `None`.
///
/// Resynchronises on the next header after any error. Never panics. After every
/// `pull` has returned `None`, at most [`MAX_FRAME_LEN`] + 1 bytes are held.
#[derive(Debug, Clone)]
pub struct StreamDecoder {
    runs: Deframer,
}

impl Default for StreamDecoder {
    fn default() -> Self {
        Self::new()
    }
}

impl StreamDecoder {
    /// An empty decoder.
    pub fn new() -> Self {
        // Runs of MAX_FRAME_LEN + 1 bytes reach the parser, which names the excess.
        Self {
            runs: Deframer::new(HEADERS, MAX_FRAME_LEN + 1, false),
        }
    }

    /// Adds received bytes.
    #[inline]
    pub fn push(&mut self, bytes: &[u8]) {
        self.runs.push(bytes);
    }

    /// Bytes received but not yet returned as a frame or an error.
    pub fn pending(&self) -> usize {
        self.runs.pending()
    }

    /// Drops the pending bytes and returns them (e.g. after a reply time-out).
    pub fn take_pending(&mut self) -> Vec<u8> {
        self.runs.take_pending()
    }

    /// The next complete frame or error, or `None` when more bytes are needed.
    pub fn pull(&mut self) -> Option<Result<OwnedFrame, DecodeError>> {
        let run = self.runs.pull()?;
        let (kind, bytes) = (run.kind, run.bytes);
        let error = match kind {
            RunKind::Noise => {
                return Some(Err(DecodeError::Garbage {
                    raw: bytes.to_vec(),
                }));
            }
            RunKind::Candidate => match Frame::parse(bytes) {
                Ok(frame) => return Some(Ok(frame.into_owned())),
                Err(e) => DecodeError::Frame(e),
            },
            RunKind::Overlong => DecodeError::Overlong {
                raw: bytes.to_vec(),
            },
            // Not made without `cut_at_header`; read like a frame cut by a header.
            RunKind::Cut => return Some(Err(cut_short(bytes.to_vec()))),
        };
        // A header inside means an earlier frame was cut short: report the piece before
        // it and restart there (the rest is split again).
        let inner = bytes
            .get(1..)
            .and_then(|c| c.iter().position(|&b| is_header(b)))
            .map(|k| k + 1);
        let Some(k) = inner else {
            return Some(Err(error));
        };
        let raw = bytes.get(..k).unwrap_or(&[]).to_vec();
        let rest = bytes.len() - k;
        self.runs.rewind(rest);
        Some(Err(cut_short(raw)))
    }
}

/// A run from a header that lacks its line end because the next header came first.
fn cut_short(raw: Vec<u8>) -> DecodeError {
    let kind = match Frame::parse(&raw) {
        Err(e) => e.kind,
        Ok(_) => FrameErrorKind::MissingLineEnd {
            column: raw.len() + 1,
        },
    };
    DecodeError::Frame(FrameError { raw, kind })
}

#[inline]
fn is_header(b: u8) -> bool {
    HEADERS.contains(&b)
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
