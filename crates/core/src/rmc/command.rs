//! The RMC's commands the pendant sends (RMC.md section 4), encoded as one command block:
//! the command number (plus 256 when REQ is set, section 5) and its parameters, all REALs.

use std::fmt;

use super::words::{real_to_words, words_to_real};
use crate::robot::RelativeTo;

/// What REQ adds to a command number (RMC.md section 5).
pub const REQ_OFFSET: u16 = 256;
/// Registers of the zeros block: a command number and five parameters, all 0.0. Written
/// after a connection opens, it sets ACK to 0 (RMC.md section 5).
pub const ZEROS_REGISTERS: usize = 12;

/// Move Relative (21)'s parameters (RMC.md section 4).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MoveRelative {
    /// Position units; the sign is the direction.
    pub distance: f32,
    /// pu/s, > 0.
    pub speed: f32,
    /// pu/s², > 0.
    pub accel: f32,
    /// pu/s², > 0.
    pub decel: f32,
    /// What the distance is added to, taken when the RMC receives the command.
    pub relative_to: RelativeTo,
}

/// Move Absolute (20)'s parameters (RMC.md section 4); its fifth, the direction, is sent
/// as 0 [I: it matters for rotary axes only, which the pendant does not drive].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MoveAbsolute {
    /// Position units.
    pub position: f32,
    pub speed: f32,
    pub accel: f32,
    pub decel: f32,
}

/// A command for one axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Command {
    /// No-op (0): the axis ignores it.
    NoOp,
    /// Closed Loop Halt (1).
    ClosedLoopHalt,
    /// Clear Faults (4).
    ClearFaults,
    /// Hold Current Position (5); `reset` is control behaviour 1.
    HoldCurrentPosition { reset: bool },
    /// Stop (Closed Loop) (6) at this deceleration, pu/s².
    Stop { decel: f32 },
    /// Move Relative (21).
    MoveRelative(MoveRelative),
    /// Move Absolute (20).
    MoveAbsolute(MoveAbsolute),
    /// Enable/Disable Axis (97).
    Enable(bool),
    /// Any other command number, with its first parameters as read (the simulator
    /// acknowledges it and does nothing).
    Other(u16),
}

/// Why a command is not sent, or a block not understood.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum CommandError {
    #[error("{what} must be a number greater than 0 (it is {value})")]
    NotPositive { what: &'static str, value: f32 },
    #[error("the distance must be a finite number (it is {0})")]
    BadDistance(f32),
    #[error("the command block is empty")]
    Empty,
    #[error("{0} is not a command number")]
    BadNumber(f32),
}

/// Move Relative's "relative to" code (RMC.md section 4, parameter 5).
pub fn relative_to_code(r: RelativeTo) -> f32 {
    match r {
        RelativeTo::Command => 0.0,
        RelativeTo::Actual => 1.0,
        RelativeTo::Target => 2.0,
    }
}

fn relative_to_from_code(code: f32) -> RelativeTo {
    // Codes other than 0, 1, 2 are not documented [U]: taken as command position.
    match code as i32 {
        1 => RelativeTo::Actual,
        2 => RelativeTo::Target,
        _ => RelativeTo::Command,
    }
}

impl Command {
    /// The command number, without REQ.
    pub fn number(&self) -> u16 {
        match self {
            Command::NoOp => 0,
            Command::ClosedLoopHalt => 1,
            Command::ClearFaults => 4,
            Command::HoldCurrentPosition { .. } => 5,
            Command::Stop { .. } => 6,
            Command::MoveRelative(_) => 21,
            Command::MoveAbsolute(_) => 20,
            Command::Enable(_) => 97,
            Command::Other(n) => *n,
        }
    }

