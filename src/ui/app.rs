//! The eframe application: owns the pendant model and the live session, drains link
//! events at the start of a frame within a budget, lays out the panels, and runs the
//! pendant's requests at the end of the frame (STOP at once).

use std::time::{Duration, Instant};

use egui::{Panel, Theme};

use super::arm_view::ArmView;
use super::connection::ConnectionPanel;
use super::coords::CoordsPanel;
use super::file_field::FolderCache;
use super::frame_log::FrameLogPanel;
use super::inbox::{Inbox, Next};
use super::jog::JogPanel;
use super::keys::{self, Keys};
use super::layout::{self, Tab, Tabs};
use super::pad::PadOutput;
use super::simulator::SimulatorPanel;
use super::teach::TeachPanel;
use super::wake::{IDLE_WAKE, LINK_REPAINT, RmcWake, Wake, WakeFilter};
use super::work_files::WorkFiles;
use super::{safety_band, top_bar};
use crate::pendant::axes::{AxisCall, AxisIntent};
use crate::pendant::{
    ConnectionSettings, Intent, JogInput, Pendant, Press, Request, Settings, StopCause,
};
use crate::protocol::CoordKind;
use crate::robot::RobotModel;
use crate::session::SimHandle;
use crate::session::closing::Closing;
use crate::session::rmc::RmcSession;
use crate::session::{LineOwner, Session, load_model};

/// The storage key and window title.
pub const APP_ID: &str = "xsel-pendant";
const SETTINGS_KEY: &str = "settings";
const LAYOUT_KEY: &str = "layout";
/// Most time spent applying link events in one frame (about 5 us each: one frame takes
/// in what 25 s of idle polling of both links brings).
const EVENT_BUDGET: Duration = Duration::from_millis(16);
/// Set when the process is asked to end (SIGTERM, SIGHUP, SIGINT; on Windows the console's
/// close and logoff events): the next frame closes the window as Ctrl+Q does.
pub static END_ASKED: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// How often the window looks whether a closing line has closed.
const CLOSE_CHECK: Duration = Duration::from_millis(20);
/// The simulator's thread answers the front panel within a tick (20 ms); the window looks
/// again after this.
const PANEL_ANSWER: Duration = Duration::from_millis(60);

/// How the window starts.
#[derive(Clone, Debug, Default)]
pub struct StartOptions {
    /// A connection given on the command line replaces the saved one.
    pub connection: Option<ConnectionSettings>,
    /// The RMC151 named on the command line: `Some(None)` none this run (`--no-rmc`; the
    /// saved choice is kept for the next), `Some(Some(""))` the built-in one,
    /// `Some(Some(addr))` a real one (saved, as a named line is); `None` the saved choice.
    pub rmc: Option<Option<String>>,
    /// Ignore saved settings (tests, a clean start).
    pub fresh: bool,
    /// Open no line at start (image tests drive the pendant with scripted events).
    pub offline: bool,
    /// Where the teach list, the coordinate-table drafts (and, unless fresh, the
    /// settings) are saved and restored from; `None`: the app's data directory, or
    /// nowhere in a fresh start.
    pub data_dir: Option<std::path::PathBuf>,
    /// Who owns a serial port or TCP bridge: a guardian process (the window binary's
    /// default) or the window's own link thread (`--no-guardian`, tests).
    pub line_owner: LineOwner,
}

impl StartOptions {
    /// A clean start on the built-in simulator, ignoring saved settings (tests, benches).
    pub fn fresh_simulator() -> Self {
        Self {
            connection: None,
            rmc: None,
            fresh: true,
            offline: false,
            data_dir: None,
            line_owner: LineOwner::InProcess,
        }
    }

    /// A clean start with no line at all, for scripted events (image tests).
    pub fn fresh_offline() -> Self {
        Self {
            offline: true,
            ..Self::fresh_simulator()
        }
    }
}

/// The two devices' connections.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Device {
    Xsel,
    Rmc,
}

/// The shares of the window's width the left column (the jog pad) keeps within.
const LEFT_SHARE: std::ops::Range<f32> = 0.27..0.36;

