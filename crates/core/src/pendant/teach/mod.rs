//! The teach list: named poses recorded from the arm, kept in order, replayed with 2D4H.
//!
//! Positions stay in the wire's integers (0.001 mm, 0.001 deg) from the status reply to the
//! file and back to the move command, so nothing drifts. Files (CSV, JSON) live in
//! [`file`] and `json`; the list with its pending load and Undo in [`book`].

pub mod book;
pub mod file;
mod json;

use std::fmt;

use serde::{Deserialize, Serialize};

use crate::protocol::{
    ArmPolicy, ArmSystem, Axis, Command, Milli, PerAxis, ScaraMotion, ScaraMove,
};

/// The longest name, in characters.
pub const MAX_NAME_CHARS: usize = 32;
/// The most points a list holds (a file with more is refused, Record says the list is
/// full): the list draws only its visible rows, and a file of this many is about 1 MB.
pub const MAX_POINTS: usize = 10_000;
/// The highest work or tool coordinate system number a point may name: the last entry of
/// the largest table a robot model can have. Whether the robot at hand has it is checked
/// at Go, against the numbers the controller has selected.
pub const MAX_FRAME_NUMBER: u8 = (crate::robot::MAX_TABLE_SIZE - 1) as u8;

/// What "Record" takes from the arm: the pose in the selected work frame and the frames
/// and arm system it was taken in.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct TaughtPose {
    /// Work X, Y, Z in 0.001 mm and R in 0.001 deg (wire units).
    pub pose: [i32; 4],
    /// The arm system at the time.
    pub arm: ArmSystem,
    /// The selected work coordinate system number (0-31).
    pub work: u8,
    /// The selected tool coordinate system number (0-127).
    pub tool: u8,
}

/// One named point of the teach list. Deserialising checks every field (name, range of
/// work and tool), so a loaded point is as valid as a recorded one.
#[derive(Clone, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct TeachPoint {
    /// Unique within its list, trimmed, 1 to 32 characters, no control characters.
    #[serde(deserialize_with = "json::de_name")]
    pub name: String,
    /// Work X, Y, Z in 0.001 mm and R in 0.001 deg (wire units).
    #[serde(deserialize_with = "json::de_pose")]
    pub pose: [i32; 4],
    /// The arm system the point was taught in (`right`, `left`, `undetermined` in files).
    #[serde(serialize_with = "json::ser_arm", deserialize_with = "json::de_arm")]
    pub arm: ArmSystem,
    /// The work coordinate system number it was taught in (0-31).
    #[serde(deserialize_with = "json::de_work")]
    pub work: u8,
    /// The tool coordinate system number it was taught in (0-127).
    #[serde(deserialize_with = "json::de_tool")]
    pub tool: u8,
    /// The RMC151's axes' positions taken with it, in 0.001 position units, axis 1 first
    /// (empty: the point moves the arm only). Go moves each with Move Absolute (20).
    #[serde(
        default,
        skip_serializing_if = "Vec::is_empty",
        deserialize_with = "json::de_axes"
    )]
    pub axes: Vec<i32>,
}

impl TeachPoint {
    /// A point named `name` at `at` (not yet checked; [`TeachList`] checks on insertion).
    pub fn new(name: impl Into<String>, at: TaughtPose) -> TeachPoint {
        TeachPoint {
            name: name.into(),
            pose: at.pose,
            arm: at.arm,
            work: at.work,
            tool: at.tool,
            axes: Vec::new(),
        }
    }

    /// The pose, arm and frames without the name.
    pub fn taught(&self) -> TaughtPose {
        TaughtPose {
            pose: self.pose,
            arm: self.arm,
            work: self.work,
            tool: self.tool,
        }
    }

    /// The PTP arm policy that reaches the point in the arm it was taught in (keep the
    /// current arm, no switching, when that was undetermined).
    pub fn arm_policy(&self) -> ArmPolicy {
        match self.arm {
            ArmSystem::Right => ArmPolicy::Right,
            ArmSystem::Left => ArmPolicy::Left,
            ArmSystem::Undetermined => ArmPolicy::KeepNoSwitch,
        }
    }

