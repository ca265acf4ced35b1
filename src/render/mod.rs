//! The arm view: the SCARA seen from above as a scene of plain primitives in millimetres
//! of the base frame ([`scene`], built from the robot model and state by [`build`]), and
//! two painters of it: egui shapes for the live window ([`paint_egui`]) and tiny-skia to
//! a PNG of any size ([`paint_png`]). The scene and its builder know no painter and
//! import only [`crate::robot`] of the project.

pub mod build;
mod envelope;
mod gauge;
mod glyphs;
pub mod labels;
pub mod paint_egui;
pub mod paint_png;
pub mod plot;
pub mod scene;
pub mod style;
pub mod view;

pub use build::{
    Ghost, GhostCheck, Marker, OverlayFrame, SceneInput, SelectedFrame, build_scene, reach_at,
};
pub use scene::{Anchor, Item, Mm, Role, Scene, Shape};
pub use style::{Palette, Rgba, Style};
pub use view::View;

#[cfg(test)]
mod tests;
