//! Receiving side of Format B as a controller sees it: splitting the byte stream into
//! frames, the silence rules (header, station, checksum, CR LF) and reply framing.

/// Longest command a controller can receive (PROTOCOL.md 1.7: 2051 bytes on the larger
/// controllers); a longer run without LF is dropped.
pub const MAX_COMMAND: usize = 2051;

/// Sum check of PROTOCOL.md 1.4: low byte of the sum of the bytes, header to last data char.
pub fn checksum(bytes: &[u8]) -> u8 {
    bytes.iter().fold(0u8, |s, &b| s.wrapping_add(b))
}

/// Why a frame gets no reply at all (PROTOCOL.md 1.6). Logged, never sent.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Silence {
    /// Shorter than the shortest command.
    TooShort,
    /// First byte is not `!`.
    Header,
    /// Station digits are not hex or not this controller's number.
    Station,
    /// No CR LF at the end.
    Terminator,
    /// SC wrong (and not `@@`).
    Checksum,
    /// Longer than the receive buffer.
    Overflow,
    /// The controller is rebooting after 25BH.
    Rebooting,
}

/// A frame that passed the silence rules: its message ID and data characters.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Accepted<'a> {
    pub id: [u8; 3],
    pub data: &'a [u8],
}

/// Applies the silence rules to one complete frame (including CR LF).
pub fn accept(frame: &[u8], station: u8) -> Result<Accepted<'_>, Silence> {
    if frame.len() > MAX_COMMAND {
        return Err(Silence::Overflow);
    }
    let Some(body) = frame.strip_suffix(b"\r\n") else {
        return Err(if frame.len() < 10 {
            Silence::TooShort
        } else {
            Silence::Terminator
        });
    };
    if body.first() != Some(&b'!') {
        return Err(Silence::Header);
    }
    if body.len() < 8 {
        return Err(Silence::TooShort);
    }
    if hex_value(&body[1..3]) != Some(u32::from(station)) {
        return Err(Silence::Station);
    }
    let (payload, sc) = body.split_at(body.len() - 2);
    // PROTOCOL.md 1.4: `@@` in the SC position is accepted as "no check" [observed/inferred].
    if sc != b"@@" && hex_value(sc) != Some(u32::from(checksum(payload))) {
        return Err(Silence::Checksum);
    }
    let mut id = [0u8; 3];
    id.copy_from_slice(&payload[3..6]);
    id.make_ascii_uppercase();
    Ok(Accepted {
        id,
        data: &payload[6..],
    })
}

/// Parses hex digits of either case (PROTOCOL.md 1.3: accept both cases in commands).
pub fn hex_value(digits: &[u8]) -> Option<u32> {
    if digits.is_empty() || digits.len() > 8 {
        return None;
    }
    let mut v: u32 = 0;
    for &d in digits {
        let n = (d as char).to_digit(16)?;
        v = (v << 4) | n;
    }
    Some(v)
}

/// Appends `value` as `width` upper-case hex digits (low bits kept).
pub fn push_hex(out: &mut Vec<u8>, value: u32, width: usize) {
    const DIGITS: &[u8; 16] = b"0123456789ABCDEF";
    for i in (0..width).rev() {
        let shift = 4 * i;
        let nibble = if shift >= 32 {
            0
        } else {
            (value >> shift) & 0xF
        };
        out.push(DIGITS[nibble as usize]);
    }
}

/// Appends a signed 32-bit value as 8 hex digits, two's complement (PROTOCOL.md 4).
pub fn push_i32(out: &mut Vec<u8>, value: i32) {
    push_hex(out, value as u32, 8);
}

/// Starts a normal reply: `#`, station, message ID. Finish with [`finish`].
pub fn begin_reply(out: &mut Vec<u8>, station: u8, id: [u8; 3]) {
    out.clear();
    out.push(b'#');
    push_hex(out, u32::from(station), 2);
    out.extend_from_slice(&id);
}

/// Appends SC and CR LF to whatever `out` holds.
pub fn finish(out: &mut Vec<u8>) {
    let sc = checksum(out);
    push_hex(out, u32::from(sc), 2);
    out.extend_from_slice(b"\r\n");
}

/// Writes a whole error reply `&` + station + code + SC + CR LF (PROTOCOL.md 2).
pub fn error_reply(out: &mut Vec<u8>, station: u8, code: u16) {
    out.clear();
    out.push(b'&');
    push_hex(out, u32::from(station), 2);
    push_hex(out, u32::from(code), 3);
    finish(out);
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
    fn worked_examples_from_protocol_md() {
        assert_eq!(checksum(b"!9921201"), 0x89);
        assert_eq!(checksum(b"#99232"), 0x2C);
        let mut out = Vec::new();
        error_reply(&mut out, 0x99, 0xCC1);
        assert_eq!(out, b"&99CC14F\r\n");
    }

    #[test]
    fn silence_rules() {
        assert!(accept(b"!992120189\r\n", 0x99).is_ok());
        assert!(accept(b"!9921201@@\r\n", 0x99).is_ok());
        assert_eq!(accept(b"!992120188\r\n", 0x99), Err(Silence::Checksum));
        assert_eq!(accept(b"!982120188\r\n", 0x99), Err(Silence::Station));
        assert_eq!(accept(b"#992120189\r\n", 0x99), Err(Silence::Header));
        assert_eq!(accept(b"!992120189\n", 0x99), Err(Silence::Terminator));
        assert_eq!(accept(b"!99\r\n", 0x99), Err(Silence::TooShort));
        let ok = accept(b"!992a10f0dd\r\n", 0x99);
        // lower-case: ID upper-cased, data kept, SC of the lower-case bytes differs
        assert!(ok.is_err() || ok.unwrap().id == *b"2A1");
    }

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

    #[test]
    fn hex_helpers() {
        let mut v = Vec::new();
        push_i32(&mut v, -12345);
        assert_eq!(v, b"FFFFCFC7");
        assert_eq!(hex_value(b"c350"), Some(50000));
        assert_eq!(hex_value(b"g0"), None);
    }
}
