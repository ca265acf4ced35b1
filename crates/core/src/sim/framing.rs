//! Receiving side of Format B as a controller sees it: splitting the byte stream into
//! candidate frames, and the reasons for silence. Frames themselves are read by
//! [`crate::protocol::Frame::parse`].

use crate::protocol::deframe::{Deframer, End, RunKind};

/// Longest command the larger controllers can receive (PROTOCOL.md 1.7: 2051 bytes);
/// see [`max_command`] for the 1024-byte reply-buffer setting.
pub const MAX_COMMAND: usize = 2051;

/// Why a frame gets no reply at all (PROTOCOL.md 1.6). Logged, never sent.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Silence {
    /// Shorter than the shortest command.
    TooShort,
    /// First byte is not `!`.
    Header,
    /// Station digits are not hex or not this controller's number.
    Station,
    /// The message ID is not 3 hex digits.
    MessageId,
    /// No CR LF at the end (or a new `!` came before the LF).
    Terminator,
    /// SC wrong or not hex (and not `@@`).
    Checksum,
    /// Longer than the receive buffer.
    Overflow,
    /// The controller is rebooting after 25BH.
    Rebooting,
    /// 25BH was carried out without a reply (`reset_replies` off).
    Reset,
    /// The reply could not be encoded (a simulator bug; never expected).
    Unencodable,
}

impl Silence {
    /// Short text for logs.
    pub fn text(self) -> &'static str {
        match self {
            Silence::TooShort => "shorter than any command",
            Silence::Header => "no '!' header",
            Silence::Station => "wrong station",
            Silence::MessageId => "message ID not 3 hex digits",
            Silence::Terminator => "no CR LF at the end",
            Silence::Checksum => "wrong checksum",
            Silence::Overflow => "longer than the receive buffer",
            Silence::Rebooting => "rebooting after 25BH",
            Silence::Reset => "25BH: reset without a reply",
            Silence::Unencodable => "reply could not be encoded",
        }
    }
}

/// The longest command the controller receives for its reply buffer setting
/// (PROTOCOL.md 1.7): 1023 bytes with the 1024-byte buffer (J/K/TT models), else 2051.
pub fn max_command(reply_buffer: usize) -> usize {
    if reply_buffer <= 1024 {
        1023
    } else {
        MAX_COMMAND
    }
}

