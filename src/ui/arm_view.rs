//! The arm view pane: the scene of `render` painted live with egui, with zoom (wheel,
//! pinch), pan (drag), fit (double-click or "Fit"), a hover readout in base and work
//! coordinates with reachability per arm system, a right-click "Step here" that only
//! fills the jog panel's target, a fading trail of the polled path, the controller's zones,
//! the taught positions as markers (hover: the row; right-click: Go to, Select in the
//! table), and "Export view as PNG".

use std::time::Instant;

use egui::{Color32, RichText, Sense, Ui};

use super::arm_export::Export;
use super::arm_markers::{self, MarkerKey, Placed};
use super::pane::{Pane, PaneCx};
use crate::pendant::jog::JogAxis;
use crate::pendant::jog::target::StepPreview;
use crate::pendant::{Intent, Pendant};
use crate::protocol::Direction;
use crate::render::{
    Ghost, GhostCheck, Mm, OverlayFrame, Palette, Scene, SceneInput, SelectedFrame, View,
    build_scene, paint_egui, reach_at,
};
use crate::robot::{CoordSystem, FrameKind, Pose};

/// Trail points kept (the newest).
pub const TRAIL_POINTS: usize = 10_000;
/// A new trail point closer than this to the last one is not kept (mm).
const TRAIL_MIN_MOVE_MM: f64 = 0.01;

/// The frames drawn over the arm besides the selected work and tool frames: the rows the
/// coordinate-table editor shows over the arm, with the draft's values.
pub fn overlay_frames(pendant: &Pendant) -> Vec<OverlayFrame> {
    pendant
        .frames_over_arm()
        .into_iter()
        .map(|(kind, number, system)| OverlayFrame {
            label: match kind {
                FrameKind::Work => format!("work {number}"),
                FrameKind::Tool => format!("tool {number}"),
            },
            kind,
            system,
        })
        .collect()
}

/// The arm view's state between frames.
#[derive(Default)]
pub struct ArmView {
    /// `None` until the first frame, or after "Fit": fitted to the pane.
    view: Option<View>,
    /// The operator zoomed or panned: a resized pane keeps the scale.
    moved: bool,
    trail: Vec<Mm>,
    last_poll: Option<Instant>,
    /// The jog button under the pointer this frame (its step is the ghost).
    pub hovered_step: Option<(JogAxis, Direction)>,
    /// The taught point whose Go is under the pointer (last frame).
    pub hovered_point: Option<usize>,
    /// The position record whose move is under the pointer (the Positions view's Go or
    /// a row of its write preview).
    pub hovered_position: Option<crate::protocol::PositionRecord>,
    /// Where the context menu was opened, scene mm.
    menu_at: Option<Mm>,
    /// The taught positions selected in their tables (set by the layout each frame).
    pub selected_markers: Vec<MarkerKey>,
    /// "Select in the table" asked on a marker: the layout hands it to the table.
    pub select_request: Option<MarkerKey>,
    /// The marker under the pointer (its Go is the ghost), and the one the open context
    /// menu is for.
    hovered_marker: Option<MarkerKey>,
    menu_marker: Option<MarkerKey>,
    /// The taught positions placed this frame.
    placed: Vec<Placed>,
    /// The labels as painted last (shortened and hidden ones too): their whole text on
    /// hover; the size tests check that none overlap.
    labels: Vec<crate::render::labels::ShownLabel>,
    /// The last scene painted (tests read it).
    scene: Option<Scene>,
    export: Export,
    /// In a narrow pane the export controls are folded behind "PNG..." (opened).
    export_open: bool,
}

/// Below this pane width the export controls fold behind one button, so the toolbar
/// keeps to one row and the drawing keeps its height (a 1024x700 panel PC).
const EXPORT_INLINE_FROM: f32 = 760.0;

impl ArmView {
    /// The scene painted last.
    pub fn scene(&self) -> Option<&Scene> {
        self.scene.as_ref()
    }

    /// The labels as painted last.
    pub fn labels(&self) -> &[crate::render::labels::ShownLabel] {
        &self.labels
    }

