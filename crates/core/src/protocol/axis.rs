//! Axes, axis patterns (bit n = axis n+1) and per-axis value blocks.

use std::fmt;

/// One axis, 1 to 8. SCARA unit 1 is X = 1, Y = 2, Z = 3, R = 4; unit 2 is axes 5-8.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Axis(u8);

impl Axis {
    /// Axis 1 (SCARA X).
    pub const A1: Axis = Axis(0);
    /// Axis 2 (SCARA Y).
    pub const A2: Axis = Axis(1);
    /// Axis 3 (SCARA Z).
    pub const A3: Axis = Axis(2);
    /// Axis 4 (SCARA R).
    pub const A4: Axis = Axis(3);
    /// Axis 5.
    pub const A5: Axis = Axis(4);
    /// Axis 6.
    pub const A6: Axis = Axis(5);
    /// Axis 7.
    pub const A7: Axis = Axis(6);
    /// Axis 8.
    pub const A8: Axis = Axis(7);

    /// The axis with this number (1 to 8).
    pub const fn new(number: u8) -> Option<Axis> {
        if number >= 1 && number <= 8 {
            Some(Axis(number - 1))
        } else {
            None
        }
    }

    /// The axis for a 0-based index (0 to 7).
    pub const fn from_index(index: u8) -> Option<Axis> {
        if index < 8 { Some(Axis(index)) } else { None }
    }

    /// The axis number, 1 to 8.
    pub const fn number(self) -> u8 {
        self.0 + 1
    }

    /// The 0-based index, 0 to 7 (the bit in an axis pattern).
    pub const fn index(self) -> usize {
        self.0 as usize
    }

    /// Whether this is the R (rotary) axis of a SCARA unit (axis 4 or 8).
    pub const fn is_scara_r(self) -> bool {
        self.0 == 3 || self.0 == 7
    }

    /// Whether this is a rotary joint of a SCARA unit in the each-axis (joint) system:
    /// the arm joints 1, 2 and R (axes 1, 2, 4 and 5, 6, 8); Z is linear.
    pub const fn is_scara_rotary_joint(self) -> bool {
        !matches!(self.0, 2 | 6)
    }
}

impl fmt::Display for Axis {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "axis {}", self.number())
    }
}

/// An axis pattern: 2 hex digits, bit n selects axis n+1 (PROTOCOL.md 1.8).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct AxisPattern(pub u8);

impl AxisPattern {
    /// No axis.
    pub const NONE: AxisPattern = AxisPattern(0);
    /// SCARA unit 1, axes 1-4 (`0F`).
    pub const SCARA_1: AxisPattern = AxisPattern(0x0F);
    /// SCARA unit 2, axes 5-8 (`F0`).
    pub const SCARA_2: AxisPattern = AxisPattern(0xF0);
    /// All eight axes (`FF`).
    pub const ALL: AxisPattern = AxisPattern(0xFF);

    /// A pattern of one axis.
    pub const fn single(axis: Axis) -> AxisPattern {
        AxisPattern(1 << axis.0)
    }

    /// Whether `axis` is selected.
    pub const fn contains(self, axis: Axis) -> bool {
        self.0 & (1 << axis.0) != 0
    }

    /// This pattern with `axis` added.
    pub const fn with(self, axis: Axis) -> AxisPattern {
        AxisPattern(self.0 | (1 << axis.0))
    }

    /// Number of selected axes.
    pub const fn count(self) -> usize {
        self.0.count_ones() as usize
    }

    /// Whether no axis is selected.
    pub const fn is_empty(self) -> bool {
        self.0 == 0
    }

    /// The selected axes, ascending (the order of per-axis data blocks).
    pub fn iter(self) -> AxisIter {
        AxisIter(self.0)
    }
}

impl fmt::Display for AxisPattern {
    /// `0F (axes 1, 2, 3, 4)`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{:02X} (", self.0)?;
        if self.is_empty() {
            f.write_str("no axis")?;
        } else {
            f.write_str(if self.count() == 1 { "axis " } else { "axes " })?;
            for (i, a) in self.iter().enumerate() {
                if i > 0 {
                    f.write_str(", ")?;
                }
                write!(f, "{}", a.number())?;
            }
        }
        f.write_str(")")
    }
}

impl IntoIterator for AxisPattern {
    type Item = Axis;
    type IntoIter = AxisIter;
    fn into_iter(self) -> AxisIter {
        self.iter()
    }
}

impl FromIterator<Axis> for AxisPattern {
    fn from_iter<I: IntoIterator<Item = Axis>>(iter: I) -> Self {
        iter.into_iter().fold(AxisPattern::NONE, AxisPattern::with)
    }
}

/// Iterator over the axes of a pattern, ascending.
#[derive(Clone, Debug)]
pub struct AxisIter(u8);

