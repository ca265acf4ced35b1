//! Wire units as types: 0.001 of the axis unit, 0.01 G, mm/s, percent.

use std::fmt;

/// A position, distance or offset in thousandths of the axis unit, as sent on the wire:
/// 0.001 mm for linear axes, 0.001 deg for rotary ones (micrometres / millidegrees): the
/// one wire unit of positions.
/// Signed 32-bit, sent as 8 hex digits in two's complement: -5.000 mm = `FFFFEC78`
/// (PROTOCOL.md section 4).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Milli(pub i32);

impl Milli {
    /// Zero.
    pub const ZERO: Milli = Milli(0);

    /// From a value in axis units (mm or deg), rounded to the nearest 0.001;
    /// `None` when it does not fit or is not finite.
    pub fn from_units(v: f64) -> Option<Milli> {
        let t = (v * 1000.0).round();
        if t.is_finite() && t >= f64::from(i32::MIN) && t <= f64::from(i32::MAX) {
            Some(Milli(t as i32))
        } else {
            None
        }
    }

    /// The value in axis units (mm or deg).
    pub fn units(self) -> f64 {
        f64::from(self.0) / 1000.0
    }

    /// The wire form: the 32-bit two's complement pattern.
    pub const fn to_wire(self) -> u32 {
        self.0 as u32
    }

    /// From the wire form (two's complement).
    pub const fn from_wire(w: u32) -> Milli {
        Milli(w as i32)
    }

    /// Displays with the given unit: `-5.000 mm`.
    pub fn with_unit(self, unit: AxisUnit) -> impl fmt::Display {
        struct D(Milli, AxisUnit);
        impl fmt::Display for D {
            fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                write!(f, "{} {}", self.0, self.1)
            }
        }
        D(self, unit)
    }
}

impl fmt::Display for Milli {
    /// Three decimals, no unit: `-5.000`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let v = i64::from(self.0);
        let sign = if v < 0 { "-" } else { "" };
        let a = v.abs();
        write!(f, "{sign}{}.{:03}", a / 1000, a % 1000)
    }
}

/// The unit of a per-axis value: linear axes in mm, rotary axes in deg.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum AxisUnit {
    /// Millimetres (0.001 mm on the wire).
    Mm,
    /// Degrees (0.001 deg on the wire).
    Deg,
}

impl fmt::Display for AxisUnit {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            AxisUnit::Mm => "mm",
            AxisUnit::Deg => "deg",
        })
    }
}

/// Acceleration or deceleration in 0.01 G (4 hex digits); 0 = use the parameter value.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct CentiG(pub u16);

impl fmt::Display for CentiG {
    /// `0.30 G`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}.{:02} G", self.0 / 100, self.0 % 100)
    }
}

/// Speed in mm/s (4 hex digits; 3 in 233H); 0 = use the parameter value.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct MmPerSec(pub u16);

impl fmt::Display for MmPerSec {
    /// `100 mm/s`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} mm/s", self.0)
    }
}

/// A percentage (of the parameter maximum), 4 hex digits: SCARA PTP acc/dec/speed and
/// each-axis jogging. 0 = use the parameter value.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Percent(pub u16);

impl fmt::Display for Percent {
    /// `30 %`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} %", self.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn negative_coordinates_use_twos_complement() {
        assert_eq!(Milli(-5000).to_wire(), 0xFFFF_EC78);
        assert_eq!(Milli::from_wire(0xFFFF_EC78), Milli(-5000));
        assert_eq!(Milli::from_wire(0xFFFF_CFC7), Milli(-12_345));
    }

    #[test]
    fn displays_three_decimals_and_units() {
        assert_eq!(
            Milli(-5000).with_unit(AxisUnit::Mm).to_string(),
            "-5.000 mm"
        );
        assert_eq!(
            Milli(45_000).with_unit(AxisUnit::Deg).to_string(),
            "45.000 deg"
        );
        assert_eq!(Milli(-5).to_string(), "-0.005");
        assert_eq!(Milli(i32::MIN).to_string(), "-2147483.648");
        assert_eq!(CentiG(30).to_string(), "0.30 G");
        assert_eq!(MmPerSec(100).to_string(), "100 mm/s");
        assert_eq!(Percent(30).to_string(), "30 %");
    }

    #[test]
    fn from_units_rounds_and_bounds() {
        assert_eq!(Milli::from_units(-12.345), Some(Milli(-12_345)));
        assert_eq!(Milli::from_units(1e12), None);
        assert_eq!(Milli::from_units(f64::NAN), None);
    }
}