pub struct PendantApp {
    pendant: Pendant,
    session: Option<Session>,
    /// The RMC151's connection, apart from the robot's line: motion on one never waits
    /// for the other.
    rmc: Option<RmcSession>,
    /// The links' events, taken in oldest first.
    inbox: Inbox,
    /// Sessions closing on threads of their own (the window draws, STOP reaches them).
    closing: Vec<(Device, Closing)>,
    /// A line asked for while its old one still closes: opened once it has.
    open_when_closed: Vec<Device>,
    line_owner: LineOwner,
    connection: ConnectionPanel,
    jog: JogPanel,
    keys: Keys,
    teach: TeachPanel,
    simulator: SimulatorPanel,
    coords: CoordsPanel,
    positions: super::positions::PositionsPanel,
    signals: super::signals::SignalsPanel,
    programs: super::programs::ProgramsPanel,
    alarms: super::alarms::AlarmsPanel,
    /// The teach list and the coordinate drafts in files of their own.
    work_files: WorkFiles,
    arm: ArmView,
    frame_log: FrameLogPanel,
    plots: super::plots::PlotsPanel,
    /// Where a file name typed without a folder goes.
    folder: FolderCache,
    /// Whether a live frame log was drawn in the last frame (its rows are worth a wake).
    live_log_shown: std::sync::Arc<std::sync::atomic::AtomicBool>,
    /// Link events that woke the window so far.
    link_wakes: std::sync::Arc<std::sync::atomic::AtomicU64>,
    /// Link events left for later since the window last took every event in (see
    /// `wake`).
    unread: std::sync::Arc<std::sync::atomic::AtomicUsize>,
    dock: egui_tiles::Tree<Tab>,
    /// Where each pane shown in the last frame was drawn.
    pane_rects: Vec<(Tab, egui::Rect)>,
    started: Instant,
    help_open: bool,
    applied_theme: Option<bool>,
}

impl PendantApp {
    pub fn new(cc: &eframe::CreationContext<'_>, options: StartOptions) -> Self {
        // Settings and the operator's work live in files of their own (written whole,
        // with a backup); eframe's storage keeps the window and the layout, and is read
        // for settings only when an earlier version left them there.
        let data_dir = match options.data_dir.clone() {
            Some(dir) => Some(dir),
            None if !options.fresh => eframe::storage_dir(APP_ID),
            None => None,
        };
        // Fields and buttons with a visible edge on the light theme's near-white (its
        // default draws input fields as white on white).
        cc.egui_ctx.style_mut_of(Theme::Light, |style| {
            style.visuals.widgets.inactive.bg_stroke =
                egui::Stroke::new(1.0, egui::Color32::from_gray(150));
        });
        let mut work_files = WorkFiles::in_folder(data_dir.as_deref(), !options.fresh);
        let (from_file, mut notes) = work_files.restore_settings();
        let saved: Option<Settings> = if options.fresh {
            None
        } else {
            from_file.or_else(|| cc.storage.and_then(|s| eframe::get_value(s, SETTINGS_KEY)))
        };
        // The layout's own file; the copy earlier versions kept in eframe's file is read
        // once when there is none.
        let (layout_file, layout_notes) = work_files.restore_layout();
        notes.extend(layout_notes);
        let saved_layout = if options.fresh {
            None
        } else {
            layout_file.or_else(|| cc.storage.and_then(|s| eframe::get_value(s, LAYOUT_KEY)))
        };
        let mut settings = saved.unwrap_or_default();
        match options.connection {
            Some(c) => settings.connection = c,
            // No line named: the built-in simulator, the saved line settings kept.
            None => settings.connection.kind = crate::pendant::LineKind::Simulator,
        }
        if let Some(Some(address)) = &options.rmc {
            settings.rmc.enabled = true;
            settings.rmc.address = address.clone();
        }
        // `--no-rmc` leaves the RMC disconnected this run only.
        let rmc_this_run = options.rmc != Some(None);
        let now = Instant::now();
        let (model, problem) = match load_model(&settings.connection.robot) {
            Ok(m) => (m, None),
            Err(e) => (RobotModel::default_model(), Some(e)),
        };
        if let Some(scale) = settings.ui_scale {
            cc.egui_ctx.set_zoom_factor(scale);
        }
        let mut pendant = Pendant::new(settings, model);
        // Frame log times count from the window's start.
        pendant
            .frame_log
            .set_origin(Some(now), std::time::SystemTime::now());
        for text in notes.drain(..) {
            pendant.say(crate::pendant::Level::Warning, text, now);
        }
        if let Some(e) = problem {
            pendant.connect_failed(e, now);
        } else if !options.offline {
            pendant.connect(now);
        }
        if !options.offline && rmc_this_run && pendant.settings.rmc.enabled {
            pendant.apply(Intent::Axes(crate::pendant::axes::AxisIntent::Connect), now);
        }
        if let Some(rows) = std::env::var("XSEL_PENDANT_BENCH_LOG_ROWS")
            .ok()
            .and_then(|v| v.parse::<u64>().ok())
        {
            // Opt-in, for `benches/window_startup.sh --rss-log`: a full frame log.
            pendant.frame_log.fill_synthetic(rows);
        }
        let mut app = Self {
            pendant,
            session: None,
            rmc: None,
            inbox: Inbox::default(),
            closing: Vec::new(),
            open_when_closed: Vec::new(),
            line_owner: options.line_owner.clone(),
            connection: ConnectionPanel::default(),
            jog: JogPanel::default(),
            keys: Keys::default(),
            teach: TeachPanel::default(),
            simulator: SimulatorPanel::default(),
            coords: CoordsPanel::default(),
            positions: super::positions::PositionsPanel::default(),
            signals: super::signals::SignalsPanel::default(),
            programs: super::programs::ProgramsPanel::default(),
            alarms: super::alarms::AlarmsPanel::default(),
            work_files,
            arm: ArmView::default(),
            frame_log: FrameLogPanel::default(),
            plots: super::plots::PlotsPanel::default(),
            folder: FolderCache::default(),
            live_log_shown: Default::default(),
            link_wakes: Default::default(),
            unread: Default::default(),
            dock: layout::checked_layout(saved_layout),
            pane_rects: Vec::new(),
            started: now,
            help_open: false,
            applied_theme: None,
        };
        app.work_files.restore(&mut app.pendant, now);
        app.run_requests(&cc.egui_ctx, now);
        app
    }

