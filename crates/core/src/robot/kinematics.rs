//! Forward and inverse kinematics of a 2-link SCARA with Z and R, with typed refusals.
//!
//! Conventions (all of `robot`):
//! - Angles in degrees, counter-clockwise positive seen from above; J1 = 0 points along
//!   base +X. J2 is arm 2 relative to arm 1; J4 (the R joint) is the flange relative to
//!   arm 2.
//! - Cartesian R is the flange orientation in the base frame: `R = J1 + J2 + J4`.
//! - Cartesian Z is the Z axis coordinate itself (same value and sense as the joint).
//! - Right arm system: J2 > 0 (elbow bent counter-clockwise); left: J2 < 0; inside the
//!   model's singular band around 0 the arm system is undetermined. PROTOCOL.md 3.17/3.18
//!   only name the three states; which sign is "right" is the brief's convention
//!   `[inferred]`, to check against a real controller's 2A1H report.

use std::fmt;

use thiserror::Error;

use super::model::{JointSpec, RobotModel};
use super::units::{Joints, Pose};

/// The arm system a pose is in, as a controller reports it (2A1H/2A3H decode into this).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ArmSystem {
    Right,
    Left,
    Undetermined,
}

/// Which of the two inverse-kinematics solutions is asked for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Arm {
    /// J2 > 0.
    Right,
    /// J2 < 0.
    Left,
}

impl Arm {
    /// The other arm.
    pub fn other(self) -> Arm {
        match self {
            Arm::Right => Arm::Left,
            Arm::Left => Arm::Right,
        }
    }
}

impl From<Arm> for ArmSystem {
    fn from(a: Arm) -> Self {
        match a {
            Arm::Right => ArmSystem::Right,
            Arm::Left => ArmSystem::Left,
        }
    }
}

impl fmt::Display for Arm {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Arm::Right => "right",
            Arm::Left => "left",
        })
    }
}

/// One of the four axes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Joint {
    J1,
    J2,
    Z,
    /// The R joint (J4).
    R,
}

impl Joint {
    /// "°" for rotary joints, " mm" for Z.
    pub fn unit(self) -> &'static str {
        match self {
            Joint::Z => " mm",
            _ => "°",
        }
    }
}

impl fmt::Display for Joint {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Joint::J1 => "J1",
            Joint::J2 => "J2",
            Joint::Z => "Z",
            Joint::R => "R",
        })
    }
}

/// Why a pose cannot be reached. The Display text is written for the operator, to be
/// shown beside the jog button that asked for it.
#[derive(Debug, Clone, Copy, PartialEq, Error)]
pub enum IkError {
    #[error("out of reach: {distance_mm:.3} mm from the J1 axis, the arm reaches {max_mm:.3} mm")]
    TooFar { distance_mm: f64, max_mm: f64 },
    #[error(
        "too close to the J1 axis: {distance_mm:.3} mm, the {arm} arm needs at least {min_mm:.3} mm"
    )]
    TooNear {
        distance_mm: f64,
        min_mm: f64,
        arm: Arm,
    },
    #[error(
        "arm nearly straight (J2 {j2_deg:.3}°, inside ±{band_deg:.3}°): the arm system is undetermined there"
    )]
    Singular { j2_deg: f64, band_deg: f64 },
    #[error(
        "{joint} would be at {value:.3}{unit}, {excess:.3}{unit} beyond its limit of {limit:.3}{unit}",
        unit = joint.unit()
    )]
    JointLimit {
        joint: Joint,
        value: f64,
        limit: f64,
        excess: f64,
    },
    #[error("the position is not a number")]
    NotFinite,
}

/// Kinematics of one robot model: geometry and limits copied out of the model with the
/// derived figures precomputed, so the hot paths (IK, CP checks) are arithmetic only.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Scara {
    pub l1: f64,
    pub l2: f64,
    pub band_deg: f64,
    pub j1: JointSpec,
    pub j2: JointSpec,
    pub z: JointSpec,
    pub r: JointSpec,
    sq_sum: f64,
    two_l1l2: f64,
    cos_band: f64,
    outer: f64,
    inner_right: f64,
    inner_left: f64,
}

