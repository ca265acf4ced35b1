//! The SCARA model: kinematics, frames, motion, CP lines, robot files and bad input.
//!
//! One test binary for the group: each links the whole app, so fewer binaries build faster.

mod cp;
mod frames;
mod kinematics;
mod model;
mod motion;
mod robustness;
