//! What one 215H probe got back: a reply, an error reply, an echo, garbage or silence.

use std::fmt;

use crate::protocol::{
    Command, ErrorCode, Header, Reply, ScMode, Station, StreamDecoder, SystemStatus,
};

/// Received bytes kept as a sample for the report.
const SAMPLE_LEN: usize = 32;

/// What a probe got back within its time-out.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Outcome {
    /// A valid 215H reply (PROTOCOL.md 3.4): a controller at this setting.
    Answered {
        /// The station the reply carries (the one asked: a controller answers only its
        /// own station, PROTOCOL.md 1.3).
        station: Station,
        status: SystemStatus,
    },
    /// An `&` error reply (PROTOCOL.md section 2): the command was understood, so this is
    /// still a controller at this setting.
    ErrorReply { station: Station, code: ErrorCode },
    /// Only our own command came back: a loopback plug or an echoing adapter, no controller
    /// `[inferred]`.
    Echo,
    /// Bytes that do not make a reply: likely a wrong baud rate, data bits or parity.
    Garbage {
        /// How many bytes were received that are not our echo.
        bytes: usize,
        /// Why the first of them did not decode.
        detail: String,
        /// The first bytes received (at most 32), for the report.
        sample: Vec<u8>,
    },
    /// Nothing came back: no controller, another station, or a setting so wrong that the
    /// controller dropped the command (PROTOCOL.md 1.6).
    Silence,
}

impl Outcome {
    /// Whether a controller answered (normally or with an error reply).
    pub fn is_controller(&self) -> bool {
        matches!(self, Outcome::Answered { .. } | Outcome::ErrorReply { .. })
    }
}

impl fmt::Display for Outcome {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Outcome::Answered { station, status } => {
                write!(f, "answered as station {station}: ")?;
                describe_status(status, f)
            }
            Outcome::ErrorReply { station, code } => write!(
                f,
                "error reply {code} from station {station} (a controller, which refused 215H)"
            ),
            Outcome::Echo => f.write_str("only the command's echo came back (loopback?)"),
            Outcome::Garbage { bytes, detail, .. } => write!(
                f,
                "{bytes} byte(s) that do not decode (wrong baud rate or parity?): {detail}"
            ),
            Outcome::Silence => f.write_str("no answer"),
        }
    }
}

/// "AUTO, ready" or "MANUAL, not ready, emergency stop, critical error 0A1".
fn describe_status(s: &SystemStatus, f: &mut fmt::Formatter<'_>) -> fmt::Result {
    match s.mode.name() {
        Some(name) => f.write_str(name)?,
        None => write!(f, "mode {}", s.mode.0)?,
    }
    f.write_str(if s.status3.ready() {
        ", ready"
    } else {
        ", not ready"
    })?;
    if s.status1.emergency_stop() {
        f.write_str(", emergency stop")?;
    }
    if s.status3.drive_cut_off() {
        f.write_str(", drive source cut off")?;
    }
    if s.critical_error != ErrorCode::NONE {
        write!(f, ", critical error {}", s.critical_error)?;
    }
    Ok(())
}

/// One 215H probe, sans-IO: holds the command to send, takes the bytes that come back in
/// any split, and says what they were.
#[derive(Debug)]
pub struct Attempt {
    command: Vec<u8>,
    decoder: StreamDecoder,
    answer: Option<Outcome>,
    echoed: bool,
    garbage: usize,
    detail: Option<String>,
    sample: Vec<u8>,
}

impl Attempt {
    /// A 215H system status query to `station`, with a computed SC.
    pub fn new(station: Station) -> Self {
        let mut command = Vec::with_capacity(10);
        // 215H has no data, so encoding cannot fail; an empty command would be refused
        // by the write and reported as silence, never a panic.
        let _ = Command::SystemStatus.encode_into(station, ScMode::Computed, &mut command);
        Self {
            command,
            decoder: StreamDecoder::new(),
            answer: None,
            echoed: false,
            garbage: 0,
            detail: None,
            sample: Vec::new(),
        }
    }

    /// The command frame to write.
    pub fn command(&self) -> &[u8] {
        &self.command
    }

