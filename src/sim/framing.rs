//! Receiving side of Format B as a controller sees it: splitting the byte stream into
//! candidate frames, and the reasons for silence. Frames themselves are read by
//! [`crate::protocol::Frame::parse`].

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
    /// A run that can never be a command, reported at its LF or when a new `!` starts:
    /// no `!` header, a frame cut by a new `!`, or one longer than the limit (`bytes`
    /// then holds only its first `limit` bytes).
    Dropped { bytes: &'a [u8], reason: Silence },
}

/// Splits an incoming byte stream into candidate frames.
///
/// A frame starts at `!` and ends at LF. Bytes before a `!` are line noise; a run longer
/// than the receive limit without LF is dropped whole `[inferred, PROTOCOL.md 1.6: the
/// controller answers nothing it cannot recognise]`. Dropped runs are reported so they
/// can be logged and counted.
#[derive(Debug)]
pub struct Assembler {
    /// The current run (at most `limit` bytes kept).
    buf: Vec<u8>,
    /// All bytes of the current run, kept or not.
    run: usize,
    /// The current run started with `!`.
    in_frame: bool,
    /// The last push handed out `buf`: clear it on the next byte.
    delivered: bool,
    /// A dropped run reported when a `!` starts a new frame.
    report: Vec<u8>,
    limit: usize,
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
            buf: Vec::new(),
            run: 0,
            in_frame: false,
            delivered: false,
            report: Vec::new(),
            limit: limit.max(1),
            dropped: 0,
        }
    }

    fn reason(&self) -> Silence {
        if !self.in_frame {
            Silence::Header
        } else if self.run > self.limit {
            Silence::Overflow
        } else {
            Silence::Terminator
        }
    }

    /// Feeds one byte; returns a complete frame (with CR LF) or a dropped run when this
    /// byte ends one.
    pub fn push(&mut self, byte: u8) -> Option<Received<'_>> {
        if self.delivered {
            self.buf.clear();
            self.run = 0;
            self.in_frame = false;
            self.delivered = false;
        }
        if byte == b'!' && self.run > 0 {
            // A new header ends the run before it: noise or a frame without LF.
            let reason = self.reason();
            self.dropped += self.run as u64;
            std::mem::swap(&mut self.report, &mut self.buf);
            self.buf.clear();
            self.buf.push(byte);
            self.run = 1;
            self.in_frame = true;
            return Some(Received::Dropped {
                bytes: &self.report,
                reason,
            });
        }
        if byte == b'!' {
            self.in_frame = true;
        }
        self.run += 1;
        if self.buf.len() < self.limit {
            self.buf.push(byte);
        }
        if byte != b'\n' {
            return None;
        }
        self.delivered = true;
        if self.in_frame && self.run <= self.limit {
            return Some(Received::Frame(&self.buf));
        }
        self.dropped += self.run as u64;
        Some(Received::Dropped {
            bytes: &self.buf,
            reason: self.reason(),
        })
    }

    /// Bytes of an unfinished run are waiting.
    pub fn pending(&self) -> bool {
        !self.delivered && self.run > 0
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
    fn overflow_is_reported_at_its_lf() {
        let mut a = Assembler::with_limit(12);
        let got = runs(&mut a, b"!99200123456789\r\n!9920027\r\n");
        assert_eq!(
            got,
            vec![
                (b"!99200123456".to_vec(), Some(Silence::Overflow)),
                (b"!9920027\r\n".to_vec(), None),
            ]
        );
        assert_eq!(max_command(1024), 1023);
        assert_eq!(max_command(2048), 2051);
    }
}
