//! Axis motion commands: 232H servo, 233H home, 234H/235H moves, 236H jog, 238H stop,
//! 262H speed change.

use crate::protocol::axis::{Axis, AxisPattern, PerAxis};
use crate::protocol::error::{EncodeError, MessageError};
use crate::protocol::fields::{BitDef, Name, Reader, Show, bit};
use crate::protocol::units::{AxisUnit, CentiG, Milli, MmPerSec, Percent};
use crate::protocol::writer::Writer;

/// 232H: servo ON or OFF for the axes of `axes`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Servo {
    /// Axes to switch.
    pub axes: AxisPattern,
    /// `true` = servo ON.
    pub on: bool,
}

impl Servo {
    pub(crate) fn read(r: &mut Reader<'_, '_>) -> Result<Self, MessageError> {
        let axes = r.pattern("axis pattern")?;
        let op = r.u8(
            Name::new("operation type"),
            1,
            Show::Code(&[(0, "servo OFF"), (1, "servo ON")]),
        )?;
        if op > 1 {
            return Err(r.invalid("0 (servo OFF) or 1 (servo ON); bits 1-3 are reserved"));
        }
        Ok(Servo { axes, on: op == 1 })
    }

    pub(crate) fn write(&self, w: &mut Writer<'_>) -> Result<(), EncodeError> {
        w.hex_fit(u32::from(self.axes.0), 2);
        w.hex_fit(u32::from(self.on), 1);
        Ok(())
    }
}

/// 233H: home return. Speeds are 3 hex digits (max 4095 mm/s); 0 = parameter value.
/// [observed] PROTOCOL.md 3.7 and erratum 15: 3+3 speed digits.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Home {
    /// Axes to home.
    pub axes: AxisPattern,
    /// Search speed.
    pub search: MmPerSec,
    /// Creep speed.
    pub creep: MmPerSec,
}

impl Home {
    pub(crate) fn read(r: &mut Reader<'_, '_>) -> Result<Self, MessageError> {
        let axes = r.pattern("axis pattern")?;
        let search = MmPerSec(r.u16(Name::new("search speed"), 3, Show::Speed)?);
        let creep = MmPerSec(r.u16(Name::new("creep speed"), 3, Show::Speed)?);
        Ok(Home {
            axes,
            search,
            creep,
        })
    }

    pub(crate) fn write(&self, w: &mut Writer<'_>) -> Result<(), EncodeError> {
        w.hex_fit(u32::from(self.axes.0), 2);
        w.hex("search speed", u32::from(self.search.0), 3)?;
        w.hex("creep speed", u32::from(self.creep.0), 3)
    }
}

/// 234H (absolute targets) and 235H (relative distances): per-axis move.
/// [inferred] PROTOCOL.md 3.8: 234H layout equal to 235H (page not retrieved; observed
/// frames agree).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct AxisMove {
    /// Acceleration; 0 = parameter value.
    pub acc: CentiG,
    /// Deceleration; 0 = parameter value.
    pub dec: CentiG,
    /// Speed; 0 = parameter value.
    pub speed: MmPerSec,
    /// Target coordinate (234H) or distance (235H) per axis; its pattern is the axis
    /// pattern sent.
    pub targets: PerAxis<Milli>,
}

impl AxisMove {
    pub(crate) fn read(r: &mut Reader<'_, '_>, what: &'static str) -> Result<Self, MessageError> {
        let axes = r.pattern("axis pattern")?;
        let acc = r.accel("acceleration")?;
        let dec = r.accel("deceleration")?;
        let speed = r.speed("speed")?;
        let mut targets = PerAxis::new();
        for a in axes {
            targets.set(a, r.coord(Name::axis(what, a), AxisUnit::Mm)?);
        }
        Ok(AxisMove {
            acc,
            dec,
            speed,
            targets,
        })
    }

    pub(crate) fn write(&self, w: &mut Writer<'_>) -> Result<(), EncodeError> {
        w.hex_fit(u32::from(self.targets.pattern().0), 2);
        w.hex_fit(u32::from(self.acc.0), 4);
        w.hex_fit(u32::from(self.dec.0), 4);
        w.hex_fit(u32::from(self.speed.0), 4);
        for (_, v) in self.targets.iter() {
            w.coord(v);
        }
        Ok(())
    }
}

