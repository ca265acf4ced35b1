//! The continuous jog's lease (dead man's switch): its caller renews it while the button
//! is held; when it is not renewed in time the core stops the jog by itself.
//!
//! Renewal is an atomic timestamp (`LeaseClock`), not a channel message: the window
//! renews every frame, and a renewal must neither queue up behind other messages nor cost
//! an allocation. The driver reads the clock and hands the core the instant
//! ([`super::core::Input::LeaseRenewed`]); the core's `JogLease` is plain state.

use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

use super::driver::later;

/// How long a continuous jog lives without a renewal (the window renews it every frame
/// while a jog is held; [`RENEW_EVERY`]).
pub const JOG_LEASE: Duration = Duration::from_millis(250);

/// How often a held jog renews its lease: six times a lease, so a frame or two late
/// never lets it lapse.
pub const RENEW_EVERY: Duration = Duration::from_millis(JOG_LEASE.as_millis() as u64 / 6);

/// When the lease was last renewed, shared by the handle and the driver.
#[derive(Debug)]
pub(crate) struct LeaseClock {
    epoch: Instant,
    /// Nanoseconds from `epoch` to the last renewal, plus one; 0 = never renewed.
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
        let nanos = u64::try_from(self.epoch.elapsed().as_nanos()).unwrap_or(u64::MAX - 1);
        self.renewed.fetch_max(nanos + 1, Ordering::Relaxed);
    }

    /// The last renewal, if there was one.
    pub(crate) fn renewed_at(&self) -> Option<Instant> {
        let stamp = self.renewed.load(Ordering::Relaxed);
        let nanos = stamp.checked_sub(1)?;
        self.epoch.checked_add(Duration::from_nanos(nanos))
    }
}

/// A core's view of the lease: when it was last renewed, and whether a jog runs on it.
#[derive(Debug, Clone)]
pub(crate) struct JogLease {
    renewed_at: Option<Instant>,
    length: Duration,
    /// When a continuous jog went out with no STOP acknowledged since; `None` when none
    /// runs on the lease.
    held_since: Option<Instant>,
}

impl JogLease {
    pub(crate) fn new(length: Duration) -> Self {
        Self {
            renewed_at: None,
            length,
            held_since: None,
        }
    }

    /// The caller renewed the lease at `at`.
    pub(crate) fn renewed(&mut self, at: Instant) {
        self.renewed_at = Some(self.renewed_at.map_or(at, |r| r.max(at)));
    }

    /// When the lease runs out (it may already have); never renewed: already out.
    fn expires(&self) -> Option<Instant> {
        self.renewed_at.map(|at| later(at, self.length))
    }

    pub(crate) fn lapsed(&self, now: Instant) -> bool {
        self.expires().is_none_or(|t| now > t)
    }

    /// A continuous jog went out at `now`: from now on the lease keeps it alive.
    /// Answers whether this jog took the lease (no other was held on it).
    pub(crate) fn hold(&mut self, now: Instant) -> bool {
        self.held_since.replace(now).is_none()
    }

    /// The jog was stopped (or a STOP for it is on its way).
    pub(crate) fn release(&mut self) {
        self.held_since = None;
    }

    /// While a jog runs on the lease, the instant the core must look at it: just after
    /// it runs out.
    pub(crate) fn deadline(&self) -> Option<Instant> {
        let held_since = self.held_since?;
        let out = self.expires().unwrap_or(held_since);
        Some(later(out, Duration::from_nanos(1)))
    }

    /// True once, when a running jog's lease has lapsed (the jog is then released).
    pub(crate) fn take_lapse(&mut self, now: Instant) -> bool {
        if self.held_since.is_some() && self.lapsed(now) {
            self.held_since = None;
            return true;
        }
        false
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_held_lease_lapses_once_unless_renewed() {
        let now = Instant::now();
        let mut lease = JogLease::new(Duration::from_millis(50));
        lease.renewed(now);
        assert!(!lease.take_lapse(now), "not held yet");
        lease.hold(now);
        assert!(!lease.take_lapse(now + Duration::from_millis(50)));
        let later = now + Duration::from_millis(200);
        assert!(lease.take_lapse(later));
        assert!(!lease.take_lapse(later), "reported once");
        assert_eq!(lease.deadline(), None);
    }

    #[test]
    fn the_clock_says_never_until_renewed() {
        let clock = LeaseClock::new();
        assert_eq!(clock.renewed_at(), None);
        clock.renew();
        let at = clock.renewed_at().expect("renewed");
        assert!(at <= Instant::now());
    }
}
