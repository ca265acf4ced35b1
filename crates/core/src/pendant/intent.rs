//! What the window's panels ask of the pendant: one type for every intent, collected
//! while drawing and applied after it with `Pendant::apply` (STOP at once), as in the
//! egui demo app and rerun's viewer. No panel writes a model field.

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
    /// Read the controller's interference zones again (2A2H).
    ReadZones,
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
