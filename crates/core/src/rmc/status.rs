//! An axis's status as read in one FC3 of its status file (RMC.md sections 2 and 3): the
//! Status Bits with every named bit, the Error Bits, the positions and velocities; and the
//! Controller Status Bits.

use super::registers::element;
use super::words::{dword_at, dword_to_words, real_at, real_to_words};

/// Status Bits, %MD(8+n).0 (RMC.md section 3).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct StatusBits(pub u32);

/// The named Status Bits, bit number and tag (RMC.md section 3).
pub const STATUS_BIT_NAMES: [(u32, &str); 15] = [
    (StatusBits::IN_POSITION, "In Position"),
    (StatusBits::AT_VELOCITY, "At Velocity"),
    (StatusBits::OPEN_LOOP, "Open Loop"),
    (StatusBits::FAULT_INPUT, "Fault Input"),
    (StatusBits::POS_LIMIT_INPUT, "Positive Limit Input"),
    (StatusBits::NEG_LIMIT_INPUT, "Negative Limit Input"),
    (StatusBits::STOPPED, "Stopped"),
    (StatusBits::ENABLE_OUTPUT, "Enable Output"),
    (StatusBits::TG_DONE, "Target Generator Done"),
    (StatusBits::TG_STATE_A, "TG State A"),
    (StatusBits::TG_STATE_B, "TG State B"),
    (StatusBits::ENABLED, "Enabled"),
    (StatusBits::EXTERNAL_HALT, "External Halt"),
    (StatusBits::HALTED, "Halted"),
    (StatusBits::ACK, "Command Acknowledge"),
];

impl StatusBits {
    pub const IN_POSITION: u32 = 0;
    pub const AT_VELOCITY: u32 = 1;
    pub const OPEN_LOOP: u32 = 2;
    pub const FAULT_INPUT: u32 = 3;
    pub const POS_LIMIT_INPUT: u32 = 4;
    pub const NEG_LIMIT_INPUT: u32 = 5;
    pub const STOPPED: u32 = 6;
    pub const ENABLE_OUTPUT: u32 = 8;
    pub const TG_DONE: u32 = 9;
    pub const TG_STATE_A: u32 = 10;
    pub const TG_STATE_B: u32 = 11;
    /// [I for the exact meaning] set while Enable/Disable Axis (97) has enabled it.
    pub const ENABLED: u32 = 13;
    pub const EXTERNAL_HALT: u32 = 14;
    pub const HALTED: u32 = 15;
    pub const ACK: u32 = 31;

    pub fn bit(self, bit: u32) -> bool {
        self.0 & (1 << bit) != 0
    }

    pub fn with(self, bit: u32, on: bool) -> Self {
        if on {
            Self(self.0 | (1 << bit))
        } else {
            Self(self.0 & !(1 << bit))
        }
    }

    pub fn in_position(self) -> bool {
        self.bit(Self::IN_POSITION)
    }

    pub fn tg_done(self) -> bool {
        self.bit(Self::TG_DONE)
    }

    pub fn enabled(self) -> bool {
        self.bit(Self::ENABLED)
    }

    pub fn halted(self) -> bool {
        self.bit(Self::HALTED)
    }

    pub fn ack(self) -> bool {
        self.bit(Self::ACK)
    }

    /// The target generator's phase from TG State B and A.
    pub fn phase(self) -> TgPhase {
        match (self.bit(Self::TG_STATE_B), self.bit(Self::TG_STATE_A)) {
            (false, false) => TgPhase::Complete,
            (false, true) => TgPhase::Accelerating,
            (true, false) => TgPhase::ConstantVelocity,
            (true, true) => TgPhase::Decelerating,
        }
    }

    /// These bits with the phase's TG State B and A.
    pub fn with_phase(self, phase: TgPhase) -> Self {
        let (b, a) = match phase {
            TgPhase::Complete => (false, false),
            TgPhase::Accelerating => (false, true),
            TgPhase::ConstantVelocity => (true, false),
            TgPhase::Decelerating => (true, true),
        };
        self.with(Self::TG_STATE_B, b).with(Self::TG_STATE_A, a)
    }

    /// The names of the bits set, in bit order.
    pub fn names(self) -> Vec<&'static str> {
        STATUS_BIT_NAMES
            .iter()
            .filter(|(bit, _)| self.bit(*bit))
            .map(|(_, name)| *name)
            .collect()
    }
}

/// The target generator's state, TG State B A (RMC.md section 3).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum TgPhase {
    #[default]
    Complete,
    Accelerating,
    ConstantVelocity,
    Decelerating,
}

impl TgPhase {
    pub fn name(self) -> &'static str {
        match self {
            TgPhase::Complete => "complete",
            TgPhase::Accelerating => "accelerating",
            TgPhase::ConstantVelocity => "constant velocity",
            TgPhase::Decelerating => "decelerating",
        }
    }
}

/// Error Bits, %MD(8+n).1 (RMC.md section 3): latched until Clear Faults (4) or a motion
/// command, and only once the cause is gone.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ErrorBits(pub u32);

impl ErrorBits {
    pub const FOLLOWING_ERROR: u32 = 0;
    pub const OUTPUT_SATURATED: u32 = 2;
    pub const FAULT_INPUT: u32 = 3;
    pub const POSITIVE_LIMIT: u32 = 4;
    pub const NEGATIVE_LIMIT: u32 = 5;
    pub const NO_TRANSDUCER: u32 = 6;

    const NAMES: [(u32, &str); 6] = [
        (Self::FOLLOWING_ERROR, "following error"),
        (Self::OUTPUT_SATURATED, "output saturated"),
        (Self::FAULT_INPUT, "fault input"),
        (Self::POSITIVE_LIMIT, "positive limit"),
        (Self::NEGATIVE_LIMIT, "negative limit"),
        (Self::NO_TRANSDUCER, "no transducer"),
    ];

