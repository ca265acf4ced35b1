//! Robot models: arm geometry, joint limits and motion maxima, loaded from TOML.

use serde::Deserialize;
use thiserror::Error;
use toml::Spanned;

use super::units::Joints;

/// Standard gravity in mm/s^2 (1 G). Accelerations on the wire come in 0.01 G.
pub const G_MM_S2: f64 = 9806.65;

/// The model files shipped in `assets/robots/`, compiled in so a default exists without
/// file IO: `(name, TOML text)`.
pub const BUILTIN_MODELS: [(&str, &str); 2] = [
    (
        "scara-500",
        include_str!("../../../../assets/robots/scara-500.toml"),
    ),
    (
        "scara-250",
        include_str!("../../../../assets/robots/scara-250.toml"),
    ),
];

/// The most entries a work or tool table can have: 2A4H reads at most 255 records
/// (PROTOCOL.md 3.16).
pub const MAX_TABLE_SIZE: usize = 255;

/// Limits and maxima of one axis. Units: deg (J1, J2, R) or mm (Z), per s and per s^2.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JointSpec {
    pub min: f64,
    pub max: f64,
    pub max_speed: f64,
    pub max_accel: f64,
}

impl JointSpec {
    /// `value` within `min..=max`.
    pub fn contains(&self, value: f64) -> bool {
        value >= self.min && value <= self.max
    }
}

/// The positioning band: an axis is in position when within this of its command position.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InPositionBand {
    /// For J1, J2 and R, deg.
    pub deg: f64,
    /// For Z, mm.
    pub mm: f64,
}

/// What a 0 ("parameter value") in a move command's speed/accel/decel field resolves to.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MoveDefaults {
    pub ptp_speed_pct: f64,
    pub ptp_accel_pct: f64,
    pub cp_speed_mm_s: f64,
    /// In 0.01 G, the wire unit.
    pub cp_accel_cg: f64,
}

/// One SCARA robot: 2-link arm, Z, R. See `assets/robots/*.toml` for the file layout.
#[derive(Debug, Clone, PartialEq)]
pub struct RobotModel {
    pub name: String,
    pub description: String,
    pub arm1_mm: f64,
    pub arm2_mm: f64,
    /// |J2| below this (deg): arm system undetermined, Cartesian targets refused.
    pub singular_band_deg: f64,
    pub j1: JointSpec,
    pub j2: JointSpec,
    pub z: JointSpec,
    /// Z counts downward: its 0 is the top of the stroke, so raising the tool is Z-.
    /// [inferred] IAI SCARA Z axes home at the top and count down (`[z] counts`).
    pub z_counts_down: bool,
    /// The R joint (J4).
    pub r: JointSpec,
    pub cp_max_speed_mm_s: f64,
    pub cp_max_accel_mm_s2: f64,
    pub in_position: InPositionBand,
    pub home: Joints,
    pub work_table_size: usize,
    pub tool_table_size: usize,
    pub defaults: MoveDefaults,
}

/// Why a model could not be loaded. Field errors name the dotted field and the line.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum ModelError {
    #[error("robot model{}{}: {message}", line_text(*.line), field_text(.field))]
    Field {
        /// Dotted path, e.g. `j2.max`; empty when the file is not valid TOML at all.
        field: String,
        /// 1-based line in the file, when known.
        line: Option<usize>,
        message: String,
    },
    #[error("no built-in robot model named `{0}` (built in: scara-500, scara-250)")]
    UnknownBuiltin(String),
}

fn line_text(line: Option<usize>) -> String {
    line.map(|l| format!(" line {l}")).unwrap_or_default()
}

fn field_text(field: &str) -> String {
    if field.is_empty() {
        String::new()
    } else {
        format!(", field `{field}`")
    }
}

impl RobotModel {
    /// Parses and validates a model file's text.
    pub fn from_toml_str(text: &str) -> Result<Self, ModelError> {
        let raw: RawModel = toml::from_str(text).map_err(|e| toml_error(text, &e))?;
        raw.validate(text)
    }

