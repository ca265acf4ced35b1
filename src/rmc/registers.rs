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
}
