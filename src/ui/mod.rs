//! The egui window: one file per view, each a [`Pane`] drawing the
//! [`crate::pendant::Pendant`] and pushing intents; they never see the link.
//! [`app::PendantApp`] is composition and the frame loop: its lines (`lines`) feed link
//! events to the pendant and run its requests after each frame.

pub mod alarms;
pub mod app;
mod arm_export;
pub mod arm_markers;
pub mod arm_view;
mod axes;
mod connection;
mod coords;
mod coords_table;
mod detect;
mod file_field;
mod file_work;
mod first_contact;
pub mod frame_log;
mod inbox;
mod jog;
mod keys;
mod layout;
mod lines;
mod messages;
mod pad;
mod pane;
pub mod plots;
mod ports;
pub mod positions;
pub mod programs;
mod readout;
mod rmc_connection;
mod run;
mod safety_band;
pub mod signals;
mod simulator;
mod snapshots;
mod start;
mod status;
mod teach;
mod top_bar;
mod wake;
mod widgets;
mod work_files;

pub use app::{APP_ID, PendantApp};
pub use layout::Tab;
pub use pane::{Pane, PaneCx};
pub use run::run_window;
pub use start::{BenchHooks, StartOptions};
