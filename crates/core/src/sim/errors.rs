//! The simulator's own table of error codes (3 hex digits), sent in `&` replies.
//!
//! PROTOCOL.md section 2: the retrieved spec pages carry no error list, so the simulator
//! keeps this one documented table. Two numbers borrow a real controller meaning:
//! `C74` (soft limit) and `CC1` (speed change condition error); every other code is the
//! simulator's own choice `[inferred, PROTOCOL.md section 2]`.

use std::fmt;

use crate::protocol::{MessageError, MessageErrorKind};

/// Why the simulated controller refused a command it could parse.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum SimError {
    /// The message ID is not one this controller knows.
    UnknownMessage,
    /// The data part has the wrong number of characters for this message.
    WrongLength,
    /// A field holds a non-hex character or a value outside its range.
    BadValue,
    /// The axis pattern names no axis of this controller, or an axis combination the
    /// message does not allow.
    BadAxis,
    /// An axis to move has its servo off.
    ServoOff,
    /// An absolute or SCARA move needs homed axes.
    NotHomed,
    /// An axis to move is already in use (moving, homing, switching servo).
    AxisBusy,
    /// Emergency stop is active.
    EmergencyStop,
    /// The controller is in MANUAL mode; protocol commands that act need AUTO.
    ManualMode,
    /// The drive source is cut off.
    DriveCutOff,
    /// An alarm is pending; reset it with 252H first.
    AlarmPending,
    /// The target is outside the arm's reach (no inverse kinematics solution), or a CP
    /// line leaves the workspace.
    Unreachable,
    /// Reaching the target would need the other arm system, and switching is not allowed.
    ArmSystem,
    /// 2D6H, 26BH: the position number holds no data for the selected axes.
    NoPosition,
    /// A joint target or the current position lies beyond a soft limit (real number C74).
    SoftLimit,
    /// 262H: no move in progress on the selected axes to change (real number CC1).
    SpeedChange,
    /// 253H-257H: no program with this number is loaded.
    NoProgram,
    /// 253H-257H: the program is not in a state for this (run when started, one step
    /// while running freely, pause or resume when not started).
    ProgramState,
}

/// One row of the table: code, enum, short text.
pub struct CodeRow {
    pub code: u16,
    pub error: SimError,
    pub text: &'static str,
}

/// Every code the simulator sends, in one place (also printed by `xsel-sim --codes` and
/// copied into the README).
pub const CODE_TABLE: &[CodeRow] = &[
    row(0xA01, SimError::UnknownMessage),
    row(0xA02, SimError::WrongLength),
    row(0xA03, SimError::BadValue),
    row(0xA04, SimError::BadAxis),
    row(0xB01, SimError::ServoOff),
    row(0xB02, SimError::NotHomed),
    row(0xB03, SimError::AxisBusy),
    row(0xB04, SimError::EmergencyStop),
    row(0xB05, SimError::ManualMode),
    row(0xB06, SimError::DriveCutOff),
    row(0xB07, SimError::AlarmPending),
    row(0xB08, SimError::Unreachable),
    row(0xB09, SimError::ArmSystem),
    row(0xB0A, SimError::NoPosition),
    row(0xB0B, SimError::NoProgram),
    row(0xB0C, SimError::ProgramState),
    row(0xC74, SimError::SoftLimit),
    row(0xCC1, SimError::SpeedChange),
];

/// A row whose text is the protocol's: the controller's meaning where known, else the
/// simulator's own.
const fn row(code: u16, error: SimError) -> CodeRow {
    let code_of = crate::protocol::ErrorCode(code);
    let text = match (code_of.text(), code_of.sim_text()) {
        (Some(t), _) | (None, Some(t)) => t,
        (None, None) => "",
    };
    CodeRow { code, error, text }
}

impl SimError {
    /// The 3-hex-digit number sent after `&`.
    pub fn code(self) -> u16 {
        CODE_TABLE
            .iter()
            .find(|r| r.error == self)
            .map_or(0xA03, |r| r.code)
    }

    /// The table's short text.
    pub fn text(self) -> &'static str {
        CODE_TABLE
            .iter()
            .find(|r| r.error == self)
            .map_or("", |r| r.text)
    }

    /// The table's answer to a command the protocol decoder refused: an unknown ID is A01,
    /// data cut short or running on is A02 (wrong length, as is 200H data over 10
    /// characters), a value the axis-pattern field does not allow is A04, and any other bad
    /// character or value is A03.
    pub fn from_message_error(e: &MessageError) -> SimError {
        match &e.kind {
            MessageErrorKind::UnknownMessage => SimError::UnknownMessage,
            MessageErrorKind::Missing { .. } | MessageErrorKind::Trailing { .. } => {
                SimError::WrongLength
            }
            MessageErrorKind::Invalid { field, .. } if field.ends_with("axis pattern") => {
                SimError::BadAxis
            }
            MessageErrorKind::Invalid { field, .. } if field == "test data" => {
                SimError::WrongLength
            }
            _ => SimError::BadValue,
        }
    }

    /// Looks a code up in the table.
    pub fn from_code(code: u16) -> Option<SimError> {
        CODE_TABLE.iter().find(|r| r.code == code).map(|r| r.error)
    }
}

impl fmt::Display for SimError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{:03X} {}", self.code(), self.text())
    }
}

/// The table as aligned text lines, for `--help` / `--codes` and logs.
pub fn code_table_text() -> String {
    let mut s = String::new();
    for r in CODE_TABLE {
        s.push_str(&format!("  {:03X}  {}\n", r.code, r.text));
    }
    s
}

/// Text for any alarm code the controller may carry (table codes or injected alarms).
pub fn describe_code(code: u16) -> &'static str {
    match SimError::from_code(code) {
        Some(e) => e.text(),
        None if code == 0 => "no error",
        None => "alarm (raised through the control API)",
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn codes_are_unique_and_three_hex_digits() {
        for (i, a) in CODE_TABLE.iter().enumerate() {
            assert!(a.code <= 0xFFF);
            for b in &CODE_TABLE[i + 1..] {
                assert_ne!(a.code, b.code);
                assert_ne!(a.error, b.error);
            }
            assert_eq!(SimError::from_code(a.code), Some(a.error));
        }
        assert_eq!(SimError::SoftLimit.code(), 0xC74);
        assert_eq!(SimError::SpeedChange.code(), 0xCC1);
    }

    #[test]
    fn decoder_refusals_map_to_the_a_codes() {
        use crate::protocol::{Command, Frame};
        let refusal = |body: &str| {
            let sc = body.bytes().fold(0u8, |s, b| s.wrapping_add(b));
            let bytes = format!("{body}{sc:02X}\r\n").into_bytes();
            let frame = Frame::parse(&bytes).unwrap();
            SimError::from_message_error(&Command::decode(&frame).unwrap_err())
        };
        assert_eq!(refusal("!99299"), SimError::UnknownMessage);
        assert_eq!(refusal("!99215FF"), SimError::WrongLength);
        assert_eq!(refusal("!992380F"), SimError::WrongLength);
        assert_eq!(refusal("!9920001234567890A"), SimError::WrongLength);
        assert_eq!(refusal("!99212G1"), SimError::BadValue);
        assert_eq!(refusal("!992322"), SimError::WrongLength);
        assert_eq!(refusal("!992320F2"), SimError::BadValue);
        assert_eq!(refusal("!992A41F010001"), SimError::BadAxis);
    }
}
