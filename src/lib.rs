//! xsel-pendant: a teach pendant for IAI SCARA robots on X-SEL controllers.
//!
//! Layers (see DESIGN.md), arrows pointing down only:
//! `link -> protocol`, `sim -> robot, protocol`. `protocol` and `robot` import nothing of
//! the project. `cli` (the pendant's flags and line set-up) and `headless` (its text mode)
//! sit above `link` and `sim`, for the binaries.

pub mod cli;
pub mod headless;
pub mod link;
pub mod pendant;
pub mod protocol;
pub mod robot;
pub mod sim;
