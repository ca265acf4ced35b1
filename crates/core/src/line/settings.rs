//! Serial line settings (baud, data bits, parity, stop bits) and the wire time they imply.

use std::fmt;
use std::time::Duration;

/// Parity bit of a serial character.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
pub enum Parity {
    #[default]
    None,
    Odd,
    Even,
}

impl Parity {
    pub const ALL: [Parity; 3] = [Parity::None, Parity::Odd, Parity::Even];

    /// "none", "odd", "even".
    pub fn name(self) -> &'static str {
        match self {
            Parity::None => "none",
            Parity::Odd => "odd",
            Parity::Even => "even",
        }
    }
}

/// Settings of an RS-232C line as the controller's I/O parameters 92-95 allow them
/// (PROTOCOL.md 1.1).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LineSettings {
    pub baud: u32,
    /// 7 or 8.
    pub data_bits: u8,
    pub parity: Parity,
    /// 1 or 2.
    pub stop_bits: u8,
}

impl Default for LineSettings {
    fn default() -> Self {
        Self {
            baud: 115_200,
            data_bits: 8,
            parity: Parity::None,
            stop_bits: 1,
        }
    }
}

/// Baud rates offered to the user: the X-SEL family's (PROTOCOL.md 1.1) plus 230400 for
/// serial-to-Ethernet bridges.
pub const STANDARD_BAUDS: [u32; 6] = [9_600, 19_200, 38_400, 57_600, 115_200, 230_400];

/// The line rates accepted anywhere (the pendant's line, the simulator's pacing): the
/// X-SEL family's 9600 to 115200 (PROTOCOL.md 1.1) and 230400 for serial-to-Ethernet
/// bridges.
pub const BAUD_RANGE: std::ops::RangeInclusive<u32> = 9_600..=230_400;

/// Why a line setting cannot be used.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum LineSettingsError {
    #[error("baud rate {0} is outside 9600-230400")]
    Baud(u32),
    #[error("data bits must be 7 or 8, not {0}")]
    DataBits(u8),
    #[error("stop bits must be 1 or 2, not {0}")]
    StopBits(u8),
}

impl LineSettings {
    /// Checks the values against what the controller and this program support.
    pub fn validate(&self) -> Result<(), LineSettingsError> {
        if !BAUD_RANGE.contains(&self.baud) {
            return Err(LineSettingsError::Baud(self.baud));
        }
        if !matches!(self.data_bits, 7 | 8) {
            return Err(LineSettingsError::DataBits(self.data_bits));
        }
        if !matches!(self.stop_bits, 1 | 2) {
            return Err(LineSettingsError::StopBits(self.stop_bits));
        }
        Ok(())
    }

    /// Bits one character occupies on the wire: start + data + parity + stop.
    pub fn bits_per_char(&self) -> u32 {
        1 + u32::from(self.data_bits)
            + u32::from(self.parity != Parity::None)
            + u32::from(self.stop_bits)
    }

    /// Time one character takes on the wire.
    pub fn byte_time(&self) -> Duration {
        Duration::from_nanos(
            1_000_000_000 * u64::from(self.bits_per_char()) / u64::from(self.baud.max(1)),
        )
    }

    /// Time `bytes` characters take on the wire.
    pub fn wire_time(&self, bytes: usize) -> Duration {
        Duration::from_nanos(
            1_000_000_000 * u64::from(self.bits_per_char()) * bytes as u64
                / u64::from(self.baud.max(1)),
        )
    }
}

impl fmt::Display for LineSettings {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let parity = match self.parity {
            Parity::None => 'N',
            Parity::Odd => 'O',
            Parity::Even => 'E',
        };
        write!(
            f,
            "{} {}{}{}",
            self.baud, self.data_bits, parity, self.stop_bits
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn eight_n_one_at_9600_is_about_a_millisecond_a_byte() {
        let line = LineSettings {
            baud: 9_600,
            ..LineSettings::default()
        };
        assert_eq!(line.bits_per_char(), 10);
        assert_eq!(line.byte_time(), Duration::from_nanos(1_041_666));
        assert_eq!(line.to_string(), "9600 8N1");
    }

    #[test]
    fn parity_and_two_stop_bits_lengthen_a_character() {
        let line = LineSettings {
            baud: 38_400,
            data_bits: 7,
            parity: Parity::Even,
            stop_bits: 2,
        };
        assert_eq!(line.bits_per_char(), 11);
        assert_eq!(line.to_string(), "38400 7E2");
    }

    #[test]
    fn out_of_range_values_are_named() {
        let bad = LineSettings {
            baud: 300,
            ..LineSettings::default()
        };
        assert_eq!(
            bad.validate().unwrap_err().to_string(),
            "baud rate 300 is outside 9600-230400"
        );
        let bad = LineSettings {
            data_bits: 6,
            ..LineSettings::default()
        };
        assert_eq!(bad.validate().unwrap_err(), LineSettingsError::DataBits(6));
    }
}
