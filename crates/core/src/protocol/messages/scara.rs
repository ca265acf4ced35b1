//! SCARA moves: 2D4H absolute, 2D5H relative, 2D6H position number; PTP vs CP rates.

use crate::protocol::arm::ArmPolicy;
use crate::protocol::axis::{Axis, AxisPattern, PerAxis};
use crate::protocol::error::{EncodeError, MessageError};
use crate::protocol::fields::{BitDef, Name, Reader, Show};
use crate::protocol::units::{AxisUnit, CentiG, Milli, MmPerSec, Percent};
use crate::protocol::writer::Writer;

/// Motion control of a SCARA move, with its rates in the units that mode uses
/// (PROTOCOL.md 3.20: % for PTP, 0.01 G and mm/s for CP). 0 = parameter value (2D6H: the
/// position record's value, then the parameter).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ScaraMotion {
    /// Point to point (bit 0 = 0).
    Ptp {
        /// Acceleration, %.
        acc: Percent,
        /// Deceleration, %.
        dec: Percent,
        /// Speed, %.
        speed: Percent,
        /// Target arm policy (bits 3-4).
        arm: ArmPolicy,
    },
    /// Continuous path, straight line (bit 0 = 1); keeps the current arm.
    Cp {
        /// Acceleration.
        acc: CentiG,
        /// Deceleration.
        dec: CentiG,
        /// Speed.
        speed: MmPerSec,
    },
}

impl Default for ScaraMotion {
    fn default() -> Self {
        ScaraMotion::Ptp {
            acc: Percent(0),
            dec: Percent(0),
            speed: Percent(0),
            arm: ArmPolicy::KeepNoSwitch,
        }
    }
}

impl ScaraMotion {
    /// The positioning operation type byte: bit 0 PTP/CP, bits 1-2 = 1 (selected work
    /// coordinate system, the only value the spec defines), bits 3-4 arm policy.
    pub const fn operation_type(&self) -> u8 {
        match self {
            ScaraMotion::Ptp { arm, .. } => 0b010 | (arm.code() << 3),
            ScaraMotion::Cp { .. } => 0b011,
        }
    }
}

const OP_BITS: &[BitDef] = &[
    BitDef {
        lo: 0,
        width: 1,
        name: "motion control",
        values: &[(0, "PTP"), (1, "CP (straight line)")],
    },
    BitDef {
        lo: 1,
        width: 2,
        name: "coordinate system",
        values: &[(1, "selected work coordinate system")],
    },
    BitDef {
        lo: 3,
        width: 2,
        name: "PTP target arm",
        values: &[
            (0, "current arm, no switching"),
            (1, "current arm, switching allowed"),
            (2, "right arm"),
            (3, "left arm"),
        ],
    },
    BitDef {
        lo: 5,
        width: 3,
        name: "reserved",
        values: &[],
    },
];

/// Reads pattern, rates and operation type (columns 7-22), shared by 2D4H/2D5H/2D6H.
fn read_head(r: &mut Reader<'_, '_>) -> Result<(AxisPattern, ScaraMotion), MessageError> {
    // The operation type (columns 21-22) decides the units of the rates before it.
    let cp = r.peek_hex(14, 2).is_some_and(|t| t & 1 == 1);
    let axes = r.pattern("axis pattern")?;
    let (a, d, s) = if cp {
        (
            r.accel("acceleration")?.0,
            r.accel("deceleration")?.0,
            r.speed("speed")?.0,
        )
    } else {
        (
            r.percent("acceleration")?.0,
            r.percent("deceleration")?.0,
            r.percent("speed")?.0,
        )
    };
    let op = r.u8(
        Name::new("positioning operation type"),
        2,
        Show::Bits(OP_BITS),
    )?;
    if (op >> 1) & 3 != 1 {
        return Err(
            r.invalid("bits 1-2 = 1 (selected work coordinate system; 0, 2 and 3 are reserved)")
        );
    }
    if op & 0xE0 != 0 {
        return Err(r.invalid("bits 5-7 = 0 (reserved)"));
    }
    let arm = (op >> 3) & 3;
    let motion = if op & 1 == 1 {
        // CP keeps the current arm; bits 3-4 are then ignored rather than refused, as a
        // controller would most likely do ([inferred] PROTOCOL.md 3.20).
        ScaraMotion::Cp {
            acc: CentiG(a),
            dec: CentiG(d),
            speed: MmPerSec(s),
        }
    } else {
        ScaraMotion::Ptp {
            acc: Percent(a),
            dec: Percent(d),
            speed: Percent(s),
            arm: ArmPolicy::from_code(arm).unwrap_or_default(),
        }
    };
    Ok((axes, motion))
}

