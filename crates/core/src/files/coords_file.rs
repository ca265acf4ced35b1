//! Coordinate-table files (TOML): work and tool coordinate systems, the 2D6H position
//! table and the interference-check zones, as the simulator loads them and the pendant
//! saves its table drafts.
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
//! [[position]]            # a position record (2D6H, 26BH, 209H...), work coordinates
//! number = 1              # 1 to 20000 (PROTOCOL.md 3.24)
//! x = 300.0
//! y = 50.0                # omitted coordinates: the axis is not part of the record
//! speed = 0               # optional: 0 = parameter value (% for PTP, mm/s for CP)
//! arm = "right"           # optional: SCARA 1's arm system, "right" or "left"
//! [[zone]]                # a simple interference-check zone (2A2H), base coordinates
//! number = 1              # 1 to 10 (protocol::ZONE_NUMBERS)
//! corner1 = [100.0, -100.0, 0.0]   # X, Y, Z of one corner, mm
//! corner2 = [200.0, 100.0, 50.0]   # the opposite corner
//! name = "feeder"         # optional, for people
//! ```
//!
//! Zones are boxes on X, Y and Z only (pattern 07, as PROTOCOL.md 3.46's example): the
//! simulator's choice, so that every record of a 2A2H reply has one length `[inferred]`.
//! Files written before zones existed load unchanged (no zones).
//!
//! A position with no coordinate holds no data and is not loaded (a controller's position
//! with no axis is not "effective", PROTOCOL.md 3.25 `[inferred]`). Files written before
//! `arm` existed load unchanged (no arm system).

use std::collections::BTreeMap;
use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::protocol::{
    Axis, CentiG, Milli, MmPerSec, PerAxis, PositionRecord, RecordArm, RecordArms, ZONE_NUMBERS,
    ZoneRecord,
};
use crate::robot::{CoordSystem, CoordTables, FrameKind, Micrometres, Millidegrees, RobotModel};

/// The `format` value this module writes (and the only one it reads).
pub const FORMAT: &str = "xsel-coords 1";

/// The highest position number a file may hold: the 4-digit controllers' 20000
/// (PROTOCOL.md 3.24, `[spec p.60, p.63, p.64]` arithmetic).
pub const MAX_POSITION_NUMBER: u16 = 20_000;

/// Position number -> record (its `number` equal to the key): the simulator's position
/// table and what the file holds. Axes 1-4 are the SCARA's X, Y, Z, R in the selected
/// work frame, axes 5-6 the linear axes (mm).
pub type PositionTable = BTreeMap<u16, PositionRecord>;

/// Zone number -> record: the simulator's interference-check zones (2A2H) and what the
/// file holds. Corners on X, Y, Z of the base frame (axes 1-3).
pub type Zones = BTreeMap<u8, ZoneRecord>;

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
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    zone: Vec<FileZone>,
}

#[derive(Debug, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct FileZone {
    number: u8,
    corner1: [f64; 3],
    corner2: [f64; 3],
    #[serde(default, skip_serializing_if = "Option::is_none")]
    name: Option<String>,
}

/// The axes of a file zone's corners: X, Y, Z.
const ZONE_AXES: [Axis; 3] = [Axis::A1, Axis::A2, Axis::A3];

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
    /// SCARA 1's arm system; absent = no specification.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    arm: Option<FileArm>,
}

/// The arm system a file's position names.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
enum FileArm {
    Right,
    Left,
}

/// The file's axes in axis order: x, y, z, r (SCARA 1-4), axis5, axis6.
const FILE_AXES: [Axis; 6] = [Axis::A1, Axis::A2, Axis::A3, Axis::A4, Axis::A5, Axis::A6];

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