    /// Takes received bytes; returns true once a reply (normal or error) has come, after
    /// which more bytes change nothing.
    pub fn push(&mut self, bytes: &[u8]) -> bool {
        if self.answer.is_some() {
            return true;
        }
        if self.sample.len() < SAMPLE_LEN {
            let room = SAMPLE_LEN - self.sample.len();
            self.sample
                .extend_from_slice(bytes.get(..room.min(bytes.len())).unwrap_or(bytes));
        }
        self.decoder.push(bytes);
        while let Some(item) = self.decoder.pull() {
            let frame = match item {
                Ok(frame) => frame,
                Err(e) => {
                    self.bad(e.raw().len(), e.to_string());
                    continue;
                }
            };
            if frame.header() == Header::Command && frame.raw() == self.command.as_slice() {
                self.echoed = true;
                continue;
            }
            match Reply::decode(&frame) {
                Ok(Reply::SystemStatus(status)) => {
                    self.answer = Some(Outcome::Answered {
                        station: frame.station(),
                        status,
                    });
                }
                Ok(Reply::Error(code)) => {
                    self.answer = Some(Outcome::ErrorReply {
                        station: frame.station(),
                        code,
                    });
                }
                Ok(_) => self.bad(
                    frame.raw().len(),
                    format!("a valid frame that is not a 215H reply: {frame}"),
                ),
                Err(e) => self.bad(frame.raw().len(), format!("{frame}: {e}")),
            }
            if self.answer.is_some() {
                return true;
            }
        }
        false
    }

    fn bad(&mut self, bytes: usize, detail: String) {
        self.garbage += bytes;
        self.detail.get_or_insert(detail);
    }

    /// Whether a reply has come.
    pub fn is_settled(&self) -> bool {
        self.answer.is_some()
    }

    /// What came back: the reply if one came, else garbage (counting bytes still waiting
    /// for a line end), else an echo, else silence.
    pub fn finish(mut self) -> Outcome {
        if let Some(answer) = self.answer.take() {
            return answer;
        }
        let pending = self.decoder.take_pending();
        if !pending.is_empty() {
            let detail = format!("{} byte(s) without a line end", pending.len());
            self.bad(pending.len(), detail);
        }
        if self.garbage > 0 {
            return Outcome::Garbage {
                bytes: self.garbage,
                detail: self.detail.unwrap_or_default(),
                sample: self.sample,
            };
        }
        if self.echoed {
            Outcome::Echo
        } else {
            Outcome::Silence
        }
    }
}

