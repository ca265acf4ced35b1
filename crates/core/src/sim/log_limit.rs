//! The simulator's traffic log kept readable and bounded under garbage, as the pendant's
//! frame log is: a dropped run shows at most its first bytes (and says how many more it
//! had), at most a few dropped runs are logged a second, the rest counted in one line
//! (random input of 138 MB once grew the log to 568 MB). Frames answered and replies sent
//! are logged whole: they are bounded by the receive limit and the reply buffer.

use std::time::Duration;

use super::framing::Silence;
use super::runner::{Dir, TrafficEntry, format_entry, format_entry_cut};

/// Bytes of a logged dropped run shown before it is cut.
pub const SHOWN_BYTES: usize = 80;
/// Dropped runs logged in one second; the rest are counted.
pub const RUNS_A_SECOND: u32 = 10;
const SECOND: Duration = Duration::from_secs(1);

/// Counts dropped runs per second of traffic time and cuts long ones.
#[derive(Debug, Default)]
pub struct LogLimiter {
    window: Duration,
    shown: u32,
    held_runs: u64,
    held_bytes: u64,
}

impl LogLimiter {
    /// The log lines for `entry` (none when it is held back), after a line for what was
    /// held back before it.
    pub fn lines(&mut self, entry: &TrafficEntry) -> Vec<String> {
        let mut out = Vec::new();
        if entry.at >= self.window + SECOND {
            out.extend(self.summary(entry.at));
            self.window = entry.at;
            self.shown = 0;
        }
        if is_garbage(entry) {
            if self.shown >= RUNS_A_SECOND {
                self.held_runs += 1;
                self.held_bytes += entry.bytes.len() as u64;
                return out;
            }
            self.shown += 1;
        } else {
            out.extend(self.summary(entry.at));
        }
        out.push(if is_garbage(entry) {
            format_entry_cut(entry, SHOWN_BYTES)
        } else {
            format_entry(entry)
        });
        out
    }

    /// What was held back, said once (at the end of a run, too).
    pub fn summary(&mut self, at: Duration) -> Option<String> {
        (self.held_runs > 0).then(|| {
            let line = format!(
                "[{:>10.6}] rx {} more dropped runs ({} bytes) not shown: at most {RUNS_A_SECOND} \
                 are logged a second",
                at.as_secs_f64(),
                self.held_runs,
                self.held_bytes
            );
            self.held_runs = 0;
            self.held_bytes = 0;
            line
        })
    }
}

/// A run the simulator dropped as not a frame for it (not a reboot or reset silence).
fn is_garbage(entry: &TrafficEntry) -> bool {
    entry.dir == Dir::In
        && matches!(
            entry.silence,
            Some(
                Silence::TooShort
                    | Silence::Header
                    | Silence::Station
                    | Silence::MessageId
                    | Silence::Terminator
                    | Silence::Checksum
                    | Silence::Overflow
            )
        )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn garbage(at_ms: u64, len: usize) -> TrafficEntry {
        TrafficEntry {
            at: Duration::from_millis(at_ms),
            dir: Dir::In,
            bytes: vec![0xA5; len],
            fault: None,
            silence: Some(Silence::Header),
        }
    }

    #[test]
    fn a_flood_of_garbage_logs_a_few_runs_a_second_and_counts_the_rest() {
        let mut l = LogLimiter::default();
        let mut lines = Vec::new();
        for i in 0..1000 {
            lines.extend(l.lines(&garbage(i, 3)));
        }
        lines.extend(l.lines(&garbage(1000, 3)));
        assert_eq!(lines.len(), RUNS_A_SECOND as usize + 2, "{lines:#?}");
        let summary = &lines[RUNS_A_SECOND as usize];
        assert!(
            summary.contains("990 more dropped runs (2970 bytes)"),
            "{summary}"
        );
    }

    #[test]
    fn a_long_run_is_cut_and_says_how_much_was_left_out() {
        let mut l = LogLimiter::default();
        let line = l.lines(&garbage(0, 1_000_000)).remove(0);
        assert!(line.len() < 1000, "{} bytes", line.len());
        assert!(line.contains("… (999920 more bytes)"), "{line}");
        assert!(!line.contains("CR LF"), "no reason from the cut: {line}");
    }

    /// A long reply (2A1H answers are hundreds of bytes) is logged whole, with no reason
    /// made up from a cut head.
    #[test]
    fn a_long_reply_is_logged_whole() {
        let mut l = LogLimiter::default();
        let mut bytes = b"#992A1".to_vec();
        bytes.extend([b'0'; 300]);
        bytes.extend(b"@@\r\n");
        let reply = TrafficEntry {
            at: Duration::ZERO,
            dir: Dir::Out,
            bytes,
            fault: None,
            silence: None,
        };
        let line = l.lines(&reply).remove(0);
        assert!(line.contains(&"0".repeat(300)), "{line}");
        assert!(line.contains("@@\\r\\n"), "{line}");
        assert!(!line.contains("more bytes"), "{line}");
        assert!(!line.contains("does not end with CR LF"), "{line}");
    }

    #[test]
    fn frames_are_never_held_back_and_the_count_comes_before_them() {
        let mut l = LogLimiter::default();
        for i in 0..20 {
            l.lines(&garbage(i, 1));
        }
        let frame = TrafficEntry {
            silence: None,
            ..garbage(30, 5)
        };
        let lines = l.lines(&frame);
        assert_eq!(lines.len(), 2, "{lines:?}");
        assert!(lines[0].contains("10 more dropped runs"), "{}", lines[0]);
    }
}
