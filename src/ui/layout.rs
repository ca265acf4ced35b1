//! The rearrangeable centre of the window (egui_tiles): position, status, teach list and
//! messages as panes the operator can drag into tabs, rows and columns. The layout is
//! saved with the settings.
//!
//! egui_tiles rather than egui_dock: egui_tiles 0.18 is built on egui 0.37 (egui_dock's
//! latest release is still on 0.36, so it cannot share our egui), it is rerun's own
//! viewer layout (the model this app follows), and it allows rows, columns and grids,
//! not only binary splits. The frame log is a pane; the coordinate tables join as a further one.

use std::time::Instant;

use egui::{Ui, WidgetText};
use egui_tiles::{
    Behavior, Linear, LinearDir, SimplificationOptions, TileId, Tiles, Tree, UiResponse,
};
use serde::{Deserialize, Serialize};

use super::frame_log::FrameLogPanel;
use super::teach::TeachPanel;
use super::{messages, readout, status};
use crate::pendant::Pendant;

/// One tab of the centre.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Tab {
    Position,
    Status,
    Teach,
    Messages,
    FrameLog,
}

impl Tab {
    fn title(self) -> &'static str {
        match self {
            Tab::Position => "Position",
            Tab::Status => "Status",
            Tab::Teach => "Teach list",
            Tab::Messages => "Messages",
            Tab::FrameLog => "Frame log",
        }
    }
}

const ALL: [Tab; 5] = [
    Tab::Position,
    Tab::Status,
    Tab::Teach,
    Tab::Messages,
    Tab::FrameLog,
];

/// The first layout: position and the frame log (tabs) over messages on the left, status
/// and teach list as tabs on the right.
pub fn default_layout() -> Tree<Tab> {
    let mut tiles = Tiles::default();
    let tabs = |tiles: &mut Tiles<Tab>, panes: &[Tab]| {
        let children = panes.iter().map(|p| tiles.insert_pane(*p)).collect();
        tiles.insert_tab_tile(children)
    };
    let position = tabs(&mut tiles, &[Tab::Position, Tab::FrameLog]);
    let messages = tabs(&mut tiles, &[Tab::Messages]);
    let right = tabs(&mut tiles, &[Tab::Status, Tab::Teach]);
    let left = tiles.insert_container(Linear::new_binary(
        LinearDir::Vertical,
        [position, messages],
        0.62,
    ));
    let root = tiles.insert_container(Linear::new_binary(
        LinearDir::Horizontal,
        [left, right],
        0.6,
    ));
    Tree::new(egui::Id::unique("centre-layout"), root, tiles)
}

/// A saved layout, or the default when it lacks a pane (one saved by an older version).
pub fn checked_layout(saved: Option<Tree<Tab>>) -> Tree<Tab> {
    saved
        .filter(|t| ALL.iter().all(|p| t.tiles.find_pane(p).is_some()))
        .unwrap_or_else(default_layout)
}

/// What the panes draw with.
pub struct Tabs<'a> {
    pub pendant: &'a mut Pendant,
    pub teach: &'a mut TeachPanel,
    pub frame_log: &'a mut FrameLogPanel,
    pub now: Instant,
    pub started: Instant,
}

impl Behavior<Tab> for Tabs<'_> {
    fn tab_title_for_pane(&mut self, pane: &Tab) -> WidgetText {
        pane.title().into()
    }

    fn pane_ui(&mut self, ui: &mut Ui, _tile: TileId, pane: &mut Tab) -> UiResponse {
        let mut ui = ui.new_child(egui::UiBuilder::new().max_rect(ui.max_rect().shrink(6.0)));
        let ui = &mut ui;
        match pane {
            Tab::Position => readout::show(ui, self.pendant, self.now),
            Tab::Status => {
                egui::ScrollArea::vertical()
                    .show(ui, |ui| status::show(ui, self.pendant, self.now));
            }
            Tab::Teach => {
                egui::ScrollArea::vertical()
                    .show(ui, |ui| self.teach.show(ui, self.pendant, self.now));
            }
            Tab::Messages => messages::show(ui, self.pendant, self.started),
            Tab::FrameLog => self.frame_log.show(ui, self.pendant, self.now),
        }
        UiResponse::None
    }

    fn simplification_options(&self) -> SimplificationOptions {
        SimplificationOptions {
            all_panes_must_have_tabs: true,
            ..SimplificationOptions::default()
        }
    }
}

/// Draws the layout in `ui`.
pub fn show(ui: &mut Ui, tree: &mut Tree<Tab>, tabs: &mut Tabs<'_>) {
    tree.ui(tabs, ui);
}
