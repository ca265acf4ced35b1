//! xsel-pendant: a teach pendant for IAI SCARA robots on X-SEL controllers.
//!
//! Layers (see DESIGN.md), arrows pointing down only:
//!
//! - [`link`]: the IO engine (one thread owns the line) -> [`protocol`], [`line`](mod@line).
//! - [`sim`]: the simulated controller -> [`codes`], [`robot`], [`protocol`], [`line`](mod@line).
//! - [`codes`]: wire codes <-> robot types (arm policy, jog frame, arm system), the one
//!   place that knows both [`protocol`] and [`robot`].
//! - [`line`](mod@line): byte lines (read with a timeout, write), line settings and byte timing,
//!   shared by `link` and `sim`, which never import each other.
//! - [`protocol`] (the Format B codec) and [`robot`] (SCARA math) import nothing of the
//!   project; `line` imports nothing of it either.
//! - [`files`]: files the user names, read with a size bound (imports nothing).
//! - [`cli`] (the pendant's flags and line set-up) and [`headless`] (its text mode) sit
//!   above `link` and `sim`, for the binaries; [`flags`] answers a bad flag for both.

#![forbid(unsafe_code)]
// Library code answers bad input instead of panicking (unit tests may unwrap).
#![cfg_attr(
    not(test),
    warn(clippy::unwrap_used, clippy::expect_used, clippy::panic)
)]

pub mod cli;
pub mod codes;
pub mod files;
pub mod flags;
pub mod headless;
pub mod line;
pub mod link;
pub mod pendant;
pub mod protocol;
pub mod render;
pub mod render_cli;
pub mod robot;
pub mod session;
pub mod sim;
pub mod ui;
