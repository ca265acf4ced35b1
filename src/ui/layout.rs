//! The rearrangeable centre of the window (egui_tiles): the arm view, position, status,
//! teach list, the controller's positions and signals, coordinate tables, messages and
//! frame log as panes the operator can drag into tabs, rows and columns.
//! The layout is saved with the settings.
//!
//! egui_tiles rather than egui_dock: egui_tiles 0.18 is built on egui 0.37 (egui_dock's
//! latest release is still on 0.36, so it cannot share our egui), it is rerun's own
//! viewer layout (the model this app follows), and it allows rows, columns and grids,
//! not only binary splits.

use egui::{Ui, WidgetText};
use egui_tiles::{
    Behavior, Linear, LinearDir, SimplificationOptions, TileId, Tiles, Tree, UiResponse,
};
use serde::{Deserialize, Serialize};

use super::alarms::AlarmsPanel;
use super::arm_view::ArmView;
use super::axes::AxesPane;
use super::coords::CoordsPanel;
use super::frame_log::FrameLogPanel;
use super::messages::MessagesPane;
use super::pane::{Pane, PaneCx};
use super::plots::PlotsPanel;
use super::positions::PositionsPanel;
use super::programs::ProgramsPanel;
use super::readout::Readout;
use super::signals::SignalsPanel;
use super::simulator::SimulatorPanel;
use super::status::StatusPane;
use super::teach::TeachPanel;
use crate::pendant::{JogAxis, Pendant};
use crate::protocol::Direction;

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
/// The window size (points) from which the default layout is the wide one: a 1920x1080
/// screen, less the task bars and title.
pub const WIDE_FROM: [f32; 2] = [1600.0, 900.0];

/// Whether a window of `size` points takes the wide default layout.
pub fn is_wide(size: egui::Vec2) -> bool {
    size.x >= WIDE_FROM[0] && size.y >= WIDE_FROM[1]
}

/// The default layout for a window of `size` points ([`default_layout`] or
/// [`wide_layout`]).
pub fn default_for(size: egui::Vec2) -> Tree<Tab> {
    if is_wide(size) {
        wide_layout()
    } else {
        default_layout()
    }
}

/// Whether `tree` is one of the default layouts, unchanged by the operator (a tab chosen
/// in front does not count).
pub fn is_a_default(tree: &Tree<Tab>) -> bool {
    let shape = shape_of(tree);
    shape == shape_of(&default_layout()) || shape == shape_of(&wide_layout())
}

/// A layout's arrangement: every tile with its panes or children, each container's
/// direction and shares; not which tab is in front (choosing a tab changes no layout).
pub fn shape_of(tree: &Tree<Tab>) -> Vec<String> {
    let mut out: Vec<String> = tree
        .tiles
        .iter()
        .map(|(id, tile)| match tile {
            egui_tiles::Tile::Pane(p) => format!("{id:?} pane {p:?}"),
            egui_tiles::Tile::Container(c) => {
                let mut s = format!("{id:?} {:?} {:?}", c.kind(), c.children_vec());
                if let egui_tiles::Container::Linear(l) = c {
                    for child in &l.children {
                        s += &format!(" {:.3}", l.shares[*child]);
                    }
                }
                s
            }
        })
        .collect();
    out.push(format!("root {:?}", tree.root));
    out.sort();
    out
}

/// The default layout on a large screen: the arm view takes most of the height and
/// width, the plots a tile of their own beside Messages, Alarms and the frame log, the
/// position and the tables on the right.
pub fn wide_layout() -> Tree<Tab> {
    centre(true)
}

/// The default layout (up to [`WIDE_FROM`]).
pub fn default_layout() -> Tree<Tab> {
    centre(false)
}

/// The tabs beside Status, in both defaults.
const TABLE_TABS: [Tab; 8] = [
    Tab::Status,
    Tab::Axes,
    Tab::Teach,
    Tab::Positions,
    Tab::Coords,
    Tab::Signals,
    Tab::Programs,
    Tab::Simulator,
];

