//! What the window's panels ask of the pendant: one type for every intent, collected
//! while drawing and applied after it with [`Pendant::apply`] (STOP at once), as in the
//! egui demo app and rerun's viewer. No panel writes a model field.

use std::time::Instant;

use super::Pendant;
use super::coords::CoordsIntent;
use super::jog::JogSettings;
use super::jog::hold::{JogInput, Press, StopCause};
use crate::robot::Pose;

/// One thing an operator asked for.
#[derive(Clone, Debug, PartialEq)]
pub enum Intent {
    /// A jog input's state this frame (reported every frame while it is down, and once
    /// when it comes up).
    Jog(JogInput, Press),
    /// The window lost the keyboard and pointer: it will see no release.
    FocusLost,
    /// STOP, and who pressed it.
    Stop(StopCause),
    /// The jog panel's new choices (it edits a copy).
    JogSettings(JogSettings),
    /// 232H servo on or off, SCARA axes.
    Servo(bool),
    /// 233H home return.
    Home,
    /// 252H alarm reset.
    ResetAlarm,
    /// 2D4H to the target filled in from the arm view.
    GoToTarget,
    /// The target's coordinates, edited.
    EditTarget(Pose),
    ClearTarget,
    /// "Go" on a taught point.
    TeachGo(usize),
    /// "Record" the current pose under this name (empty: one is made up).
    TeachRecord(String),
    /// The position table's view.
    Positions(super::positions::PositionsIntent),
    /// The Signals view.
    Signals(super::signals::SignalsIntent),
    /// The Programs view.
    Programs(super::programs::ProgramsIntent),
    /// The Alarms view.
    Alarms(super::alarms::AlarmsIntent),
    /// Controller snapshots (in the Alarms view).
    Snapshot(super::snapshot::SnapshotIntent),
    /// The teach list after an edit (reorder, delete, rename), as a whole.
    TeachList(super::teach::TeachList),
    /// A teach file read (its points, or why not): waits for "Replace".
    TeachLoaded {
        path: String,
        read: Result<super::teach::TeachList, String>,
    },
    /// "Replace" the list with the loaded file's points.
    TeachConfirmLoad,
    /// Keep the list; forget the loaded file.
    TeachCancelLoad,
    /// The list as it was before the last load.
    TeachUndoLoad,
    /// "Step here" from the arm view: the target, tool tip in the selected work frame.
    SetTarget(Pose),
    /// The connection panel's new settings (it edits a copy).
    ConnectionSettings(super::ConnectionSettings),
    /// Open the line in the settings (closing the current one).
    Connect,
    /// Close the line.
    Disconnect,
    /// Allow jogs up to this speed at the tool (mm/s) until the window closes.
    RaiseSpeedCap(f64),
    /// Back to the reduced jog speed.
    ResetSpeedCap,
    /// The light (or dark) theme.
    LightTheme(bool),
    /// The coordinate tables pane.
    Coords(CoordsIntent),
    /// Keep at most this many rows in the frame log.
    FrameLogCap(usize),
    /// Keep at most this many MB of rows in the frame log.
    FrameLogBudget(usize),
    /// Empty the live frame log.
    ClearFrameLog,
    /// The plots' capture choices (on, length, pre-trigger share).
    CaptureSettings(crate::pendant::samples::capture::CaptureSettings),
    /// Forget the captures taken.
    ClearCaptures,
    /// A frame typed as its body, to send through the link.
    SendRaw(String),
    /// Everything in the window this size (1.0: 100%), kept for the next start.
    UiScale(f32),
    /// A file was read or written here: its folder is the one names are taken in next.
    FileUsed(std::path::PathBuf),
    /// The RMC151's axis panel.
    Axes(super::axes::AxisIntent),
}

/// The smallest and largest window scale kept (egui's own zoom keys stay in this range).
pub const UI_SCALES: (f32, f32) = (0.5, 3.0);