    /// One of the models shipped in `assets/robots/` (see [`BUILTIN_MODELS`]).
    pub fn builtin(name: &str) -> Result<Self, ModelError> {
        BUILTIN_MODELS
            .iter()
            .find(|(n, _)| *n == name)
            .ok_or_else(|| ModelError::UnknownBuiltin(name.to_string()))
            .and_then(|(_, text)| Self::from_toml_str(text))
    }

    /// The default model (500 mm reach).
    pub fn default_model() -> Self {
        // The shipped files are checked by a test; fall back to a literal copy of the
        // 500 mm figures rather than panic if that ever breaks.
        Self::builtin("scara-500").unwrap_or_else(|_| Self::fallback())
    }

    fn fallback() -> Self {
        let spec = |min, max, max_speed, max_accel| JointSpec {
            min,
            max,
            max_speed,
            max_accel,
        };
        RobotModel {
            name: "scara-500".into(),
            description: "500 mm reach SCARA (arm 1 250 mm + arm 2 250 mm), Z stroke 200 mm".into(),
            arm1_mm: 250.0,
            arm2_mm: 250.0,
            singular_band_deg: 2.0,
            j1: spec(-125.0, 125.0, 420.0, 2100.0),
            j2: spec(-145.0, 145.0, 720.0, 3600.0),
            z: spec(0.0, 200.0, 1120.0, 5600.0),
            z_counts_down: true,
            r: spec(-360.0, 360.0, 1800.0, 9000.0),
            cp_max_speed_mm_s: 2000.0,
            cp_max_accel_mm_s2: G_MM_S2,
            in_position: InPositionBand {
                deg: 0.01,
                mm: 0.01,
            },
            home: Joints::new(0.0, 90.0, 0.0, 0.0),
            work_table_size: 32,
            tool_table_size: 128,
            defaults: MoveDefaults {
                ptp_speed_pct: 30.0,
                ptp_accel_pct: 30.0,
                cp_speed_mm_s: 250.0,
                cp_accel_cg: 30.0,
            },
        }
    }
}

/// Turns a toml error into a field error: the dotted key path toml records (shown by its
/// Display only when no input is attached) and the line of the span.
fn toml_error(text: &str, err: &toml::de::Error) -> ModelError {
    let mut bare = err.clone();
    bare.set_input(None);
    let shown = bare.to_string();
    let field = shown
        .lines()
        .rev()
        .find_map(|l| l.strip_prefix("in `").and_then(|l| l.strip_suffix('`')))
        .unwrap_or("")
        .to_string();
    // "unknown field `x`" / "missing field `x`" come with the path of the enclosing table.
    let field = match field_from_message(err.message()) {
        Some(name) if field.is_empty() => name,
        Some(name) => format!("{field}.{name}"),
        None => field,
    };
    ModelError::Field {
        field,
        line: err.span().map(|s| line_of(text, s.start)),
        message: err.message().trim().to_string(),
    }
}

/// "missing field `x`" / "unknown field `x`": the name between the first backticks.
fn field_from_message(message: &str) -> Option<String> {
    if !(message.starts_with("missing field") || message.starts_with("unknown field")) {
        return None;
    }
    let start = message.find('`')? + 1;
    let len = message[start..].find('`')?;
    Some(message[start..start + len].to_string())
}

