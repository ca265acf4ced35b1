//! What the pendant knows of the controller: the latest status of each kind with its
//! time, the positions in work, base and joint coordinates, and the coordinate tables.

pub mod readiness;
pub(super) mod transitions;

use std::time::{Duration, Instant};

use crate::protocol::{
    Axis, AxisPattern, AxisState, Command, CoordKind, Milli, PerAxis, PositionSystem, ScaraStatus,
    ScaraStatusQuery, SystemStatus, VersionInfo, VersionQuery,
};
use crate::robot::{CoordSystem, Joints, Pose};

/// A status older than this is shown as stale and blocks motion.
pub const STALE_AFTER: Duration = Duration::from_millis(1500);

/// A value with the time it was read.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stamped<T> {
    pub value: T,
    pub at: Instant,
}

impl<T> Stamped<T> {
    pub fn is_stale(&self, now: Instant) -> bool {
        now.saturating_duration_since(self.at) > STALE_AFTER
    }
}

/// One coordinate table as read with 2A4H: `None` marks a record that could not be read
/// (never shown as zeros).
#[derive(Clone, Debug, PartialEq)]
pub struct ReadTable {
    pub records: Vec<Option<CoordSystem>>,
    pub at: Instant,
}

/// The latest of everything polled or read from the controller.
#[derive(Clone, Debug, Default)]
pub struct ControllerState {
    pub version: Option<VersionInfo>,
    pub system: Option<Stamped<SystemStatus>>,
    /// 2A1H in the selected work frame: also work and tool numbers, arm system, axes.
    pub work: Option<Stamped<ScaraStatus>>,
    /// 2A1H in the base frame.
    pub base: Option<Stamped<ScaraStatus>>,
    /// 2A1H in the each-axis (joint) system.
    pub joints: Option<Stamped<ScaraStatus>>,
    pub work_table: Option<ReadTable>,
    pub tool_table: Option<ReadTable>,
}

/// The status reads that make one poll cycle: positions in all three systems and the
/// system status.
pub fn poll_commands() -> Vec<Command> {
    let scara = |system| {
        Command::ScaraStatus(ScaraStatusQuery {
            axes: AxisPattern::SCARA_1,
            system,
        })
    };
    vec![
        scara(PositionSystem::Work),
        Command::SystemStatus,
        scara(PositionSystem::Joint),
        scara(PositionSystem::Base),
    ]
}

/// The version query sent once per connection.
pub fn version_query() -> Command {
    Command::Version(VersionQuery::default())
}

/// The four SCARA axes' positions as `[x|j1, y|j2, z, r|j4]` in mm and deg.
fn four(s: &ScaraStatus) -> Option<[f64; 4]> {
    let mut out = [0.0; 4];
    for (i, slot) in out.iter_mut().enumerate() {
        let axis = Axis::from_index(i as u8)?;
        *slot = s.axes.get(axis)?.position.units();
    }
    Some(out)
}

impl ControllerState {
    /// Forgets everything read on a line that is gone; the tables survive (they are
    /// shown with the time they were read).
    pub fn line_lost(&mut self) {
        self.version = None;
        self.system = None;
        self.work = None;
        self.base = None;
        self.joints = None;
    }

    /// Files a status reply under its kind.
    pub fn scara_status(&mut self, s: ScaraStatus, at: Instant) {
        let slot = match s.common.system {
            PositionSystem::Work => &mut self.work,
            PositionSystem::Base => &mut self.base,
            PositionSystem::Joint => &mut self.joints,
        };
        *slot = Some(Stamped { value: s, at });
    }

    /// Files a table download of `size` definitions; `records[i]` is definition
    /// `first + i`, `None` where it could not be read. A whole table (from record 0, at
    /// least `size` records) replaces the one held; a partial read (a retry, which may
    /// start at record 0) fills in the records it got.
    pub fn table(
        &mut self,
        kind: CoordKind,
        first: u16,
        size: usize,
        records: &[Option<PerAxis<Milli>>],
        at: Instant,
    ) {
        let read: Vec<Option<CoordSystem>> = records
            .iter()
            .map(|r| {
                r.map(|axes| {
                    let v = |i: u8| {
                        Axis::from_index(i)
                            .and_then(|a| axes.get(a))
                            .map_or(0, |t| t.0)
                    };
                    CoordSystem::from_wire([v(0), v(1), v(2), v(3)])
                })
            })
            .collect();
        let slot = match kind {
            CoordKind::Work => &mut self.work_table,
            CoordKind::Tool => &mut self.tool_table,
        };
        let first = usize::from(first);
        // A read of the whole table replaces what was held (records it missed show as
        // unread); a read of part of it (a retry, which may start at record 0) fills in
        // the records it got and keeps the rest.
        let whole = first == 0 && read.len() >= size;
        let records = match slot.take() {
            _ if whole => read,
            Some(mut held) => {
                if held.records.len() < first + read.len() {
                    held.records.resize(first + read.len(), None);
                }
                for (i, r) in read.into_iter().enumerate() {
                    if r.is_some() {
                        held.records[first + i] = r;
                    }
                }
                held.records
            }
            None => {
                let mut all = vec![None; size.max(first + read.len())];
                for (i, r) in read.into_iter().enumerate() {
                    all[first + i] = r;
                }
                all
            }
        };
        *slot = Some(ReadTable { records, at });
    }