/// Classifies everything received after a 215H to `station` (pure: for recorded bytes).
pub fn classify(station: Station, received: &[u8]) -> Outcome {
    let mut attempt = Attempt::new(station);
    attempt.push(received);
    attempt.finish()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::protocol::SystemMode;

    fn reply(station: Station, status: SystemStatus) -> Vec<u8> {
        Reply::SystemStatus(status)
            .to_bytes(station)
            .unwrap_or_default()
    }

    #[test]
    fn the_spec_example_reply_is_an_answer() {
        // PROTOCOL.md 3.4: "#9921510000000000060004" answers "!992152B".
        let got = classify(Station::DEFAULT, b"#9921510000000000060004\r\n");
        let Outcome::Answered { station, status } = got else {
            panic!("{got:?}");
        };
        assert_eq!(station, Station::DEFAULT);
        assert_eq!(status.mode, SystemMode::AUTO);
        assert!(status.status3.ready());
        assert_eq!(Attempt::new(Station::DEFAULT).command(), b"!992152B\r\n");
    }

    #[test]
    fn a_reply_in_pieces_after_an_echo_settles_the_attempt() {
        let status = SystemStatus::default();
        let bytes = reply(Station(0x05), status);
        let mut a = Attempt::new(Station(0x05));
        let echo = a.command().to_vec();
        assert!(!a.push(&echo));
        let (x, y) = bytes.split_at(7);
        assert!(!a.push(x));
        assert!(a.push(y));
        assert!(a.push(b"\xFFtrailing junk changes nothing"));
        assert_eq!(
            a.finish(),
            Outcome::Answered {
                station: Station(0x05),
                status
            }
        );
    }

    #[test]
    fn an_error_reply_is_still_a_controller() {
        // PROTOCOL.md section 2 example: "&99CC14F".
        let got = classify(Station::DEFAULT, b"&99CC14F\r\n");
        assert_eq!(
            got,
            Outcome::ErrorReply {
                station: Station::DEFAULT,
                code: ErrorCode(0xCC1)
            }
        );
        assert!(got.is_controller());
        assert!(got.to_string().contains("CC1"), "{got}");
    }

    /// What a UART set to `rx_baud` 8N1 receives when `bytes` are sent at `tx_baud` 8N1:
    /// line levels sampled 16 times a bit to find each start edge, then once in the middle
    /// of each bit, as a UART does (synthesised here; no recording was available).
    fn received_at(bytes: &[u8], tx_baud: u32, rx_baud: u32) -> Vec<u8> {
        let bits: Vec<bool> = bytes
            .iter()
            .flat_map(|&b| {
                std::iter::once(false)
                    .chain((0..8).map(move |i| b >> i & 1 == 1))
                    .chain(std::iter::once(true))
            })
            .collect();
        let level = |t: f64| {
            bits.get((t * f64::from(tx_baud)) as usize)
                .copied()
                .unwrap_or(true)
        };
        let (rx_bit, end) = (
            1.0 / f64::from(rx_baud),
            bits.len() as f64 / f64::from(tx_baud),
        );
        let mut out = Vec::new();
        let mut t = 0.0;
        while t < end {
            if level(t) {
                t += rx_bit / 16.0;
                continue;
            }
            let byte = (0..8).fold(0u8, |acc, i| {
                acc | u8::from(level(t + (1.5 + f64::from(i)) * rx_bit)) << i
            });
            out.push(byte);
            t += 9.5 * rx_bit;
        }
        out
    }

    #[test]
    fn a_reply_at_the_wrong_baud_rate_is_garbage() {
        let reply = b"#9921510000000000060004\r\n";
        assert_eq!(received_at(reply, 38_400, 38_400), reply);
        for (tx, rx) in [
            (115_200, 38_400),
            (38_400, 115_200),
            (9_600, 19_200),
            (57_600, 9_600),
        ] {
            let received = received_at(reply, tx, rx);
            let got = classify(Station::DEFAULT, &received);
            let Outcome::Garbage { bytes, sample, .. } = &got else {
                panic!("{tx} read at {rx}: {received:?} gave {got:?}");
            };
            assert_eq!(*bytes, received.len());
            assert_eq!(sample.as_slice(), &received[..received.len().min(32)]);
            assert!(!got.is_controller());
            assert!(got.to_string().contains("wrong baud rate"), "{got}");
        }
    }

    #[test]
    fn seven_bit_replies_read_as_eight_bit_are_garbage() {
        // A 7E1 controller's reply read as 8N1: the parity bit lands in bit 7 of the
        // characters with an odd number of ones.
        let good = b"#9921510000000000060004\r\n";
        let garbled: Vec<u8> = good
            .iter()
            .map(|&b| if b.count_ones() % 2 == 1 { b | 0x80 } else { b })
            .collect();
        assert!(matches!(
            classify(Station::DEFAULT, &garbled),
            Outcome::Garbage { .. }
        ));
    }

    #[test]
    fn a_bad_checksum_or_a_cut_reply_is_garbage_not_silence() {
        let got = classify(Station::DEFAULT, b"#9921510000000000060005\r\n");
        assert!(matches!(got, Outcome::Garbage { bytes: 25, .. }), "{got:?}");
        let got = classify(Station::DEFAULT, b"#99215100000");
        assert!(matches!(got, Outcome::Garbage { bytes: 12, .. }), "{got:?}");
        // Another message's valid reply is not a 215H answer.
        let got = classify(Station::DEFAULT, b"#992322C\r\n");
        assert!(matches!(got, Outcome::Garbage { .. }), "{got:?}");
    }

    #[test]
    fn nothing_is_silence_and_only_the_echo_is_echo() {
        assert_eq!(classify(Station::DEFAULT, b""), Outcome::Silence);
        assert_eq!(classify(Station::DEFAULT, b"!992152B\r\n"), Outcome::Echo);
    }

    #[test]
    fn any_bytes_classify_without_panicking() {
        const ALPHABET: &[u8] = b"#&!\r\n0123456789ABCDEF\xff";
        let mut seed = 0x2545_F491_u32;
        for len in 0..400 {
            let bytes: Vec<u8> = (0..len)
                .map(|_| {
                    seed ^= seed << 13;
                    seed ^= seed >> 17;
                    seed ^= seed << 5;
                    ALPHABET[seed as usize % ALPHABET.len()]
                })
                .collect();
            let _ = classify(Station(0x99), &bytes).to_string();
        }
    }
}
