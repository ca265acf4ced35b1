//! SCARA arm systems: one enum, decoded per message with that message's own code table.

use std::fmt;

/// The arm system (right- or left-handed elbow) a SCARA unit reports.
///
/// The wire codes differ between messages (PROTOCOL.md section 5, erratum 4): use
/// [`ArmSystem::from_2a1`] / [`ArmSystem::to_2a1`] for 2A1H and
/// [`ArmSystem::from_2a3`] / [`ArmSystem::to_2a3`] for 2A3H; never share one mapping.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ArmSystem {
    /// Right arm system.
    Right,
    /// Left arm system.
    Left,
    /// Not determined (e.g. on the arm's singular line).
    Undetermined,
}

impl ArmSystem {
    /// 2A1H common status bits 0-1: 0 = right, 1 = left, 2 = undetermined, 3 reserved.
    pub const fn from_2a1(code: u8) -> Option<ArmSystem> {
        match code {
            0 => Some(ArmSystem::Right),
            1 => Some(ArmSystem::Left),
            2 => Some(ArmSystem::Undetermined),
            _ => None,
        }
    }

    /// The 2A1H code.
    pub const fn to_2a1(self) -> u8 {
        match self {
            ArmSystem::Right => 0,
            ArmSystem::Left => 1,
            ArmSystem::Undetermined => 2,
        }
    }

    /// 2A3H common status bits 0-1: 0 = undetermined, 1 = right, 2 = left, 3 reserved.
    pub const fn from_2a3(code: u8) -> Option<ArmSystem> {
        match code {
            0 => Some(ArmSystem::Undetermined),
            1 => Some(ArmSystem::Right),
            2 => Some(ArmSystem::Left),
            _ => None,
        }
    }

    /// The 2A3H code.
    pub const fn to_2a3(self) -> u8 {
        match self {
            ArmSystem::Undetermined => 0,
            ArmSystem::Right => 1,
            ArmSystem::Left => 2,
        }
    }
}

impl fmt::Display for ArmSystem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            ArmSystem::Right => "right arm",
            ArmSystem::Left => "left arm",
            ArmSystem::Undetermined => "arm undetermined",
        })
    }
}

/// Target arm policy of a SCARA PTP move, bits 3-4 of the 2D4H/2D5H/2D6H positioning
/// operation type.
///
/// [inferred] PROTOCOL.md section 5 erratum 5: the spec's qualifiers for values 2 and 3 are
/// asymmetric; read as the SEL PTP variants (current arm no switch / current arm may switch
/// / right arm / left arm).
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize,
)]
pub enum ArmPolicy {
    /// 0: keep the current arm; do not switch to the other arm if unreachable.
    #[default]
    KeepNoSwitch,
    /// 1: keep the current arm; switching to the other arm is allowed.
    KeepMaySwitch,
    /// 2: right arm.
    Right,
    /// 3: left arm.
    Left,
}

impl ArmPolicy {
    pub const ALL: [ArmPolicy; 4] = [
        ArmPolicy::KeepNoSwitch,
        ArmPolicy::KeepMaySwitch,
        ArmPolicy::Right,
        ArmPolicy::Left,
    ];

    /// From the 2-bit code (bits 3-4).
    pub const fn from_code(code: u8) -> Option<ArmPolicy> {
        match code {
            0 => Some(ArmPolicy::KeepNoSwitch),
            1 => Some(ArmPolicy::KeepMaySwitch),
            2 => Some(ArmPolicy::Right),
            3 => Some(ArmPolicy::Left),
            _ => None,
        }
    }

    /// The 2-bit code.
    pub const fn code(self) -> u8 {
        match self {
            ArmPolicy::KeepNoSwitch => 0,
            ArmPolicy::KeepMaySwitch => 1,
            ArmPolicy::Right => 2,
            ArmPolicy::Left => 3,
        }
    }
}

impl fmt::Display for ArmPolicy {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            ArmPolicy::KeepNoSwitch => "current arm, no switching",
            ArmPolicy::KeepMaySwitch => "current arm, switching allowed",
            ArmPolicy::Right => "right arm",
            ArmPolicy::Left => "left arm",
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_two_status_messages_use_different_codes() {
        assert_eq!(ArmSystem::from_2a1(0), Some(ArmSystem::Right));
        assert_eq!(ArmSystem::from_2a3(0), Some(ArmSystem::Undetermined));
        assert_eq!(ArmSystem::from_2a1(1), Some(ArmSystem::Left));
        assert_eq!(ArmSystem::from_2a3(1), Some(ArmSystem::Right));
        assert_eq!(ArmSystem::from_2a1(3), None);
        for a in [ArmSystem::Right, ArmSystem::Left, ArmSystem::Undetermined] {
            assert_eq!(ArmSystem::from_2a1(a.to_2a1()), Some(a));
            assert_eq!(ArmSystem::from_2a3(a.to_2a3()), Some(a));
        }
    }

    #[test]
    fn arm_policy_codes() {
        for c in 0..4 {
            assert_eq!(ArmPolicy::from_code(c).map(ArmPolicy::code), Some(c));
        }
        assert_eq!(ArmPolicy::from_code(4), None);
    }
}
