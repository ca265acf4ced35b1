//! xsel-pendant: a teach pendant for IAI SCARA robots on X-SEL controllers.
//!
//! Layers (see DESIGN.md), arrows pointing down only:
//!
//! - [`ui`]: egui panels drawing the pendant and pushing intents -> [`pendant`],
//!   [`session`], [`render`] (never `link` or `sim`).
//! - [`pendant`]: the application model, sans-IO -> [`link`]'s events, [`robot`],
//!   [`protocol`].
//! - [`session`]: a connection: the line prepared and opened, the link driver on it, the
//!   embedded simulator and its front panel -> [`link`], [`sim`].
//! - [`link`]: one driver thread per line running a sans-IO protocol core (Format B in
//!   `link::format_b`, the port probe) -> [`protocol`], [`line`](mod@line).
//! - [`sim`]: the simulated controllers (X-SEL, and the RMC151 in `sim::rmc`) ->
//!   [`robot_wire`], [`robot`], [`protocol`], [`rmc`], [`line`](mod@line).
//! - [`robot_wire`]: wire codes <-> robot types (arm policy, jog frame, arm system, table
//!   kind), the one place that knows both [`protocol`] and [`robot`].
//! - [`files`]: files the user names, read with a size bound and written whole, and the
//!   coordinate file both the pendant and the simulator read.
//! - [`line`](mod@line): byte lines (read with a timeout, write), line and connection
//!   settings, byte timing, the serial port list; shared by `link` and `sim`, which never
//!   import each other.
//! - [`protocol`] (the Format B codec) and [`robot`] (SCARA math) import nothing of the
//!   project; `line` imports nothing of it either.
//! - [`cli`] (the pendant's flags and line set-up) and [`headless`] (its text mode) sit
//!   above `link` and `sim`, for the binaries; [`flags`] answers a bad flag for both.

#![forbid(unsafe_code)]
// Library code answers bad input instead of panicking (unit tests may unwrap).
#![cfg_attr(
    not(test),
    warn(clippy::unwrap_used, clippy::expect_used, clippy::panic)
)]

pub mod cli;
pub mod files;
pub mod flags;
pub mod headless;
pub mod line;
pub mod link;
pub mod pendant;
pub mod protocol;
pub mod render;
pub mod render_cli;
pub mod rmc;
pub mod robot;
pub mod robot_wire;
pub mod session;
pub mod sim;
pub mod ui;