/// What the assembler hands on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Received<'a> {
    /// A run from `!` to LF, within the receive limit: for the controller.
    Frame(&'a [u8]),
    /// A run that can never be a command, reported at its LF, when a new `!` starts, or
    /// at the limit: no `!` header, a frame cut by a new `!`, or one longer than the
    /// limit (`bytes` then holds only its first `limit` bytes).
    Dropped { bytes: &'a [u8], reason: Silence },
}

/// Splits an incoming byte stream into candidate frames, as the controller receives.
///
/// A frame starts at `!` and ends at LF; any `!` starts a new frame. Bytes before a `!`
/// are line noise; a run longer than the receive limit without LF is dropped whole
/// `[inferred, PROTOCOL.md 1.6: the controller answers nothing it cannot recognise]`.
/// Each dropped run is reported once, with at most its first `limit` bytes, so it can be
/// logged and counted; a run longer than the limit is reported when the limit is reached
/// and the rest of it is counted in [`dropped`](Self::dropped) only.
#[derive(Debug)]
pub struct Assembler {
    runs: Deframer,
    /// The run reported at the limit goes on: its remaining noise is not reported again.
    skipping: bool,
    /// Bytes dropped as noise, cut frames or overflow.
    pub dropped: u64,
}

impl Default for Assembler {
    fn default() -> Self {
        Self::new()
    }
}

impl Assembler {
    /// An assembler with the larger controllers' limit, [`MAX_COMMAND`].
    pub fn new() -> Self {
        Self::with_limit(MAX_COMMAND)
    }

    /// An assembler that drops runs longer than `limit` bytes.
    pub fn with_limit(limit: usize) -> Self {
        Self {
            runs: Deframer::new(b"!", limit, true),
            skipping: false,
            dropped: 0,
        }
    }

    /// Feeds one byte; returns a complete frame (with CR LF) or a dropped run when this
    /// byte ends one (or, for a run longer than the limit, reaches the limit).
    pub fn push(&mut self, byte: u8) -> Option<Received<'_>> {
        self.runs.push(&[byte]);
        // One byte completes at most one run, so one pull takes it.
        let run = self.runs.pull()?;
        self.dropped += match run.kind {
            RunKind::Candidate => 0,
            _ => run.bytes.len() as u64,
        };
        let reason = match run.kind {
            RunKind::Candidate => {
                self.skipping = false;
                return Some(Received::Frame(run.bytes));
            }
            RunKind::Noise if self.skipping => {
                self.skipping = run.end == End::Limit;
                return None;
            }
            RunKind::Noise => Silence::Header,
            RunKind::Cut => Silence::Terminator,
            RunKind::Overlong => Silence::Overflow,
        };
        self.skipping = run.end == End::Limit;
        Some(Received::Dropped {
            bytes: run.bytes,
            reason,
        })
    }

    /// How many bytes of an unfinished run are waiting.
    pub fn pending_len(&self) -> usize {
        self.runs.pending()
    }

    /// Bytes of an unfinished run are waiting.
    pub fn pending(&self) -> bool {
        self.skipping || self.runs.pending() > 0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every run handed out, as (bytes, None) for frames or (bytes, Some(reason)).
    fn runs(a: &mut Assembler, input: &[u8]) -> Vec<(Vec<u8>, Option<Silence>)> {
        let mut out = Vec::new();
        for &b in input {
            match a.push(b) {
                Some(Received::Frame(f)) => out.push((f.to_vec(), None)),
                Some(Received::Dropped { bytes, reason }) => {
                    out.push((bytes.to_vec(), Some(reason)))
                }
                None => {}
            }
        }
        out
    }

    #[test]
    fn assembler_resyncs_on_header() {
        let mut a = Assembler::new();
        let got = runs(&mut a, b"xx\r\n!99215!992152B\r\nzz");
        assert_eq!(
            got,
            vec![
                (b"xx\r\n".to_vec(), Some(Silence::Header)),
                (b"!99215".to_vec(), Some(Silence::Terminator)),
                (b"!992152B\r\n".to_vec(), None),
            ]
        );
        assert_eq!(a.dropped, 10);
        assert!(a.pending(), "zz waits");
    }

    #[test]
    fn runs_without_a_header_are_reported() {
        let mut a = Assembler::new();
        let got = runs(&mut a, b"#992152D\r\nhello\r\n!992152B\r\nzz!992152B\r\n");
        assert_eq!(
            got,
            vec![
                (b"#992152D\r\n".to_vec(), Some(Silence::Header)),
                (b"hello\r\n".to_vec(), Some(Silence::Header)),
                (b"!992152B\r\n".to_vec(), None),
                (b"zz".to_vec(), Some(Silence::Header)),
                (b"!992152B\r\n".to_vec(), None),
            ]
        );
        assert_eq!(a.dropped, 19, "frames are not counted as dropped");
        assert!(!a.pending());
    }

    #[test]
    fn overflow_is_reported_once_with_its_first_limit_bytes() {
        let mut a = Assembler::with_limit(12);
        let got = runs(&mut a, b"!99200123456789\r\n!9920027\r\n");
        assert_eq!(
            got,
            vec![
                (b"!99200123456".to_vec(), Some(Silence::Overflow)),
                (b"!9920027\r\n".to_vec(), None),
            ]
        );
        assert_eq!(a.dropped, 17, "the whole overlong run is counted");
        let got = runs(&mut a, b"abcdefghijklmnopqrstuvwxyz!9920027\r\n");
        assert_eq!(
            got,
            vec![
                (b"abcdefghijkl".to_vec(), Some(Silence::Header)),
                (b"!9920027\r\n".to_vec(), None),
            ],
            "a long stretch of noise is reported once"
        );
        assert_eq!(a.dropped, 17 + 26);
        assert_eq!(max_command(1024), 1023);
        assert_eq!(max_command(2048), 2051);
    }
}