/// Direction of a jog or inching step (236H operation type bit 0).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Direction {
    /// 0: negative.
    #[default]
    Negative,
    /// 1: positive.
    Positive,
}

/// Cartesian frame of a SCARA jog (236H bits 1-2 = 0, 1, 2). Linear axes use `Base`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum JogFrame {
    /// 0: base coordinate system.
    #[default]
    Base,
    /// 1: selected work coordinate system.
    Work,
    /// 2: selected tool coordinate system.
    Tool,
}

/// How a jog moves, with its rates in the units that system uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum JogMotion {
    /// Base, work or tool coordinates: 0.01 G and mm/s.
    Cartesian {
        /// Coordinate system.
        frame: JogFrame,
        /// Acceleration; 0 = parameter value.
        acc: CentiG,
        /// Deceleration; 0 = parameter value.
        dec: CentiG,
        /// Speed; 0 = parameter value.
        speed: MmPerSec,
    },
    /// Each-axis (joint) system (bits 1-2 = 3): rates in %.
    /// [inferred] PROTOCOL.md section 5 erratum 12: % applies in the each-axis system.
    Joint {
        /// Acceleration; 0 = parameter value.
        acc: Percent,
        /// Deceleration; 0 = parameter value.
        dec: Percent,
        /// Speed; 0 = parameter value.
        speed: Percent,
    },
}

impl Default for JogMotion {
    fn default() -> Self {
        JogMotion::Cartesian {
            frame: JogFrame::Base,
            acc: CentiG(0),
            dec: CentiG(0),
            speed: MmPerSec(0),
        }
    }
}

/// 236H: jog (distance 0, runs until 238H) or inching (distance > 0).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Jog {
    /// Axis pattern (SCARA: exactly one axis).
    pub axes: AxisPattern,
    /// Direction.
    pub direction: Direction,
    /// Inching distance, a magnitude (0 to 7FFFFFFFH); 0 = jog until stopped.
    pub distance: Milli,
    /// Coordinate system and rates.
    pub motion: JogMotion,
}

const JOG_OP_BITS: &[BitDef] = &[
    BitDef {
        lo: 0,
        width: 1,
        name: "direction",
        values: &[(0, "negative"), (1, "positive")],
    },
    BitDef {
        lo: 1,
        width: 2,
        name: "coordinate system",
        values: &[
            (0, "base"),
            (1, "selected work"),
            (2, "selected tool"),
            (3, "each-axis (joint)"),
        ],
    },
    bit(3, "reserved"),
];

impl Jog {
    /// A jog that runs until 238H, the workspace edge or the joint limit: distance 0
    /// (PROTOCOL.md 3.10).
    pub const fn until_stopped(axes: AxisPattern, direction: Direction, motion: JogMotion) -> Jog {
        Jog {
            axes,
            direction,
            distance: Milli(0),
            motion,
        }
    }

    /// Whether this jog runs until stopped: distance 0 (PROTOCOL.md 3.10), the one home
    /// of that rule.
    pub const fn is_continuous(&self) -> bool {
        self.distance.0 == 0
    }

    pub(crate) fn read(r: &mut Reader<'_, '_>) -> Result<Self, MessageError> {
        // The operation type (column 29) decides the units of the rates before it.
        let joint = r.peek_hex(22, 1).is_some_and(|t| (t >> 1) & 3 == 3);
        let axes = r.pattern("axis pattern")?;
        let (a, d, s) = if joint {
            (
                u32::from(r.percent("acceleration")?.0),
                u32::from(r.percent("deceleration")?.0),
                u32::from(r.percent("speed")?.0),
            )
        } else {
            (
                u32::from(r.accel("acceleration")?.0),
                u32::from(r.accel("deceleration")?.0),
                u32::from(r.speed("speed")?.0),
            )
        };
        // Rotary joints in the each-axis system, and R in the Cartesian ones, turn in
        // 0.001 deg ([inferred] PROTOCOL.md section 5, erratum 12).
        let first = axes.iter().next();
        let rotary = if joint {
            first.is_some_and(Axis::is_scara_rotary_joint)
        } else {
            first.is_some_and(Axis::is_scara_r)
        };
        let unit = if rotary { AxisUnit::Deg } else { AxisUnit::Mm };
        let dist = r.hex(
            Name::new("inching distance (0 = jog)"),
            8,
            Show::Magnitude(unit),
        )?;
        if dist > i32::MAX as u32 {
            return Err(
                r.invalid("a magnitude of 0 to 7FFFFFFF (the direction is in the operation type)")
            );
        }
        let op = r.u8(Name::new("operation type"), 1, Show::Bits(JOG_OP_BITS))?;
        if op & 0x8 != 0 {
            return Err(r.invalid("bit 3 = 0 (reserved)"));
        }
        let direction = if op & 1 == 1 {
            Direction::Positive
        } else {
            Direction::Negative
        };
        let (a16, d16, s16) = (a as u16, d as u16, s as u16);
        let motion = match (op >> 1) & 3 {
            3 => JogMotion::Joint {
                acc: Percent(a16),
                dec: Percent(d16),
                speed: Percent(s16),
            },
            f => JogMotion::Cartesian {
                frame: match f {
                    0 => JogFrame::Base,
                    1 => JogFrame::Work,
                    _ => JogFrame::Tool,
                },
                acc: CentiG(a16),
                dec: CentiG(d16),
                speed: MmPerSec(s16),
            },
        };
        Ok(Jog {
            axes,
            direction,
            distance: Milli(dist as i32),
            motion,
        })
    }