/// Distance of the flange axis from J1's for elbow angle `j2_deg`.
fn radius(l1: f64, l2: f64, j2_deg: f64) -> f64 {
    (l1 * l1 + l2 * l2 + 2.0 * l1 * l2 * j2_deg.to_radians().cos())
        .max(0.0)
        .sqrt()
}

impl Scara {
    pub fn new(m: &RobotModel) -> Self {
        let (l1, l2) = (m.arm1_mm, m.arm2_mm);
        Scara {
            l1,
            l2,
            band_deg: m.singular_band_deg,
            j1: m.j1,
            j2: m.j2,
            z: m.z,
            r: m.r,
            sq_sum: l1 * l1 + l2 * l2,
            two_l1l2: 2.0 * l1 * l2,
            cos_band: m.singular_band_deg.to_radians().cos(),
            outer: l1 + l2,
            inner_right: radius(l1, l2, m.j2.max.min(180.0)),
            inner_left: radius(l1, l2, (-m.j2.min).min(180.0)),
        }
    }

    /// Inner and outer reach radius (mm) of one arm system, J2 limits included. Targets
    /// just inside the outer radius are singular (J2 inside the band).
    pub fn reach(&self, arm: Arm) -> (f64, f64) {
        match arm {
            Arm::Right => (self.inner_right, self.outer),
            Arm::Left => (self.inner_left, self.outer),
        }
    }

    /// Flange pose in the base frame.
    pub fn forward(&self, j: &Joints) -> Pose {
        let (s1, c1) = j.j1.to_radians().sin_cos();
        let (s12, c12) = (j.j1 + j.j2).to_radians().sin_cos();
        Pose::new(
            self.l1 * c1 + self.l2 * c12,
            self.l1 * s1 + self.l2 * s12,
            j.z,
            j.j1 + j.j2 + j.j4,
        )
    }

    /// The arm system of a joint pose: from the sign of J2, undetermined inside the band.
    pub fn arm_system(&self, j: &Joints) -> ArmSystem {
        if j.j2.abs() < self.band_deg || j.j2.is_nan() {
            ArmSystem::Undetermined
        } else if j.j2 > 0.0 {
            ArmSystem::Right
        } else {
            ArmSystem::Left
        }
    }

    /// Joint pose putting the flange at `p` (base frame) with the given arm system. J1
    /// and J4 are taken, among their 360° multiples inside the limits, nearest to `near`
    /// (normally the current joints), so R never spins a turn for nothing.
    pub fn inverse(&self, p: &Pose, arm: Arm, near: &Joints) -> Result<Joints, IkError> {
        if !p.is_finite() {
            return Err(IkError::NotFinite);
        }
        let (j1_raw, j2) = self.planar(p.x, p.y, arm)?;
        let j1 = wrap_nearest(j1_raw, near.j1, &self.j1, Joint::J1)?;
        let z = check(p.z, &self.z, Joint::Z)?;
        let j4 = wrap_nearest(p.r - j1 - j2, near.j4, &self.r, Joint::R)?;
        Ok(Joints::new(j1, j2, z, j4))
    }

    /// Joint pose putting the flange at `p` with the Cartesian R taken as given: J1 is
    /// chosen as in [`Scara::inverse`], but J4 is exactly `p.r - J1 - J2`, never another
    /// 360° multiple, so the flange's R after the move reads `p.r` and a move turns R the
    /// way and the distance its target names. Beyond the R joint's limits it is refused
    /// (a relative R of +300° from J4 = 0 turns +300°, never -60°).
    pub fn inverse_exact_r(&self, p: &Pose, arm: Arm, near: &Joints) -> Result<Joints, IkError> {
        if !p.is_finite() {
            return Err(IkError::NotFinite);
        }
        let (j1_raw, j2) = self.planar(p.x, p.y, arm)?;
        let j1 = wrap_nearest(j1_raw, near.j1, &self.j1, Joint::J1)?;
        let z = check(p.z, &self.z, Joint::Z)?;
        let j4 = check(p.r - j1 - j2, &self.r, Joint::R)?;
        Ok(Joints::new(j1, j2, z, j4))
    }