    /// The oldest time among the statuses motion depends on, or `None` if one is missing.
    pub fn oldest_status(&self) -> Option<Instant> {
        let times = [
            self.system.as_ref().map(|s| s.at),
            self.work.as_ref().map(|s| s.at),
            self.joints.as_ref().map(|s| s.at),
        ];
        times.into_iter().try_fold(None::<Instant>, |oldest, t| {
            let t = t?;
            Some(Some(oldest.map_or(t, |o| o.min(t))))
        })?
    }

    /// Whether any status motion depends on is missing or older than [`STALE_AFTER`].
    pub fn is_stale(&self, now: Instant) -> bool {
        self.oldest_status()
            .is_none_or(|t| now.saturating_duration_since(t) > STALE_AFTER)
    }

    /// The joint angles (deg) and Z (mm).
    pub fn joint_position(&self) -> Option<Joints> {
        let [j1, j2, z, j4] = four(&self.joints.as_ref()?.value)?;
        Some(Joints::new(j1, j2, z, j4))
    }

    /// The tool tip in the selected work frame.
    pub fn work_position(&self) -> Option<Pose> {
        let [x, y, z, r] = four(&self.work.as_ref()?.value)?;
        Some(Pose::new(x, y, z, r))
    }

    /// The tool tip in the base frame.
    pub fn base_position(&self) -> Option<Pose> {
        let [x, y, z, r] = four(&self.base.as_ref()?.value)?;
        Some(Pose::new(x, y, z, r))
    }

    /// Work and base positions of one sample, as the readouts show them: the work
    /// position of the latest 2A1H in the work system, and its base position through the
    /// selected work frame (so work No. 0 reads the same in both), each to 0.001. The
    /// polled base-system 2A1H, a poll apart, is used only until the work table is read.
    pub fn sample(&self) -> Option<(Pose, Pose)> {
        let work = self.work_position()?;
        let base = match self.work_frame() {
            Some(frame) => round_pose(frame.work_to_base(&work)),
            None => self.base_position()?,
        };
        Some((work, base))
    }

    /// The selected work and tool numbers (from 2A1H).
    pub fn frame_numbers(&self) -> Option<(u8, u8)> {
        let s = &self.work.as_ref()?.value;
        Some((s.work, s.tool))
    }

    /// The selected work frame's definition, once the work table is read.
    pub fn work_frame(&self) -> Option<CoordSystem> {
        let (work, _) = self.frame_numbers()?;
        let table = self.work_table.as_ref()?;
        *table.records.get(usize::from(work))?
    }

    /// Work frame `n`'s definition, once the work table is read.
    pub fn work_frame_of(&self, n: u8) -> Option<CoordSystem> {
        *self.work_table.as_ref()?.records.get(usize::from(n))?
    }

    /// The selected tool's definition, once the tool table is read.
    pub fn tool_frame(&self) -> Option<CoordSystem> {
        let (_, tool) = self.frame_numbers()?;
        let table = self.tool_table.as_ref()?;
        *table.records.get(usize::from(tool))?
    }

    /// Every SCARA axis block of the latest 2A1H (any system: the status bits are the same).
    pub fn axes(&self) -> Option<&PerAxis<AxisState>> {
        self.work
            .as_ref()
            .or(self.joints.as_ref())
            .map(|s| &s.value.axes)
    }
}

/// Every coordinate to the wire's 0.001.
fn round_pose(p: Pose) -> Pose {
    let r = |v: f64| (v * 1000.0).round() / 1000.0;
    Pose::new(r(p.x), r(p.y), r(p.z), r(p.r))
}
