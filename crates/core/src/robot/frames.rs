//! Work and tool coordinate systems, their tables, and conversions between the frames.
//!
//! A work coordinate system is an offset (X, Y, Z) of its origin in the base frame and a
//! rotation R about Z: a point's base coordinates are the work coordinates rotated by R,
//! then translated by (X, Y, Z); base R = work R + offset R. A tool coordinate system is
//! the tool tip's offset in the flange frame (which turns with Cartesian R): tip XY =
//! flange XY + rotate(flange R)(tool X, tool Y), tip Z = flange Z + tool Z, tip R = flange
//! R + tool R. PROTOCOL.md 3.15/3.16 give only the record fields (X, Y, Z, R offsets);
//! the order "translate then rotate about Z" and the sign of the Z offset are `[inferred]`.
//!
//! Conversions work in f64 and round only at the wire edge ([`CoordSystem::to_wire`],
//! [`Pose::to_wire`]), so base -> work -> base returns the same wire integers. A rotation
//! is not a bijection on the 1 µm grid: rounding the work coordinates in between (as a
//! 2D4H target must be) can move the point back by up to 1 µm.

use nalgebra::{Isometry2, Point2, Vector2};
use thiserror::Error;

use super::kinematics::{Arm, IkError, Scara};
use super::model::RobotModel;
use super::units::{Joints, Micrometres, Millidegrees, Pose, round_wire};

/// One work or tool coordinate system definition, in wire units.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct CoordSystem {
    pub x: Micrometres,
    pub y: Micrometres,
    pub z: Micrometres,
    pub r: Millidegrees,
}

impl CoordSystem {
    /// All zeros: the base frame (work No. 0), or no tool offset.
    pub const ZERO: CoordSystem = CoordSystem {
        x: Micrometres(0),
        y: Micrometres(0),
        z: Micrometres(0),
        r: Millidegrees(0),
    };

    /// From wire integers `[x µm, y µm, z µm, r mdeg]` (a 2A0H/2A4H record).
    pub fn from_wire(w: [i32; 4]) -> Self {
        CoordSystem {
            x: Micrometres(w[0]),
            y: Micrometres(w[1]),
            z: Micrometres(w[2]),
            r: Millidegrees(w[3]),
        }
    }

    /// To wire integers `[x µm, y µm, z µm, r mdeg]`.
    pub fn to_wire(&self) -> [i32; 4] {
        [self.x.0, self.y.0, self.z.0, self.r.0]
    }

    /// The offsets in mm and deg.
    pub fn offset(&self) -> Pose {
        Pose::from_wire(self.to_wire())
    }

    fn isometry(&self) -> Isometry2<f64> {
        let o = self.offset();
        Isometry2::new(Vector2::new(o.x, o.y), o.r.to_radians())
    }

    /// A base-frame pose expressed in this work frame.
    pub fn base_to_work(&self, p: &Pose) -> Pose {
        let o = self.offset();
        let q = self
            .isometry()
            .inverse_transform_point(&Point2::new(p.x, p.y));
        Pose::new(q.x, q.y, p.z - o.z, p.r - o.r)
    }

    /// A pose in this work frame expressed in the base frame.
    pub fn work_to_base(&self, p: &Pose) -> Pose {
        let o = self.offset();
        let q = self.isometry().transform_point(&Point2::new(p.x, p.y));
        Pose::new(q.x, q.y, p.z + o.z, p.r + o.r)
    }

    /// With this as the tool: the tool tip pose of a flange pose (both in one frame).
    pub fn flange_to_tip(&self, flange: &Pose) -> Pose {
        let t = self.offset();
        let (s, c) = flange.r.to_radians().sin_cos();
        Pose::new(
            flange.x + c * t.x - s * t.y,
            flange.y + s * t.x + c * t.y,
            flange.z + t.z,
            flange.r + t.r,
        )
    }

    /// With this as the tool: the flange pose that puts the tool tip at `tip`.
    pub fn tip_to_flange(&self, tip: &Pose) -> Pose {
        let t = self.offset();
        let r = tip.r - t.r;
        let (s, c) = r.to_radians().sin_cos();
        Pose::new(
            tip.x - (c * t.x - s * t.y),
            tip.y - (s * t.x + c * t.y),
            tip.z - t.z,
            r,
        )
    }
}

/// Work or tool.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum FrameKind {
    Work,
    Tool,
}

impl std::fmt::Display for FrameKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            FrameKind::Work => "work",
            FrameKind::Tool => "tool",
        })
    }
}

/// Why a table edit was refused.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum FrameError {
    #[error("there is no {kind} coordinate system No. {number} (the table has 0 to {})", .size.saturating_sub(1))]
    NoSuchNumber {
        kind: FrameKind,
        number: usize,
        size: usize,
    },
    #[error("work coordinate system No. 0 is the base frame and stays all zeros")]
    WorkZeroIsBase,
}

/// A table of work or tool coordinate systems, numbered from 0.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CoordTable {
    kind: FrameKind,
    entries: Vec<CoordSystem>,
}

impl CoordTable {
    /// `size` all-zero entries (at least one, No. 0).
    pub fn new(kind: FrameKind, size: usize) -> Self {
        CoordTable {
            kind,
            entries: vec![CoordSystem::ZERO; size.max(1)],
        }
    }
    pub fn kind(&self) -> FrameKind {
        self.kind
    }
    pub fn len(&self) -> usize {
        self.entries.len()
    }
    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }
    pub fn get(&self, number: usize) -> Option<&CoordSystem> {
        self.entries.get(number)
    }
    pub fn entries(&self) -> &[CoordSystem] {
        &self.entries
    }
    /// Sets one entry. Work No. 0 accepts only zeros.
    pub fn set(&mut self, number: usize, cs: CoordSystem) -> Result<(), FrameError> {
        if self.kind == FrameKind::Work && number == 0 && cs != CoordSystem::ZERO {
            return Err(FrameError::WorkZeroIsBase);
        }
        let size = self.entries.len();
        let kind = self.kind;
        let slot = self
            .entries
            .get_mut(number)
            .ok_or(FrameError::NoSuchNumber { kind, number, size })?;
        *slot = cs;
        Ok(())
    }
}