impl Iterator for AxisIter {
    type Item = Axis;
    #[inline]
    fn next(&mut self) -> Option<Axis> {
        if self.0 == 0 {
            return None;
        }
        let i = self.0.trailing_zeros() as u8;
        self.0 &= self.0 - 1;
        Some(Axis(i))
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        let n = self.0.count_ones() as usize;
        (n, Some(n))
    }
}

impl ExactSizeIterator for AxisIter {}

/// One value per selected axis: the per-axis data blocks of a message, sent once per set
/// bit of the pattern, lowest axis first. Unselected slots always hold `T::default()`, so
/// two blocks with the same axes and values compare equal.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub struct PerAxis<T> {
    pattern: AxisPattern,
    values: [T; 8],
}

impl<T: Copy + Default> PerAxis<T> {
    /// No axis.
    pub fn new() -> Self {
        PerAxis {
            pattern: AxisPattern::NONE,
            values: [T::default(); 8],
        }
    }

    /// From a pattern and values indexed by axis (slots outside the pattern are reset).
    pub(crate) fn from_slots(pattern: AxisPattern, mut values: [T; 8]) -> Self {
        for (i, v) in values.iter_mut().enumerate() {
            if pattern.0 & (1 << i) == 0 {
                *v = T::default();
            }
        }
        PerAxis { pattern, values }
    }

    /// A value for every axis of `pattern`, from `f`.
    pub fn from_fn(pattern: AxisPattern, mut f: impl FnMut(Axis) -> T) -> Self {
        let mut p = Self::new();
        for a in pattern {
            p.set(a, f(a));
        }
        p
    }

    /// From (axis, value) pairs; a later pair for the same axis wins.
    pub fn from_pairs(pairs: impl IntoIterator<Item = (Axis, T)>) -> Self {
        let mut p = Self::new();
        for (a, v) in pairs {
            p.set(a, v);
        }
        p
    }

    /// This block with `axis` set to `v`.
    pub fn with(mut self, axis: Axis, v: T) -> Self {
        self.set(axis, v);
        self
    }

    /// Selects `axis` with value `v`.
    pub fn set(&mut self, axis: Axis, v: T) {
        self.pattern = self.pattern.with(axis);
        if let Some(slot) = self.values.get_mut(axis.index()) {
            *slot = v;
        }
    }

    /// Deselects `axis`.
    pub fn remove(&mut self, axis: Axis) {
        self.pattern = AxisPattern(self.pattern.0 & !(1 << axis.index()));
        if let Some(slot) = self.values.get_mut(axis.index()) {
            *slot = T::default();
        }
    }

    /// The value of `axis`, if selected.
    pub fn get(&self, axis: Axis) -> Option<T> {
        if self.pattern.contains(axis) {
            self.values.get(axis.index()).copied()
        } else {
            None
        }
    }

    /// The selected axes.
    pub fn pattern(&self) -> AxisPattern {
        self.pattern
    }

    /// Number of selected axes.
    pub fn len(&self) -> usize {
        self.pattern.count()
    }

    /// Whether no axis is selected.
    pub fn is_empty(&self) -> bool {
        self.pattern.is_empty()
    }

    /// (axis, value) for the selected axes, ascending.
    pub fn iter(&self) -> impl Iterator<Item = (Axis, T)> + '_ {
        self.pattern
            .iter()
            .filter_map(|a| self.values.get(a.index()).map(|v| (a, *v)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pattern_iterates_set_axes_ascending() {
        let p = AxisPattern(0b1010_0101);
        let n: Vec<u8> = p.iter().map(Axis::number).collect();
        assert_eq!(n, [1, 3, 6, 8]);
        assert_eq!(p.count(), 4);
        assert_eq!(AxisPattern::SCARA_1.to_string(), "0F (axes 1, 2, 3, 4)");
        assert_eq!(AxisPattern(0x02).to_string(), "02 (axis 2)");
        assert!(AxisPattern(0x07).contains(Axis::A3));
        assert!(!AxisPattern(0x07).contains(Axis::A4));
    }

    #[test]
    fn per_axis_keeps_unselected_slots_default() {
        let mut a = PerAxis::new().with(Axis::A2, 5i32).with(Axis::A1, 1);
        a.remove(Axis::A2);
        assert_eq!(a, PerAxis::new().with(Axis::A1, 1));
        assert_eq!(a.get(Axis::A2), None);
        assert_eq!(a.iter().collect::<Vec<_>>(), [(Axis::A1, 1)]);
    }

    #[test]
    fn axis_numbers() {
        assert_eq!(Axis::new(0), None);
        assert_eq!(Axis::new(9), None);
        assert_eq!(Axis::new(4), Some(Axis::A4));
        assert!(Axis::A8.is_scara_r());
        assert!(!Axis::A3.is_scara_rotary_joint());
    }
}
