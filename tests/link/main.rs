//! The link over real lines and threads (smoke tests beside the core's virtual-clock tests) and the guardian process.
//!
//! One test binary for the group: each links the whole app, so fewer binaries build faster.

#[path = "../common/mod.rs"]
mod common;
#[path = "../wait/mod.rs"]
mod wait;

mod backlog;
mod faults;
mod guardian;
mod probe;
mod programs;
mod rmc_guardian;
mod rmc_hold;
mod shutdown;
mod soak;
mod with_sim;