    /// This point with its name trimmed, after checking name, work and tool.
    pub fn checked(mut self) -> Result<TeachPoint, TeachError> {
        self.name = check_name(&self.name)?;
        if self.axes.len() > crate::rmc::MAX_AXES {
            return Err(TeachError::TooManyAxes(self.axes.len()));
        }
        check_frames(self.work, self.tool)?;
        Ok(self)
    }
}

/// Why the teach list refused an edit. The texts are written for the operator.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum TeachError {
    /// More RMC axes than an RMC151 has.
    #[error("{0} RMC axes: an RMC151 has at most 8")]
    TooManyAxes(usize),
    /// The name is empty or only spaces.
    #[error("a point needs a name")]
    EmptyName,
    /// The name is longer than [`MAX_NAME_CHARS`].
    #[error("the name is {chars} characters long; at most 32 are allowed")]
    NameTooLong {
        /// Its length in characters.
        chars: usize,
    },
    /// The name holds a tab, line break or other control character.
    #[error("the name contains a control character (tab, line break...)")]
    NameControl,
    /// Another point already has this name.
    #[error("the name \"{name}\" is already used by point {}; choose another, e.g. \"{suggestion}\"", .existing + 1)]
    DuplicateName {
        /// The name asked for.
        name: String,
        /// Index of the point that has it.
        existing: usize,
        /// A free name built from it.
        suggestion: String,
    },
    /// The work coordinate system number is above [`MAX_FRAME_NUMBER`].
    #[error("work coordinate system {0} is out of range (0-{MAX_FRAME_NUMBER})")]
    WorkOutOfRange(u8),
    /// The tool coordinate system number is above [`MAX_FRAME_NUMBER`].
    #[error("tool coordinate system {0} is out of range (0-{MAX_FRAME_NUMBER})")]
    ToolOutOfRange(u8),
    /// The list already holds [`MAX_POINTS`].
    #[error("the list is full ({MAX_POINTS} points); delete points or save and start a new list")]
    ListFull,
    /// No point at this index.
    #[error("there is no point {} (the list has {len})", .index + 1)]
    NoSuchPoint {
        /// The index asked for (0-based).
        index: usize,
        /// The list's length.
        len: usize,
    },
}

impl TeachError {
    /// The file column the error is about, when it is about one.
    pub fn field(&self) -> Option<&'static str> {
        match self {
            TeachError::EmptyName
            | TeachError::NameTooLong { .. }
            | TeachError::NameControl
            | TeachError::DuplicateName { .. } => Some("name"),
            TeachError::WorkOutOfRange(_) => Some("work"),
            TeachError::ToolOutOfRange(_) => Some("tool"),
            TeachError::NoSuchPoint { .. } | TeachError::ListFull => None,
            TeachError::TooManyAxes(_) => Some("axes"),
        }
    }
}

/// `name` trimmed, or why it cannot be a point's name (uniqueness aside).
pub fn check_name(name: &str) -> Result<String, TeachError> {
    let t = name.trim();
    if t.is_empty() {
        return Err(TeachError::EmptyName);
    }
    let chars = t.chars().count();
    if chars > MAX_NAME_CHARS {
        return Err(TeachError::NameTooLong { chars });
    }
    if t.chars().any(char::is_control) {
        return Err(TeachError::NameControl);
    }
    Ok(t.to_owned())
}

fn check_frames(work: u8, tool: u8) -> Result<(), TeachError> {
    if work > MAX_FRAME_NUMBER {
        return Err(TeachError::WorkOutOfRange(work));
    }
    if tool > MAX_FRAME_NUMBER {
        return Err(TeachError::ToolOutOfRange(tool));
    }
    Ok(())
}

/// The ordered list of teach points. Names are unique (compared exactly, after trimming).
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(default)]
pub struct TeachList {
    #[serde(deserialize_with = "json::de_points")]
    points: Vec<TeachPoint>,
}

impl TeachList {
    /// An empty list.
    pub fn new() -> TeachList {
        TeachList::default()
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.points.len()
    }

    /// No points.
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    /// The point at `index`.
    pub fn get(&self, index: usize) -> Option<&TeachPoint> {
        self.points.get(index)
    }