    /// The pendant model (tests and benches read it).
    pub fn pendant(&self) -> &Pendant {
        &self.pendant
    }

    /// The pendant model, for scripted events (image tests).
    pub fn pendant_mut(&mut self) -> &mut Pendant {
        &mut self.pendant
    }

    /// The arm view (tests read the scene it painted last).
    pub fn arm_view(&self) -> &ArmView {
        &self.arm
    }

    /// The frame log pane (tests and benches read it).
    pub fn frame_log_panel(&self) -> &FrameLogPanel {
        &self.frame_log
    }

    /// The Plots pane's state (tests and benches read and set it).
    pub fn plots_panel(&self) -> &super::plots::PlotsPanel {
        &self.plots
    }

    pub fn plots_panel_mut(&mut self) -> &mut super::plots::PlotsPanel {
        &mut self.plots
    }

    /// The frame log pane, to drive it from tests and benches.
    /// Where the pane `tab` was drawn in the last frame, if it was shown (a tab behind
    /// another is not).
    pub fn pane_rect(&self, tab: Tab) -> Option<egui::Rect> {
        self.pane_rects
            .iter()
            .find(|(t, _)| *t == tab)
            .map(|(_, r)| *r)
    }

    pub fn frame_log_panel_mut(&mut self) -> &mut FrameLogPanel {
        &mut self.frame_log
    }

    /// When the window started (the messages' times count from here).
    pub fn started(&self) -> Instant {
        self.started
    }

    /// The embedded simulator, when the line is the built-in one.
    /// How many link events so far changed what the window shows (and so woke it).
    pub fn link_wakes(&self) -> u64 {
        self.link_wakes.load(std::sync::atomic::Ordering::Relaxed)
    }

    /// How many old connections are still closing (on threads of their own).
    pub fn lines_closing(&self) -> usize {
        self.closing.len()
    }

    /// The RMC151's session (tests reach its built-in simulator).
    pub fn rmc(&self) -> Option<&RmcSession> {
        self.rmc.as_ref()
    }

    pub fn sim(&self) -> Option<&SimHandle> {
        self.session.as_ref().and_then(|s| s.sim.as_ref())
    }

    /// The built-in simulator's front panel, when the line is the built-in one.
    fn panel(&self) -> Option<&crate::session::simulator::FrontPanel> {
        self.session.as_ref().and_then(|s| s.panel.as_ref())
    }

