//! The rearrangeable centre of the window (egui_tiles): the arm view, position, status,
//! teach list, the controller's positions and signals, coordinate tables, messages and
//! frame log as panes the operator can drag into tabs, rows and columns.
//! The layout is saved with the settings.
//!
//! egui_tiles rather than egui_dock: egui_tiles 0.18 is built on egui 0.37 (egui_dock's
//! latest release is still on 0.36, so it cannot share our egui), it is rerun's own
//! viewer layout (the model this app follows), and it allows rows, columns and grids,
//! not only binary splits.

use std::time::Instant;

use egui::{Ui, WidgetText};
use egui_tiles::{
    Behavior, Linear, LinearDir, SimplificationOptions, TileId, Tiles, Tree, UiResponse,
};
use serde::{Deserialize, Serialize};

use super::arm_view::ArmView;
use super::coords::CoordsPanel;
use super::frame_log::FrameLogPanel;
use super::positions::PositionsPanel;
use super::signals::SignalsPanel;
use super::simulator::SimulatorPanel;
use super::teach::TeachPanel;
use super::{messages, readout, status};
use crate::pendant::{Intent, Pendant};

/// One tab of the centre.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Tab {
    Arm,
    Position,
    Status,
    Teach,
    Positions,
    Signals,
    Programs,
    Alarms,
    Messages,
    Coords,
    FrameLog,
    Simulator,
    Axes,
    Plots,
}

impl Tab {
    fn title(self) -> &'static str {
        match self {
            Tab::Arm => "Arm view",
            Tab::Position => "Position",
            Tab::Status => "Status",
            Tab::Teach => "Teach list",
            Tab::Positions => "Positions",
            Tab::Signals => "Signals",
            Tab::Programs => "Programs",
            Tab::Alarms => "Alarms",
            Tab::Messages => "Messages",
            Tab::Coords => "Coordinate tables",
            Tab::FrameLog => "Frame log",
            Tab::Simulator => "Simulator",
            Tab::Axes => "RMC axes",
            Tab::Plots => "Plots",
        }
    }
}

const ALL: [Tab; 14] = [
    Tab::Arm,
    Tab::Position,
    Tab::Status,
    Tab::Teach,
    Tab::Positions,
    Tab::Signals,
    Tab::Programs,
    Tab::Alarms,
    Tab::Messages,
    Tab::Coords,
    Tab::FrameLog,
    Tab::Simulator,
    Tab::Axes,
    Tab::Plots,
];

/// The first layout: the arm view large on the left over the messages, the frame log and
/// the plots (tabs); on the right the position over the status (servo, home), teach list,
/// the controller's positions, coordinate tables and signals as tabs.
pub fn default_layout() -> Tree<Tab> {
    let mut tiles = Tiles::default();
    let tabs = |tiles: &mut Tiles<Tab>, panes: &[Tab]| {
        let children = panes.iter().map(|p| tiles.insert_pane(*p)).collect();
        tiles.insert_tab_tile(children)
    };
    let arm = tabs(&mut tiles, &[Tab::Arm]);
    let position = tabs(&mut tiles, &[Tab::Position]);
    let status = tabs(
        &mut tiles,
        &[
            Tab::Status,
            Tab::Axes,
            Tab::Teach,
            Tab::Positions,
            Tab::Coords,
            Tab::Signals,
            Tab::Programs,
            Tab::Simulator,
        ],
    );
    let traffic = tabs(
        &mut tiles,
        &[Tab::Messages, Tab::Alarms, Tab::FrameLog, Tab::Plots],
    );
    let left = tiles.insert_container(Linear::new_binary(
        LinearDir::Vertical,
        [arm, traffic],
        0.48,
    ));
    let right = tiles.insert_container(Linear::new_binary(
        LinearDir::Vertical,
        [position, status],
        0.3,
    ));
    let root = tiles.insert_container(Linear::new_binary(
        LinearDir::Horizontal,
        [left, right],
        0.56,
    ));
    Tree::new(egui::Id::unique("centre-layout"), root, tiles)
}

/// A saved layout with any pane it lacks (one saved by an older version) added as a tab
/// beside the position table (or beside any pane it has); the default when none fits.
pub fn checked_layout(saved: Option<Tree<Tab>>) -> Tree<Tab> {
    let Some(mut tree) = saved else {
        return default_layout();
    };
    for pane in ALL {
        if tree.tiles.find_pane(&pane).is_some() {
            continue;
        }
        let beside = [Tab::Positions, Tab::Coords, Tab::Teach, Tab::Status]
            .iter()
            .chain(ALL.iter())
            .filter_map(|p| tree.tiles.find_pane(p))
            .find_map(|id| {
                let parent = tree.tiles.parent_of(id)?;
                matches!(
                    tree.tiles.get(parent),
                    Some(egui_tiles::Tile::Container(egui_tiles::Container::Tabs(_)))
                )
                .then_some(parent)
            });
        let Some(parent) = beside else {
            return default_layout();
        };
        let id = tree.tiles.insert_pane(pane);
        if let Some(egui_tiles::Tile::Container(c)) = tree.tiles.get_mut(parent) {
            c.add_child(id);
        }
    }
    tree
}