    /// The points in order.
    pub fn iter(&self) -> std::slice::Iter<'_, TeachPoint> {
        self.points.iter()
    }

    /// The index of the point named `name` (trimmed first).
    pub fn position(&self, name: &str) -> Option<usize> {
        let t = name.trim();
        self.points.iter().position(|p| p.name == t)
    }

    /// Stores `at` under `name` at the end of the list; returns its index. Refuses a bad
    /// or duplicate name and out-of-range frame numbers, leaving the list as it was.
    pub fn record(&mut self, name: &str, at: TaughtPose) -> Result<usize, TeachError> {
        self.record_with_axes(name, at, Vec::new())
    }

    /// As [`TeachList::record`], with the RMC axes' positions (0.001 pu) taken with it.
    pub fn record_with_axes(
        &mut self,
        name: &str,
        at: TaughtPose,
        axes: Vec<i32>,
    ) -> Result<usize, TeachError> {
        let mut point = TeachPoint::new(name, at);
        point.axes = axes;
        self.insert(self.points.len(), point)
    }

    /// Inserts `point` at `index` (at most `len()`); returns the index. Same checks as
    /// [`TeachList::record`].
    pub fn insert(&mut self, index: usize, point: TeachPoint) -> Result<usize, TeachError> {
        if index > self.points.len() {
            return Err(self.no_such(index));
        }
        if self.points.len() >= MAX_POINTS {
            return Err(TeachError::ListFull);
        }
        let point = point.checked()?;
        self.check_free(&point.name, None)?;
        self.points.insert(index, point);
        Ok(index)
    }

    /// Replaces the pose of point `index` with `at`, keeping its name ("touch up").
    pub fn update(&mut self, index: usize, at: TaughtPose) -> Result<(), TeachError> {
        check_frames(at.work, at.tool)?;
        let len = self.points.len();
        let p = self
            .points
            .get_mut(index)
            .ok_or(TeachError::NoSuchPoint { index, len })?;
        let name = std::mem::take(&mut p.name);
        *p = TeachPoint::new(name, at);
        Ok(())
    }

    /// Renames point `index`. Its own name (or the same name with other spacing) is allowed.
    pub fn rename(&mut self, index: usize, name: &str) -> Result<(), TeachError> {
        if index >= self.points.len() {
            return Err(self.no_such(index));
        }
        let name = check_name(name)?;
        self.check_free(&name, Some(index))?;
        if let Some(p) = self.points.get_mut(index) {
            p.name = name;
        }
        Ok(())
    }

    /// Moves point `index` one place up; returns its new index (unchanged at the top).
    pub fn move_up(&mut self, index: usize) -> Result<usize, TeachError> {
        if index >= self.points.len() {
            return Err(self.no_such(index));
        }
        if index == 0 {
            return Ok(0);
        }
        self.points.swap(index - 1, index);
        Ok(index - 1)
    }

    /// Moves point `index` one place down; returns its new index (unchanged at the bottom).
    pub fn move_down(&mut self, index: usize) -> Result<usize, TeachError> {
        if index >= self.points.len() {
            return Err(self.no_such(index));
        }
        if index + 1 == self.points.len() {
            return Ok(index);
        }
        self.points.swap(index, index + 1);
        Ok(index + 1)
    }

    /// Removes point `index` and returns it.
    pub fn remove(&mut self, index: usize) -> Result<TeachPoint, TeachError> {
        if index >= self.points.len() {
            return Err(self.no_such(index));
        }
        Ok(self.points.remove(index))
    }

    /// A name not yet used: `base` followed by the smallest number from 1 ("P1", "P2"...),
    /// shortened so that it fits in 32 characters. `base` is trimmed and loses any control
    /// characters; an empty base gives "P".
    pub fn unique_name(&self, base: &str) -> String {
        let base: String = base.chars().filter(|c| !c.is_control()).collect();
        let base = match base.trim() {
            "" => "P",
            b => b,
        };
        for n in 1..=self.points.len() + 1 {
            let num = n.to_string();
            let keep = MAX_NAME_CHARS.saturating_sub(num.len());
            let stem: String = base.chars().take(keep).collect();
            let name = format!("{}{num}", stem.trim_end());
            if self.position(&name).is_none() {
                return name;
            }
        }
        // len() + 1 distinct candidates cannot all be taken by len() points.
        base.to_owned()
    }

    /// Appends an already checked point whose name the caller has proven unique.
    pub(super) fn push_checked(&mut self, point: TeachPoint) {
        self.points.push(point);
    }

    fn check_free(&self, name: &str, except: Option<usize>) -> Result<(), TeachError> {
        match self.position(name) {
            Some(existing) if Some(existing) != except => Err(TeachError::DuplicateName {
                name: name.to_owned(),
                existing,
                suggestion: self.unique_name(name),
            }),
            _ => Ok(()),
        }
    }

    fn no_such(&self, index: usize) -> TeachError {
        TeachError::NoSuchPoint {
            index,
            len: self.points.len(),
        }
    }
}