fn write_head(w: &mut Writer<'_>, axes: AxisPattern, m: &ScaraMotion) {
    let (a, d, s) = match *m {
        ScaraMotion::Ptp {
            acc, dec, speed, ..
        } => (acc.0, dec.0, speed.0),
        ScaraMotion::Cp { acc, dec, speed } => (acc.0, dec.0, speed.0),
    };
    w.hex_fit(u32::from(axes.0), 2);
    w.hex_fit(u32::from(a), 4);
    w.hex_fit(u32::from(d), 4);
    w.hex_fit(u32::from(s), 4);
    w.hex_fit(u32::from(m.operation_type()), 2);
}

/// Unit of a SCARA target: R axes (4, 8) in deg, X/Y/Z in mm.
fn target_unit(a: Axis) -> AxisUnit {
    if a.is_scara_r() {
        AxisUnit::Deg
    } else {
        AxisUnit::Mm
    }
}

/// 2D4H (absolute targets) / 2D5H (relative distances) in the selected work coordinate
/// system. [inferred] PROTOCOL.md 3.19: 2D4H layout assumed equal to 2D5H.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct ScaraMove {
    /// PTP or CP, with rates.
    pub motion: ScaraMotion,
    /// Target (2D4H) or distance (2D5H) per axis; its pattern is the axis pattern sent.
    pub targets: PerAxis<Milli>,
}

impl ScaraMove {
    pub(crate) fn read(r: &mut Reader<'_, '_>, what: &'static str) -> Result<Self, MessageError> {
        let (axes, motion) = read_head(r)?;
        let mut targets = PerAxis::new();
        for a in axes {
            targets.set(a, r.coord(Name::axis(what, a), target_unit(a))?);
        }
        Ok(ScaraMove { motion, targets })
    }

    #[inline]
    pub(crate) fn write(&self, w: &mut Writer<'_>) -> Result<(), EncodeError> {
        write_head(w, self.targets.pattern(), &self.motion);
        for (_, v) in self.targets.iter() {
            w.coord(v);
        }
        Ok(())
    }
}

/// 2D6H: move to a stored position number.
/// [inferred] PROTOCOL.md 3.21 and erratum 8: the position number is 4 hex digits.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct ScaraPositionMove {
    /// Axis pattern (ANDed with the position record's pattern).
    pub axes: AxisPattern,
    /// PTP or CP, with rates (0 = the position record's value).
    pub motion: ScaraMotion,
    /// Position number.
    pub position: u16,
}

impl ScaraPositionMove {
    pub(crate) fn read(r: &mut Reader<'_, '_>) -> Result<Self, MessageError> {
        let (axes, motion) = read_head(r)?;
        let position = r.u16(Name::new("position number"), 4, Show::Number)?;
        Ok(ScaraPositionMove {
            axes,
            motion,
            position,
        })
    }

    pub(crate) fn write(&self, w: &mut Writer<'_>) -> Result<(), EncodeError> {
        write_head(w, self.axes, &self.motion);
        w.hex_fit(u32::from(self.position), 4);
        Ok(())
    }
}