    pub(crate) fn write(&self, w: &mut Writer<'_>) -> Result<(), EncodeError> {
        if self.distance.0 < 0 {
            return Err(w.error(
                "inching distance",
                format!(
                    "= {}: must be a magnitude; set the direction instead",
                    self.distance
                ),
            ));
        }
        let (a, d, s, sys) = match self.motion {
            JogMotion::Cartesian {
                frame,
                acc,
                dec,
                speed,
            } => (
                acc.0,
                dec.0,
                speed.0,
                match frame {
                    JogFrame::Base => 0,
                    JogFrame::Work => 1,
                    JogFrame::Tool => 2,
                },
            ),
            JogMotion::Joint { acc, dec, speed } => (acc.0, dec.0, speed.0, 3),
        };
        w.hex_fit(u32::from(self.axes.0), 2);
        w.hex_fit(u32::from(a), 4);
        w.hex_fit(u32::from(d), 4);
        w.hex_fit(u32::from(s), 4);
        w.coord(self.distance);
        let dir = u32::from(self.direction == Direction::Positive);
        w.hex_fit(dir | (sys << 1), 1);
        Ok(())
    }
}

/// 238H: stop (and cancel) operations on the axes of `axes`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Stop {
    /// Axes to stop (`FF` = all).
    pub axes: AxisPattern,
    /// Appended byte bit 0: also cancel output-port changes held by an interlock.
    pub cancel_held_outputs: bool,
}

const STOP_BITS: &[BitDef] = &[bit(0, "cancel held output-port changes")];

impl Stop {
    pub(crate) fn read(r: &mut Reader<'_, '_>) -> Result<Self, MessageError> {
        let axes = r.pattern("stop axis pattern")?;
        // PROTOCOL.md section 5 erratum 16: the appended byte is required.
        let b = r.u8(Name::new("appended command byte"), 2, Show::Bits(STOP_BITS))?;
        if b > 1 {
            return Err(r.invalid("00 or 01 (bits 1-7 reserved)"));
        }
        Ok(Stop {
            axes,
            cancel_held_outputs: b == 1,
        })
    }

    pub(crate) fn write(&self, w: &mut Writer<'_>) -> Result<(), EncodeError> {
        w.hex_fit(u32::from(self.axes.0), 2);
        w.hex_fit(u32::from(self.cancel_held_outputs), 2);
        Ok(())
    }
}

/// 262H: change the speed of the move in progress.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct SpeedChange {
    /// Axes (not SCARA axes on PX/QX/RX/SX).
    pub axes: AxisPattern,
    /// New speed.
    pub speed: MmPerSec,
}

impl SpeedChange {
    pub(crate) fn read(r: &mut Reader<'_, '_>) -> Result<Self, MessageError> {
        let axes = r.pattern("axis pattern")?;
        let speed = r.speed("speed")?;
        Ok(SpeedChange { axes, speed })
    }

    pub(crate) fn write(&self, w: &mut Writer<'_>) -> Result<(), EncodeError> {
        w.hex_fit(u32::from(self.axes.0), 2);
        w.hex_fit(u32::from(self.speed.0), 4);
        Ok(())
    }
}