/// Work/tool tables, position table and zones read from a file.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CoordsFile {
    pub tables: CoordTables,
    pub positions: PositionTable,
    pub zones: Zones,
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
        if !(1..=MAX_POSITION_NUMBER).contains(&p.number) {
            return Err(CoordsFileError::Entry(format!(
                "{what}: numbers run from 1 to {MAX_POSITION_NUMBER}"
            )));
        }
        let mut coords = PerAxis::new();
        for (axis, v) in FILE_AXES
            .into_iter()
            .zip([p.x, p.y, p.z, p.r, p.axis5, p.axis6])
        {
            if let Some(v) = v {
                coords.set(axis, Milli(wire(v, &what)?));
            }
        }
        let scara1 = match p.arm {
            None => RecordArm::Unspecified,
            Some(FileArm::Right) => RecordArm::Right,
            Some(FileArm::Left) => RecordArm::Left,
        };
        if scara1 != RecordArm::Unspecified && coords.pattern().0 & 0x0F == 0 {
            return Err(CoordsFileError::Entry(format!(
                "{what}: an arm system needs a SCARA coordinate (x, y, z or r)"
            )));
        }
        if coords.is_empty() {
            continue;
        }
        positions.insert(
            p.number,
            PositionRecord {
                number: p.number,
                coords,
                accel: CentiG(p.accel),
                decel: CentiG(p.decel),
                speed: MmPerSec(p.speed),
                arms: RecordArms {
                    scara1,
                    scara2: RecordArm::Unspecified,
                },
            },
        );
    }
    let zones = parse_zones(&doc.zone)?;
    Ok(CoordsFile {
        tables,
        positions,
        zones,
    })
}