    /// The view the scene was painted through last (tests find screen points with it).
    pub fn view(&self) -> Option<View> {
        self.view
    }

    /// Adds the newest polled tool tip to the trail (once per poll).
    fn record_trail(&mut self, pendant: &Pendant) {
        let Some(at) = pendant.controller.joints.as_ref().map(|s| s.at) else {
            return;
        };
        if self.last_poll == Some(at) {
            return;
        }
        self.last_poll = Some(at);
        let Some(j) = pendant.controller.joint_position() else {
            return;
        };
        let tool = pendant.controller.tool_frame().unwrap_or(CoordSystem::ZERO);
        let tip = tool.flange_to_tip(&pendant.kinematics().forward(&j));
        let tip = Mm::new(tip.x, tip.y);
        if self
            .trail
            .last()
            .is_none_or(|l| l.distance(tip) >= TRAIL_MIN_MOVE_MM)
        {
            self.trail.push(tip);
        }
        if self.trail.len() > TRAIL_POINTS + TRAIL_POINTS / 5 {
            self.trail.drain(..self.trail.len() - TRAIL_POINTS);
        }
    }

    /// Draws the view; "Step here" goes to `intents`.
    pub fn show(
        &mut self,
        ui: &mut Ui,
        pendant: &Pendant,
        folder: &std::path::Path,
        now: Instant,
        intents: &mut Vec<Intent>,
    ) {
        self.record_trail(pendant);
        self.placed = arm_markers::taught(pendant);
        let markers = arm_markers::markers(&self.placed, &self.selected_markers);
        let preview = self.preview(pendant, now);
        let ghost = preview.as_ref().map(ghost_of);
        let overlays = overlay_frames(pendant);
        let c = &pendant.controller;
        let frame = |n: Option<u8>, s: Option<CoordSystem>| {
            Some(SelectedFrame {
                number: n?,
                system: s?,
            })
        };
        let numbers = c.frame_numbers();
        let trail_from = self.trail.len().saturating_sub(TRAIL_POINTS);
        let input = SceneInput {
            kin: pendant.kinematics(),
            joints: c.joint_position(),
            stale: c.is_stale(now),
            work: frame(numbers.map(|n| n.0), c.work_frame()),
            tool: frame(numbers.map(|n| n.1), c.tool_frame()),
            overlays: &overlays,
            ghost: ghost.as_ref(),
            trail: &self.trail[trail_from..],
            reported_tip: c.sample().map(|(_, base)| base),
            zones: pendant.zones.boxes(),
            markers: &markers,
        };
        let scene = build_scene(&input);
        let palette = Palette::for_theme(ui.visuals().dark_mode);
        self.toolbar(ui, &scene, &palette, folder, now, intents);
        // Room for four lines under the view, whatever they say: the view never jumps.
        let readout_h = 4.0 * ui.text_style_height(&egui::TextStyle::Body) + 14.0;
        let avail = ui.available_rect_before_wrap();
        let rect = egui::Rect::from_min_max(
            avail.min,
            egui::pos2(
                avail.max.x,
                (avail.max.y - readout_h).max(avail.min.y + 40.0),
            ),
        );
        let response = ui.allocate_rect(rect, Sense::click_and_drag());
        let area = ([rect.min.x, rect.min.y], [rect.width(), rect.height()]);
        let mut view = match self.view {
            Some(v) if self.moved => v.on_area(area.0, area.1),
            _ => View::fit(&scene.bounds, area.0, area.1, 12.0),
        };
        self.interact(ui, &response, &mut view, pendant, intents);
        self.view = Some(view);
        self.labels = paint_egui::paint(&ui.painter_at(rect), &scene, &palette, &view);
        // The zones first: short, never pushed out of the room by a wrapped readout.
        ui.horizontal_wrapped(|ui| zones_status(ui, pendant, intents));
        self.readout(ui, &response, &view, pendant, preview.as_ref());
        self.scene = Some(scene);
    }

