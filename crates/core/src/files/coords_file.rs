//! Coordinate-table files (TOML): work and tool coordinate systems and the 2D6H position
//! table, as the simulator loads them and the pendant saves its table drafts.
//!
//! Layout (every section optional; numbers not listed stay all zeros; lengths in mm and
//! angles in deg, resolution 0.001 as on the wire):
//!
//! ```toml
//! format = "xsel-coords 1"
//! [[work]]                # work coordinate system No. 1 (No. 0 is the base frame)
//! number = 1
//! x = 300.0
//! y = -100.0
//! z = 0.0
//! r = 30.0
//! name = "fixture"        # optional, for people
//! [[tool]]
//! number = 1
//! z = -35.0
//! [[position]]            # a 2D6H position record, in work coordinates
//! number = 1
//! x = 300.0
//! y = 50.0                # omitted coordinates: the axis is not part of the record
//! speed = 0               # optional: 0 = parameter value (% for PTP, mm/s for CP)
//! ```

use std::collections::BTreeMap;
use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::robot::{CoordSystem, CoordTables, FrameKind, Micrometres, Millidegrees, RobotModel};

/// The `format` value this module writes (and the only one it reads).
pub const FORMAT: &str = "xsel-coords 1";

/// One 2D6H position record: coordinates of axes 1-6 in the selected work frame (axes
/// 5-6: mm), `None` = axis not in the record; speed/accel/decel 0 = parameter value.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct PositionRecord {
    pub values: [Option<i32>; 6],
    pub speed: u16,
    pub accel: u16,
    pub decel: u16,
}

impl PositionRecord {
    /// Axis pattern of the axes the record holds.
    pub fn pattern(&self) -> u8 {
        self.values
            .iter()
            .enumerate()
            .filter(|(_, v)| v.is_some())
            .fold(0, |p, (i, _)| p | (1 << i))
    }
}

/// Position number -> record.
pub type PositionTable = BTreeMap<u16, PositionRecord>;

#[derive(Debug, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct FileDoc {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    format: Option<String>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    work: Vec<FileFrame>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    tool: Vec<FileFrame>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    position: Vec<FilePosition>,
}

#[derive(Debug, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct FileFrame {
    number: usize,
    #[serde(default)]
    x: f64,
    #[serde(default)]
    y: f64,
    #[serde(default)]
    z: f64,
    #[serde(default)]
    r: f64,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    name: Option<String>,
}

#[derive(Debug, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct FilePosition {
    number: u16,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    x: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    y: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    z: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    r: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    axis5: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    axis6: Option<f64>,
    #[serde(default)]
    speed: u16,
    #[serde(default)]
    accel: u16,
    #[serde(default)]
    decel: u16,
}

/// Why a coordinate file could not be used.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum CoordsFileError {
    #[error("coordinate file {path}: {message}")]
    Io { path: String, message: String },
    #[error("coordinate file: {0}")]
    Syntax(String),
    #[error("coordinate file: format `{0}` is not `{FORMAT}`")]
    Format(String),
    #[error("coordinate file: {0}")]
    Entry(String),
}

/// Work/tool tables and position table read from a file.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CoordsFile {
    pub tables: CoordTables,
    pub positions: PositionTable,
}

fn wire(v: f64, what: &str) -> Result<i32, CoordsFileError> {
    if !v.is_finite() || v.abs() > 2_000_000.0 {
        return Err(CoordsFileError::Entry(format!(
            "{what}: {v} is not a usable value"
        )));
    }
    Ok(Micrometres::from_mm(v).0)
}

