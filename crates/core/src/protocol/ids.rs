//! Frame-level identifiers: header kind, station, message ID, error code, role.

use std::fmt;

/// The first character of a frame (PROTOCOL.md 1.3).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Header {
    /// `!`: a command, host to controller.
    Command,
    /// `#`: a normal reply.
    Reply,
    /// `&`: an error reply (no message ID, a 3-digit error code instead).
    Error,
}

impl Header {
    /// The header byte on the wire.
    pub const fn byte(self) -> u8 {
        match self {
            Header::Command => b'!',
            Header::Reply => b'#',
            Header::Error => b'&',
        }
    }

    /// The header for a wire byte, if it is one.
    pub const fn from_byte(b: u8) -> Option<Header> {
        match b {
            b'!' => Some(Header::Command),
            b'#' => Some(Header::Reply),
            b'&' => Some(Header::Error),
            _ => None,
        }
    }

    /// Words for the frame log: "command", "reply", "error reply".
    pub const fn describe(self) -> &'static str {
        match self {
            Header::Command => "command",
            Header::Reply => "reply",
            Header::Error => "error reply",
        }
    }
}

impl fmt::Display for Header {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "'{}' ({})", self.byte() as char, self.describe())
    }
}

/// Which side of a transaction a message belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Role {
    /// Host to controller (`!`).
    Command,
    /// Controller to host (`#` or `&`).
    Reply,
}

impl fmt::Display for Role {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Role::Command => "command",
            Role::Reply => "reply",
        })
    }
}

/// A station number: the wire value of the 2-hex-digit station field. The usual station
/// "99" is `Station(0x99)` (PROTOCOL.md 1.3).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Station(pub u8);

impl Station {
    /// Station "99", used by every observed host.
    pub const DEFAULT: Station = Station(0x99);
}

impl Default for Station {
    fn default() -> Self {
        Station::DEFAULT
    }
}

impl fmt::Display for Station {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{:02X}", self.0)
    }
}

/// A station number that is not exactly 2 hex digits.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct StationParseError(pub String);

impl fmt::Display for StationParseError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "`{}` is not a station number: give exactly 2 hex digits, e.g. 99",
            self.0
        )
    }
}

impl std::error::Error for StationParseError {}

impl std::str::FromStr for Station {
    type Err = StationParseError;

    /// Exactly 2 hex digits, either case, as on the wire (PROTOCOL.md 1.3): "99", "0a".
    fn from_str(s: &str) -> Result<Station, StationParseError> {
        match super::hex::parse_hex(s.as_bytes()) {
            Some(v) if s.len() == 2 => Ok(Station(v as u8)),
            _ => Err(StationParseError(s.to_owned())),
        }
    }
}

/// A 3-hex-digit message ID, e.g. `MessageId::AXIS_STATUS` = 212H.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct MessageId(pub u16);

