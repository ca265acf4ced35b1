//! The UI-free core of xsel-pendant: everything but the window and its pictures, which
//! live in the `xsel-pendant` crate above it (so the simulators link no UI).
//!
//! Layers (see DESIGN.md), arrows pointing down only (`ui` and `render` sit above these,
//! in `xsel-pendant`):
//!
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
//! - [`sel`]: SEL program text (the simulator's program file), parsed with errors by
//!   line and column; read by `sim` (to run) and `pendant` (to show) -> [`protocol`].
//! - [`files`]: files the user names, read with a size bound and written whole, and the
//!   coordinate file both the pendant and the simulator read.
//! - [`line`](mod@line): byte lines (read with a timeout, write), line and connection
//!   settings, byte timing, the serial port list; shared by `link` and `sim`, which never
//!   import each other.
//! - [`protocol`] (the Format B codec) and [`robot`] (SCARA math) import nothing of the
//!   project; `line` imports nothing of it either.
//! - [`cli`] (the pendant's flags and line set-up), [`headless`] (its text mode),
//!   [`driven`] (the model on a line with no window: `--snapshot`) and [`first_contact`]
//!   (the read-only report) sit above `link`, `sim` and `pendant`, for the binaries;
//!   [`flags`] answers a bad flag for all.

#![forbid(unsafe_code)]
// Library code answers bad input instead of panicking (unit tests may unwrap).
#![cfg_attr(
    not(test),
    warn(clippy::unwrap_used, clippy::expect_used, clippy::panic)
)]

pub mod cli;
pub mod driven;
pub mod files;
pub mod first_contact;
pub mod flags;
pub mod headless;
pub mod line;
pub mod link;
pub mod pendant;
pub mod protocol;
pub mod rmc;
pub mod robot;
pub mod robot_wire;
pub mod sel;
pub mod session;
pub mod sim;
