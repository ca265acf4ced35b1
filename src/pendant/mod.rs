//! The application model (no egui, no threads; time passed in).

pub mod teach;
pub mod teach_file;