impl MessageId {
    /// 200H test call.
    pub const TEST_CALL: MessageId = MessageId(0x200);
    /// 201H version code query.
    pub const VERSION: MessageId = MessageId(0x201);
    /// 212H axis status query.
    pub const AXIS_STATUS: MessageId = MessageId(0x212);
    /// 215H system status query.
    pub const SYSTEM_STATUS: MessageId = MessageId(0x215);
    /// 216H error detail query.
    pub const ERROR_DETAIL: MessageId = MessageId(0x216);
    /// 232H servo ON/OFF.
    pub const SERVO: MessageId = MessageId(0x232);
    /// 233H home return.
    pub const HOME: MessageId = MessageId(0x233);
    /// 234H absolute-coordinate move.
    pub const MOVE_ABSOLUTE: MessageId = MessageId(0x234);
    /// 235H relative-coordinate move.
    pub const MOVE_RELATIVE: MessageId = MessageId(0x235);
    /// 236H jogging / inching.
    pub const JOG: MessageId = MessageId(0x236);
    /// 238H operation stop and cancel.
    pub const STOP: MessageId = MessageId(0x238);
    /// 252H alarm reset.
    pub const ALARM_RESET: MessageId = MessageId(0x252);
    /// 25BH software reset.
    pub const SOFTWARE_RESET: MessageId = MessageId(0x25B);
    /// 262H speed change.
    pub const SPEED_CHANGE: MessageId = MessageId(0x262);
    /// 2A0H coordinate system definition data query (4 axes per record).
    pub const COORD_QUERY: MessageId = MessageId(0x2A0);
    /// 2A1H SCARA axis status query.
    pub const SCARA_STATUS: MessageId = MessageId(0x2A1);
    /// 2A2H simple interference-check zone definition data query.
    pub const ZONE_QUERY: MessageId = MessageId(0x2A2);
    /// 2A3H SCARA axis status query 2.
    pub const SCARA_STATUS_2: MessageId = MessageId(0x2A3);
    /// 2A4H coordinate system definition data query 2 (axis pattern).
    pub const COORD_QUERY_2: MessageId = MessageId(0x2A4);
    /// 209H effective position data query (3-digit numbers).
    pub const POSITION_QUERY: MessageId = MessageId(0x209);
    /// 21FH effective position data query 2 (4-digit numbers).
    pub const POSITION_QUERY_2: MessageId = MessageId(0x21F);
    /// 22DH effective position data query 3 (4-digit numbers, arm systems).
    pub const POSITION_QUERY_3: MessageId = MessageId(0x22D);
    /// 244H position data range-specification continuous write.
    pub const POSITION_RANGE_WRITE: MessageId = MessageId(0x244);
    /// 245H change position data continuous write.
    pub const POSITION_CHANGE_WRITE: MessageId = MessageId(0x245);
    /// 26BH position-number specification movement 2.
    pub const POSITION_MOVE: MessageId = MessageId(0x26B);
    /// 26DH change position data continuous write 2 (4-digit numbers).
    pub const POSITION_CHANGE_WRITE_2: MessageId = MessageId(0x26D);
    /// 290H position data range write 3 (arm systems).
    pub const POSITION_RANGE_WRITE_3: MessageId = MessageId(0x290);
    /// 291H change position data continuous write 3 (arm systems).
    pub const POSITION_CHANGE_WRITE_3: MessageId = MessageId(0x291);
    /// 2D4H SCARA absolute-coordinate move.
    pub const SCARA_MOVE_ABSOLUTE: MessageId = MessageId(0x2D4);
    /// 2D5H SCARA relative-coordinate move.
    pub const SCARA_MOVE_RELATIVE: MessageId = MessageId(0x2D5);
    /// 2D6H SCARA position-number move.
    pub const SCARA_MOVE_POSITION: MessageId = MessageId(0x2D6);

    /// 20BH input port query.
    pub const INPUT_QUERY: MessageId = MessageId(0x20B);
    /// 20CH output port query.
    pub const OUTPUT_QUERY: MessageId = MessageId(0x20C);
    /// 20DH flag query.
    pub const FLAG_QUERY: MessageId = MessageId(0x20D);
    /// 20EH integer variable query (page not retrieved: layout inferred, PROTOCOL.md 3.39).
    pub const INTEGER_QUERY: MessageId = MessageId(0x20E);
    /// 20FH real variable query.
    pub const REAL_QUERY: MessageId = MessageId(0x20F);
    /// 210H string variable query.
    pub const STRING_QUERY: MessageId = MessageId(0x210);
    /// 24AH output port status change.
    pub const OUTPUT_CHANGE: MessageId = MessageId(0x24A);
    /// 24BH flag status change.
    pub const FLAG_CHANGE: MessageId = MessageId(0x24B);
    /// 24CH integer variable change.
    pub const INTEGER_CHANGE: MessageId = MessageId(0x24C);
    /// 24DH real variable change.
    pub const REAL_CHANGE: MessageId = MessageId(0x24D);
    /// 213H program status query.
    pub const PROGRAM_STATUS: MessageId = MessageId(0x213);
    /// 253H program run.
    pub const PROGRAM_RUN: MessageId = MessageId(0x253);
    /// 254H program end.
    pub const PROGRAM_END: MessageId = MessageId(0x254);
    /// 255H program pause.
    pub const PROGRAM_PAUSE: MessageId = MessageId(0x255);
    /// 256H program one-step run.
    pub const PROGRAM_STEP: MessageId = MessageId(0x256);
    /// 257H program resume.
    pub const PROGRAM_RESUME: MessageId = MessageId(0x257);

