//! One shape for every view: a pane draws the pendant and pushes intents, given the
//! frame's context; none writes a model field. The tile layout and the left column hold
//! panes and call them all the same way.

use std::path::Path;
use std::time::Instant;

use egui::Ui;

use crate::pendant::{Intent, Pendant};
use crate::session::simulator::FrontPanel;

/// What a pane draws with this frame.
pub struct PaneCx<'a> {
    pub pendant: &'a Pendant,
    pub now: Instant,
    /// When the window started (the messages' times count from here).
    pub started: Instant,
    /// The folder a file name typed without one is in.
    pub folder: &'a Path,
    /// What the panes ask for, applied after drawing (STOP at once).
    pub intents: &'a mut Vec<Intent>,
    /// The built-in simulator's front panel, when the line is the built-in one.
    pub sim: Option<&'a FrontPanel>,
}

/// A view of the window.
pub trait Pane {
    /// Draws the view in `ui` and pushes what the operator asked for.
    fn ui(&mut self, ui: &mut Ui, cx: &mut PaneCx<'_>);
}
