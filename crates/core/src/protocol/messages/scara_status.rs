//! 2A1H and 2A3H SCARA axis status: queries, common status and arm-system codes.

use crate::protocol::arm::ArmSystem;
use crate::protocol::axis::{Axis, AxisPattern, PerAxis};
use crate::protocol::error::{EncodeError, MessageError};
use crate::protocol::fields::{BitDef, Name, Reader, Show};
use crate::protocol::units::AxisUnit;
use crate::protocol::writer::Writer;

use super::status::{AxisState, read_axis_blocks, write_axis_blocks};

/// Coordinate system of the positions a SCARA status reply reports (2A1H/2A3H type field,
/// and bits 2-3 of the common status). Code 2 is reserved.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum PositionSystem {
    /// 0: base coordinate system.
    #[default]
    Base,
    /// 1: the selected work coordinate system.
    Work,
    /// 3: each-axis (joint) system.
    Joint,
}

impl PositionSystem {
    /// From the 2-bit code.
    pub const fn from_code(c: u8) -> Option<PositionSystem> {
        match c {
            0 => Some(PositionSystem::Base),
            1 => Some(PositionSystem::Work),
            3 => Some(PositionSystem::Joint),
            _ => None,
        }
    }

    /// The 2-bit code.
    pub const fn code(self) -> u8 {
        match self {
            PositionSystem::Base => 0,
            PositionSystem::Work => 1,
            PositionSystem::Joint => 3,
        }
    }

    /// Unit of a SCARA axis's position in this system: joints 1, 2 and R in deg and Z in mm
    /// for the joint system; R in deg, X/Y/Z in mm otherwise.
    /// [inferred] PROTOCOL.md 3.17 (units of the joint system).
    pub const fn unit_of(self, axis: Axis) -> AxisUnit {
        let rotary = match self {
            PositionSystem::Joint => axis.is_scara_rotary_joint(),
            _ => axis.is_scara_r(),
        };
        if rotary { AxisUnit::Deg } else { AxisUnit::Mm }
    }
}

const SYSTEM_CODES: &[(u32, &str)] = &[
    (0, "base coordinates"),
    (1, "selected work coordinates"),
    (3, "each-axis (joint) system"),
];

/// The common axis status of a SCARA unit, decoded per message.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct CommonStatus {
    /// Current arm system.
    pub arm: ArmSystem,
    /// Coordinate system of the reported positions.
    pub system: PositionSystem,
}

impl Default for CommonStatus {
    fn default() -> Self {
        CommonStatus {
            arm: ArmSystem::Right,
            system: PositionSystem::Base,
        }
    }
}

const COMMON_2A1: &[BitDef] = &[
    BitDef {
        lo: 0,
        width: 2,
        name: "current arm",
        values: &[(0, "right"), (1, "left"), (2, "undetermined")],
    },
    BitDef {
        lo: 2,
        width: 2,
        name: "position coordinate system",
        values: SYSTEM_CODES,
    },
];

const COMMON_2A3: &[BitDef] = &[
    BitDef {
        lo: 0,
        width: 2,
        name: "current arm",
        values: &[(0, "undetermined"), (1, "right"), (2, "left")],
    },
    BitDef {
        lo: 2,
        width: 2,
        name: "position coordinate system",
        values: SYSTEM_CODES,
    },
];

/// Which message's arm code table applies (PROTOCOL.md section 5, erratum 4).
#[derive(Clone, Copy)]
enum ArmTable {
    A1,
    A3,
}

/// Reads a common status byte of a reply. A reserved arm code (3) reads as
/// undetermined rather than failing the whole status reply. A reserved coordinate-system
/// code (2) fails it, since the positions could not be read, unless `inferred_field`
/// (2A3H's second-unit fields, whose place is [inferred] PROTOCOL.md 3.18): those must
/// never cost the pendant its status poll, and read as base.
fn read_common(
    r: &mut Reader<'_, '_>,
    name: &'static str,
    t: ArmTable,
    inferred_field: bool,
) -> Result<CommonStatus, MessageError> {
    let bits = match t {
        ArmTable::A1 => COMMON_2A1,
        ArmTable::A3 => COMMON_2A3,
    };
    // Bits 4-7 are reserved: ignored in replies.
    let v = r.u8(Name::new(name), 2, Show::Bits(bits))?;
    let arm = match t {
        ArmTable::A1 => ArmSystem::from_2a1(v & 3),
        ArmTable::A3 => ArmSystem::from_2a3(v & 3),
    }
    .unwrap_or(ArmSystem::Undetermined);
    let system = match PositionSystem::from_code((v >> 2) & 3) {
        Some(system) => system,
        None if inferred_field => PositionSystem::Base,
        None => return Err(r.invalid("coordinate system (bits 2-3) 0, 1 or 3; 2 is reserved")),
    };
    Ok(CommonStatus { arm, system })
}

