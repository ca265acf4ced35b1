//! The eframe application: composition and the frame loop. It owns the pendant model, the
//! two lines and the panes; each frame it takes in link events within a budget, draws
//! the panes (which push intents), applies the intents (STOP at once) and forwards the
//! pendant's requests to the lines.

use std::sync::atomic::Ordering;
use std::time::{Duration, Instant};

use egui::{Panel, Theme};

use super::connection::ConnectionPanel;
use super::file_field::FolderCache;
use super::jog::JogPanel;
use super::keys::{self, Keys};
use super::layout::{self, Panes, Tab};
use super::lines::{Lines, PANEL_ANSWER};
use super::pane::{Pane, PaneCx};
use super::rmc_connection::RmcConnectionPane;
use super::safety_band::SafetyBand;
use super::start::{BenchHooks, Start, StartOptions};
use super::top_bar::TopBar;
use super::wake::IDLE_WAKE;
use super::work_files::WorkFiles;
use crate::pendant::{Intent, Pendant, StopCause};

pub use super::start::APP_ID;
use super::start::{LAYOUT_KEY, SETTINGS_KEY};

mod access;

/// Set when the process is asked to end (SIGTERM, SIGHUP, SIGINT; on Windows the console's
/// close and logoff events): the next frame closes the window as Ctrl+Q does.
pub static END_ASKED: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// How often the window looks whether a closing line has closed.
const CLOSE_CHECK: Duration = Duration::from_millis(20);
/// The shares of the window's width the left column (the jog pad) keeps within.
const LEFT_SHARE: std::ops::Range<f32> = 0.27..0.36;

/// The left column's sections, top to bottom: the jog pad first, so it never moves.
#[derive(Default)]
struct LeftColumn {
    jog: JogPanel,
    connection: ConnectionPanel,
    rmc: RmcConnectionPane,
}

pub struct PendantApp {
    pendant: Pendant,
    lines: Lines,
    keys: Keys,
    top_bar: TopBar,
    safety_band: SafetyBand,
    left: LeftColumn,
    panes: Panes,
    /// The teach list and the coordinate drafts in files of their own.
    work_files: WorkFiles,
    /// Where a file name typed without a folder goes.
    folder: FolderCache,
    dock: egui_tiles::Tree<Tab>,
    /// While the operator has not changed the layout: its arrangement as this window put
    /// it in place ([`layout::shape_of`]) and whether it is the wide one. The default
    /// layout then follows the window's size ([`layout::default_for`]); any change of the
    /// arrangement by the operator (not a tab chosen) ends that.
    auto_layout: Option<(Vec<String>, bool)>,
    /// Where each pane shown in the last frame was drawn.
    pane_rects: Vec<(Tab, egui::Rect)>,
    started: Instant,
    help_open: bool,
    applied_theme: Option<bool>,
    bench: BenchHooks,
}

impl PendantApp {
    /// The default layout for the window's `size` (points), while the operator has not
    /// changed the layout since this window put it in place.
    fn fit_default_layout(&mut self, size: egui::Vec2) {
        let Some((shape, wide)) = &self.auto_layout else {
            return;
        };
        if *shape != layout::shape_of(&self.dock) {
            // A divider dragged, a pane moved or closed: the operator's layout stays.
            self.auto_layout = None;
            return;
        }
        if layout::is_wide(size) != *wide {
            self.dock = layout::default_for(size);
            self.auto_layout = Some((layout::shape_of(&self.dock), layout::is_wide(size)));
        }
    }

    pub fn new(cc: &eframe::CreationContext<'_>, options: StartOptions) -> Self {
        let now = Instant::now();
        let Start {
            pendant,
            work_files,
            layout,
        } = Start::open(cc, &options, now);
        let mut app = Self {
            pendant,
            lines: Lines::new(options.line_owner.clone()),
            keys: Keys::default(),
            top_bar: TopBar,
            safety_band: SafetyBand,
            left: LeftColumn::default(),
            panes: Panes::default(),
            work_files,
            folder: FolderCache::default(),
            auto_layout: layout::is_a_default(&layout).then(|| {
                let shape = layout::shape_of(&layout);
                let wide = shape == layout::shape_of(&layout::wide_layout());
                (shape, wide)
            }),
            dock: layout,
            pane_rects: Vec::new(),
            started: now,
            help_open: false,
            applied_theme: None,
            bench: options.bench,
        };
        app.work_files.restore(&mut app.pendant, now);
        app.lines.run_requests(&cc.egui_ctx, &mut app.pendant, now);
        app
    }