    fn toolbar(
        &mut self,
        ui: &mut Ui,
        scene: &Scene,
        palette: &Palette,
        folder: &std::path::Path,
        now: Instant,
        intents: &mut Vec<Intent>,
    ) {
        ui.horizontal_wrapped(|ui| {
            if ui
                .button("Fit")
                .on_hover_text("Show the whole reach (double-click the view)")
                .clicked()
            {
                self.moved = false;
            }
            if ui.button("Clear trail").clicked() {
                self.trail.clear();
            }
            ui.separator();
            let inline = ui.max_rect().width() >= EXPORT_INLINE_FROM;
            if !inline {
                ui.toggle_value(&mut self.export_open, "PNG...")
                    .on_hover_text("Export the view as a PNG file");
            }
            if inline || self.export_open {
                let pane = self.view.map_or([1280, 800], |v| {
                    [v.size[0].round() as u32, v.size[1].round() as u32]
                });
                if let Some(view) = self.view {
                    let shown = (scene, palette, &view, pane);
                    self.export.controls(ui, shown, folder, now);
                }
            }
        });
        self.export.poll(ui, now, intents);
    }

    fn interact(
        &mut self,
        ui: &Ui,
        r: &egui::Response,
        view: &mut View,
        pendant: &Pendant,
        intents: &mut Vec<Intent>,
    ) {
        if r.hovered() {
            let (zoom, scroll) = ui.input(|i| (i.zoom_delta(), i.smooth_scroll_delta.y));
            let factor = f64::from(zoom) * (f64::from(scroll) * 0.002).exp();
            if (factor - 1.0).abs() > 1e-4
                && let Some(p) = r.hover_pos()
            {
                view.zoom_about([p.x, p.y], factor);
                self.moved = true;
            }
        }
        if r.dragged_by(egui::PointerButton::Primary) || r.dragged_by(egui::PointerButton::Middle) {
            let d = r.drag_delta();
            if d != egui::Vec2::ZERO {
                view.pan([d.x, d.y]);
                self.moved = true;
            }
        }
        if r.double_clicked() {
            self.moved = false;
            *view = View::fit(
                &crate::render::build::bounds(pendant.kinematics()),
                view.origin,
                view.size,
                12.0,
            );
        }
        self.hovered_marker = r
            .hover_pos()
            .and_then(|p| arm_markers::pick(&self.placed, view, [p.x, p.y]));
        let hidden = r
            .hover_pos()
            .and_then(|p| hidden_label(&self.labels, [p.x, p.y]));
        if let Some(key) = self.hovered_marker {
            let row = arm_markers::row_text(pendant, key);
            r.clone().on_hover_ui_at_pointer(|ui| {
                ui.label(row);
            });
        } else if let Some(text) = hidden {
            r.clone().on_hover_ui_at_pointer(|ui| {
                ui.label(text);
            });
        }
        if r.secondary_clicked()
            && let Some(p) = r.interact_pointer_pos()
        {
            self.menu_at = Some(view.to_scene([p.x, p.y]));
            self.menu_marker = arm_markers::pick(&self.placed, view, [p.x, p.y]);
        }
        let menu = r.context_menu(|ui| {
            let Some(at) = self.menu_at else {
                ui.close();
                return;
            };
            if let Some(key) = self.menu_marker {
                ui.label(arm_markers::row_text(pendant, key));
                let go = ui.button(arm_markers::go_label(pendant, key)).on_hover_text(
                    "The same checks as the table's Go: reach, limits, the whole path, zones (a second press where it enters one)",
                );
                if go.clicked() {
                    intents.push(match key {
                        MarkerKey::Teach(i) => Intent::TeachGo(i),
                        MarkerKey::Position(n) => Intent::Positions(
                            crate::pendant::positions::PositionsIntent::Go(n),
                        ),
                    });
                    ui.close();
                }
                if ui.button("Select in the table").clicked() {
                    self.select_request = Some(key);
                    ui.close();
                }
                ui.separator();
            }
            let work = pendant.controller.work_frame();
            let Some((w, tip)) = work.zip(pendant.controller.work_position()) else {
                ui.label("The position and frames are not known yet");
                return;
            };
            let p = w.base_to_work(&Pose::new(at.x, at.y, 0.0, 0.0));
            ui.label(format!("work X {:.3}  Y {:.3}", p.x, p.y));
            let step = ui.button("Step here").on_hover_text(
                "Fills the jog panel's target (Z and R kept); nothing moves until \"Go to target\"",
            );
            if step.clicked() {
                intents.push(Intent::SetTarget(Pose::new(p.x, p.y, tip.z, tip.r)));
                ui.close();
            }
        });
        if menu.is_none() {
            self.menu_marker = None;
        }
    }