    /// The planar part of IK: `(J1 in -180..=180, J2)` for the flange at (x, y), with the
    /// reach, band and J2-limit checks. J1's limits are not checked here.
    pub fn planar(&self, x: f64, y: f64, arm: Arm) -> Result<(f64, f64), IkError> {
        let (j2, c2, s2) = self.elbow(x, y, arm)?;
        // J1 = atan2(y, x) - atan2(k2, k1), folded into one atan2 of the product
        // (x + iy)(k1 - i k2): one transcendental call fewer on the hot path.
        let (k1, k2) = (self.l1 + self.l2 * c2, self.l2 * s2);
        let j1 = (y * k1 - x * k2).atan2(x * k1 + y * k2).to_degrees();
        Ok((j1, j2))
    }

    /// The elbow for the flange at (x, y): `(J2 deg, cos J2, sin J2)`, after the reach,
    /// singular-band and J2-limit checks.
    pub(crate) fn elbow(&self, x: f64, y: f64, arm: Arm) -> Result<(f64, f64, f64), IkError> {
        let d2 = x * x + y * y;
        let d = d2.sqrt();
        if !d.is_finite() {
            return Err(IkError::NotFinite);
        }
        let (inner, outer) = self.reach(arm);
        if d > outer {
            return Err(IkError::TooFar {
                distance_mm: d,
                max_mm: outer,
            });
        }
        if d < inner {
            return Err(IkError::TooNear {
                distance_mm: d,
                min_mm: inner,
                arm,
            });
        }
        let c = ((d2 - self.sq_sum) / self.two_l1l2).clamp(-1.0, 1.0);
        let mag = c.acos().to_degrees();
        let s = (1.0 - c * c).sqrt();
        let (j2, s) = match arm {
            Arm::Right => (mag, s),
            Arm::Left => (-mag, -s),
        };
        if c > self.cos_band {
            return Err(IkError::Singular {
                j2_deg: j2,
                band_deg: self.band_deg,
            });
        }
        Ok((check(j2, &self.j2, Joint::J2)?, c, s))
    }

    /// All four joints finite and within their limits; the first offender otherwise.
    pub fn check_joints(&self, j: &Joints) -> Result<(), IkError> {
        if !j.is_finite() {
            return Err(IkError::NotFinite);
        }
        check(j.j1, &self.j1, Joint::J1)?;
        check(j.j2, &self.j2, Joint::J2)?;
        check(j.z, &self.z, Joint::Z)?;
        check(j.j4, &self.r, Joint::R)?;
        Ok(())
    }
}

/// How far (deg or mm) a value may pass a limit and still count as on it: float noise
/// of FK/IK round trips, a million times finer than the wire unit.
pub const LIMIT_EPS: f64 = 1e-9;

/// `value` within the limits (clamped onto a limit it passes by at most [`LIMIT_EPS`]),
/// or which limit it passes and by how much.
pub fn check(value: f64, spec: &JointSpec, joint: Joint) -> Result<f64, IkError> {
    if value < spec.min - LIMIT_EPS {
        Err(IkError::JointLimit {
            joint,
            value,
            limit: spec.min,
            excess: spec.min - value,
        })
    } else if value > spec.max + LIMIT_EPS {
        Err(IkError::JointLimit {
            joint,
            value,
            limit: spec.max,
            excess: value - spec.max,
        })
    } else if value.is_nan() {
        Err(IkError::NotFinite)
    } else {
        Ok(value.clamp(spec.min, spec.max))
    }
}

