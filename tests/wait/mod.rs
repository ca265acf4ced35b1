//! Waits with deadlines for the tests that run real threads, lines and processes: the one
//! polling helper and the time limits they share.
#![allow(dead_code)] // each test binary uses its own subset

use std::time::{Duration, Instant};

/// How long a wait on the link or a simulator in this process may take before the test
/// fails (only a failing test waits this long).
pub const LONG: Duration = Duration::from_secs(10);

/// How long a wait on another process (a guardian, a window or a binary the test started)
/// may take: it starts slower on a loaded machine.
pub const PROCESS: Duration = Duration::from_secs(20);

/// How often [`eventually`] checks its condition.
pub const POLL: Duration = Duration::from_millis(5);

/// Checks `cond` at once and then every [`POLL`] until it holds (true) or `within` has
/// passed (false). The only sleep of the polling waits.
pub fn eventually(within: Duration, mut cond: impl FnMut() -> bool) -> bool {
    let deadline = Instant::now() + within;
    loop {
        if cond() {
            return true;
        }
        if Instant::now() >= deadline {
            return false;
        }
        std::thread::sleep(POLL);
    }
}

/// Waits until `cond` holds; fails naming `what` once `within` has passed.
#[track_caller]
pub fn until(what: &str, within: Duration, cond: impl FnMut() -> bool) {
    assert!(
        eventually(within, cond),
        "timed out after {within:?} waiting for {what}"
    );
}