    /// The next step's ghost: the jog button under the pointer (in step mode: a
    /// continuous jog has no end), else the target from "Step here", else the move in
    /// progress.
    fn preview(&self, pendant: &Pendant, now: Instant) -> Option<StepPreview> {
        let stepping = pendant.settings.jog.mode == crate::pendant::JogMode::Step;
        self.hovered_step
            .filter(|_| stepping)
            .and_then(|(axis, dir)| pendant.preview_jog(axis, dir, now))
            .or_else(|| self.hovered_point.and_then(|i| pendant.preview_go(i, now)))
            .or_else(|| {
                self.hovered_position
                    .and_then(|r| pendant.preview_position(&r, now))
            })
            .or_else(|| {
                let key = self.hovered_marker.or(self.menu_marker)?;
                match key {
                    MarkerKey::Teach(i) => pendant.preview_go(i, now),
                    MarkerKey::Position(n) => match pendant.positions.row(n) {
                        crate::pendant::positions::Row::Held(r) => pendant.preview_position(r, now),
                        _ => None,
                    },
                }
            })
            .or_else(|| pendant.preview_target(now))
            .or_else(|| pendant.preview_followed(now))
    }

    fn readout(
        &self,
        ui: &mut Ui,
        r: &egui::Response,
        view: &View,
        pendant: &Pendant,
        preview: Option<&StepPreview>,
    ) {
        let c = &pendant.controller;
        let kin = pendant.kinematics();
        let tool = c.tool_frame().unwrap_or(CoordSystem::ZERO);
        let joints = c.joint_position();
        let tip = joints.map(|j| tool.flange_to_tip(&kin.forward(&j)));
        ui.horizontal_wrapped(|ui| {
            // The same sample as the Position pane, not the joints' forward kinematics.
            match c.sample() {
                Some((w, b)) => ui.label(format!(
                    "Tool tip  base X {:.3} Y {:.3}  |  work X {:.3} Y {:.3} Z {:.3} R {:.3}",
                    b.x, b.y, w.x, w.y, w.z, w.r
                )),
                None => ui.label("Tool tip: no position yet"),
            };
            if let Some(p) = preview
                && let Err(why) = &p.plan
            {
                // The short sentence here and on the ghost; the details on hover.
                ui.label(
                    RichText::new(format!("{}: refused: {}", p.label, why.short()))
                        .color(Color32::from_rgb(230, 90, 80)),
                )
                .on_hover_text(why.to_string());
            }
        });
        let Some(p) = r.hover_pos() else {
            ui.label(RichText::new("Wheel or pinch: zoom  |  drag: pan  |  double-click: fit  |  right-click: step here").weak());
            return;
        };
        let at = view.to_scene([p.x, p.y]);
        let near = joints.unwrap_or(pendant.model.home);
        let (z, rr) = tip.map_or((0.0, 0.0), |t| (t.z, t.r));
        let work = c
            .work_frame()
            .map(|w| w.base_to_work(&Pose::new(at.x, at.y, 0.0, 0.0)));
        let mut text = format!("Cursor  base X {:.3} Y {:.3}", at.x, at.y);
        if let Some(w) = work {
            text += &format!("  |  work X {:.3} Y {:.3}", w.x, w.y);
        }
        for (arm, result) in reach_at(kin, at, z, rr, &tool, &near) {
            text += &match result {
                Ok(_) => format!("  |  {arm} arm: reachable"),
                Err(e) => format!("  |  {arm} arm: {e}"),
            };
        }
        ui.label(text);
    }
}

