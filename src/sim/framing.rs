//! Receiving side of Format B as a controller sees it: splitting the byte stream into
//! candidate frames, and the reasons for silence. Frames themselves are read by
//! [`crate::protocol::Frame::parse`].

/// Longest command a controller can receive (PROTOCOL.md 1.7: 2051 bytes on the larger
/// controllers); a longer run without LF is dropped.
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
    /// No CR LF at the end.
    Terminator,
    /// SC wrong or not hex (and not `@@`).
    Checksum,
    /// Longer than the receive buffer.
    Overflow,
    /// The controller is rebooting after 25BH.
    Rebooting,
}

/// Splits an incoming byte stream into candidate frames.
///
/// A frame starts at `!` and ends at LF. Bytes before a `!` are line noise and are
/// dropped (counted); a run longer than [`MAX_COMMAND`] without LF is dropped whole
/// `[inferred, PROTOCOL.md 1.6: the controller answers nothing it cannot recognise]`.
/// A frame without `!` never reaches the controller, which is the "wrong header" silence.
#[derive(Debug, Default)]
pub struct Assembler {
    buf: Vec<u8>,
    in_frame: bool,
    overflow: bool,
    /// Bytes dropped as noise or overflow.
    pub dropped: u64,
}

impl Assembler {
    pub fn new() -> Self {
        Self::default()
    }

    /// Feeds one byte; returns a complete frame (with CR LF) when this byte ends one.
    pub fn push(&mut self, byte: u8) -> Option<&[u8]> {
        if byte == b'!' {
            // A new header restarts the frame: what came before was noise.
            self.dropped += self.buf.len() as u64;
            self.buf.clear();
            self.in_frame = true;
            self.overflow = false;
        }
        if !self.in_frame {
            self.dropped += 1;
            return None;
        }
        if self.overflow {
            self.dropped += 1;
        } else {
            self.buf.push(byte);
            if self.buf.len() > MAX_COMMAND {
                self.dropped += self.buf.len() as u64;
                self.buf.clear();
                self.overflow = true;
            }
        }
        if byte == b'\n' {
            self.in_frame = false;
            if self.overflow {
                self.overflow = false;
                return None;
            }
            return Some(&self.buf);
        }
        None
    }

    /// Bytes of an unfinished frame are waiting.
    pub fn pending(&self) -> bool {
        self.in_frame
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn assembler_resyncs_on_header() {
        let mut a = Assembler::new();
        let mut frames = Vec::new();
        for &b in b"xx\r\n!99215!992152B\r\nzz" {
            if let Some(f) = a.push(b) {
                frames.push(f.to_vec());
            }
        }
        assert_eq!(frames, vec![b"!992152B\r\n".to_vec()]);
        assert!(a.dropped > 0);
    }
}