    /// Its name as Delta's manual gives it.
    pub fn name(&self) -> &'static str {
        match self {
            Command::NoOp => "No-op",
            Command::ClosedLoopHalt => "Closed Loop Halt",
            Command::ClearFaults => "Clear Faults",
            Command::HoldCurrentPosition { .. } => "Hold Current Position",
            Command::Stop { .. } => "Stop (Closed Loop)",
            Command::MoveRelative(_) => "Move Relative",
            Command::MoveAbsolute(_) => "Move Absolute",
            Command::Enable(true) => "Enable Axis",
            Command::Enable(false) => "Disable Axis",
            Command::Other(_) => "command",
        }
    }

    /// Its parameters in order.
    pub fn parameters(&self) -> Vec<f32> {
        match *self {
            Command::NoOp | Command::ClosedLoopHalt | Command::ClearFaults | Command::Other(_) => {
                Vec::new()
            }
            Command::HoldCurrentPosition { reset } => vec![if reset { 1.0 } else { 0.0 }],
            Command::Stop { decel } => vec![decel],
            Command::MoveRelative(m) => vec![
                m.distance,
                m.speed,
                m.accel,
                m.decel,
                relative_to_code(m.relative_to),
            ],
            Command::Enable(on) => vec![if on { 1.0 } else { 0.0 }],
            Command::MoveAbsolute(m) => vec![m.position, m.speed, m.accel, m.decel, 0.0],
        }
    }

    /// Whether it starts motion (the ones STOP drops from the queue).
    pub fn moves(&self) -> bool {
        matches!(self, Command::MoveRelative(_) | Command::MoveAbsolute(_))
    }

    /// Checks the parameters before anything is sent.
    pub fn check(&self) -> Result<(), CommandError> {
        let positive = |what, value: f32| {
            if value.is_finite() && value > 0.0 {
                Ok(())
            } else {
                Err(CommandError::NotPositive { what, value })
            }
        };
        match *self {
            Command::Stop { decel } => positive("the deceleration", decel),
            Command::MoveRelative(m) => {
                if !m.distance.is_finite() {
                    return Err(CommandError::BadDistance(m.distance));
                }
                positive("the speed", m.speed)?;
                positive("the acceleration", m.accel)?;
                positive("the deceleration", m.decel)
            }
            Command::MoveAbsolute(m) => {
                if !m.position.is_finite() {
                    return Err(CommandError::BadDistance(m.position));
                }
                positive("the speed", m.speed)?;
                positive("the acceleration", m.accel)?;
                positive("the deceleration", m.decel)
            }
            _ => Ok(()),
        }
    }

    /// The block written at the axis's Command Area: the number (+256 with `req`) and the
    /// parameters, each a REAL as two registers.
    pub fn block(&self, req: bool) -> Vec<u16> {
        let number = self.number() + if req { REQ_OFFSET } else { 0 };
        std::iter::once(f32::from(number))
            .chain(self.parameters())
            .flat_map(real_to_words)
            .collect()
    }

    /// A block as the controller reads it: the command and its REQ bit. Parameters the
    /// block leaves out read as 0.0.
    pub fn from_block(words: &[u16]) -> Result<(Command, bool), CommandError> {
        let real = |i: usize| {
            let low = words.get(2 * i).copied().unwrap_or(0);
            let high = words.get(2 * i + 1).copied().unwrap_or(0);
            words_to_real([low, high])
        };
        if words.len() < 2 {
            return Err(CommandError::Empty);
        }
        let raw = real(0);
        // "An integer number in floating point format" (RMC.md section 1).
        if !raw.is_finite() || raw < 0.0 || raw.fract() != 0.0 || raw >= 512.0 {
            return Err(CommandError::BadNumber(raw));
        }
        let raw = raw as u16;
        let (number, req) = if raw >= REQ_OFFSET {
            (raw - REQ_OFFSET, true)
        } else {
            (raw, false)
        };
        let p = |i: usize| real(i);
        let command = match number {
            0 => Command::NoOp,
            1 => Command::ClosedLoopHalt,
            4 => Command::ClearFaults,
            5 => Command::HoldCurrentPosition { reset: p(1) == 1.0 },
            6 => Command::Stop { decel: p(1) },
            20 => Command::MoveAbsolute(MoveAbsolute {
                position: p(1),
                speed: p(2),
                accel: p(3),
                decel: p(4),
            }),
            21 => Command::MoveRelative(MoveRelative {
                distance: p(1),
                speed: p(2),
                accel: p(3),
                decel: p(4),
                relative_to: relative_to_from_code(p(5)),
            }),
            97 => Command::Enable(p(1) == 1.0),
            n => Command::Other(n),
        };
        Ok((command, req))
    }
}