/// Among `value + k * 360` inside the limits, the one nearest `near`; when none fits, the
/// refusal names the candidate that misses the limits by least.
pub fn wrap_nearest(value: f64, near: f64, spec: &JointSpec, joint: Joint) -> Result<f64, IkError> {
    // Usual case: the value itself is inside and within half a turn of `near`, so no
    // other multiple can be nearer.
    if value >= spec.min && value <= spec.max && (value - near).abs() <= 180.0 {
        return Ok(value);
    }
    let k_lo = ((spec.min - LIMIT_EPS - value) / 360.0).ceil();
    let k_hi = ((spec.max + LIMIT_EPS - value) / 360.0).floor();
    if k_lo <= k_hi {
        let k_near = if near.is_finite() {
            ((near - value) / 360.0).round()
        } else {
            0.0
        };
        return check(value + 360.0 * k_near.clamp(k_lo, k_hi), spec, joint);
    }
    if !value.is_finite() {
        return Err(IkError::NotFinite);
    }
    let below = value + 360.0 * k_hi; // under min
    let above = value + 360.0 * k_lo; // over max
    if spec.min - below <= above - spec.max {
        check(below, spec, joint)
    } else {
        check(above, spec, joint)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scara() -> Scara {
        Scara::new(&RobotModel::default_model())
    }

    #[test]
    fn forward_of_known_poses() {
        let k = scara();
        let p = k.forward(&Joints::new(0.0, 90.0, 10.0, 0.0));
        assert!((p.x - 250.0).abs() < 1e-9 && (p.y - 250.0).abs() < 1e-9);
        assert_eq!((p.z, p.r), (10.0, 90.0));
    }

    #[test]
    fn inverse_gives_both_arms() {
        let k = scara();
        let near = Joints::default();
        let p = Pose::new(250.0, 250.0, 10.0, 90.0);
        let r = k.inverse(&p, Arm::Right, &near).unwrap();
        assert!((r.j1 - 0.0).abs() < 1e-9 && (r.j2 - 90.0).abs() < 1e-9);
        assert!(r.j4.abs() < 1e-9);
        let l = k.inverse(&p, Arm::Left, &near).unwrap();
        assert!((l.j1 - 90.0).abs() < 1e-9 && (l.j2 + 90.0).abs() < 1e-9);
        assert_eq!(k.arm_system(&r), ArmSystem::Right);
        assert_eq!(k.arm_system(&l), ArmSystem::Left);
        assert_eq!(
            k.arm_system(&Joints::new(0.0, 1.0, 0.0, 0.0)),
            ArmSystem::Undetermined
        );
    }

    #[test]
    fn r_joint_is_nearest_the_current_angle_within_limits() {
        let k = scara();
        let p = Pose::new(250.0, 250.0, 0.0, 90.0 + 350.0);
        // Raw J4 = 350; nearest to 0 inside ±360 is -10.
        let j = k.inverse(&p, Arm::Right, &Joints::default()).unwrap();
        assert!((j.j4 + 10.0).abs() < 1e-9, "{j:?}");
        let near = Joints::new(0.0, 90.0, 0.0, 300.0);
        let j = k.inverse(&p, Arm::Right, &near).unwrap();
        assert!((j.j4 - 350.0).abs() < 1e-9, "{j:?}");
    }

    #[test]
    fn exact_r_keeps_the_angle_asked_for() {
        let k = scara();
        let near = Joints::default();
        // Raw J4 = 350: kept, not wrapped to -10.
        let j = k
            .inverse_exact_r(
                &Pose::new(250.0, 250.0, 0.0, 90.0 + 350.0),
                Arm::Right,
                &near,
            )
            .unwrap();
        assert!((j.j4 - 350.0).abs() < 1e-9, "{j:?}");
        // J4 = 361 is beyond the limit: refused, not turned to 1.
        match k.inverse_exact_r(
            &Pose::new(250.0, 250.0, 0.0, 90.0 + 361.0),
            Arm::Right,
            &near,
        ) {
            Err(IkError::JointLimit {
                joint: Joint::R, ..
            }) => {}
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn wrap_refusal_names_the_smallest_excess() {
        let spec = JointSpec {
            min: -125.0,
            max: 125.0,
            max_speed: 1.0,
            max_accel: 1.0,
        };
        match wrap_nearest(170.0, 0.0, &spec, Joint::J1) {
            Err(IkError::JointLimit {
                joint: Joint::J1,
                value,
                limit,
                excess,
            }) => {
                assert_eq!((value, limit), (170.0, 125.0));
                assert!((excess - 45.0).abs() < 1e-9);
            }
            other => panic!("{other:?}"),
        }
        assert!(matches!(
            wrap_nearest(f64::NAN, 0.0, &spec, Joint::J1),
            Err(IkError::NotFinite)
        ));
        assert_eq!(wrap_nearest(-300.0, 0.0, &spec, Joint::J1), Ok(60.0));
    }

    #[test]
    fn messages_read_well() {
        let e = IkError::JointLimit {
            joint: Joint::Z,
            value: 210.0,
            limit: 200.0,
            excess: 10.0,
        };
        assert_eq!(
            e.to_string(),
            "Z would be at 210.000 mm, 10.000 mm beyond its limit of 200.000 mm"
        );
    }
}
