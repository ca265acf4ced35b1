//! The guardian: a child process (`xsel-pendant --guardian`, the same binary, no window)
//! that owns a serial port or TCP bridge for the window and stops the arm when the window
//! dies, freezes or is killed. The window's link runs unchanged over [`GuardianLine`];
//! the guardian relays its frames and keeps its own rules in [`core::GuardianCore`].
//!
//! What it covers: the window's process exiting, crashing, being killed or stopped. What
//! it does not: the guardian itself or the PC dying, or a cable pulled while the arm
//! moves; a real cell needs a hard-wired enabling switch and E-stop in the controller's
//! safety circuit. The built-in simulator lives in the window's process and dies with it,
//! so it needs no guardian.

pub mod client;
pub mod core;
pub mod guard;
pub mod process;
pub mod rmc_core;
pub mod wire;

use std::time::Duration;

pub use client::GuardianLine;
pub use process::run;

/// The flag that makes the binary a guardian.
pub const GUARDIAN_FLAG: &str = "--guardian";

/// How often the window's process says it is alive. Several fit in the lease, so one
/// late beat on a loaded PC costs no STOP.
pub const HEARTBEAT: Duration = Duration::from_millis(50);