/// The whole text of a label shortened under the pointer, or of one hidden (no room)
/// whose anchor is near it.
fn hidden_label(labels: &[crate::render::labels::ShownLabel], p: [f32; 2]) -> Option<String> {
    labels.iter().find_map(|l| {
        let hit = match l.rect {
            Some(r) if l.short => p[0] >= r[0] && p[0] <= r[2] && p[1] >= r[1] && p[1] <= r[3],
            Some(_) => false,
            None => (l.anchor[0] - p[0]).hypot(l.anchor[1] - p[1]) <= 8.0,
        };
        hit.then(|| l.text.clone())
    })
}

/// The zones as read (or why not) and "Read zones" (2A2H again).
fn zones_status(ui: &mut Ui, pendant: &Pendant, intents: &mut Vec<Intent>) {
    let z = &pendant.zones;
    let text = match (&z.outcome, z.reading()) {
        (_, true) => RichText::new("Zones: reading..."),
        (Some((crate::pendant::Level::Warning | crate::pendant::Level::Error, why)), _) => {
            RichText::new(format!("Zones: {why}")).color(Color32::from_rgb(230, 90, 80))
        }
        (Some(_), _) if z.boxes().is_empty() => RichText::new("Zones: none defined"),
        (Some(_), _) => RichText::new(format!(
            "Zones: {}",
            z.boxes()
                .iter()
                .map(|b| b.number.to_string())
                .collect::<Vec<_>>()
                .join(", ")
        )),
        (None, _) => RichText::new("Zones: not read"),
    };
    let hover: Vec<String> = z
        .read()
        .iter()
        .filter(|r| z.boxes().iter().any(|b| b.number == r.number))
        .map(|r| {
            let b = crate::robot_wire::zone_box(r.number, &r.record);
            format!("{}: {}", b.label(), r.action())
        })
        .collect();
    let label = ui.label(text);
    if !hover.is_empty() {
        label.on_hover_text(hover.join("\n"));
    }
    let read = ui
        .add_enabled(
            pendant.line.is_up() && !z.reading(),
            egui::Button::new("Read zones"),
        )
        .on_hover_text("Read the controller's interference zones again (2A2H)");
    if read.clicked() {
        intents.push(Intent::ReadZones);
    }
}

/// The ghost of a preview, coloured by its check, with the whole path the checks
/// followed and the first point that fails one.
pub fn ghost_of(p: &StepPreview) -> Ghost {
    use crate::pendant::jog::Refusal;
    use crate::robot::MoveError;
    let mm = |t: &Pose| Mm::new(t.x, t.y);
    let mut g = Ghost::at(p.label.clone(), p.tip_base, p.joints, GhostCheck::Reachable);
    match &p.plan {
        Ok(plan) => {
            g.check = match plan.second_press() {
                Some(why) if !plan.path.zones.is_empty() && p.in_progress => {
                    GhostCheck::Zone(format!("{why} (confirmed)"))
                }
                Some(why) if !plan.path.zones.is_empty() => {
                    GhostCheck::Zone(format!("{why}: press twice"))
                }
                Some(_) => GhostCheck::ArmFlip,
                None => GhostCheck::Reachable,
            };
            g.line = plan.line.map(|(a, b)| (mm(&a), mm(&b)));
            g.path = plan.path.tips.iter().map(mm).collect();
            g.mark = plan
                .path
                .first
                .as_ref()
                .map(|m| (mm(&m.tip), m.fault.to_string()));
            g.zones = plan.path.zones.clone();
        }
        Err(why) => {
            g.check = GhostCheck::Refused(why.short());
            if let Refusal::Move(MoveError::CpLine {
                position, reason, ..
            }) = why
            {
                g.mark = Some((mm(position), format!("fails ({reason})")));
            }
        }
    }
    g
}

impl Pane for ArmView {
    fn ui(&mut self, ui: &mut Ui, cx: &mut PaneCx<'_>) {
        self.show(ui, cx.pendant, cx.folder, cx.now, cx.intents);
    }
}