/// What the panes draw with.
pub struct Tabs<'a> {
    pub pendant: &'a Pendant,
    /// What the panels that draw `&Pendant` ask for, applied after drawing.
    pub intents: &'a mut Vec<Intent>,
    pub arm: &'a mut ArmView,
    pub teach: &'a mut TeachPanel,
    pub coords: &'a mut CoordsPanel,
    pub positions: &'a mut PositionsPanel,
    pub signals: &'a mut SignalsPanel,
    pub programs: &'a mut super::programs::ProgramsPanel,
    pub alarms: &'a mut super::alarms::AlarmsPanel,
    pub frame_log: &'a mut FrameLogPanel,
    pub plots: &'a mut super::plots::PlotsPanel,
    pub simulator: &'a mut SimulatorPanel,
    /// The folder a file name typed without one is in.
    pub folder: &'a std::path::Path,
    /// The built-in simulator's front panel, when the line is the built-in one.
    pub sim: Option<&'a crate::session::simulator::FrontPanel>,
    /// The simulator action clicked, handed to the front panel after drawing.
    pub sim_action: &'a mut Option<crate::session::simulator::OperatorAction>,
    pub now: Instant,
    pub started: Instant,
    /// Where each pane shown this frame was drawn (for the size tests).
    pub pane_rects: &'a mut Vec<(Tab, egui::Rect)>,
    /// What the RMC axis buttons saw this frame.
    pub axes_pad: &'a mut super::axes::AxesPadOutput,
}

impl Behavior<Tab> for Tabs<'_> {
    fn tab_title_for_pane(&mut self, pane: &Tab) -> WidgetText {
        pane.title().into()
    }

    fn pane_ui(&mut self, ui: &mut Ui, _tile: TileId, pane: &mut Tab) -> UiResponse {
        self.pane_rects
            .push((*pane, ui.clip_rect().intersect(ui.max_rect())));
        let mut ui = ui.new_child(egui::UiBuilder::new().max_rect(ui.max_rect().shrink(6.0)));
        let ui = &mut ui;
        match pane {
            Tab::Arm => self
                .arm
                .show(ui, self.pendant, self.folder, self.now, self.intents),
            Tab::Position => readout::show(ui, self.pendant, self.now),
            Tab::Status => {
                egui::ScrollArea::vertical().show(ui, |ui| {
                    status::show(ui, self.pendant, self.now, self.intents)
                });
            }
            Tab::Teach => {
                egui::ScrollArea::vertical().show(ui, |ui| {
                    self.teach
                        .show(ui, self.pendant, self.folder, self.now, self.intents)
                });
            }
            Tab::Positions => {
                self.positions
                    .show(ui, self.pendant, self.folder, self.now, self.intents)
            }
            Tab::Signals => {
                self.signals
                    .show(ui, self.pendant, self.folder, self.now, self.intents)
            }
            Tab::Programs => {
                self.programs
                    .show(ui, self.pendant, self.folder, self.now, self.intents)
            }
            Tab::Alarms => self
                .alarms
                .show(ui, self.pendant, self.folder, self.now, self.intents),
            Tab::Messages => messages::show(ui, self.pendant, self.started),
            Tab::Coords => self
                .coords
                .show(ui, self.pendant, self.folder, self.now, self.intents),
            Tab::FrameLog => {
                self.frame_log
                    .show(ui, self.pendant, self.folder, self.now, self.intents)
            }
            Tab::Plots => super::plots::show(
                self.plots,
                ui,
                self.pendant,
                self.intents,
                self.folder,
                self.now,
            ),
            Tab::Axes => {
                egui::ScrollArea::vertical().show(ui, |ui| {
                    super::axes::show(ui, self.pendant, self.intents, self.axes_pad)
                });
            }
            Tab::Simulator => match self.sim.map(|panel| panel.state()) {
                Some(Some(state)) => {
                    if let Some(action) = self.simulator.show(ui, state) {
                        *self.sim_action = Some(action);
                    }
                }
                Some(None) => {
                    ui.label("Waiting for the built-in simulator's panel...");
                }
                None => {
                    ui.label("Not on the built-in simulator: the line goes to a real controller.");
                }
            },
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

#[cfg(test)]
mod tests {
    use super::*;

    /// A layout saved before a pane existed keeps its arrangement and gains the pane as a
    /// tab beside the position table.
    #[test]
    fn an_older_layout_gains_the_new_panes_beside_the_position_table() {
        let mut old = default_layout();
        for pane in [Tab::Signals, Tab::Plots] {
            let id = old.tiles.find_pane(&pane).unwrap();
            old.remove_recursively(id);
        }
        let containers = |t: &Tree<Tab>| t.tiles.tiles().filter(|t| t.is_container()).count();
        let before = containers(&old);
        let tree = checked_layout(Some(old));
        for pane in ALL {
            assert!(tree.tiles.find_pane(&pane).is_some(), "{pane:?}");
        }
        let parent = |t: &Tree<Tab>, p: Tab| t.tiles.parent_of(t.tiles.find_pane(&p).unwrap());
        assert_eq!(parent(&tree, Tab::Signals), parent(&tree, Tab::Positions));
        assert_eq!(parent(&tree, Tab::Plots), parent(&tree, Tab::Positions));
        assert_eq!(containers(&tree), before, "the arrangement is kept");
        assert!(
            checked_layout(None)
                .tiles
                .find_pane(&Tab::Signals)
                .is_some()
        );
    }
}