    /// Every message ID this library knows, ascending.
    pub const ALL: [MessageId; 47] = [
        Self::TEST_CALL,
        Self::VERSION,
        Self::POSITION_QUERY,
        Self::INPUT_QUERY,
        Self::OUTPUT_QUERY,
        Self::FLAG_QUERY,
        Self::INTEGER_QUERY,
        Self::REAL_QUERY,
        Self::STRING_QUERY,
        Self::AXIS_STATUS,
        Self::PROGRAM_STATUS,
        Self::SYSTEM_STATUS,
        Self::ERROR_DETAIL,
        Self::POSITION_QUERY_2,
        Self::POSITION_QUERY_3,
        Self::SERVO,
        Self::HOME,
        Self::MOVE_ABSOLUTE,
        Self::MOVE_RELATIVE,
        Self::JOG,
        Self::STOP,
        Self::POSITION_RANGE_WRITE,
        Self::POSITION_CHANGE_WRITE,
        Self::OUTPUT_CHANGE,
        Self::FLAG_CHANGE,
        Self::INTEGER_CHANGE,
        Self::REAL_CHANGE,
        Self::ALARM_RESET,
        Self::PROGRAM_RUN,
        Self::PROGRAM_END,
        Self::PROGRAM_PAUSE,
        Self::PROGRAM_STEP,
        Self::PROGRAM_RESUME,
        Self::SOFTWARE_RESET,
        Self::SPEED_CHANGE,
        Self::POSITION_MOVE,
        Self::POSITION_CHANGE_WRITE_2,
        Self::POSITION_RANGE_WRITE_3,
        Self::POSITION_CHANGE_WRITE_3,
        Self::COORD_QUERY,
        Self::SCARA_STATUS,
        Self::ZONE_QUERY,
        Self::SCARA_STATUS_2,
        Self::COORD_QUERY_2,
        Self::SCARA_MOVE_ABSOLUTE,
        Self::SCARA_MOVE_RELATIVE,
        Self::SCARA_MOVE_POSITION,
    ];

    /// The spec's name of the message, or `None` for an ID this library does not know.
    pub const fn name(self) -> Option<&'static str> {
        Some(match self.0 {
            0x200 => "test call",
            0x201 => "version code query",
            0x209 => "effective position data query",
            0x20B => "input port query",
            0x20C => "output port query",
            0x20D => "flag query",
            0x20E => "integer variable query",
            0x20F => "real variable query",
            0x210 => "string variable query",
            0x212 => "axis status query",
            0x213 => "program status query",
            0x215 => "system status query",
            0x216 => "error detail query",
            0x21F => "effective position data query 2",
            0x22D => "effective position data query 3",
            0x232 => "servo ON/OFF",
            0x233 => "home return",
            0x234 => "absolute move",
            0x235 => "relative move",
            0x236 => "jog / inching",
            0x238 => "stop and cancel",
            0x244 => "position data range write",
            0x245 => "change position data write",
            0x24A => "output port status change",
            0x24B => "flag status change",
            0x24C => "integer variable change",
            0x24D => "real variable change",
            0x252 => "alarm reset",
            0x253 => "program run",
            0x254 => "program end",
            0x255 => "program pause",
            0x256 => "program one-step run",
            0x257 => "program resume",
            0x25B => "software reset",
            0x262 => "speed change",
            0x26B => "position-number move 2",
            0x26D => "change position data write 2",
            0x290 => "position data range write 3",
            0x291 => "change position data write 3",
            0x2A0 => "coordinate system data query",
            0x2A1 => "SCARA axis status query",
            0x2A2 => "interference-check zone data query",
            0x2A3 => "SCARA axis status query 2",
            0x2A4 => "coordinate system data query 2",
            0x2D4 => "SCARA absolute move",
            0x2D5 => "SCARA relative move",
            0x2D6 => "SCARA position-number move",
            _ => return None,
        })
    }

    /// Whether the normal reply to this message is the plain 10-character acknowledge
    /// (`#` + station + ID + SC) (PROTOCOL.md 1.3 and section 3).
    pub const fn is_plain_ack(self) -> bool {
        matches!(
            self.0,
            0x232
                | 0x233
                | 0x234
                | 0x235
                | 0x236
                | 0x238
                | 0x24A
                | 0x24B
                | 0x252
                | 0x253
                | 0x254
                | 0x255
                | 0x256
                | 0x257
                | 0x25B
                | 0x262
                | 0x26B
                | 0x2D4
                | 0x2D5
                | 0x2D6
        )
    }
}

impl fmt::Display for MessageId {
    /// Written as in the spec: `212H`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{:03X}H", self.0)
    }
}

/// A controller error number: 3 hex digits (PROTOCOL.md section 2). `000` means none.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Default)]
pub struct ErrorCode(pub u16);