    /// Closes the session as the window does on exit: the link stops any jog or move.
    pub fn close(&mut self) {
        if self.pendant.held_jog().is_some() || self.pendant.axes.hold.jog().is_some() {
            let now = Instant::now();
            self.pendant.apply(Intent::Stop(StopCause::Exit), now);
            if let Some(s) = &self.session {
                s.link.stop_all();
            }
            if let Some(r) = &self.rmc {
                r.link.stop_all();
            }
        }
        // Both links close at once, each sending its STOPs; the window waits for both
        // and for any close already under way.
        self.open_when_closed.clear();
        self.close_session();
        self.close_rmc();
        for (_, closing) in self.closing.drain(..) {
            drop(closing.finish());
        }
    }

    /// Closes the X-SEL's line on a thread of its own (its link sends the STOPs owed
    /// first); the window goes on drawing.
    fn close_session(&mut self) {
        if let Some(session) = self.session.take() {
            self.closing
                .push((Device::Xsel, session.close_in_background()));
        }
        self.inbox.forget_xsel();
    }

    /// Closes the RMC151's connection on a thread of its own (its link stops what may
    /// move first).
    fn close_rmc(&mut self) {
        if let Some(rmc) = self.rmc.take() {
            let closing = Closing::start("the RMC151's connection", rmc, None, |rmc| {
                drop(rmc);
                None
            });
            self.closing.push((Device::Rmc, closing));
        }
        self.inbox.forget_rmc();
    }

    /// Opens `device`'s line once its old one has closed (once, however often asked).
    fn open_later(&mut self, device: Device) {
        if !self.open_when_closed.contains(&device) {
            self.open_when_closed.push(device);
        }
    }

    /// Whether `device`'s old connection is still closing.
    fn still_closing(&self, device: Device) -> bool {
        self.closing.iter().any(|(d, _)| *d == device)
    }

    /// Takes in the closes that ended (a problem goes to Messages) and opens the lines
    /// that waited for them; true while any close runs.
    fn closes_done(&mut self, ctx: &egui::Context, now: Instant) -> bool {
        let mut i = 0;
        while i < self.closing.len() {
            if self.closing[i].1.is_done() {
                let (_, closing) = self.closing.remove(i);
                if let Some(problem) = closing.finish() {
                    self.pendant
                        .say(crate::pendant::Level::Warning, problem, now);
                }
            } else {
                i += 1;
            }
        }
        for device in std::mem::take(&mut self.open_when_closed) {
            match device {
                Device::Xsel => self.open_session(ctx, now),
                Device::Rmc => self.open_rmc(ctx, now),
            }
        }
        !self.closing.is_empty()
    }

    /// Takes in the links' events, both lines' oldest first, for at most
    /// [`EVENT_BUDGET`]; true when some are left for the next frame.
    fn drain_events(&mut self, now: Instant) -> bool {
        if let Some(session) = &mut self.session {
            // What the simulator's front panel did, said beside it and in Messages.
            for line in session
                .panel
                .as_mut()
                .map(|p| p.take_news())
                .unwrap_or_default()
            {
                self.simulator.done(format!("Simulator: {line}"));
                self.pendant.note(format!("simulator: {line}"), now);
            }
        }
        let deadline = now + EVENT_BUDGET;
        let xsel = self.session.as_ref().map(|s| &s.events);
        let rmc = self.rmc.as_ref().map(|r| &r.events);
        while let Some(next) = self.inbox.next(xsel, rmc) {
            match next {
                Next::Xsel(event) => self.pendant.handle_event(Instant::now(), event),
                Next::Rmc(event) => self.pendant.handle_axes_event(Instant::now(), event),
            }
            if Instant::now() >= deadline {
                return true;
            }
        }
        false
    }

