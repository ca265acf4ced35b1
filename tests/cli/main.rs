//! The binaries as processes: the pendant's and the simulator's flags, headless PNG rendering.
//!
//! One test binary for the group: each links the whole app, so fewer binaries build faster.

#[path = "../bin_common/mod.rs"]
mod bin_common;
#[path = "../wait/mod.rs"]
mod wait;

mod first_contact;
mod flags;
mod lean;
mod pendant;
mod render_png;
mod sim;
mod snapshot;
