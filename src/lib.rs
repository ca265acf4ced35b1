//! xsel-pendant: a teach pendant for IAI SCARA robots on X-SEL controllers.
//!
//! This crate is the window and its pictures; everything below it is the UI-free
//! `xsel-pendant-core` (crates/core), re-exported here under the same paths. Layers (see
//! DESIGN.md), arrows pointing down only:
//!
//! - [`ui`]: egui panels drawing the pendant and pushing intents -> [`pendant`],
//!   [`session`], [`render`] (never `link` or `sim`).
//! - [`render`]: the arm view's scene and the plots' picture, painted with egui or
//!   tiny-skia; [`render_cli`] paints them to PNG files for the binary's flags.
//! - The core's layers: [`pendant`] (the model, sans-IO), [`session`], [`link`], [`sim`],
//!   [`robot_wire`], [`files`], [`line`](mod@line), [`protocol`], [`rmc`], [`robot`],
//!   [`cli`], [`headless`], [`flags`].

#![forbid(unsafe_code)]
// Library code answers bad input instead of panicking (unit tests may unwrap).
#![cfg_attr(
    not(test),
    warn(clippy::unwrap_used, clippy::expect_used, clippy::panic)
)]

pub use xsel_pendant_core::{
    cli, driven, files, first_contact, flags, headless, line, link, pendant, protocol, rmc, robot,
    robot_wire, sel, session, sim,
};

pub mod render;
pub mod render_cli;
pub mod ui;