fn parse_zones(list: &[FileZone]) -> Result<Zones, CoordsFileError> {
    let mut zones = Zones::new();
    for z in list {
        let what = format!("zone No. {}", z.number);
        if !ZONE_NUMBERS.contains(&z.number) {
            return Err(CoordsFileError::Entry(format!(
                "{what}: numbers run from {} to {}",
                ZONE_NUMBERS.start(),
                ZONE_NUMBERS.end()
            )));
        }
        let corner = |c: &[f64; 3]| -> Result<PerAxis<Milli>, CoordsFileError> {
            let mut p = PerAxis::new();
            for (axis, v) in ZONE_AXES.into_iter().zip(c) {
                p.set(axis, Milli(wire(*v, &what)?));
            }
            Ok(p)
        };
        let rec = ZoneRecord::new(corner(&z.corner1)?, corner(&z.corner2)?);
        if zones.insert(z.number, rec).is_some() {
            return Err(CoordsFileError::Entry(format!("{what} is given twice")));
        }
    }
    Ok(zones)
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

/// Writes tables, positions and zones in the file format (non-zero entries only; axes
/// 7-8, SCARA 2's arm system and zone axes other than X, Y, Z, which this single-SCARA
/// format has no place for, are left out).
pub fn to_toml(tables: &CoordTables, positions: &PositionTable, zones: &Zones) -> String {
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
                let v = FILE_AXES.map(|a| p.coords.get(a).map(|v| mm(v.0)));
                FilePosition {
                    number,
                    x: v[0],
                    y: v[1],
                    z: v[2],
                    r: v[3],
                    axis5: v[4],
                    axis6: v[5],
                    speed: p.speed.0,
                    accel: p.accel.0,
                    decel: p.decel.0,
                    arm: match p.arms.scara1 {
                        RecordArm::Unspecified => None,
                        RecordArm::Right => Some(FileArm::Right),
                        RecordArm::Left => Some(FileArm::Left),
                    },
                }
            })
            .collect(),
        zone: zones
            .iter()
            .map(|(&number, z)| {
                let corner =
                    |c: &PerAxis<Milli>| ZONE_AXES.map(|a| mm(c.get(a).unwrap_or_default().0));
                FileZone {
                    number,
                    corner1: corner(&z.corner1),
                    corner2: corner(&z.corner2),
                    name: None,
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
        zones: Zones::new(),
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
        assert!(f.zones.len() >= 2, "the built-in simulator shows zones");
        let again = parse(&to_toml(&f.tables, &f.positions, &f.zones), &model).unwrap();
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
        for bad in [
            "[[position]]\nnumber = 0\nx = 1.0",
            "[[position]]\nnumber = 20001\nx = 1.0",
            "[[position]]\nnumber = 3\naxis5 = 1.0\narm = \"left\"",
        ] {
            assert!(
                matches!(parse(bad, &model), Err(CoordsFileError::Entry(_))),
                "{bad}"
            );
        }
        assert!(matches!(
            parse("[[position]]\nnumber = 3\nx = 1.0\narm = \"up\"", &model),
            Err(CoordsFileError::Syntax(_))
        ));
    }

    #[test]
    fn positions_keep_their_arm_system_and_old_files_load() {
        let model = RobotModel::default_model();
        let text = "[[position]]\nnumber = 7\nx = 300.0\ny = -150.0\nr = 45.5\nspeed = 20\narm = \"left\"\n\
                    [[position]]\nnumber = 8\naxis6 = 12.5\naccel = 30\n\
                    [[position]]\nnumber = 9\n";
        let f = parse(text, &model).unwrap();
        let p7 = f.positions[&7];
        assert_eq!(p7.number, 7);
        assert_eq!(p7.coords.pattern().0, 0b1011);
        assert_eq!(p7.coords.get(Axis::A4), Some(Milli(45_500)));
        assert_eq!(p7.speed, MmPerSec(20));
        assert_eq!(p7.arms.scara1, RecordArm::Left);
        let p8 = f.positions[&8];
        assert_eq!(p8.coords.pattern().0, 0b10_0000);
        assert_eq!((p8.accel, p8.arms), (CentiG(30), RecordArms::default()));
        assert!(
            !f.positions.contains_key(&9),
            "a position with no axis holds no data"
        );
        let again = parse(&to_toml(&f.tables, &f.positions, &f.zones), &model).unwrap();
        assert_eq!(again.positions, f.positions);
        assert!(f.zones.is_empty(), "a file without zones has none");
    }

    #[test]
    fn zones_load_by_two_corners_and_bad_ones_are_refused() {
        let model = RobotModel::default_model();
        let text = "[[zone]]\nnumber = 2\ncorner1 = [100.0, -100.0, 0.0]\ncorner2 = [200.0, 100.0, 50.0]\nname = \"feeder\"\n";
        let f = parse(text, &model).unwrap();
        let z = &f.zones[&2];
        assert_eq!(z.corner1.pattern().0, 0b111);
        assert_eq!(z.corner1.get(Axis::A2), Some(Milli(-100_000)));
        assert_eq!(z.corner2.get(Axis::A3), Some(Milli(50_000)));
        let again = parse(&to_toml(&f.tables, &f.positions, &f.zones), &model).unwrap();
        assert_eq!(again.zones, f.zones);
        for bad in [
            "[[zone]]\nnumber = 0\ncorner1 = [0.0, 0.0, 0.0]\ncorner2 = [1.0, 1.0, 1.0]",
            "[[zone]]\nnumber = 11\ncorner1 = [0.0, 0.0, 0.0]\ncorner2 = [1.0, 1.0, 1.0]",
            "[[zone]]\nnumber = 1\ncorner1 = [0.0, 0.0, 0.0]\ncorner2 = [1.0, 1.0, 1.0]\n[[zone]]\nnumber = 1\ncorner1 = [0.0, 0.0, 0.0]\ncorner2 = [1.0, 1.0, 1.0]",
            "[[zone]]\nnumber = 1\ncorner1 = [0.0, 0.0, 0.0]\ncorner2 = [1.0, 1.0, inf]",
        ] {
            assert!(
                matches!(parse(bad, &model), Err(CoordsFileError::Entry(_))),
                "{bad}"
            );
        }
        for bad in [
            "[[zone]]\nnumber = 1\ncorner1 = [0.0, 0.0]\ncorner2 = [1.0, 1.0, 1.0]",
            "[[zone]]\nnumber = 1\ncorner1 = [0.0, 0.0, 0.0]",
        ] {
            assert!(
                matches!(parse(bad, &model), Err(CoordsFileError::Syntax(_))),
                "{bad}"
            );
        }
    }
}
