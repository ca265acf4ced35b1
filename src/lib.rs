//! xsel-pendant: a teach pendant for IAI SCARA robots on X-SEL controllers.
//!
//! Layers (see DESIGN.md), arrows pointing down only:
//! `link -> protocol`, `sim -> robot, protocol`. `protocol` and `robot` import nothing of
//! the project.

pub mod codes;
pub mod line;
pub mod link;
pub mod protocol;
pub mod robot;
pub mod sim;
