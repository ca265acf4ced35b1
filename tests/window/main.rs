//! The whole app driven headless with egui_kittest: the window, its panes, snapshots, the frame log.
//!
//! One test binary for the group: each links the whole app, so fewer binaries build faster.

#[path = "../kittest_common/mod.rs"]
mod kittest_common;
#[path = "../wire/mod.rs"]
mod wire;

mod alarms;
mod axes;
mod coords;
mod first_contact;
mod frame_log;
mod frame_log_replay;
mod jog_panel;
mod layout_file;
// Image snapshots render with wgpu: `cargo test --features wgpu` (CI runs them).
#[cfg(feature = "wgpu")]
mod frame_log_snapshot;
mod main_window;
mod markers;
mod plots;
mod positions;
mod programs;
mod sessions;
mod signals;
mod simulator;
mod sizes;
#[cfg(feature = "wgpu")]
mod snapshots;
mod zones;