    /// Whether a continuous jog is held on the robot or an RMC axis.
    fn jog_held(&self) -> bool {
        self.pendant.held_jog().is_some() || self.pendant.axes.hold.jog().is_some()
    }

    /// Closes the session as the window does on exit: the link stops any jog or move.
    pub fn close(&mut self) {
        if self.jog_held() {
            self.pendant
                .apply(Intent::Stop(StopCause::Exit), Instant::now());
            self.lines.stop_all();
        }
        // Both links close at once, each sending its STOPs; the window waits for both
        // and for any close already under way.
        self.lines.close();
    }

    fn apply_theme(&mut self, ctx: &egui::Context) {
        let light = self.pendant.settings.light_theme;
        if self.applied_theme != Some(light) {
            ctx.set_theme(if light { Theme::Light } else { Theme::Dark });
            self.applied_theme = Some(light);
        }
    }
}

impl eframe::App for PendantApp {
    fn logic(&mut self, ctx: &egui::Context, _frame: &mut eframe::Frame) {
        let now = Instant::now();
        // What the simulator's front panel did, said beside it and in Messages.
        for line in self.lines.take_sim_news() {
            self.panes.simulator.done(format!("Simulator: {line}"));
            self.pendant.note(format!("simulator: {line}"), now);
        }
        if self.lines.drain_events(&mut self.pendant, now) {
            // The rest of a backlog is taken in next frame.
            ctx.request_repaint();
        }
        // A window that lost focus cannot see a key or button come up: stop the jog.
        if ctx.input(|i| i.viewport().focused) == Some(false) {
            self.pendant.apply(Intent::FocusLost, now);
        }
        self.pendant.tick(now);
        self.lines.run_requests(ctx, &mut self.pendant, now);
        if self.lines.closes_done(ctx, &mut self.pendant, now) {
            // A close takes up to a reply time-out or two: look again soon.
            ctx.request_repaint_after(CLOSE_CHECK);
        }
        if self.jog_held() {
            // While a continuous jog is held the window runs at least this often.
            ctx.request_repaint_after(crate::pendant::RENEW_EVERY);
        } else if self.lines.has_session() {
            ctx.request_repaint_after(IDLE_WAKE);
        }
    }

    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        let ctx = ui.ctx().clone();
        self.apply_theme(&ctx);
        self.fit_default_layout(ctx.content_rect().size());
        let now = Instant::now();
        let mut intents = Vec::new();
        let keys = self.keys.handle(&ctx, &self.pendant, now, &mut intents);
        // egui zooms on Ctrl + / Ctrl - / Ctrl 0; the size chosen is kept.
        let zoom = ctx.zoom_factor();
        if (zoom - self.pendant.settings.ui_scale.unwrap_or(1.0)).abs() > 1e-3 {
            intents.push(Intent::UiScale(zoom));
        }
        // Ctrl+Q, or the process asked to end (SIGTERM, a desktop logout, Ctrl-C in its
        // terminal): the same way out, STOPs first and every file written.
        if keys.quit || END_ASKED.swap(false, Ordering::Relaxed) {
            ctx.send_viewport_cmd(egui::ViewportCommand::Close);
        }
        if keys.toggle_help {
            self.help_open = !self.help_open;
        }
        let folder = self
            .folder
            .get(self.pendant.settings.last_folder.as_deref());
        let mut cx = PaneCx {
            pendant: &self.pendant,
            now,
            started: self.started,
            folder,
            intents: &mut intents,
            sim: self.lines.panel(),
        };
        Panel::top("top-bar").show(ui, |ui| self.top_bar.ui(ui, &mut cx));
        if cx.intents.iter().any(|i| matches!(i, Intent::Stop(_))) {
            // STOP goes to the link now, ahead of everything drawn below.
            self.pendant.apply_all(std::mem::take(&mut intents), now);
            self.lines.run_requests(&ctx, &mut self.pendant, now);
            cx = PaneCx {
                pendant: &self.pendant,
                now,
                started: self.started,
                folder,
                intents: &mut intents,
                sim: self.lines.panel(),
            };
        }
        Panel::top("safety-band").show(ui, |ui| self.safety_band.ui(ui, &mut cx));
        // The column (and the pad at its top) follows the window: 27% to 36% of its
        // width (370 px at 1280 unless dragged), so a column widened on a large screen
        // shrinks back with the window.
        let window_width = ctx.content_rect().width();
        let least = (window_width * LEFT_SHARE.start).clamp(300.0, 600.0);
        let left = &mut self.left;
        left.jog.pad = Default::default();
        let mut help_clicked = false;
        Panel::left("left")
            .resizable(true)
            .default_size(370.0)
            .size_range(least..=(window_width * LEFT_SHARE.end).max(least))
            .show(ui, |ui| {
                egui::ScrollArea::vertical().show(ui, |ui| {
                    let sections: [(&str, bool, &mut dyn Pane); 3] = [
                        ("Jog", true, &mut left.jog),
                        ("Connection", true, &mut left.connection),
                        ("Delta RMC151 (Modbus/TCP)", false, &mut left.rmc),
                    ];
                    for (title, open, pane) in sections {
                        egui::CollapsingHeader::new(title)
                            .default_open(open)
                            .show(ui, |ui| pane.ui(ui, &mut cx));
                    }
                    help_clicked = ui.button("Keyboard (F1)").clicked();
                });
            });
        self.help_open ^= help_clicked;
        let pad = std::mem::take(&mut self.left.jog.pad);
        self.panes
            .before(pad.hovered.map(|t| (t.axis, t.direction)), cx.pendant);
        egui::CentralPanel::default().show(ui, |ui| {
            layout::show(
                ui,
                &mut self.dock,
                &mut self.panes,
                &mut cx,
                &mut self.pane_rects,
            );
            self.panes.after(ui.ctx(), ui.max_rect(), &mut cx);
        });

