//! The RMC150/151 register map (RMC.md section 2): 32-bit registers `%MDfile.element`, each
//! two Modbus registers at PDU address 2 × (256 × file + element).

use std::fmt;

/// Axes an RMC151 can have (RMC.md section 2: n = 0..7).
pub const MAX_AXES: usize = 8;

/// Modbus registers in one status read: elements 0..=57 of an axis's status file, Status
/// Bits through Command Velocity (RMC.md section 2) [I: one transaction covers them].
pub const STATUS_REGISTERS: u16 = 116;

/// Most registers one read may ask for (RMC.md section 1).
pub const MAX_READ: u16 = 125;
/// Most registers one write may carry (RMC.md section 1).
pub const MAX_WRITE: u16 = 100;

/// One axis of the controller, 0-based on the wire, "Axis 1".."Axis 8" to people.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct AxisId(u8);

impl AxisId {
    /// The axis with 0-based index `index`, if the controller can have it.
    pub fn new(index: usize) -> Option<Self> {
        (index < MAX_AXES).then_some(Self(index as u8))
    }

    /// Every axis of a controller with `count` of them.
    pub fn first(count: usize) -> impl Iterator<Item = AxisId> {
        (0..count.min(MAX_AXES)).map(|i| Self(i as u8))
    }

    pub fn index(self) -> usize {
        usize::from(self.0)
    }

    /// Where its status file starts: Status Bits, %MD(8+n).0.
    pub fn status_block(self) -> u16 {
        md(8 + u16::from(self.0), 0)
    }

    /// Where its command block starts: %MD40.(10n), the Command Area.
    pub fn command_block(self) -> u16 {
        md(40, 10 * u16::from(self.0))
    }

    /// The low copy of its command block (%MD2.(10n), RMC.md section 2).
    pub fn command_block_low(self) -> u16 {
        md(2, 10 * u16::from(self.0))
    }

    /// Its Position Scale, %MD(24+n).0.
    pub fn position_scale(self) -> u16 {
        md(24 + u16::from(self.0), 0)
    }

    /// Its In Position Tolerance, %MD(24+n).56.
    pub fn in_position_tolerance(self) -> u16 {
        md(24 + u16::from(self.0), 56)
    }
}

impl fmt::Display for AxisId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "Axis {}", self.0 + 1)
    }
}

/// The PDU address of `%MDfile.element` (RMC.md section 1: 2 × (256 × file + element)).
pub const fn md(file: u16, element: u16) -> u16 {
    2 * (256 * file + element)
}

/// Controller Status Bits, %MD44.7.
pub const CONTROLLER_STATUS: u16 = md(44, 7);
/// CPU Module ID, %MD7.2: 16 on an RMC150E, 17 on an RMC151E.
pub const CPU_MODULE_ID: u16 = md(7, 2);
/// The CPU Module ID an RMC151E reports.
pub const RMC151E_ID: u32 = 17;

/// Elements of an axis's status file (%MD(8+n).element), in 32-bit registers.
pub mod element {
    pub const STATUS_BITS: usize = 0;
    pub const ERROR_BITS: usize = 1;
    pub const LAST_ERROR: usize = 2;
    pub const ACTUAL_POSITION: usize = 8;
    pub const ACTUAL_VELOCITY: usize = 9;
    pub const TARGET_POSITION: usize = 53;
    pub const TARGET_VELOCITY: usize = 54;
    pub const TARGET_ACCELERATION: usize = 55;
    pub const COMMAND_POSITION: usize = 56;
    pub const COMMAND_VELOCITY: usize = 57;
}

/// How a 32-bit register's two words are read.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// Bits (Status Bits, Error Bits, Controller Status Bits, the CPU Module ID).
    Dword,
    /// An f32 (every command, parameter, position and velocity: RMC.md section 1).
    Real,
}

/// A 32-bit register as RMCTools names it (RMC.md section 2), for the frame log.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Register {
    /// `Actual Position, Axis 1`, or `%MD8.3` for one the reference does not name.
    pub name: String,
    pub kind: Kind,
    /// `pu`, `pu/s`, or empty.
    pub unit: &'static str,
    /// The element within an axis's status file or command block (what [`range_name`]
    /// names without the axis).
    short: String,
    axis: Option<AxisId>,
}

impl Register {
    /// The command word of an axis's Command Area (its first register).
    pub fn is_command(&self) -> bool {
        self.short.starts_with("Command Area") && self.short.ends_with(": command")
    }
}

/// The names of an axis's status file elements (RMC.md section 2).
const STATUS_FILE: [(usize, &str, Kind, &str); 10] = [
    (element::STATUS_BITS, "Status Bits", Kind::Dword, ""),
    (element::ERROR_BITS, "Error Bits", Kind::Dword, ""),
    (element::LAST_ERROR, "Last Error Number", Kind::Real, ""),
    (
        element::ACTUAL_POSITION,
        "Actual Position",
        Kind::Real,
        "pu",
    ),
    (
        element::ACTUAL_VELOCITY,
        "Actual Velocity",
        Kind::Real,
        "pu/s",
    ),
    (
        element::TARGET_POSITION,
        "Target Position",
        Kind::Real,
        "pu",
    ),
    (
        element::TARGET_VELOCITY,
        "Target Velocity",
        Kind::Real,
        "pu/s",
    ),
    (
        element::TARGET_ACCELERATION,
        "Target Acceleration",
        Kind::Real,
        "pu/s²",
    ),
    (
        element::COMMAND_POSITION,
        "Command Position",
        Kind::Real,
        "pu",
    ),
    (
        element::COMMAND_VELOCITY,
        "Command Velocity",
        Kind::Real,
        "pu/s",
    ),
];

