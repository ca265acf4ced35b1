//! How the window starts: the connection and RMC151 named on the command line, saved
//! settings or a fresh start, where the operator's files live, who owns the line, and the
//! benches' opt-in hooks (read from the environment by the binary's entry point only).

use std::time::Instant;

use egui::Theme;

use super::layout::{self, Tab};
use super::work_files::WorkFiles;
use crate::pendant::axes::AxisIntent;
use crate::pendant::{ConnectionSettings, Intent, Level, LineKind, Pendant, Settings};
use crate::robot::RobotModel;
use crate::session::{LineOwner, load_model};

/// The storage key and window title.
pub const APP_ID: &str = "xsel-pendant";
/// Where earlier versions kept the settings and the layout in eframe's storage.
pub const SETTINGS_KEY: &str = "settings";
pub const LAYOUT_KEY: &str = "layout";

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
    /// The benches' hooks (none unless the binary read them from its environment).
    pub bench: BenchHooks,
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
            bench: BenchHooks::default(),
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

/// Opt-in hooks for `benches/window_startup.sh`; all off by default. The binary's entry
/// point reads them from the environment ([`BenchHooks::from_env`]); the library never
/// does.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct BenchHooks {
    /// `XSEL_PENDANT_BENCH_LOG_ROWS`: start with a frame log of this many synthetic rows
    /// (`--rss-log`: the memory of a full log).
    pub log_rows: Option<u64>,
    /// `XSEL_PENDANT_FIRST_FRAME=1`: print `first frame unix_us=<wall clock, µs since the
    /// Unix epoch> app_us=<µs since the app was created>` on stderr once, at the end of
    /// the first `ui()` call (layout done; that frame is then tessellated and painted).
    pub first_frame: bool,
    /// `XSEL_PENDANT_EXIT_AFTER_FIRST_FRAME=1`: then close the window.
    pub exit_after_first_frame: bool,
}

impl BenchHooks {
    /// The hooks the environment asks for.
    pub fn from_env() -> Self {
        let on = |name: &str| std::env::var_os(name).is_some_and(|v| v == "1");
        Self {
            log_rows: std::env::var("XSEL_PENDANT_BENCH_LOG_ROWS")
                .ok()
                .and_then(|v| v.parse::<u64>().ok()),
            first_frame: on("XSEL_PENDANT_FIRST_FRAME"),
            exit_after_first_frame: on("XSEL_PENDANT_EXIT_AFTER_FIRST_FRAME"),
        }
    }

    /// At start: a full frame log when asked for.
    pub fn started(&self, pendant: &mut Pendant) {
        if let Some(rows) = self.log_rows {
            pendant.fill_log_synthetic(rows);
        }
    }

    /// At the end of each `ui()` call: the first frame's probe.
    pub fn frame_done(&self, ctx: &egui::Context, app_started: Instant) {
        if ctx.cumulative_frame_nr() != 0 {
            return;
        }
        if self.first_frame {
            let unix_us = std::time::SystemTime::now()
                .duration_since(std::time::UNIX_EPOCH)
                .map_or(0, |d| d.as_micros());
            let app_us = app_started.elapsed().as_micros();
            eprintln!("first frame unix_us={unix_us} app_us={app_us}");
        }
        if self.exit_after_first_frame {
            ctx.send_viewport_cmd(egui::ViewportCommand::Close);
        }
    }
}

/// What the window starts with: the pendant (its line asked for), the operator's files
/// and the layout.
pub struct Start {
    pub pendant: Pendant,
    pub work_files: WorkFiles,
    pub layout: egui_tiles::Tree<Tab>,
}

impl Start {
    /// Settings and layout as saved (unless fresh) with the command line's choices over
    /// them; the pendant on the robot model they name, its lines asked for (unless
    /// offline).
    pub fn open(cc: &eframe::CreationContext<'_>, options: &StartOptions, now: Instant) -> Self {
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
        match &options.connection {
            Some(c) => settings.connection = c.clone(),
            // No line named: the built-in simulator, the saved line settings kept.
            None => settings.connection.kind = LineKind::Simulator,
        }
        if let Some(Some(address)) = &options.rmc {
            settings.rmc.enabled = true;
            settings.rmc.address = address.clone();
        }
        // `--no-rmc` leaves the RMC disconnected this run only.
        let rmc_this_run = options.rmc != Some(None);
        let (model, problem) = match load_model(&settings.connection.robot) {
            Ok(m) => (m, None),
            Err(e) => (RobotModel::default_model(), Some(e)),
        };
        if let Some(scale) = settings.ui_scale {
            cc.egui_ctx.set_zoom_factor(scale);
        }
        let mut pendant = Pendant::new(settings, model);
        // Frame log times count from the window's start.
        pendant.window_started(now, std::time::SystemTime::now());
        for text in notes.drain(..) {
            pendant.say(Level::Warning, text, now);
        }
        if let Some(e) = problem {
            pendant.connect_failed(e, now);
        } else if !options.offline {
            pendant.connect(now);
        }
        if !options.offline && rmc_this_run && pendant.settings.rmc.enabled {
            pendant.apply(Intent::Axes(AxisIntent::Connect), now);
        }
        options.bench.started(&mut pendant);
        Self {
            pendant,
            work_files,
            layout: layout::checked_layout(saved_layout),
        }
    }
}