impl Pendant {
    /// Applies one intent.
    pub fn apply(&mut self, intent: Intent, now: Instant) {
        match intent {
            Intent::Jog(input, press) => self.jog_input(input, press, now),
            Intent::FocusLost => self.focus_lost(now),
            Intent::Stop(cause) => self.stop_by(cause, now),
            Intent::JogSettings(settings) => self.set_jog_settings(settings),
            Intent::Servo(on) => self.servo(on, now),
            Intent::Home => self.home(now),
            Intent::ResetAlarm => self.reset_alarm(now),
            Intent::GoToTarget => self.go_to_target(now),
            Intent::EditTarget(pose) => self.edit_step_target(pose),
            Intent::ClearTarget => self.clear_step_target(),
            Intent::TeachGo(index) => self.teach_go(index, now),
            Intent::TeachRecord(name) => self.teach_record(&name, now),
            Intent::TeachList(list) => self.teach.set(list),
            Intent::Positions(p) => self.apply_positions(p, now),
            Intent::Signals(s) => self.apply_signals(s, now),
            Intent::Programs(p) => self.apply_programs(p, now),
            Intent::Alarms(a) => self.apply_alarms(a, now),
            Intent::Snapshot(s) => self.apply_snapshot(s, now),
            Intent::TeachLoaded { path, read } => self.teach_loaded(&path, read, now),
            Intent::TeachConfirmLoad => self.teach_confirm_load(now),
            Intent::TeachCancelLoad => self.teach_cancel_load(),
            Intent::TeachUndoLoad => self.teach_undo_load(now),
            Intent::SetTarget(pose) => self.set_step_target(pose, now),
            Intent::ConnectionSettings(c) => self.settings.connection = c,
            Intent::Connect => self.connect(now),
            Intent::Disconnect => self.disconnect(now),
            Intent::RaiseSpeedCap(mm_s) => self.raise_speed_cap(mm_s, now),
            Intent::ResetSpeedCap => self.reset_speed_cap(now),
            Intent::LightTheme(light) => self.settings.light_theme = light,
            Intent::Coords(c) => self.apply_coords(c, now),
            Intent::FrameLogCap(cap) => {
                self.frame_log.set_cap(cap);
                self.settings.frame_log_cap = Some(cap);
            }
            Intent::FrameLogBudget(mb) => {
                self.frame_log.set_budget(mb.saturating_mul(1024 * 1024));
                self.settings.frame_log_budget_mb = Some(mb);
            }
            Intent::ClearFrameLog => self.frame_log.clear(),
            Intent::CaptureSettings(c) => {
                self.settings.captures = c;
                self.samples.captures.settings = c;
            }
            Intent::ClearCaptures => self.samples.captures.list.clear(),
            Intent::UiScale(scale) => {
                self.settings.ui_scale = (scale.is_finite() && (scale - 1.0).abs() > 1e-3)
                    .then(|| scale.clamp(UI_SCALES.0, UI_SCALES.1));
            }
            Intent::FileUsed(path) => {
                self.settings.last_folder = path.parent().map(std::path::Path::to_path_buf);
            }
            Intent::Axes(intent) => {
                if let Some((level, text)) = self.axes.apply(intent, &mut self.settings.rmc, now) {
                    self.say(level, text, now);
                }
            }
            Intent::SendRaw(body) => {
                // The outcome is kept for the frame log pane and said in Messages.
                self.raw_sent = Some(self.send_raw(&body, now).map(|c| c.id().to_string()));
            }
        }
    }

    /// Applies a frame's intents: the jog inputs' states first (so a STOP latches every
    /// input down this frame), then STOPs, then the rest in order.
    pub fn apply_all(&mut self, intents: impl IntoIterator<Item = Intent>, now: Instant) {
        let rank = |i: &Intent| match i {
            Intent::Jog(..)
            | Intent::FocusLost
            | Intent::Axes(super::axes::AxisIntent::Jog(..)) => 0,
            Intent::Stop(_) => 1,
            _ => 2,
        };
        let mut intents: Vec<Intent> = intents.into_iter().collect();
        intents.sort_by_key(rank);
        for intent in intents {
            self.apply(intent, now);
        }
    }
}

impl From<super::positions::PositionsIntent> for Intent {
    fn from(i: super::positions::PositionsIntent) -> Intent {
        Intent::Positions(i)
    }
}

impl From<super::programs::ProgramsIntent> for Intent {
    fn from(i: super::programs::ProgramsIntent) -> Intent {
        Intent::Programs(i)
    }
}

impl From<super::signals::SignalsIntent> for Intent {
    fn from(i: super::signals::SignalsIntent) -> Intent {
        Intent::Signals(i)
    }
}