/// The register at PDU address `address` (its even word; an odd address names the
/// register whose high word it is).
pub fn register_at(address: u16) -> Register {
    let index = address / 2;
    let (file, el) = (index / 256, usize::from(index % 256));
    let plain = |short: String, kind, unit, axis: Option<AxisId>| Register {
        name: match axis {
            Some(a) => format!("{short}, {a}"),
            None => short.clone(),
        },
        kind,
        unit,
        short,
        axis,
    };
    let md = format!("%MD{file}.{el}");
    let axis_of = |first: u16| AxisId::new(usize::from(file - first));
    match file {
        8..=15 => {
            let axis = axis_of(8);
            match STATUS_FILE.iter().find(|(e, ..)| *e == el) {
                Some(&(_, name, kind, unit)) => plain(name.into(), kind, unit, axis),
                None => plain(md, Kind::Real, "", axis),
            }
        }
        24..=31 => {
            let axis = axis_of(24);
            let (name, unit) = match el {
                0 => ("Position Scale", ""),
                1 => ("Position Offset", "pu"),
                56 => ("In Position Tolerance", "pu"),
                _ => return plain(md, Kind::Real, "", axis),
            };
            plain(name.into(), Kind::Real, unit, axis)
        }
        2 | 40 if el < 10 * MAX_AXES => {
            let axis = AxisId::new(el / 10);
            let low = if file == 2 { " (low copy)" } else { "" };
            let short = match el % 10 {
                0 => format!("Command Area{low}: command"),
                k => format!("Command Area{low}: parameter {k}"),
            };
            plain(short, Kind::Real, "", axis)
        }
        44 if el == 7 => plain("Controller Status Bits".into(), Kind::Dword, "", None),
        7 if el == 2 => plain("CPU Module ID".into(), Kind::Dword, "", None),
        _ => plain(md, Kind::Real, "", None),
    }
}

/// A run of `count` Modbus registers from `address`, named by its first and last 32-bit
/// register: `Status Bits..Command Velocity, Axis 1`, `Command Area, Axis 2`.
pub fn range_name(address: u16, count: u16) -> String {
    let first = register_at(address);
    if count <= 2 {
        return first.name;
    }
    let last = register_at(address.saturating_add(count - 1));
    if first.short.starts_with("Command Area") && first.axis == last.axis {
        let low = if first.short.contains("low copy") {
            " (low copy)"
        } else {
            ""
        };
        return match first.axis {
            Some(a) => format!("Command Area{low}, {a}"),
            None => format!("Command Area{low}"),
        };
    }
    match (first.axis, last.axis) {
        (Some(a), Some(b)) if a == b => format!("{}..{}, {a}", first.short, last.short),
        _ => format!("{}..{}", first.name, last.name),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn addresses_are_those_of_the_reference_table() {
        let a0 = AxisId::new(0).unwrap();
        let a1 = AxisId::new(1).unwrap();
        assert_eq!(a0.status_block(), 4096);
        assert_eq!(a1.status_block(), 4096 + 512);
        assert_eq!(a0.command_block(), 20480);
        assert_eq!(a1.command_block(), 20500);
        assert_eq!(a0.command_block_low(), 1024);
        assert_eq!(a0.position_scale(), 12288);
        assert_eq!(a0.in_position_tolerance(), 12400);
        assert_eq!(CONTROLLER_STATUS, 22542);
        assert_eq!(CPU_MODULE_ID, 3588);
        assert_eq!(
            a0.status_block() + 2 * element::COMMAND_POSITION as u16,
            4208
        );
        assert!(AxisId::new(MAX_AXES).is_none());
        assert_eq!(AxisId::new(7).unwrap().to_string(), "Axis 8");
    }

    #[test]
    fn ranges_are_named_as_rmctools_names_them() {
        let a0 = AxisId::new(0).unwrap();
        let a1 = AxisId::new(1).unwrap();
        assert_eq!(
            range_name(a0.status_block(), STATUS_REGISTERS),
            "Status Bits..Command Velocity, Axis 1"
        );
        assert_eq!(range_name(a1.command_block(), 12), "Command Area, Axis 2");
        assert_eq!(range_name(CONTROLLER_STATUS, 2), "Controller Status Bits");
        assert_eq!(range_name(CPU_MODULE_ID, 2), "CPU Module ID");
        assert_eq!(
            register_at(a1.status_block() + 2 * element::ACTUAL_POSITION as u16).name,
            "Actual Position, Axis 2"
        );
        assert_eq!(register_at(md(9, 3)).name, "%MD9.3, Axis 2");
        assert_eq!(register_at(md(60, 1)).name, "%MD60.1");
        assert_eq!(
            register_at(a0.command_block_low() + 2).name,
            "Command Area (low copy): parameter 1, Axis 1"
        );
    }
}