impl ErrorCode {
    /// `000`: no error.
    pub const NONE: ErrorCode = ErrorCode(0);
    /// CC1: speed change condition error (262H on an S-motion axis) [spec p.57].
    pub const SPEED_CHANGE_CONDITION: ErrorCode = ErrorCode(0xCC1);
    /// C74: actual position beyond the soft limit (vendor manual; PROTOCOL.md section 2).
    pub const SOFT_LIMIT: ErrorCode = ErrorCode(0xC74);

    /// The meaning a real controller gives this number, where known.
    pub const fn text(self) -> Option<&'static str> {
        match self.0 {
            0 => Some("no error"),
            0xCC1 => Some("speed change condition error"),
            0xC74 => Some("actual position beyond the soft limit"),
            _ => None,
        }
    }

    /// The meaning the built-in simulator gives this number, where the controller's own
    /// is not known: the one table of its codes (`sim::CODE_TABLE` takes its texts from
    /// here, and the controller's text where there is one). [inferred] Only C74 and CC1 are
    /// real controller numbers (PROTOCOL.md section 2); the others are the simulator's.
    pub const fn sim_text(self) -> Option<&'static str> {
        match self.0 {
            0xA01 => Some("unknown message ID"),
            0xA02 => Some("wrong data length for this message"),
            0xA03 => Some("field value invalid or out of range"),
            0xA04 => Some("axis pattern invalid for this message or controller"),
            0xB01 => Some("servo off on an axis to move"),
            0xB02 => Some("axis not homed"),
            0xB03 => Some("axis busy (moving, homing or switching servo)"),
            0xB04 => Some("emergency stop active"),
            0xB05 => Some("controller in MANUAL mode"),
            0xB06 => Some("drive source cut off"),
            0xB07 => Some("alarm pending (reset with 252H)"),
            0xB08 => Some("target or path outside the arm's reach"),
            0xB09 => Some("target needs the other arm system; switching not allowed"),
            0xB0A => Some("position number holds no data for these axes"),
            0xB0B => Some("no program with this number"),
            0xB0C => Some("program not in a state for this (started, running or not started)"),
            _ => None,
        }
    }

    /// Words for an operator: the controller's meaning, else the simulator's (said to be
    /// the simulator's), else that the number is not in the table.
    pub fn describe(self) -> String {
        match (self.text(), self.sim_text()) {
            (Some(t), _) => t.to_owned(),
            (None, Some(t)) => format!("{t} (the simulator's meaning)"),
            (None, None) => "not in the pendant's code table".to_owned(),
        }
    }
}

impl fmt::Display for ErrorCode {
    /// The 3 hex digits, plus the meaning where known: `CC1 (speed change condition error)`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{:03X}", self.0)?;
        match (self.text(), self.sim_text()) {
            (Some(t), _) => write!(f, " ({t})"),
            (None, Some(t)) => write!(f, " ({t}, the simulator's meaning)"),
            (None, None) => Ok(()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn displays_as_in_the_spec() {
        assert_eq!(MessageId::SCARA_MOVE_RELATIVE.to_string(), "2D5H");
        assert_eq!(Station::default().to_string(), "99");
        assert_eq!(
            ErrorCode(0xCC1).to_string(),
            "CC1 (speed change condition error)"
        );
        assert_eq!(ErrorCode(0x0A2).to_string(), "0A2");
    }

    #[test]
    fn a_station_is_exactly_two_hex_digits() {
        assert_eq!("99".parse(), Ok(Station(0x99)));
        assert_eq!("0a".parse(), Ok(Station(0x0A)));
        assert_eq!("FF".parse(), Ok(Station(0xFF)));
        for bad in ["9", "099", "+9", "", "9G", " 9", "99 ", "\u{e9}"] {
            let e = bad.parse::<Station>().unwrap_err();
            assert_eq!(
                e.to_string(),
                format!("`{bad}` is not a station number: give exactly 2 hex digits, e.g. 99")
            );
        }
    }

    #[test]
    fn every_known_id_has_a_name() {
        for id in MessageId::ALL {
            assert!(id.name().is_some(), "{id}");
        }
        assert_eq!(MessageId(0x2FF).name(), None);
    }

    #[test]
    fn header_bytes_round_trip() {
        for h in [Header::Command, Header::Reply, Header::Error] {
            assert_eq!(Header::from_byte(h.byte()), Some(h));
        }
        assert_eq!(Header::from_byte(b':'), None);
    }
}
