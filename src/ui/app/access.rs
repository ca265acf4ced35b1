//! What tests and benches read of the running window (and the few parts they drive).

use std::time::Instant;

use super::PendantApp;
use crate::pendant::Pendant;
use crate::session::SimHandle;
use crate::session::rmc::RmcSession;
use crate::ui::frame_log::FrameLogPanel;
use crate::ui::layout::Tab;

impl PendantApp {
    /// The pendant model (tests and benches read it).
    pub fn pendant(&self) -> &Pendant {
        &self.pendant
    }

    /// The pendant model, for scripted events (image tests).
    pub fn pendant_mut(&mut self) -> &mut Pendant {
        &mut self.pendant
    }

    /// The arm view (tests read the scene it painted last).
    pub fn arm_view(&self) -> &crate::ui::arm_view::ArmView {
        &self.panes.arm
    }

    /// The frame log pane (tests and benches read it).
    pub fn frame_log_panel(&self) -> &FrameLogPanel {
        &self.panes.frame_log
    }

    /// The frame log pane, to drive it from tests and benches.
    pub fn frame_log_panel_mut(&mut self) -> &mut FrameLogPanel {
        &mut self.panes.frame_log
    }

    /// The Plots pane's state (tests and benches read and set it).
    pub fn plots_panel(&self) -> &crate::ui::plots::PlotsPanel {
        &self.panes.plots
    }

    pub fn plots_panel_mut(&mut self) -> &mut crate::ui::plots::PlotsPanel {
        &mut self.panes.plots
    }

    /// Where the pane `tab` was drawn in the last frame, if it was shown (a tab behind
    /// another is not).
    pub fn pane_rect(&self, tab: Tab) -> Option<egui::Rect> {
        self.pane_rects
            .iter()
            .find(|(t, _)| *t == tab)
            .map(|(_, r)| *r)
    }

    /// When the window started (the messages' times count from here).
    pub fn started(&self) -> Instant {
        self.started
    }

    /// How many link events so far changed what the window shows (and so woke it).
    pub fn link_wakes(&self) -> u64 {
        self.lines.link_wakes()
    }

    /// How many old connections are still closing (on threads of their own).
    pub fn lines_closing(&self) -> usize {
        self.lines.closing()
    }

    /// The RMC151's session (tests reach its built-in simulator).
    pub fn rmc(&self) -> Option<&RmcSession> {
        self.lines.rmc()
    }

    /// The embedded simulator, when the line is the built-in one.
    pub fn sim(&self) -> Option<&SimHandle> {
        self.lines.sim()
    }
}