    fn run_requests(&mut self, ctx: &egui::Context, now: Instant) {
        // In the model's order: a STOP already ended what was asked before it (and the
        // link's STOP channel overtakes the rest), so nothing here reorders.
        for request in self.pendant.take_requests() {
            match request {
                Request::Stop => {
                    if let Some(s) = &self.session {
                        s.stop_all();
                    }
                    if let Some(r) = &self.rmc {
                        r.link.stop_all();
                    }
                    for (_, closing) in &self.closing {
                        closing.stop_all();
                    }
                }
                Request::Submit(command) => {
                    if let Some(s) = &self.session {
                        s.submit(command);
                    }
                }
                Request::Background(command) => {
                    if let Some(s) = &self.session {
                        s.submit_background(command);
                    }
                }
                Request::Spare(command) => {
                    if let Some(s) = &self.session {
                        s.submit_spare(command);
                    }
                }
                Request::RenewJogLease => {
                    if let Some(s) = &self.session {
                        s.renew_jog_lease();
                    }
                }
                Request::ReadTable(kind) => {
                    let records = match kind {
                        CoordKind::Work => self.pendant.model.work_table_size,
                        CoordKind::Tool => self.pendant.model.tool_table_size,
                    };
                    self.read_records(kind, 0..records.min(256) as u16);
                }
                Request::ReadRecords(kind, range) => self.read_records(kind, range),
                Request::CancelTableRead => {
                    if let Some(s) = &self.session {
                        s.cancel_table_read();
                    }
                }
                Request::SimulatorTables(tables) => match self.panel() {
                    Some(panel) => panel.try_tables(tables),
                    None => self.pendant.note(
                        "no built-in simulator on this line: the draft was not given",
                        now,
                    ),
                },
                Request::Connect => self.open_session(ctx, now),
                Request::Disconnect => {
                    self.open_when_closed.retain(|d| *d != Device::Xsel);
                    self.close_session();
                }
                Request::Axes(call) => self.axes_call(ctx, call, now),
            }
        }
    }

    fn axes_call(&mut self, ctx: &egui::Context, call: AxisCall, now: Instant) {
        if let AxisCall::Connect = call {
            return self.open_rmc(ctx, now);
        }
        if let AxisCall::Disconnect = call {
            self.open_when_closed.retain(|d| *d != Device::Rmc);
            return self.close_rmc();
        }
        let Some(rmc) = &self.rmc else {
            return;
        };
        match call {
            // The model records what the link says went out under each id (its Sent
            // events), never what was asked for.
            AxisCall::Send(axis, command) => {
                rmc.link.send(axis, command);
            }
            AxisCall::Hold(axis, jog) => {
                rmc.link.hold(axis, jog);
            }
            AxisCall::Release(axis) => rmc.link.release(axis),
            AxisCall::RenewLease => rmc.link.renew_lease(),
            AxisCall::Connect | AxisCall::Disconnect => {}
        }
    }

    /// Opens the RMC151's connection in the settings (closing the current one).
    fn open_rmc(&mut self, ctx: &egui::Context, now: Instant) {
        self.close_rmc();
        if self.still_closing(Device::Rmc) {
            // The old connection closes first (its STOP); this one opens after it.
            return self.open_later(Device::Rmc);
        }
        let repaint_ctx = ctx.clone();
        let wakes = self.link_wakes.clone();
        let last = std::sync::Mutex::new(RmcWake::new(
            self.live_log_shown.clone(),
            self.unread.clone(),
            crate::rmc::EVENT_BACKLOG,
        ));
        let repaint = std::sync::Arc::new(move |event: &crate::rmc::RmcEvent| {
            // A poll that reads what is already shown wakes nobody.
            if last.lock().map_or(Wake::Soon, |mut l| l.on_event(event)) == Wake::Soon {
                wakes.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                repaint_ctx.request_repaint_after(LINK_REPAINT);
            }
        });
        match RmcSession::open(&self.pendant.settings.rmc, repaint, &self.line_owner) {
            Ok(session) => self.rmc = Some(session),
            Err(e) => {
                let axes = &mut self.pendant.axes;
                axes.line = crate::pendant::LineState::Down {
                    reason: e.clone(),
                    since: now,
                };
                self.pendant
                    .say(crate::pendant::Level::Error, format!("RMC: {e}"), now);
            }
        }
    }

    fn read_records(&self, kind: CoordKind, range: std::ops::Range<u16>) {
        if let Some(s) = &self.session {
            s.read_table(kind, range);
        }
    }