/// Parses a coordinate file's text for a robot model (table sizes come from the model).
pub fn parse(text: &str, model: &RobotModel) -> Result<CoordsFile, CoordsFileError> {
    let doc: FileDoc = toml::from_str(text).map_err(|e| CoordsFileError::Syntax(e.to_string()))?;
    if let Some(f) = &doc.format
        && f != FORMAT
    {
        return Err(CoordsFileError::Format(f.clone()));
    }
    let mut tables = CoordTables::for_model(model);
    for (kind, list) in [(FrameKind::Work, &doc.work), (FrameKind::Tool, &doc.tool)] {
        for e in list {
            let what = format!("{kind} No. {}", e.number);
            let cs = CoordSystem {
                x: Micrometres(wire(e.x, &what)?),
                y: Micrometres(wire(e.y, &what)?),
                z: Micrometres(wire(e.z, &what)?),
                r: Millidegrees(wire(e.r, &what)?),
            };
            let table = match kind {
                FrameKind::Work => &mut tables.work,
                FrameKind::Tool => &mut tables.tool,
            };
            table
                .set(e.number, cs)
                .map_err(|err| CoordsFileError::Entry(err.to_string()))?;
        }
    }
    let mut positions = PositionTable::new();
    for p in &doc.position {
        let what = format!("position No. {}", p.number);
        let mut values = [None; 6];
        for (slot, v) in values
            .iter_mut()
            .zip([p.x, p.y, p.z, p.r, p.axis5, p.axis6])
        {
            *slot = v.map(|v| wire(v, &what)).transpose()?;
        }
        positions.insert(
            p.number,
            PositionRecord {
                values,
                speed: p.speed,
                accel: p.accel,
                decel: p.decel,
            },
        );
    }
    Ok(CoordsFile { tables, positions })
}

/// Reads and parses a coordinate file.
pub fn load(path: impl AsRef<Path>, model: &RobotModel) -> Result<CoordsFile, CoordsFileError> {
    let path = path.as_ref();
    let text = crate::files::read_text_bounded(path, crate::files::CONFIG_LIMIT).map_err(|e| {
        CoordsFileError::Io {
            path: path.display().to_string(),
            message: e,
        }
    })?;
    parse(&text, model)
}

/// Writes tables and positions in the file format (non-zero entries only).
pub fn to_toml(tables: &CoordTables, positions: &PositionTable) -> String {
    let mm = |v: i32| crate::protocol::Milli(v).units();
    let frames = |entries: &[CoordSystem]| {
        entries
            .iter()
            .enumerate()
            .filter(|(_, cs)| **cs != CoordSystem::ZERO)
            .map(|(number, cs)| FileFrame {
                number,
                x: mm(cs.x.0),
                y: mm(cs.y.0),
                z: mm(cs.z.0),
                r: mm(cs.r.0),
                name: None,
            })
            .collect()
    };
    let doc = FileDoc {
        format: Some(FORMAT.to_owned()),
        work: frames(tables.work.entries()),
        tool: frames(tables.tool.entries()),
        position: positions
            .iter()
            .map(|(&number, p)| {
                let v = p.values.map(|v| v.map(mm));
                FilePosition {
                    number,
                    x: v[0],
                    y: v[1],
                    z: v[2],
                    r: v[3],
                    axis5: v[4],
                    axis6: v[5],
                    speed: p.speed,
                    accel: p.accel,
                    decel: p.decel,
                }
            })
            .collect(),
    };
    toml::to_string(&doc).unwrap_or_default()
}

/// The shipped example (`assets/coords/example.toml`), compiled in: the simulator's
/// default tables.
pub const EXAMPLE: &str = include_str!("../../../../assets/coords/example.toml");

/// The default tables and positions for a model: the shipped example, or empty tables if
/// it does not fit the model.
pub fn defaults(model: &RobotModel) -> CoordsFile {
    parse(EXAMPLE, model).unwrap_or_else(|_| CoordsFile {
        tables: CoordTables::for_model(model),
        positions: PositionTable::new(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn example_loads_and_round_trips() {
        let model = RobotModel::default_model();
        let f = parse(EXAMPLE, &model).unwrap();
        assert_ne!(f.tables.work.get(1), Some(&CoordSystem::ZERO));
        assert_ne!(f.tables.tool.get(1), Some(&CoordSystem::ZERO));
        assert!(!f.positions.is_empty());
        let again = parse(&to_toml(&f.tables, &f.positions), &model).unwrap();
        assert_eq!(again, f);
    }

    #[test]
    fn bad_files_are_refused_with_a_reason() {
        let model = RobotModel::default_model();
        assert!(matches!(
            parse("work = 3", &model),
            Err(CoordsFileError::Syntax(_))
        ));
        assert!(matches!(
            parse("[[work]]\nnumber = 0\nx = 1.0", &model),
            Err(CoordsFileError::Entry(_))
        ));
        assert!(matches!(
            parse("[[tool]]\nnumber = 9999", &model),
            Err(CoordsFileError::Entry(_))
        ));
        assert!(matches!(
            parse("format = \"other\"", &model),
            Err(CoordsFileError::Format(_))
        ));
        assert!(parse("[[work]]\nnumber = 1\nx = nan", &model).is_err());
    }
}
