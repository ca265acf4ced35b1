//! One cell of a coordinate table: its column, how it is shown, and the checks an entry
//! passes before it reaches the draft (format, resolution 0.001, range, work No. 0).

use crate::protocol::Milli;
use crate::robot::{CoordSystem, FrameKind};

use crate::pendant::teach::file::parse_milli;

/// A column of a coordinate table.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Column {
    X,
    Y,
    Z,
    R,
}

impl Column {
    pub const ALL: [Column; 4] = [Column::X, Column::Y, Column::Z, Column::R];

    /// Index in [`CoordSystem::to_wire`].
    pub fn index(self) -> usize {
        match self {
            Column::X => 0,
            Column::Y => 1,
            Column::Z => 2,
            Column::R => 3,
        }
    }

    /// The heading with its unit: `X mm`, `R deg`.
    pub fn heading(self) -> &'static str {
        match self {
            Column::X => "X mm",
            Column::Y => "Y mm",
            Column::Z => "Z mm",
            Column::R => "R deg",
        }
    }

    /// The file column name: `x_mm`, `r_deg`.
    pub fn file_name(self) -> &'static str {
        match self {
            Column::X => "x_mm",
            Column::Y => "y_mm",
            Column::Z => "z_mm",
            Column::R => "r_deg",
        }
    }

    /// The largest magnitude an entry may have, in wire units (0.001 mm / 0.001 deg).
    /// `[inferred]`: PROTOCOL.md gives only the signed 32-bit field; the limits are the
    /// controller's usual parameter ranges (5 integer digits for lengths, a full turn
    /// either way for R).
    pub fn limit(self) -> i32 {
        match self {
            Column::R => 360_000,
            _ => LENGTH_LIMIT,
        }
    }

    pub fn get(self, cs: &CoordSystem) -> i32 {
        cs.to_wire()[self.index()]
    }

    pub fn with(self, cs: &CoordSystem, value: i32) -> CoordSystem {
        let mut w = cs.to_wire();
        w[self.index()] = value;
        CoordSystem::from_wire(w)
    }
}

/// The largest length an entry may have, 0.001 mm: 5 integer digits, the controller's
/// usual parameter range `[inferred]` (PROTOCOL.md gives only the signed 32-bit field).
/// Position records' coordinates take the same.
pub const LENGTH_LIMIT: i32 = 99_999_999;

/// How a value is shown and written: three decimals, `-12.345`.
pub fn show(value: i32) -> String {
    Milli(value).to_string()
}

/// Checks a typed entry for `column`; the value in wire units, or why it is refused.
pub fn parse_entry(column: Column, text: &str) -> Result<i32, String> {
    let v = parse_milli(text)?;
    check_range(column, v)?;
    Ok(v)
}

/// Refuses a value beyond the column's range.
pub fn check_range(column: Column, v: i32) -> Result<(), String> {
    let limit = column.limit();
    if v.unsigned_abs() > limit.unsigned_abs() {
        return Err(format!(
            "{} is out of range ({} to {})",
            show(v),
            show(-limit),
            show(limit)
        ));
    }
    Ok(())
}

/// Work No. 0 is the base frame and stays all zeros (PROTOCOL.md 3.16, `[spec]` tables
/// number from 0; the fixed zero is the controller's convention `[inferred]`).
pub fn read_only(kind: FrameKind, number: usize) -> bool {
    kind == FrameKind::Work && number == 0
}

/// The message for an edit of a read-only row.
pub const READ_ONLY: &str = "work No. 0 is the base frame and stays zero";

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn entries_are_checked_for_format_resolution_and_range() {
        assert_eq!(parse_entry(Column::X, " -12.5 "), Ok(-12_500));
        assert_eq!(parse_entry(Column::R, "359.999"), Ok(359_999));
        assert!(
            parse_entry(Column::X, "12,5")
                .unwrap_err()
                .contains("not a number")
        );
        assert!(
            parse_entry(Column::X, "1.0005")
                .unwrap_err()
                .contains("0.001")
        );
        assert!(
            parse_entry(Column::X, "100000")
                .unwrap_err()
                .contains("out of range")
        );
        assert!(
            parse_entry(Column::R, "-360.001")
                .unwrap_err()
                .contains("out of range")
        );
        assert!(parse_entry(Column::Y, "").is_err());
        assert!(read_only(FrameKind::Work, 0));
        assert!(!read_only(FrameKind::Tool, 0));
    }
}