    fn open_session(&mut self, ctx: &egui::Context, now: Instant) {
        // The old link shuts down first (stopping any motion), then the new one opens:
        // the same port cannot be opened twice.
        self.close_session();
        if self.still_closing(Device::Xsel) {
            return self.open_later(Device::Xsel);
        }
        let settings = self.pendant.settings.connection.clone();
        let model = match load_model(&settings.robot) {
            Ok(m) => m,
            Err(e) => return self.pendant.connect_failed(e, now),
        };
        self.pendant.set_model(model.clone());
        // A link event wakes the window only when it changes what is shown, and then at
        // most every LINK_REPAINT: polls alone bring ~40 events a second, and a repaint
        // each would keep a software renderer busy (see `wake`).
        let repaint_ctx = ctx.clone();
        let filter = std::sync::Mutex::new(WakeFilter::new(
            self.live_log_shown.clone(),
            self.unread.clone(),
            crate::session::EVENT_BACKLOG,
        ));
        let wakes = self.link_wakes.clone();
        let repaint = std::sync::Arc::new(move |event: &crate::pendant::LinkEvent| {
            let wake = filter.lock().map_or(Wake::Soon, |mut f| f.on_event(event));
            if wake == Wake::Soon {
                wakes.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                repaint_ctx.request_repaint_after(LINK_REPAINT);
            }
        });
        let polls = crate::pendant::controller::poll_commands();
        match Session::open(&settings, &model, polls, repaint, &self.line_owner) {
            Ok(session) => self.session = Some(session),
            Err(e) => self.pendant.connect_failed(e, now),
        }
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
        if self.drain_events(now) {
            // The rest of a backlog is taken in next frame.
            ctx.request_repaint();
        } else {
            self.unread.store(0, std::sync::atomic::Ordering::Relaxed);
        }
        // A window that lost focus cannot see a key or button come up: stop the jog.
        if ctx.input(|i| i.viewport().focused) == Some(false) {
            self.pendant.apply(Intent::FocusLost, now);
        }
        self.pendant.tick(now);
        self.run_requests(ctx, now);
        if self.closes_done(ctx, now) {
            // A close takes up to a reply time-out or two: look again soon.
            ctx.request_repaint_after(CLOSE_CHECK);
        }
        if self.pendant.held_jog().is_some() || self.pendant.axes.hold.jog().is_some() {
            // While a continuous jog is held the window runs at least this often.
            ctx.request_repaint_after(crate::pendant::RENEW_EVERY);
        } else if self.session.is_some() {
            ctx.request_repaint_after(IDLE_WAKE);
        }
    }

    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        let ctx = ui.ctx().clone();
        self.apply_theme(&ctx);
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
        if keys.quit || END_ASKED.swap(false, std::sync::atomic::Ordering::Relaxed) {
            ctx.send_viewport_cmd(egui::ViewportCommand::Close);
        }
        if keys.toggle_help {
            self.help_open = !self.help_open;
        }
        Panel::top("top-bar").show(ui, |ui| {
            top_bar::show(ui, &self.pendant, now, &mut intents);
        });
        if intents.iter().any(|i| matches!(i, Intent::Stop(_))) {
            // STOP goes to the link now, ahead of everything drawn below.
            self.pendant.apply_all(std::mem::take(&mut intents), now);
            self.run_requests(&ctx, now);
        }
        Panel::top("safety-band").show(ui, |ui| safety_band::show(ui, &self.pendant, now));
        let mut sim_action = None;
        let mut pad = PadOutput::default();
        let mut axes_pad = super::axes::AxesPadOutput::default();
        // The jog panel first, at the top of the column: the pad never moves.
        // The column (and the pad in it) follows the window: 27% to 36% of its width
        // (370 px at 1280 unless dragged), so a column widened on a large screen shrinks
        // back with the window.
        let window_width = ui.ctx().content_rect().width();
        let least = (window_width * LEFT_SHARE.start).clamp(300.0, 600.0);
        Panel::left("left")
            .resizable(true)
            .default_size(370.0)
            .size_range(least..=(window_width * LEFT_SHARE.end).max(least))
            .show(ui, |ui| {
                egui::ScrollArea::vertical().show(ui, |ui| {
                    egui::CollapsingHeader::new("Jog")
                        .default_open(true)
                        .show(ui, |ui| {
                            pad = self.jog.show(ui, &self.pendant, now, &mut intents);
                        });
                    egui::CollapsingHeader::new("Connection")
                        .default_open(true)
                        .show(ui, |ui| {
                            self.connection.show(ui, &self.pendant, &mut intents)
                        });
                    egui::CollapsingHeader::new("Delta RMC151 (Modbus/TCP)")
                        .default_open(false)
                        .show(ui, |ui| {
                            super::rmc_connection::show(ui, &self.pendant, &mut intents)
                        });
                    if ui.button("Keyboard (F1)").clicked() {
                        self.help_open = !self.help_open;
                    }
                });
            });
        self.arm.hovered_step = pad.hovered.map(|t| (t.axis, t.direction));
        self.arm.hovered_point = self.teach.hovered_go;
        // Last frame's hovered Go or preview row; this frame's is found while drawing.
        self.arm.hovered_position = self.positions.hovered.take();
        self.frame_log.live_in_sight = false;
        egui::CentralPanel::default().show(ui, |ui| {
            let mut tabs = Tabs {
                pendant: &self.pendant,
                intents: &mut intents,
                arm: &mut self.arm,
                teach: &mut self.teach,
                coords: &mut self.coords,
                positions: &mut self.positions,
                signals: &mut self.signals,
                programs: &mut self.programs,
                alarms: &mut self.alarms,
                frame_log: &mut self.frame_log,
                plots: &mut self.plots,
                simulator: &mut self.simulator,
                folder: self
                    .folder
                    .get(self.pendant.settings.last_folder.as_deref()),
                sim: self.session.as_ref().and_then(|s| s.panel.as_ref()),
                sim_action: &mut sim_action,
                now,
                started: self.started,
                pane_rects: &mut self.pane_rects,
                axes_pad: &mut axes_pad,
            };
            tabs.pane_rects.clear();
            layout::show(ui, &mut self.dock, &mut tabs);
            let centre = ui.max_rect();
            self.positions
                .preview_window(ui.ctx(), centre, &self.pendant, &mut intents);
            self.signals.after_panes(
                ui.ctx(),
                centre,
                &self.pendant,
                &mut self.plots,
                &mut intents,
            );
            self.programs
                .after_panes(ui.ctx(), centre, &self.pendant, &mut intents);
        });
        self.live_log_shown.store(
            self.frame_log.live_in_sight,
            std::sync::atomic::Ordering::Relaxed,
        );
        keys::help(&ctx, &self.pendant, &mut self.help_open);
        // The pointer's jog input: on the pad button it was pressed on, aside, or up.
        if let Some(target) = pad.tapped {
            intents.push(Intent::Jog(JogInput::Pointer, Press::On(target)));
        }
        let press = match (ctx.input(|i| i.pointer.primary_down()), pad.held_on) {
            (false, _) => Press::Up,
            (true, Some(target)) => Press::On(target),
            (true, None) => Press::Aside,
        };
        intents.push(Intent::Jog(JogInput::Pointer, press));
        // The same pointer on the RMC axis buttons: one hold machine each, one STOP.
        if let Some(target) = axes_pad.tapped {
            intents.push(Intent::Axes(AxisIntent::Jog(
                JogInput::Pointer,
                Press::On(target),
            )));
        }
        let axes_press = match (ctx.input(|i| i.pointer.primary_down()), axes_pad.held_on) {
            (false, _) => Press::Up,
            (true, Some(target)) => Press::On(target),
            (true, None) => Press::Aside,
        };
        intents.push(Intent::Axes(AxisIntent::Jog(JogInput::Pointer, axes_press)));
        self.pendant.apply_all(intents, now);
        if let Some(action) = sim_action
            && let Some(panel) = self.panel()
        {
            panel.act(action);
            // Its result comes back from the simulator's thread within a tick.
            ctx.request_repaint_after(PANEL_ANSWER);
        }
        self.run_requests(&ctx, now);
        self.work_files.autosave(&mut self.pendant, &self.dock, now);
        first_frame_probe(&ctx, self.started);
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

/// Opt-in start-up probe for `benches/window_startup.sh`; does nothing unless its
/// variables are set to `1`. `XSEL_PENDANT_FIRST_FRAME` prints
/// `first frame unix_us=<wall clock, µs since the Unix epoch> app_us=<µs since the app was
/// created>` on stderr once, at the end of the first `ui()` call (layout done; that frame
/// is then tessellated and painted). `XSEL_PENDANT_EXIT_AFTER_FIRST_FRAME` then closes
/// the window.
fn first_frame_probe(ctx: &egui::Context, app_started: Instant) {
    if ctx.cumulative_frame_nr() != 0 {
        return;
    }
    let on = |name: &str| std::env::var_os(name).is_some_and(|v| v == "1");
    if on("XSEL_PENDANT_FIRST_FRAME") {
        let unix_us = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| d.as_micros());
        let app_us = app_started.elapsed().as_micros();
        eprintln!("first frame unix_us={unix_us} app_us={app_us}");
    }
    if on("XSEL_PENDANT_EXIT_AFTER_FIRST_FRAME") {
        ctx.send_viewport_cmd(egui::ViewportCommand::Close);
    }
}