/// 1-based line of a byte offset.
fn line_of(text: &str, offset: usize) -> usize {
    let end = offset.min(text.len());
    text.as_bytes()[..end]
        .iter()
        .filter(|b| **b == b'\n')
        .count()
        + 1
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawModel {
    name: String,
    #[serde(default)]
    description: String,
    arms: RawArms,
    j1: RawJoint,
    j2: RawJoint,
    z: RawJoint,
    r: RawJoint,
    cp: RawCp,
    in_position: RawInPosition,
    home: RawHome,
    #[serde(default)]
    tables: RawTables,
    defaults: RawDefaults,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawArms {
    arm1_mm: Spanned<f64>,
    arm2_mm: Spanned<f64>,
    singular_band_deg: Spanned<f64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawJoint {
    min: Spanned<f64>,
    max: Spanned<f64>,
    max_speed: Spanned<f64>,
    max_accel: Spanned<f64>,
    /// Z only: "down" (the default) or "up", the way the coordinate counts.
    #[serde(default)]
    counts: Option<Spanned<String>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawCp {
    max_speed_mm_s: Spanned<f64>,
    max_accel_g: Spanned<f64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawInPosition {
    deg: Spanned<f64>,
    mm: Spanned<f64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawHome {
    j1: Spanned<f64>,
    j2: Spanned<f64>,
    z: Spanned<f64>,
    j4: Spanned<f64>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct RawTables {
    work: Option<Spanned<i64>>,
    tool: Option<Spanned<i64>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawDefaults {
    ptp_speed_pct: Spanned<f64>,
    ptp_accel_pct: Spanned<f64>,
    cp_speed_mm_s: Spanned<f64>,
    cp_accel_cg: Spanned<f64>,
}

/// Value checks that remember the text, to name the line of a bad value.
struct Checker<'a> {
    text: &'a str,
}

impl Checker<'_> {
    fn fail<T>(&self, field: &str, span_start: usize, message: String) -> Result<T, ModelError> {
        Err(ModelError::Field {
            field: field.to_string(),
            line: Some(line_of(self.text, span_start)),
            message,
        })
    }

    fn finite(&self, field: &str, v: &Spanned<f64>) -> Result<f64, ModelError> {
        let x = *v.get_ref();
        if x.is_finite() {
            Ok(x)
        } else {
            self.fail(
                field,
                v.span().start,
                format!("must be a finite number, got {x}"),
            )
        }
    }

    fn positive(&self, field: &str, v: &Spanned<f64>) -> Result<f64, ModelError> {
        let x = self.finite(field, v)?;
        if x > 0.0 {
            Ok(x)
        } else {
            self.fail(field, v.span().start, format!("must be positive, got {x}"))
        }
    }

    fn in_range(&self, field: &str, v: &Spanned<f64>, lo: f64, hi: f64) -> Result<f64, ModelError> {
        let x = self.finite(field, v)?;
        if (lo..=hi).contains(&x) {
            Ok(x)
        } else {
            self.fail(
                field,
                v.span().start,
                format!("must be between {lo} and {hi}, got {x}"),
            )
        }
    }

    fn joint(&self, name: &str, j: &RawJoint) -> Result<JointSpec, ModelError> {
        let min = self.finite(&format!("{name}.min"), &j.min)?;
        let max = self.finite(&format!("{name}.max"), &j.max)?;
        if min >= max {
            return self.fail(
                &format!("{name}.max"),
                j.max.span().start,
                format!("must be greater than {name}.min ({min}), got {max}"),
            );
        }
        Ok(JointSpec {
            min,
            max,
            max_speed: self.positive(&format!("{name}.max_speed"), &j.max_speed)?,
            max_accel: self.positive(&format!("{name}.max_accel"), &j.max_accel)?,
        })
    }

    fn z_counts(&self, z: &RawJoint) -> Result<bool, ModelError> {
        match z
            .counts
            .as_ref()
            .map(|v| (v.get_ref().as_str(), v.span().start))
        {
            None | Some(("down", _)) => Ok(true),
            Some(("up", _)) => Ok(false),
            Some((other, at)) => self.fail(
                "z.counts",
                at,
                format!("must be \"down\" or \"up\", got \"{other}\""),
            ),
        }
    }

    fn table(
        &self,
        field: &str,
        v: &Option<Spanned<i64>>,
        default: usize,
    ) -> Result<usize, ModelError> {
        match v {
            None => Ok(default),
            // 1 is the least (No. 0 always exists).
            Some(s) => match usize::try_from(*s.get_ref()) {
                Ok(n) if (1..=MAX_TABLE_SIZE).contains(&n) => Ok(n),
                _ => self.fail(
                    field,
                    s.span().start,
                    format!(
                        "must be between 1 and {MAX_TABLE_SIZE}, got {}",
                        s.get_ref()
                    ),
                ),
            },
        }
    }
}

impl RawModel {
    fn validate(self, text: &str) -> Result<RobotModel, ModelError> {
        let c = Checker { text };
        let arm1_mm = c.positive("arms.arm1_mm", &self.arms.arm1_mm)?;
        let arm2_mm = c.positive("arms.arm2_mm", &self.arms.arm2_mm)?;
        let j1 = c.joint("j1", &self.j1)?;
        let j2 = c.joint("j2", &self.j2)?;
        let z = c.joint("z", &self.z)?;
        let r = c.joint("r", &self.r)?;
        let z_counts_down = c.z_counts(&self.z)?;
        for (name, j) in [("j1", &self.j1), ("j2", &self.j2), ("r", &self.r)] {
            if let Some(v) = &j.counts {
                return c.fail(
                    &format!("{name}.counts"),
                    v.span().start,
                    "only [z] says which way it counts".into(),
                );
            }
        }
        // Both arm systems must exist outside the band: j2.min < -band, j2.max > band.
        let band_hi = j2.max.min(-j2.min).min(90.0);
        let band = c.positive("arms.singular_band_deg", &self.arms.singular_band_deg)?;
        if band >= band_hi {
            return c.fail(
                "arms.singular_band_deg",
                self.arms.singular_band_deg.span().start,
                format!("must be smaller than |j2.min|, j2.max and 90 ({band_hi}), got {band}"),
            );
        }
        let home = Joints::new(
            c.finite("home.j1", &self.home.j1)?,
            c.finite("home.j2", &self.home.j2)?,
            c.finite("home.z", &self.home.z)?,
            c.finite("home.j4", &self.home.j4)?,
        );
        let home_checks = [
            ("home.j1", &self.home.j1, &j1),
            ("home.j2", &self.home.j2, &j2),
            ("home.z", &self.home.z, &z),
            ("home.j4", &self.home.j4, &r),
        ];
        for (field, v, spec) in home_checks {
            if !spec.contains(*v.get_ref()) {
                return c.fail(
                    field,
                    v.span().start,
                    format!(
                        "must be within the joint limits {}..{}, got {}",
                        spec.min,
                        spec.max,
                        v.get_ref()
                    ),
                );
            }
        }
        Ok(RobotModel {
            name: self.name,
            description: self.description,
            arm1_mm,
            arm2_mm,
            singular_band_deg: band,
            j1,
            j2,
            z,
            z_counts_down,
            r,
            cp_max_speed_mm_s: c.positive("cp.max_speed_mm_s", &self.cp.max_speed_mm_s)?,
            cp_max_accel_mm_s2: c.positive("cp.max_accel_g", &self.cp.max_accel_g)? * G_MM_S2,
            in_position: InPositionBand {
                deg: c.positive("in_position.deg", &self.in_position.deg)?,
                mm: c.positive("in_position.mm", &self.in_position.mm)?,
            },
            home,
            work_table_size: c.table("tables.work", &self.tables.work, 32)?,
            tool_table_size: c.table("tables.tool", &self.tables.tool, 128)?,
            defaults: MoveDefaults {
                ptp_speed_pct: c.in_range(
                    "defaults.ptp_speed_pct",
                    &self.defaults.ptp_speed_pct,
                    0.01,
                    100.0,
                )?,
                ptp_accel_pct: c.in_range(
                    "defaults.ptp_accel_pct",
                    &self.defaults.ptp_accel_pct,
                    0.01,
                    100.0,
                )?,
                cp_speed_mm_s: c
                    .positive("defaults.cp_speed_mm_s", &self.defaults.cp_speed_mm_s)?,
                cp_accel_cg: c.positive("defaults.cp_accel_cg", &self.defaults.cp_accel_cg)?,
            },
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn builtins_load() {
        for (name, _) in BUILTIN_MODELS {
            let m = RobotModel::builtin(name).unwrap();
            assert_eq!(m.name, name);
        }
        let m = RobotModel::default_model();
        assert_eq!(m.arm1_mm + m.arm2_mm, 500.0);
        assert_eq!(m, RobotModel::fallback());
        assert_eq!(RobotModel::builtin("scara-250").unwrap().arm1_mm, 125.0);
        assert!(matches!(
            RobotModel::builtin("nope"),
            Err(ModelError::UnknownBuiltin(_))
        ));
    }
}