        self.lines
            .live_log_shown
            .store(self.panes.frame_log.live_in_sight, Ordering::Relaxed);
        keys::help(&ctx, &self.pendant, &mut self.help_open);
        let axes_pad = std::mem::take(&mut self.panes.axes.pad);
        super::pad::pointer_intents(&ctx, &pad, &axes_pad, &mut intents);
        self.pendant.apply_all(intents, now);
        if let Some(action) = self.panes.simulator.action.take()
            && let Some(panel) = self.lines.panel()
        {
            panel.act(action);
            // Its result comes back from the simulator's thread within a tick.
            ctx.request_repaint_after(PANEL_ANSWER);
        }
        self.lines.run_requests(&ctx, &mut self.pendant, now);
        self.work_files.autosave(&mut self.pendant, &self.dock, now);
        self.bench.frame_done(&ctx, self.started);
    }

    fn save(&mut self, storage: &mut dyn eframe::Storage) {
        // The settings are in their own file (written on every change); the copy an earlier
        // version kept here goes once that file and the teach list's are written.
        if self.work_files.all_saved() {
            storage.remove_string(SETTINGS_KEY);
        }
        // So is the layout, which its own file keeps (written whole, set aside when
        // unreadable): eframe's file, written in place, keeps the window's place only.
        if self.work_files.layout_saved() {
            storage.remove_string(LAYOUT_KEY);
        }
    }

    fn on_exit(&mut self, _gl: Option<&eframe::glow::Context>) {
        // Dropping the session shuts the link down: queued STOPs, and a STOP of its own
        // when a jog or move may still run, go out before the line closes.
        self.close();
    }
}

impl Drop for PendantApp {
    /// However the app ends (the window closed, a test's harness dropped), writes under
    /// way finish and what is still unsaved is written.
    fn drop(&mut self) {
        self.work_files.flush(&self.pendant, &self.dock);
    }
}