    pub fn bit(self, bit: u32) -> bool {
        self.0 & (1 << bit) != 0
    }

    pub fn any(self) -> bool {
        self.0 != 0
    }

    /// The named bits set; a bit the reference does not name reads "error bit N".
    pub fn names(self) -> Vec<String> {
        (0..32)
            .filter(|b| self.bit(*b))
            .map(|b| {
                Self::NAMES
                    .iter()
                    .find(|(n, _)| *n == b)
                    .map_or_else(|| format!("error bit {b}"), |(_, name)| (*name).to_string())
            })
            .collect()
    }
}

/// One axis's status file, as polled.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct AxisStatus {
    pub bits: StatusBits,
    pub errors: ErrorBits,
    /// Last Error Number (a DINT inside a REAL, RMC.md section 2).
    pub last_error: f32,
    pub actual_position: f32,
    pub actual_velocity: f32,
    pub target_position: f32,
    pub target_velocity: f32,
    pub target_acceleration: f32,
    pub command_position: f32,
    pub command_velocity: f32,
}

impl AxisStatus {
    /// Reads the registers of one status read ([`super::registers::STATUS_REGISTERS`]);
    /// `None` if there are too few.
    pub fn decode(regs: &[u16]) -> Option<Self> {
        Some(Self {
            bits: StatusBits(dword_at(regs, element::STATUS_BITS)?),
            errors: ErrorBits(dword_at(regs, element::ERROR_BITS)?),
            last_error: real_at(regs, element::LAST_ERROR)?,
            actual_position: real_at(regs, element::ACTUAL_POSITION)?,
            actual_velocity: real_at(regs, element::ACTUAL_VELOCITY)?,
            target_position: real_at(regs, element::TARGET_POSITION)?,
            target_velocity: real_at(regs, element::TARGET_VELOCITY)?,
            target_acceleration: real_at(regs, element::TARGET_ACCELERATION)?,
            command_position: real_at(regs, element::COMMAND_POSITION)?,
            command_velocity: real_at(regs, element::COMMAND_VELOCITY)?,
        })
    }

    /// The registers of one status read, other elements 0 (the simulator's side).
    pub fn encode(&self) -> Vec<u16> {
        let mut regs = vec![0u16; usize::from(super::registers::STATUS_REGISTERS)];
        let mut put = |element: usize, words: [u16; 2]| {
            regs[2 * element] = words[0];
            regs[2 * element + 1] = words[1];
        };
        put(element::STATUS_BITS, dword_to_words(self.bits.0));
        put(element::ERROR_BITS, dword_to_words(self.errors.0));
        put(element::LAST_ERROR, real_to_words(self.last_error));
        put(
            element::ACTUAL_POSITION,
            real_to_words(self.actual_position),
        );
        put(
            element::ACTUAL_VELOCITY,
            real_to_words(self.actual_velocity),
        );
        put(
            element::TARGET_POSITION,
            real_to_words(self.target_position),
        );
        put(
            element::TARGET_VELOCITY,
            real_to_words(self.target_velocity),
        );
        put(
            element::TARGET_ACCELERATION,
            real_to_words(self.target_acceleration),
        );
        put(
            element::COMMAND_POSITION,
            real_to_words(self.command_position),
        );
        put(
            element::COMMAND_VELOCITY,
            real_to_words(self.command_velocity),
        );
        regs
    }

    /// Following error: Target − Actual.
    pub fn following_error(&self) -> f32 {
        self.target_position - self.actual_position
    }
}

/// Controller Status Bits, %MD44.7.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ControllerStatus(pub u32);

impl ControllerStatus {
    /// RUN mode (bit 0 set) rather than PROGRAM.
    pub fn run_mode(self) -> bool {
        self.0 & 1 != 0
    }

    /// Controller Enabled (bit 1).
    pub fn enabled(self) -> bool {
        self.0 & 2 != 0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_status_reads_back_from_its_registers() {
        let status = AxisStatus {
            bits: StatusBits(0)
                .with(StatusBits::ENABLED, true)
                .with(StatusBits::ACK, true)
                .with_phase(TgPhase::Decelerating),
            errors: ErrorBits(1 << ErrorBits::POSITIVE_LIMIT),
            last_error: 3.0,
            actual_position: 1.5,
            actual_velocity: -2.0,
            target_position: 1.75,
            target_velocity: -2.5,
            target_acceleration: 100.0,
            command_position: 10.0,
            command_velocity: 5.0,
        };
        let regs = status.encode();
        assert_eq!(regs.len(), 116);
        assert_eq!(AxisStatus::decode(&regs), Some(status));
        assert_eq!(AxisStatus::decode(&regs[..115]), None);
        // Status Bits is a DWORD, low word first: ACK (bit 31) is in the second word.
        assert_eq!(regs[1] & 0x8000, 0x8000);
        assert_eq!(status.bits.phase(), TgPhase::Decelerating);
        assert_eq!(status.errors.names(), ["positive limit"]);
        assert!(status.bits.names().contains(&"Command Acknowledge"));
        assert_eq!(status.following_error(), 0.25);
    }

    #[test]
    fn phases_are_tg_state_b_then_a() {
        for phase in [
            TgPhase::Complete,
            TgPhase::Accelerating,
            TgPhase::ConstantVelocity,
            TgPhase::Decelerating,
        ] {
            assert_eq!(StatusBits(0).with_phase(phase).phase(), phase);
        }
        assert_eq!(StatusBits(1 << 10).phase(), TgPhase::Accelerating);
        assert_eq!(StatusBits(1 << 11).phase(), TgPhase::ConstantVelocity);
    }
}
