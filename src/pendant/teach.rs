//! The teach list: named poses recorded from the arm, kept in order, replayed with 2D4H.
//!
//! Positions stay in the wire's integers (0.001 mm, 0.001 deg) from the status reply to the
//! file and back to the move command, so nothing drifts. Files live in
//! [`super::teach_file`].

use std::fmt;

use serde::{Deserialize, Serialize};

use crate::protocol::{ArmPolicy, ArmSystem, Axis, Command, PerAxis, ScaraMotion, ScaraMove, Thou};

/// The longest name, in characters.
pub const MAX_NAME_CHARS: usize = 32;
/// The highest work coordinate system number.
pub const MAX_WORK: u8 = 31;
/// The highest tool coordinate system number.
pub const MAX_TOOL: u8 = 127;

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
    #[serde(deserialize_with = "super::teach_file::de_name")]
    pub name: String,
    /// Work X, Y, Z in 0.001 mm and R in 0.001 deg (wire units).
    #[serde(deserialize_with = "super::teach_file::de_pose")]
    pub pose: [i32; 4],
    /// The arm system the point was taught in (`right`, `left`, `undetermined` in files).
    #[serde(
        serialize_with = "super::teach_file::ser_arm",
        deserialize_with = "super::teach_file::de_arm"
    )]
    pub arm: ArmSystem,
    /// The work coordinate system number it was taught in (0-31).
    #[serde(deserialize_with = "super::teach_file::de_work")]
    pub work: u8,
    /// The tool coordinate system number it was taught in (0-127).
    #[serde(deserialize_with = "super::teach_file::de_tool")]
    pub tool: u8,
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
        check_frames(self.work, self.tool)?;
        Ok(self)
    }
}

/// Why the teach list refused an edit. The texts are written for the operator.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum TeachError {
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
    /// The work coordinate system number is above [`MAX_WORK`].
    #[error("work coordinate system {0} is out of range (0-31)")]
    WorkOutOfRange(u8),
    /// The tool coordinate system number is above [`MAX_TOOL`].
    #[error("tool coordinate system {0} is out of range (0-127)")]
    ToolOutOfRange(u8),
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
            TeachError::NoSuchPoint { .. } => None,
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
    if work > MAX_WORK {
        return Err(TeachError::WorkOutOfRange(work));
    }
    if tool > MAX_TOOL {
        return Err(TeachError::ToolOutOfRange(tool));
    }
    Ok(())
}

