//! Wire units (0.001 mm, 0.001 deg as `i32`) and the f64 poses used inside `robot`.

use std::ops::{Add, Sub};

/// Rounds a value given in wire units (already scaled by 1000) to the nearest integer,
/// halves away from zero; saturates at the `i32` range; NaN becomes 0. Every conversion
/// from f64 to the wire in `robot` goes through this one function.
pub fn round_wire(scaled: f64) -> i32 {
    // `as` saturates and maps NaN to 0: no panic on any input.
    scaled.round() as i32
}

/// A length in the wire unit, 0.001 mm.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Default)]
pub struct Micrometres(pub i32);

impl Micrometres {
    /// From millimetres, rounded to the nearest micrometre (see [`round_wire`]).
    pub fn from_mm(mm: f64) -> Self {
        Self(round_wire(mm * 1000.0))
    }
    /// In millimetres.
    pub fn mm(self) -> f64 {
        f64::from(self.0) / 1000.0
    }
}

/// An angle in the wire unit, 0.001 deg.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Default)]
pub struct Millidegrees(pub i32);

impl Millidegrees {
    /// From degrees, rounded to the nearest millidegree (see [`round_wire`]).
    pub fn from_deg(deg: f64) -> Self {
        Self(round_wire(deg * 1000.0))
    }
    /// In degrees.
    pub fn deg(self) -> f64 {
        f64::from(self.0) / 1000.0
    }
}

/// A Cartesian pose: X, Y, Z in mm, R (rotation about Z) in deg, counter-clockwise
/// positive seen from above. Which frame and which point (flange or tool tip) is said
/// where it is used.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Pose {
    pub x: f64,
    pub y: f64,
    pub z: f64,
    pub r: f64,
}

impl Pose {
    pub const fn new(x: f64, y: f64, z: f64, r: f64) -> Self {
        Self { x, y, z, r }
    }
    /// From wire integers `[x µm, y µm, z µm, r mdeg]`.
    pub fn from_wire(w: [i32; 4]) -> Self {
        Self::new(
            f64::from(w[0]) / 1000.0,
            f64::from(w[1]) / 1000.0,
            f64::from(w[2]) / 1000.0,
            f64::from(w[3]) / 1000.0,
        )
    }
    /// To wire integers `[x µm, y µm, z µm, r mdeg]`, each rounded with [`round_wire`].
    pub fn to_wire(&self) -> [i32; 4] {
        [self.x, self.y, self.z, self.r].map(|v| round_wire(v * 1000.0))
    }
    /// All four components finite.
    pub fn is_finite(&self) -> bool {
        self.x.is_finite() && self.y.is_finite() && self.z.is_finite() && self.r.is_finite()
    }
    /// `[x, y, z, r]`.
    pub fn to_array(&self) -> [f64; 4] {
        [self.x, self.y, self.z, self.r]
    }
    /// From `[x, y, z, r]`.
    pub fn from_array(a: [f64; 4]) -> Self {
        Self::new(a[0], a[1], a[2], a[3])
    }
    /// Straight-line interpolation of all four components, `u` in 0..=1.
    pub fn lerp(&self, other: &Pose, u: f64) -> Pose {
        Pose::new(
            self.x + (other.x - self.x) * u,
            self.y + (other.y - self.y) * u,
            self.z + (other.z - self.z) * u,
            self.r + (other.r - self.r) * u,
        )
    }
}

impl Add for Pose {
    type Output = Pose;
    fn add(self, o: Pose) -> Pose {
        Pose::new(self.x + o.x, self.y + o.y, self.z + o.z, self.r + o.r)
    }
}

impl Sub for Pose {
    type Output = Pose;
    fn sub(self, o: Pose) -> Pose {
        Pose::new(self.x - o.x, self.y - o.y, self.z - o.z, self.r - o.r)
    }
}

/// A joint pose: J1 and J2 in deg (J2 relative to arm 1), Z in mm, J4 (the R joint, the
/// flange rotation relative to arm 2) in deg.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Joints {
    pub j1: f64,
    pub j2: f64,
    pub z: f64,
    pub j4: f64,
}

impl Joints {
    pub const fn new(j1: f64, j2: f64, z: f64, j4: f64) -> Self {
        Self { j1, j2, z, j4 }
    }
    /// As an array in axis order `[J1, J2, Z, J4]`.
    pub fn to_array(&self) -> [f64; 4] {
        [self.j1, self.j2, self.z, self.j4]
    }
    /// From an array in axis order `[J1, J2, Z, J4]`.
    pub fn from_array(a: [f64; 4]) -> Self {
        Self::new(a[0], a[1], a[2], a[3])
    }
    /// From wire integers `[J1 mdeg, J2 mdeg, Z µm, J4 mdeg]` (2A1H each-axis system).
    pub fn from_wire(w: [i32; 4]) -> Self {
        Self::from_array(w.map(|v| f64::from(v) / 1000.0))
    }
    /// To wire integers `[J1 mdeg, J2 mdeg, Z µm, J4 mdeg]`, rounded with [`round_wire`].
    pub fn to_wire(&self) -> [i32; 4] {
        self.to_array().map(|v| round_wire(v * 1000.0))
    }
    /// All four components finite.
    pub fn is_finite(&self) -> bool {
        self.to_array().iter().all(|v| v.is_finite())
    }
}

impl Add for Joints {
    type Output = Joints;
    fn add(self, o: Joints) -> Joints {
        Joints::new(self.j1 + o.j1, self.j2 + o.j2, self.z + o.z, self.j4 + o.j4)
    }
}

impl Sub for Joints {
    type Output = Joints;
    fn sub(self, o: Joints) -> Joints {
        Joints::new(self.j1 - o.j1, self.j2 - o.j2, self.z - o.z, self.j4 - o.j4)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rounding_is_to_nearest_half_away_and_never_panics() {
        assert_eq!(round_wire(1000.5), 1001);
        assert_eq!(round_wire(-0.5), -1);
        assert_eq!(Micrometres::from_mm(12.3456).0, 12346);
        assert_eq!(Millidegrees::from_deg(-12.3456).0, -12346);
        assert_eq!(round_wire(f64::NAN), 0);
        assert_eq!(round_wire(1e300), i32::MAX);
        assert_eq!(round_wire(-1e300), i32::MIN);
    }

    #[test]
    fn wire_round_trip() {
        let w = [300_000, -150_000, 20_000, 45_000];
        assert_eq!(Pose::from_wire(w).to_wire(), w);
        assert_eq!(Joints::from_wire(w).to_wire(), w);
    }
}