fn write_common(w: &mut Writer<'_>, c: CommonStatus, t: ArmTable) {
    let arm = match t {
        ArmTable::A1 => c.arm.to_2a1(),
        ArmTable::A3 => c.arm.to_2a3(),
    };
    w.hex_fit(u32::from(arm | (c.system.code() << 2)), 2);
}

/// 2A1H command: SCARA axis status query.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct ScaraStatusQuery {
    /// Axes to report.
    pub axes: AxisPattern,
    /// Coordinate system of the reported positions.
    pub system: PositionSystem,
}

impl ScaraStatusQuery {
    pub(crate) fn read(r: &mut Reader<'_, '_>) -> Result<Self, MessageError> {
        let axes = r.pattern("query axis pattern")?;
        let t = r.u8(Name::new("type"), 1, Show::Code(SYSTEM_CODES))?;
        let system = PositionSystem::from_code(t).ok_or_else(|| {
            r.invalid("0 (base), 1 (work) or 3 (each-axis); 2 and bits 2-3 are reserved")
        })?;
        Ok(ScaraStatusQuery { axes, system })
    }

    pub(crate) fn write(&self, w: &mut Writer<'_>) -> Result<(), EncodeError> {
        w.hex_fit(u32::from(self.axes.0), 2);
        w.hex_fit(u32::from(self.system.code()), 1);
        Ok(())
    }
}

/// 2A1H reply: selected work/tool numbers, common status and per-axis blocks.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct ScaraStatus {
    /// Selected work coordinate system number.
    pub work: u8,
    /// Selected tool coordinate system number.
    pub tool: u8,
    /// Current arm (2A1H codes) and position coordinate system.
    pub common: CommonStatus,
    /// Per-axis blocks (the reply's axis pattern is their pattern).
    pub axes: PerAxis<AxisState>,
}

impl ScaraStatus {
    pub(crate) fn read(r: &mut Reader<'_, '_>) -> Result<Self, MessageError> {
        let work = r.u8(
            Name::new("selected work coordinate system"),
            2,
            Show::Number,
        )?;
        let tool = r.u8(
            Name::new("selected tool coordinate system"),
            2,
            Show::Number,
        )?;
        let common = read_common(r, "common axis status", ArmTable::A1, false)?;
        let pattern = r.pattern("axis pattern")?;
        // [inferred] PROTOCOL.md 3.17: per-axis block as in 212H (page cut).
        let axes = read_axis_blocks(r, pattern, |a| common.system.unit_of(a))?;
        Ok(ScaraStatus {
            work,
            tool,
            common,
            axes,
        })
    }

    pub(crate) fn write(&self, w: &mut Writer<'_>) -> Result<(), EncodeError> {
        w.hex_fit(u32::from(self.work), 2);
        w.hex_fit(u32::from(self.tool), 2);
        write_common(w, self.common, ArmTable::A1);
        write_axis_blocks(w, &self.axes)
    }
}

/// 2A3H command: SCARA axis status query 2 (two SCARA units).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct ScaraStatusQuery2 {
    /// Axes to report.
    pub axes: AxisPattern,
    /// Position coordinate system for SCARA axes 1-4.
    pub system_1_4: PositionSystem,
    /// Position coordinate system for SCARA axes 5-8.
    pub system_5_8: PositionSystem,
}

const TYPE_2A3: &[BitDef] = &[
    BitDef {
        lo: 0,
        width: 2,
        name: "coordinate system, axes 1-4",
        values: SYSTEM_CODES,
    },
    BitDef {
        lo: 4,
        width: 2,
        name: "coordinate system, axes 5-8",
        values: SYSTEM_CODES,
    },
];

