//! Link health as the connection panel shows it: round trips, poll rate, faults seen.

use std::collections::VecDeque;
use std::time::{Duration, Instant};

/// Counters and recent figures of one connection; cheap to clone into an event.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct LinkHealth {
    pub transactions: u64,
    pub replies: u64,
    pub error_replies: u64,
    pub timeouts: u64,
    pub retries: u64,
    /// Frames that failed to decode (bad checksum, missing LF, garbage...).
    pub bad_frames: u64,
    pub polls_per_second: f64,
    /// Median round trip (last byte sent to last byte received) of the recent replies.
    pub median_round_trip: Option<Duration>,
    /// Share of the last second the line was busy with transactions (0..=1).
    pub line_busy: f64,
    /// Traffic events (frames, garbage) left out because the event reader fell behind.
    pub events_dropped: u64,
    /// Status polling is paused because the event reader is far behind; it resumes by
    /// itself once the reader catches up.
    pub polling_paused: bool,
    /// How many times polling was paused for a reader that fell behind.
    pub reader_stalls: u64,
}

/// Collects what the link thread sees and condenses it into [`LinkHealth`].
#[derive(Debug, Default)]
pub struct HealthMeter {
    health: LinkHealth,
    round_trips: VecDeque<Duration>,
    poll_times: VecDeque<Instant>,
    busy: VecDeque<(Instant, Duration)>,
}

const KEEP_ROUND_TRIPS: usize = 64;
const WINDOW: Duration = Duration::from_secs(1);

impl HealthMeter {
    pub fn transaction(&mut self, started: Instant, ended: Instant, is_poll: bool) {
        self.health.transactions += 1;
        self.busy
            .push_back((ended, ended.saturating_duration_since(started)));
        if is_poll {
            self.poll_times.push_back(ended);
        }
        self.expire(ended);
    }

    pub fn reply(&mut self, round_trip: Duration) {
        self.health.replies += 1;
        if self.round_trips.len() == KEEP_ROUND_TRIPS {
            self.round_trips.pop_front();
        }
        self.round_trips.push_back(round_trip);
    }

    pub fn error_reply(&mut self) {
        self.health.error_replies += 1;
    }

    pub fn timeout(&mut self) {
        self.health.timeouts += 1;
    }

    pub fn retry(&mut self) {
        self.health.retries += 1;
    }

    pub fn polling_paused(&mut self, paused: bool) {
        if paused && !self.health.polling_paused {
            self.health.reader_stalls += 1;
        }
        self.health.polling_paused = paused;
    }

    pub fn bad_frame(&mut self) {
        self.health.bad_frames += 1;
    }

    fn expire(&mut self, now: Instant) {
        while self
            .poll_times
            .front()
            .is_some_and(|t| now.saturating_duration_since(*t) > WINDOW)
        {
            self.poll_times.pop_front();
        }
        while self
            .busy
            .front()
            .is_some_and(|(t, _)| now.saturating_duration_since(*t) > WINDOW)
        {
            self.busy.pop_front();
        }
    }

    /// The figures as of `now`.
    pub fn snapshot(&mut self, now: Instant) -> LinkHealth {
        self.expire(now);
        let mut health = self.health.clone();
        health.polls_per_second = self.poll_times.len() as f64 / WINDOW.as_secs_f64();
        let busy: Duration = self.busy.iter().map(|(_, d)| *d).sum();
        health.line_busy = (busy.as_secs_f64() / WINDOW.as_secs_f64()).min(1.0);
        let mut sorted: Vec<Duration> = self.round_trips.iter().copied().collect();
        sorted.sort_unstable();
        health.median_round_trip = sorted.get(sorted.len() / 2).copied();
        health
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn poll_rate_and_median_round_trip_follow_the_last_second() {
        let mut meter = HealthMeter::default();
        let t0 = Instant::now();
        for i in 0..20u32 {
            let start = t0 + Duration::from_millis(50) * i;
            meter.transaction(start, start + Duration::from_millis(10), true);
            meter.reply(Duration::from_millis(5 + u64::from(i % 3)));
        }
        let h = meter.snapshot(t0 + Duration::from_millis(960));
        assert_eq!(h.transactions, 20);
        assert!(
            (h.polls_per_second - 20.0).abs() < 0.5,
            "{}",
            h.polls_per_second
        );
        assert_eq!(h.median_round_trip, Some(Duration::from_millis(6)));
        assert!((h.line_busy - 0.2).abs() < 0.01, "{}", h.line_busy);
        // Two seconds later nothing is recent any more.
        let later = meter.snapshot(t0 + Duration::from_secs(3));
        assert_eq!(later.polls_per_second, 0.0);
        assert_eq!(later.transactions, 20);
    }
}