/// Both defaults from one arrangement (tiles inserted in one order, so a saved default
/// is recognised): the arm view over the traffic on the left, the position over the
/// tables on the right; the wide one gives the plots a tile of their own and the arm
/// view more room.
fn centre(wide: bool) -> Tree<Tab> {
    let mut tiles = Tiles::default();
    let tabs = |tiles: &mut Tiles<Tab>, panes: &[Tab]| {
        let children = panes.iter().map(|p| tiles.insert_pane(*p)).collect();
        tiles.insert_tab_tile(children)
    };
    let arm = tabs(&mut tiles, &[Tab::Arm]);
    let position = tabs(&mut tiles, &[Tab::Position]);
    let status = tabs(&mut tiles, &TABLE_TABS);
    let (bottom, arm_share, right_share, left_share) = if wide {
        let traffic = tabs(&mut tiles, &[Tab::Messages, Tab::Alarms, Tab::FrameLog]);
        let plots = tabs(&mut tiles, &[Tab::Plots]);
        let bottom = tiles.insert_container(Linear::new_binary(
            LinearDir::Horizontal,
            [traffic, plots],
            0.5,
        ));
        (bottom, 0.6, 0.26, 0.64)
    } else {
        let traffic = tabs(
            &mut tiles,
            &[Tab::Messages, Tab::Alarms, Tab::FrameLog, Tab::Plots],
        );
        (traffic, 0.48, 0.3, 0.56)
    };
    let left = tiles.insert_container(Linear::new_binary(
        LinearDir::Vertical,
        [arm, bottom],
        arm_share,
    ));
    let right = tiles.insert_container(Linear::new_binary(
        LinearDir::Vertical,
        [position, status],
        right_share,
    ));
    let root = tiles.insert_container(Linear::new_binary(
        LinearDir::Horizontal,
        [left, right],
        left_share,
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

/// Every pane of the centre, one of each: the layout places them, and calls them all
/// through [`Pane`].
#[derive(Default)]
pub struct Panes {
    pub arm: ArmView,
    pub readout: Readout,
    pub status: StatusPane,
    pub teach: TeachPanel,
    pub positions: PositionsPanel,
    pub signals: SignalsPanel,
    pub programs: ProgramsPanel,
    pub alarms: AlarmsPanel,
    pub messages: MessagesPane,
    pub coords: CoordsPanel,
    pub frame_log: FrameLogPanel,
    pub simulator: SimulatorPanel,
    pub axes: AxesPane,
    pub plots: PlotsPanel,
}

impl Panes {
    /// The pane a tab shows.
    pub fn get(&mut self, tab: Tab) -> &mut dyn Pane {
        match tab {
            Tab::Arm => &mut self.arm,
            Tab::Position => &mut self.readout,
            Tab::Status => &mut self.status,
            Tab::Teach => &mut self.teach,
            Tab::Positions => &mut self.positions,
            Tab::Signals => &mut self.signals,
            Tab::Programs => &mut self.programs,
            Tab::Alarms => &mut self.alarms,
            Tab::Messages => &mut self.messages,
            Tab::Coords => &mut self.coords,
            Tab::FrameLog => &mut self.frame_log,
            Tab::Simulator => &mut self.simulator,
            Tab::Axes => &mut self.axes,
            Tab::Plots => &mut self.plots,
        }
    }

    /// Before drawing: what the arm view's ghost follows this frame (the jog button
    /// under the pointer, the teach row and the position hovered last frame).
    pub fn before(&mut self, hovered_step: Option<(JogAxis, Direction)>, pendant: &Pendant) {
        use super::arm_markers::MarkerKey;
        self.arm.hovered_step = hovered_step;
        // "Select in the table" on a marker, last frame: the table takes it.
        match self.arm.select_request.take() {
            Some(MarkerKey::Teach(i)) => {
                if let Some(p) = pendant.teach.list().get(i) {
                    self.teach.select(i, &p.name);
                }
            }
            Some(MarkerKey::Position(n)) => self.positions.select(n),
            None => {}
        }
        self.arm.selected_markers = self
            .teach
            .selected()
            .map(MarkerKey::Teach)
            .into_iter()
            .chain(self.positions.selected().map(MarkerKey::Position))
            .collect();
        self.arm.hovered_point = self.teach.hovered_go;
        // Last frame's hovered Go or preview row; this frame's is found while drawing.
        self.arm.hovered_position = self.positions.hovered.take();
        self.frame_log.live_in_sight = false;
    }

    /// After the layout: the confirmations drawn over the centre (whichever tab is in
    /// front, kept inside `centre`), and the signals ticked for plotting put into the
    /// Plots pane.
    pub fn after(&mut self, ctx: &egui::Context, centre: egui::Rect, cx: &mut PaneCx<'_>) {
        self.positions
            .preview_window(ctx, centre, cx.pendant, cx.intents);
        self.signals
            .after_panes(ctx, centre, cx.pendant, &mut self.plots, cx.intents);
        self.programs
            .after_panes(ctx, centre, cx.pendant, cx.intents);
    }
}

/// The layout's view of the panes for one frame.
struct Placed<'p, 'c> {
    panes: &'p mut Panes,
    cx: &'p mut PaneCx<'c>,
    /// Where each pane shown this frame was drawn (for the size tests).
    rects: &'p mut Vec<(Tab, egui::Rect)>,
}

impl Behavior<Tab> for Placed<'_, '_> {
    fn tab_title_for_pane(&mut self, pane: &Tab) -> WidgetText {
        pane.title().into()
    }

    fn pane_ui(&mut self, ui: &mut Ui, _tile: TileId, pane: &mut Tab) -> UiResponse {
        self.rects
            .push((*pane, ui.clip_rect().intersect(ui.max_rect())));
        let mut ui = ui.new_child(egui::UiBuilder::new().max_rect(ui.max_rect().shrink(6.0)));
        self.panes.get(*pane).ui(&mut ui, self.cx);
        UiResponse::None
    }

    fn simplification_options(&self) -> SimplificationOptions {
        SimplificationOptions {
            all_panes_must_have_tabs: true,
            ..SimplificationOptions::default()
        }
    }
}

/// Draws the layout in `ui`, each pane where the tree puts it; `rects` gets where each
/// pane shown was drawn.
pub fn show(
    ui: &mut Ui,
    tree: &mut Tree<Tab>,
    panes: &mut Panes,
    cx: &mut PaneCx<'_>,
    rects: &mut Vec<(Tab, egui::Rect)>,
) {
    rects.clear();
    tree.ui(&mut Placed { panes, cx, rects }, ui);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_large_screen_gets_the_wide_layout_with_every_pane_and_the_plots_in_sight() {
        let wide = default_for(egui::vec2(1920.0, 1050.0));
        assert!(wide == wide_layout() && is_a_default(&wide));
        assert!(default_for(egui::vec2(1280.0, 800.0)) == default_layout());
        assert!(default_for(egui::vec2(1920.0, 700.0)) == default_layout());
        for pane in ALL {
            assert!(wide.tiles.find_pane(&pane).is_some(), "{pane:?}");
        }
        // The plots have a tab group of their own: shown, not behind Messages.
        let plots = wide.tiles.find_pane(&Tab::Plots).unwrap();
        let group = wide.tiles.parent_of(plots).unwrap();
        let Some(egui_tiles::Tile::Container(c)) = wide.tiles.get(group) else {
            panic!("plots in a container")
        };
        assert_eq!(c.num_children(), 1);
    }

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