impl fmt::Display for Command {
    /// "Move Relative (21) 10, 5, 100, 100, relative to target".
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} ({})", self.name(), self.number())?;
        match self {
            Command::MoveRelative(m) => write!(
                f,
                " distance {}, speed {}, accel {}, decel {}, relative to {}",
                m.distance,
                m.speed,
                m.accel,
                m.decel,
                m.relative_to.name()
            ),
            Command::MoveAbsolute(m) => write!(
                f,
                " position {}, speed {}, accel {}, decel {}",
                m.position, m.speed, m.accel, m.decel
            ),
            Command::Stop { decel } => write!(f, " decel {decel}"),
            _ => Ok(()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rmc::words::words_to_real;

    fn move_relative() -> Command {
        Command::MoveRelative(MoveRelative {
            distance: 10.0,
            speed: 5.0,
            accel: 100.0,
            decel: 100.0,
            relative_to: RelativeTo::Target,
        })
    }

    #[test]
    fn the_worked_example_gives_exactly_those_words() {
        // RMC.md: FC16 at 0x5000 with 277.0, 10.0, 5.0, 100.0, 100.0, 2.0.
        let block = move_relative().block(true);
        let reals: Vec<f32> = block
            .chunks(2)
            .map(|w| words_to_real([w[0], w[1]]))
            .collect();
        assert_eq!(reals, [277.0, 10.0, 5.0, 100.0, 100.0, 2.0]);
        assert_eq!(&block[..2], &[0x8000, 0x438A]);
        assert_eq!(&block[2..4], &[0x0000, 0x4120]);
        assert_eq!(move_relative().block(false)[..2], [0x0000, 0x41A8]);
    }

    #[test]
    fn every_command_reads_back_with_its_req() {
        let commands = [
            Command::NoOp,
            Command::ClosedLoopHalt,
            Command::ClearFaults,
            Command::HoldCurrentPosition { reset: true },
            Command::Stop { decel: 250.0 },
            move_relative(),
            Command::MoveAbsolute(MoveAbsolute {
                position: -12.5,
                speed: 3.0,
                accel: 30.0,
                decel: 40.0,
            }),
            Command::Enable(true),
            Command::Enable(false),
            Command::Other(37),
        ];
        for c in commands {
            for req in [false, true] {
                assert_eq!(Command::from_block(&c.block(req)), Ok((c, req)), "{c}");
            }
        }
        assert_eq!(
            Command::from_block(&[0; ZEROS_REGISTERS]),
            Ok((Command::NoOp, false))
        );
    }

    #[test]
    fn bad_parameters_are_refused_before_sending() {
        let mut m = MoveRelative {
            distance: 1.0,
            speed: 0.0,
            accel: 1.0,
            decel: 1.0,
            relative_to: RelativeTo::Command,
        };
        assert!(Command::MoveRelative(m).check().is_err());
        m.speed = 1.0;
        assert!(Command::MoveRelative(m).check().is_ok());
        m.distance = f32::NAN;
        assert!(Command::MoveRelative(m).check().is_err());
        assert!(Command::Stop { decel: -1.0 }.check().is_err());
        assert!(Command::from_block(&real_to_words(21.5)).is_err());
    }
}
