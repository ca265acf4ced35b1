//! How long the link waits for a reply, and when the line is free for the next command.

use std::time::Duration;

use crate::line::LineSettings;

/// The link's timing policy (PROTOCOL.md 1.5: the spec's "Timeout and Retry" chapter was
/// not retrievable, so the figures here are [inferred] defaults, all configurable).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Timing {
    /// Line settings whose character time sizes the wire part of each timeout.
    pub line: LineSettings,
    /// Added to the wire time of command and longest reply: the controller's response
    /// delay (I/O parameter 97) and its processing time.
    pub margin: Duration,
    /// Pause after a reply before the next command (the spec's minimum is 1 ms).
    pub gap: Duration,
    /// How long after a time-out its reply may still arrive; motion waits for proof
    /// that no such reply is on its way (see `sync.rs`).
    pub late_reply_window: Duration,
}

impl Default for Timing {
    fn default() -> Self {
        Self {
            line: LineSettings::default(),
            margin: Duration::from_millis(300),
            gap: Duration::from_millis(1),
            late_reply_window: Duration::from_secs(1),
        }
    }
}

impl Timing {
    /// Time from the last byte written until the reply must be complete: both frames'
    /// wire time (the write may return before the bytes left the port) plus the margin.
    pub fn reply_timeout(&self, command_len: usize, max_reply_len: usize) -> Duration {
        self.line.wire_time(command_len + max_reply_len) + self.margin
    }

    /// The shortest time one transaction can take on this line with a controller whose
    /// reply delay is `reply_delay`: bytes × bits per char / baud + delay + gap.
    pub fn wire_transaction_time(
        &self,
        command_len: usize,
        reply_len: usize,
        reply_delay: Duration,
    ) -> Duration {
        self.line.wire_time(command_len + reply_len) + reply_delay + self.gap
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn timeout_grows_with_the_expected_reply_and_a_slow_line() {
        let slow = Timing {
            line: LineSettings {
                baud: 9_600,
                ..LineSettings::default()
            },
            margin: Duration::from_millis(100),
            gap: Duration::from_millis(1),
            late_reply_window: Duration::from_secs(1),
        };
        // A 2A4H command (17 bytes) whose reply may fill a 2048-byte buffer: 2065 chars
        // at 10 bits and 9600 baud is 2.151 s on the wire alone.
        let t = slow.reply_timeout(17, 2048);
        assert!(
            t > Duration::from_millis(2_250) && t < Duration::from_millis(2_260),
            "{t:?}"
        );
        let fast = Timing {
            line: LineSettings::default(),
            ..slow
        };
        assert!(fast.reply_timeout(17, 2048) < Duration::from_millis(300));
    }

    #[test]
    fn wire_transaction_time_counts_bytes_delay_and_gap() {
        let t = Timing {
            line: LineSettings {
                baud: 9_600,
                ..LineSettings::default()
            },
            margin: Duration::ZERO,
            ..Timing::default()
        };
        // 10 + 25 bytes (215H) = 350 bits = 36.458 ms, + 2 ms delay + 1 ms gap.
        let got = t.wire_transaction_time(10, 25, Duration::from_millis(2));
        assert_eq!(got.as_micros(), 36_458 + 3_000);
    }
}
