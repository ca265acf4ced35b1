//! The simulated X-SEL: conformance over a pty, the embedded pipe, lines, long runs, stand-in hosts;
//! and the simulated RMC151 (`rmc-sim`) over TCP.
//!
//! One test binary for the group: each links the whole app, so fewer binaries build faster.

#[path = "../wait/mod.rs"]
mod wait;
#[path = "../wire/mod.rs"]
mod wire;

mod conformance;
mod embedded;
mod lines;
mod long_run;
mod positions;
mod programs;
mod rmc;
mod rmc_abuse;
mod signals;
mod sim_abuse;
mod spawn;
mod stand_in;
