//! The continuous jog's lease (dead man's switch): its caller renews it while the button
//! is held; when it is not renewed in time the link thread stops the jog by itself.
//!
//! Renewal is an atomic timestamp, not a channel message: the window renews every frame,
//! and a renewal must neither queue up behind other messages nor cost an allocation.

use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

use crate::protocol::{Command, Thou};

/// When the lease was last renewed, shared by the handle and the link thread.
#[derive(Debug)]
pub(crate) struct LeaseClock {
    epoch: Instant,
    /// Nanoseconds from `epoch` to the last renewal.
    renewed: AtomicU64,
}

impl LeaseClock {
    pub(crate) fn new() -> Self {
        Self {
            epoch: Instant::now(),
            renewed: AtomicU64::new(0),
        }
    }

    pub(crate) fn renew(&self) {
        let nanos = u64::try_from(self.epoch.elapsed().as_nanos()).unwrap_or(u64::MAX);
        self.renewed.fetch_max(nanos, Ordering::Relaxed);
    }

    fn renewed_at(&self) -> Instant {
        let nanos = self.renewed.load(Ordering::Relaxed);
        self.epoch
            .checked_add(Duration::from_nanos(nanos))
            .unwrap_or(self.epoch)
    }
}

/// A jog that runs until stopped (236H with distance 0): it lives on the lease.
pub(crate) fn is_continuous_jog(command: &Command) -> bool {
    matches!(command, Command::Jog(j) if j.distance == Thou(0))
}

/// The link thread's view of the lease.
#[derive(Debug)]
pub(crate) struct JogLease {
    pub(crate) clock: std::sync::Arc<LeaseClock>,
    length: Duration,
    /// A continuous jog went out and no STOP has been acknowledged since.
    held: bool,
}

impl JogLease {
    pub(crate) fn new(clock: std::sync::Arc<LeaseClock>, length: Duration) -> Self {
        Self {
            clock,
            length,
            held: false,
        }
    }

    /// When the lease runs out (it may already have).
    pub(crate) fn expires(&self) -> Instant {
        super::engine::later(self.clock.renewed_at(), self.length)
    }

    pub(crate) fn lapsed(&self, now: Instant) -> bool {
        now > self.expires()
    }

    /// A continuous jog went out: from now on the lease keeps it alive.
    /// Answers whether this jog took the lease (no other was held on it).
    pub(crate) fn hold(&mut self) -> bool {
        !std::mem::replace(&mut self.held, true)
    }

    /// The jog was stopped (or a STOP for it is on its way).
    pub(crate) fn release(&mut self) {
        self.held = false;
    }

    /// While a jog runs on the lease, the instant the link must wake up to check it.
    pub(crate) fn deadline(&self) -> Option<Instant> {
        self.held.then(|| self.expires())
    }

    /// True once, when a running jog's lease has lapsed (the jog is then released).
    pub(crate) fn take_lapse(&mut self, now: Instant) -> bool {
        if self.held && self.lapsed(now) {
            self.held = false;
            return true;
        }
        false
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::Arc;

    #[test]
    fn a_held_lease_lapses_once_unless_renewed() {
        let clock = Arc::new(LeaseClock::new());
        let mut lease = JogLease::new(clock.clone(), Duration::from_millis(50));
        clock.renew();
        let now = Instant::now();
        assert!(!lease.take_lapse(now), "not held yet");
        lease.hold();
        assert!(!lease.take_lapse(now));
        let later = now + Duration::from_millis(200);
        assert!(lease.take_lapse(later));
        assert!(!lease.take_lapse(later), "reported once");
        assert_eq!(lease.deadline(), None);
    }
}