impl ScaraStatusQuery2 {
    pub(crate) fn read(r: &mut Reader<'_, '_>) -> Result<Self, MessageError> {
        let axes = r.pattern("query axis pattern")?;
        // PROTOCOL.md section 5 erratum 2: the type is 2 hex digits.
        let t = r.u8(Name::new("type"), 2, Show::Bits(TYPE_2A3))?;
        let sys = |c| PositionSystem::from_code(c);
        match (t & 0xCC, sys(t & 3), sys((t >> 4) & 3)) {
            (0, Some(system_1_4), Some(system_5_8)) => Ok(ScaraStatusQuery2 {
                axes,
                system_1_4,
                system_5_8,
            }),
            _ => Err(r.invalid(
                "bits 0-1 and 4-5 each 0 (base), 1 (work) or 3 (each-axis); bits 2-3 and 6-7 reserved (0)",
            )),
        }
    }

    pub(crate) fn write(&self, w: &mut Writer<'_>) -> Result<(), EncodeError> {
        w.hex_fit(u32::from(self.axes.0), 2);
        w.hex_fit(
            u32::from(self.system_1_4.code() | (self.system_5_8.code() << 4)),
            2,
        );
        Ok(())
    }
}

/// Work/tool selection and common status of one SCARA unit in a 2A3H reply.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct ScaraUnitStatus {
    /// Selected work coordinate system number.
    pub work: u8,
    /// Selected tool coordinate system number.
    pub tool: u8,
    /// Current arm (2A3H codes) and position coordinate system.
    pub common: CommonStatus,
}

/// 2A3H reply (PROTOCOL.md 3.18).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct ScaraStatus2 {
    /// SCARA axes among the reported ones.
    pub scara_axes: AxisPattern,
    /// SCARA unit 1 (axes 1-4).
    pub unit1: ScaraUnitStatus,
    /// SCARA unit 2 (axes 5-8). [inferred] PROTOCOL.md 3.18: tool number and common
    /// status of unit 2 at columns 17-20.
    pub unit2: ScaraUnitStatus,
    /// Per-axis blocks of all reported axes.
    pub axes: PerAxis<AxisState>,
}

impl ScaraStatus2 {
    pub(crate) fn read(r: &mut Reader<'_, '_>) -> Result<Self, MessageError> {
        let scara_axes = r.pattern("SCARA axis pattern")?;
        let work1 = r.u8(
            Name::new("work coordinate system (axes 1-4)"),
            2,
            Show::Number,
        )?;
        let tool1 = r.u8(
            Name::new("tool coordinate system (axes 1-4)"),
            2,
            Show::Number,
        )?;
        let common1 = read_common(r, "common status (axes 1-4)", ArmTable::A3, false)?;
        let work2 = r.u8(
            Name::new("work coordinate system (axes 5-8)"),
            2,
            Show::Number,
        )?;
        let tool2 = r.u8(
            Name::new("tool coordinate system (axes 5-8)"),
            2,
            Show::Number,
        )?;
        let common2 = read_common(r, "common status (axes 5-8)", ArmTable::A3, true)?;
        let pattern = r.pattern("axis pattern")?;
        // [inferred] PROTOCOL.md 3.18: per-axis block as in 212H.
        let axes = read_axis_blocks(r, pattern, |a| {
            if a.index() < 4 {
                common1.system.unit_of(a)
            } else {
                common2.system.unit_of(a)
            }
        })?;
        Ok(ScaraStatus2 {
            scara_axes,
            unit1: ScaraUnitStatus {
                work: work1,
                tool: tool1,
                common: common1,
            },
            unit2: ScaraUnitStatus {
                work: work2,
                tool: tool2,
                common: common2,
            },
            axes,
        })
    }

    pub(crate) fn write(&self, w: &mut Writer<'_>) -> Result<(), EncodeError> {
        w.hex_fit(u32::from(self.scara_axes.0), 2);
        for u in [self.unit1, self.unit2] {
            w.hex_fit(u32::from(u.work), 2);
            w.hex_fit(u32::from(u.tool), 2);
            write_common(w, u.common, ArmTable::A3);
        }
        write_axis_blocks(w, &self.axes)
    }
}