/// The work and tool tables of one robot, sized from its model.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CoordTables {
    pub work: CoordTable,
    pub tool: CoordTable,
}

impl CoordTables {
    pub fn for_model(model: &RobotModel) -> Self {
        CoordTables {
            work: CoordTable::new(FrameKind::Work, model.work_table_size),
            tool: CoordTable::new(FrameKind::Tool, model.tool_table_size),
        }
    }
}

/// The frame a jog step is given in (236H bits 1-2, without the each-axis system).
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Hash, Default, serde::Serialize, serde::Deserialize,
)]
pub enum JogFrame {
    Base,
    #[default]
    Work,
    Tool,
}

impl JogFrame {
    pub const ALL: [JogFrame; 3] = [JogFrame::Work, JogFrame::Base, JogFrame::Tool];

    /// "work", "base", "tool".
    pub fn name(self) -> &'static str {
        match self {
            JogFrame::Work => "work",
            JogFrame::Base => "base",
            JogFrame::Tool => "tool",
        }
    }
}

/// A jog step given in `frame` as the same motion of the tool tip in the selected work
/// frame, for 2D5H (which moves in the work frame only). `delta` holds the translation
/// (mm) and the rotation (deg); only the translation turns, R and Z pass through.
/// `flange_r_deg` is the current Cartesian R of the flange in the base frame; the tool
/// frame's X axis points along `flange_r_deg + tool R` in the base frame.
pub fn jog_delta_to_work(
    delta: &Pose,
    frame: JogFrame,
    work: &CoordSystem,
    tool: &CoordSystem,
    flange_r_deg: f64,
) -> Pose {
    let work_r = work.r.deg();
    let turn = match frame {
        JogFrame::Work => return *delta,
        JogFrame::Base => -work_r,
        JogFrame::Tool => flange_r_deg + tool.r.deg() - work_r,
    };
    let (s, c) = turn.to_radians().sin_cos();
    Pose::new(
        c * delta.x - s * delta.y,
        s * delta.x + c * delta.y,
        delta.z,
        delta.r,
    )
}

/// [`jog_delta_to_work`] on wire integers `[x µm, y µm, z µm, r mdeg]`, rounded once.
pub fn jog_delta_to_work_wire(
    delta: [i32; 4],
    frame: JogFrame,
    work: &CoordSystem,
    tool: &CoordSystem,
    flange_r_deg: f64,
) -> [i32; 4] {
    jog_delta_to_work(&Pose::from_wire(delta), frame, work, tool, flange_r_deg).to_wire()
}

/// The tool tip pose, in the work frame, of a joint pose.
pub fn tip_in_work(k: &Scara, j: &Joints, work: &CoordSystem, tool: &CoordSystem) -> Pose {
    work.base_to_work(&tool.flange_to_tip(&k.forward(j)))
}

/// The joints putting the tool tip at `tip` given in the work frame.
pub fn inverse_in_work(
    k: &Scara,
    tip: &Pose,
    work: &CoordSystem,
    tool: &CoordSystem,
    arm: Arm,
    near: &Joints,
) -> Result<Joints, IkError> {
    k.inverse(&tool.tip_to_flange(&work.work_to_base(tip)), arm, near)
}

/// Rounds a pose to the wire and back: what survives a trip through the protocol.
pub fn snap_to_wire(p: &Pose) -> Pose {
    Pose::from_wire([p.x, p.y, p.z, p.r].map(|v| round_wire(v * 1000.0)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn work_zero_is_base_and_sizes_come_from_the_model() {
        let m = RobotModel::default_model();
        let mut t = CoordTables::for_model(&m);
        assert_eq!((t.work.len(), t.tool.len()), (32, 128));
        let cs = CoordSystem::from_wire([1, 2, 3, 4]);
        assert_eq!(t.work.set(0, cs), Err(FrameError::WorkZeroIsBase));
        assert!(t.work.set(0, CoordSystem::ZERO).is_ok());
        assert!(t.work.set(31, cs).is_ok());
        assert!(matches!(
            t.work.set(32, cs),
            Err(FrameError::NoSuchNumber { number: 32, .. })
        ));
        assert!(t.tool.set(0, cs).is_ok());
    }

    #[test]
    fn work_frame_translates_then_rotates() {
        // Origin at (100, -50, 10), turned 90°: work +X is base +Y.
        let w = CoordSystem::from_wire([100_000, -50_000, 10_000, 90_000]);
        let b = w.work_to_base(&Pose::new(10.0, 0.0, 5.0, 0.0));
        assert!((b.x - 100.0).abs() < 1e-9 && (b.y + 40.0).abs() < 1e-9);
        assert_eq!((b.z, b.r), (15.0, 90.0));
        assert_eq!(w.base_to_work(&b).to_wire(), [10_000, 0, 5_000, 0]);
    }

    #[test]
    fn tool_tip_turns_with_the_flange() {
        let t = CoordSystem::from_wire([50_000, 0, 35_000, 10_000]);
        let f = Pose::new(300.0, 0.0, 20.0, 90.0);
        let tip = t.flange_to_tip(&f);
        assert_eq!(tip.to_wire(), [300_000, 50_000, 55_000, 100_000]);
        assert_eq!(t.tip_to_flange(&tip).to_wire(), f.to_wire());
    }
}