/// The ordered list of teach points. Names are unique (compared exactly, after trimming).
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(default)]
pub struct TeachList {
    #[serde(deserialize_with = "super::teach_file::de_points")]
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
        self.insert(self.points.len(), TeachPoint::new(name, at))
    }

    /// Inserts `point` at `index` (at most `len()`); returns the index. Same checks as
    /// [`TeachList::record`].
    pub fn insert(&mut self, index: usize, point: TeachPoint) -> Result<usize, TeachError> {
        if index > self.points.len() {
            return Err(self.no_such(index));
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
        (Axis::A1, Thou(x)),
        (Axis::A2, Thou(y)),
        (Axis::A3, Thou(z)),
        (Axis::A4, Thou(r)),
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
mod tests {
    use super::*;
    use crate::protocol::{CentiG, MmPerSec, Percent, ScMode, Station};

    fn at(x: i32, work: u8, tool: u8) -> TaughtPose {
        TaughtPose {
            pose: [x, -x, 20_000, 45_000],
            arm: ArmSystem::Right,
            work,
            tool,
        }
    }

    fn names(l: &TeachList) -> Vec<&str> {
        l.iter().map(|p| p.name.as_str()).collect()
    }

    fn abc() -> TeachList {
        let mut l = TeachList::new();
        for (i, n) in ["A", "B", "C"].into_iter().enumerate() {
            assert_eq!(l.record(n, at(i as i32, 0, 0)), Ok(i));
        }
        l
    }

    #[test]
    fn record_stores_the_pose_under_a_trimmed_name() {
        let mut l = TeachList::new();
        assert!(l.is_empty());
        let pose = TaughtPose {
            pose: [300_000, -150_000, 20_000, 45_000],
            arm: ArmSystem::Left,
            work: 3,
            tool: 2,
        };
        assert_eq!(l.record("  pick  ", pose), Ok(0));
        let p = l.get(0).unwrap();
        assert_eq!(p.name, "pick");
        assert_eq!(p.taught(), pose);
        assert_eq!(l.len(), 1);
        assert_eq!(l.position(" pick"), Some(0));
        assert!(l.get(1).is_none());
    }

    #[test]
    fn record_refuses_bad_names_and_frames_and_changes_nothing() {
        let mut l = abc();
        let before = l.clone();
        assert_eq!(l.record("   ", at(0, 0, 0)), Err(TeachError::EmptyName));
        let long = "x".repeat(33);
        assert_eq!(
            l.record(&long, at(0, 0, 0)),
            Err(TeachError::NameTooLong { chars: 33 })
        );
        assert!(l.record(&"é".repeat(32), at(0, 0, 0)).is_ok());
        l.remove(3).unwrap();
        assert_eq!(l.record("a\tb", at(0, 0, 0)), Err(TeachError::NameControl));
        assert_eq!(
            l.record("w", at(0, 32, 0)),
            Err(TeachError::WorkOutOfRange(32))
        );
        assert_eq!(
            l.record("t", at(0, 0, 128)),
            Err(TeachError::ToolOutOfRange(128))
        );
        assert!(l.record("edge", at(0, 31, 127)).is_ok());
        l.remove(3).unwrap();
        let dup = l.record(" B ", at(0, 0, 0)).unwrap_err();
        assert_eq!(
            dup,
            TeachError::DuplicateName {
                name: "B".into(),
                existing: 1,
                suggestion: "B1".into()
            }
        );
        assert_eq!(
            dup.to_string(),
            "the name \"B\" is already used by point 2; choose another, e.g. \"B1\""
        );
        assert_eq!(dup.field(), Some("name"));
        assert_eq!(l, before);
    }

    #[test]
    fn unique_name_counts_up_and_fits() {
        let mut l = TeachList::new();
        assert_eq!(l.unique_name("P"), "P1");
        l.record("P1", at(0, 0, 0)).unwrap();
        l.record("P3", at(0, 0, 0)).unwrap();
        assert_eq!(l.unique_name("P"), "P2");
        l.record("P2", at(0, 0, 0)).unwrap();
        assert_eq!(l.unique_name(" P "), "P4");
        assert_eq!(l.unique_name(""), "P4");
        assert_eq!(l.unique_name("\n"), "P4");
        assert_eq!(l.unique_name("a\nb"), "ab1");
        let base = "y".repeat(40);
        let n = l.unique_name(&base);
        assert_eq!(n.chars().count(), 32);
        assert!(n.ends_with('1'));
        assert!(l.record(&n, at(0, 0, 0)).is_ok());
    }

    #[test]
    fn rename_checks_like_record() {
        let mut l = abc();
        l.rename(1, " Bee ").unwrap();
        assert_eq!(names(&l), ["A", "Bee", "C"]);
        l.rename(1, "Bee").unwrap();
        assert!(matches!(
            l.rename(1, "A"),
            Err(TeachError::DuplicateName { existing: 0, .. })
        ));
        assert_eq!(l.rename(1, ""), Err(TeachError::EmptyName));
        assert_eq!(
            l.rename(3, "D"),
            Err(TeachError::NoSuchPoint { index: 3, len: 3 })
        );
        assert_eq!(names(&l), ["A", "Bee", "C"]);
    }

    #[test]
    fn reorder_and_remove() {
        let mut l = abc();
        assert_eq!(l.move_up(0), Ok(0));
        assert_eq!(l.move_down(2), Ok(2));
        assert_eq!(names(&l), ["A", "B", "C"]);
        assert_eq!(l.move_up(2), Ok(1));
        assert_eq!(names(&l), ["A", "C", "B"]);
        assert_eq!(l.move_down(0), Ok(1));
        assert_eq!(names(&l), ["C", "A", "B"]);
        assert!(l.move_up(3).is_err());
        assert!(l.move_down(3).is_err());
        assert_eq!(l.remove(1).unwrap().name, "A");
        assert_eq!(names(&l), ["C", "B"]);
        assert_eq!(
            l.remove(2),
            Err(TeachError::NoSuchPoint { index: 2, len: 2 })
        );
        assert_eq!(
            TeachError::NoSuchPoint { index: 2, len: 2 }.to_string(),
            "there is no point 3 (the list has 2)"
        );
        // The name of a removed point is free again.
        assert_eq!(l.record("A", at(0, 0, 0)), Ok(2));
    }

    #[test]
    fn insert_and_update() {
        let mut l = abc();
        let p = TeachPoint::new("Z", at(7, 1, 1));
        assert_eq!(l.insert(1, p.clone()), Ok(1));
        assert_eq!(names(&l), ["A", "Z", "B", "C"]);
        assert!(l.insert(9, TeachPoint::new("Y", at(0, 0, 0))).is_err());
        assert!(l.insert(0, p).is_err());
        l.update(1, at(99, 2, 3)).unwrap();
        assert_eq!(l.get(1).unwrap().name, "Z");
        assert_eq!(l.get(1).unwrap().taught(), at(99, 2, 3));
        assert_eq!(
            l.update(1, at(0, 40, 0)),
            Err(TeachError::WorkOutOfRange(40))
        );
        assert!(l.update(9, at(0, 0, 0)).is_err());
        assert_eq!(l.get(1).unwrap().taught(), at(99, 2, 3));
    }

    #[test]
    fn arm_words_and_policy() {
        for a in [ArmSystem::Right, ArmSystem::Left, ArmSystem::Undetermined] {
            assert_eq!(parse_arm_word(arm_word(a)), Some(a));
            assert_eq!(
                parse_arm_word(&format!(" {} ", arm_word(a).to_uppercase())),
                Some(a)
            );
        }
        assert_eq!(parse_arm_word("r"), None);
        let mut p = TeachPoint::new("p", at(0, 0, 0));
        assert_eq!(p.arm_policy(), ArmPolicy::Right);
        p.arm = ArmSystem::Left;
        assert_eq!(p.arm_policy(), ArmPolicy::Left);
        p.arm = ArmSystem::Undetermined;
        assert_eq!(p.arm_policy(), ArmPolicy::KeepNoSwitch);
    }

    /// A hand-built frame: the SC summed here, independently of the codec.
    fn frame(body: &str) -> String {
        let sc = body.bytes().fold(0u8, u8::wrapping_add);
        format!("{body}{sc:02X}\r\n")
    }

    fn encoded(c: &Command) -> String {
        let mut buf = Vec::new();
        c.encode_into(Station::DEFAULT, ScMode::Computed, &mut buf)
            .unwrap();
        String::from_utf8(buf).unwrap()
    }

    #[test]
    fn go_encodes_the_2d4h_example_of_protocol_3_19() {
        let p = TeachPoint::new(
            "P1",
            TaughtPose {
                pose: [300_000, -150_000, 20_000, 45_000],
                arm: ArmSystem::Right,
                work: 0,
                tool: 0,
            },
        );
        let ptp = ScaraMotion::Ptp {
            acc: Percent(0),
            dec: Percent(0),
            speed: Percent(30),
            arm: ArmPolicy::KeepNoSwitch,
        };
        let expected = "!992D40F00000000001E02000493E0FFFDB61000004E200000AFC85C\r\n";
        assert_eq!(encoded(&go_command(&p, ptp)), expected);
        // The hand-built frame's SC is the byte sum of everything before it.
        assert_eq!(
            frame("!992D40F00000000001E02000493E0FFFDB61000004E200000AFC8"),
            expected
        );
    }

    #[test]
    fn go_encodes_cp_and_arm_policy_and_extreme_positions() {
        let mut p = TeachPoint::new(
            "edge",
            TaughtPose {
                pose: [i32::MIN, i32::MAX, -1, 0],
                arm: ArmSystem::Left,
                work: 5,
                tool: 1,
            },
        );
        let cp = ScaraMotion::Cp {
            acc: CentiG(30),
            dec: CentiG(20),
            speed: MmPerSec(100),
        };
        assert_eq!(
            encoded(&go_command(&p, cp)),
            frame("!992D40F001E0014006403800000007FFFFFFFFFFFFFFF00000000")
        );
        let ptp = ScaraMotion::Ptp {
            acc: Percent(50),
            dec: Percent(50),
            speed: Percent(100),
            arm: p.arm_policy(),
        };
        p.pose = [1, 2, 3, 4];
        // Left arm policy = 3 in bits 3-4: 0b11010 = 1A.
        assert_eq!(
            encoded(&go_command(&p, ptp)),
            frame("!992D40F0032003200641A00000001000000020000000300000004")
        );
    }

    #[test]
    fn check_go_refuses_another_frame_and_names_both() {
        let p = TeachPoint::new("pick", at(0, 2, 1));
        assert_eq!(check_go(&p, 2, 1), Ok(()));
        let e = check_go(&p, 0, 1).unwrap_err();
        assert_eq!(
            e.to_string(),
            "\"pick\" was taught in work frame 2 but work frame 0 is selected now; \
             select work frame 2 to go there"
        );
        assert_eq!(e.selected_work, 0);
        let e = check_go(&p, 2, 3).unwrap_err();
        assert_eq!(
            e.to_string(),
            "\"pick\" was taught in tool frame 1 but tool frame 3 is selected now; \
             select tool frame 1 to go there"
        );
        let e = check_go(&p, 4, 0).unwrap_err();
        assert_eq!(
            e.to_string(),
            "\"pick\" was taught in work frame 2 / tool frame 1 but work frame 4 / tool frame 0 \
             is selected now; select work frame 2 and tool frame 1 to go there"
        );
    }
}