impl<'a> IntoIterator for &'a TeachList {
    type Item = &'a TeachPoint;
    type IntoIter = std::slice::Iter<'a, TeachPoint>;
    fn into_iter(self) -> Self::IntoIter {
        self.points.iter()
    }
}

/// The 2D4H move to `point`: all four SCARA axes (X, Y, Z, R) to its pose, in the selected
/// work frame, with `motion` (PTP or CP, rates and arm policy as given; see
/// [`TeachPoint::arm_policy`]). Call [`check_go`] first.
pub fn go_command(point: &TeachPoint, motion: ScaraMotion) -> Command {
    let [x, y, z, r] = point.pose;
    let targets = PerAxis::from_pairs([
        (Axis::A1, Milli(x)),
        (Axis::A2, Milli(y)),
        (Axis::A3, Milli(z)),
        (Axis::A4, Milli(r)),
    ]);
    Command::ScaraMoveAbsolute(ScaraMove { motion, targets })
}

/// Why "Go" is refused: the point was taught in another work or tool frame than the one
/// selected now. 2D4H moves in the selected work frame (PROTOCOL.md 3.19) and positions the
/// selected tool, so the same numbers would mean another place.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct GoRefusal {
    /// The point's name.
    pub point: String,
    /// Work frame the point was taught in.
    pub taught_work: u8,
    /// Tool frame the point was taught in.
    pub taught_tool: u8,
    /// Work frame selected now.
    pub selected_work: u8,
    /// Tool frame selected now.
    pub selected_tool: u8,
}

impl fmt::Display for GoRefusal {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let work = self.taught_work != self.selected_work;
        let tool = self.taught_tool != self.selected_tool;
        write!(f, "\"{}\" was taught in ", self.point)?;
        match (work, tool) {
            (true, false) => write!(
                f,
                "work frame {} but work frame {} is selected now; select work frame {} to go there",
                self.taught_work, self.selected_work, self.taught_work
            ),
            (false, true) => write!(
                f,
                "tool frame {} but tool frame {} is selected now; select tool frame {} to go there",
                self.taught_tool, self.selected_tool, self.taught_tool
            ),
            _ => write!(
                f,
                "work frame {} / tool frame {} but work frame {} / tool frame {} is selected now; \
                 select work frame {} and tool frame {} to go there",
                self.taught_work,
                self.taught_tool,
                self.selected_work,
                self.selected_tool,
                self.taught_work,
                self.taught_tool
            ),
        }
    }
}

impl std::error::Error for GoRefusal {}

/// Refuses "Go" when `point` was taught in another work or tool frame than the one
/// selected now (reach, limits and the CP line are the caller's checks).
pub fn check_go(point: &TeachPoint, current_work: u8, current_tool: u8) -> Result<(), GoRefusal> {
    if point.work == current_work && point.tool == current_tool {
        return Ok(());
    }
    Err(GoRefusal {
        point: point.name.clone(),
        taught_work: point.work,
        taught_tool: point.tool,
        selected_work: current_work,
        selected_tool: current_tool,
    })
}

/// The file word for an arm system: `right`, `left`, `undetermined`.
pub fn arm_word(arm: ArmSystem) -> &'static str {
    match arm {
        ArmSystem::Right => "right",
        ArmSystem::Left => "left",
        ArmSystem::Undetermined => "undetermined",
    }
}

/// The arm system for a file word (any letter case, spaces around ignored).
pub fn parse_arm_word(word: &str) -> Option<ArmSystem> {
    let w = word.trim();
    [ArmSystem::Right, ArmSystem::Left, ArmSystem::Undetermined]
        .into_iter()
        .find(|a| arm_word(*a).eq_ignore_ascii_case(w))
}

#[cfg(test)]
mod tests;
