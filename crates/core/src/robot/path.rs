//! The whole path of a planned move as the tool tip sweeps it: PTP through joint
//! interpolation, CP on its straight line, sampled at about 1 mm of the tip and checked
//! for joint limits, the singular band and interference zones, the first failing point
//! named. The planner's check and the arm view's ghost both take it from [`sweep`].

use super::frames::CoordSystem;
use super::kinematics::{ArmSystem, IkError, Scara};
use super::motion::Move;
use super::units::{Joints, Pose};

/// Tool-tip distance between the samples of a path, mm (at most: PTP paths are sampled
/// by a bound of the tip's speed, so their samples are closer).
pub const PATH_SPACING_MM: f64 = 1.0;

/// Most samples one path takes (memory and time bound): longer paths get a wider spacing.
pub const MAX_PATH_SAMPLES: usize = 20_000;

/// A box in the base frame: an interference-check zone by two opposite corners.
/// `[inferred]` A zone is entered when the tool tip lies inside the box on every axis the
/// zone names (X, Y, Z in mm, R in deg); an axis it does not name is not limited
/// (PROTOCOL.md 3.46 gives the corners, not how the controller tests them).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ZoneBox {
    /// The controller's zone number, from 1.
    pub number: u8,
    /// Low and high bound of X, Y, Z, R; `None`: the zone does not name that axis.
    pub ranges: [Option<(f64, f64)>; 4],
}

impl ZoneBox {
    /// A box from two corners given per axis (X, Y, Z, R); the bounds are sorted.
    pub fn from_corners(number: u8, c1: [Option<f64>; 4], c2: [Option<f64>; 4]) -> Self {
        let mut ranges = [None; 4];
        for (r, (a, b)) in ranges.iter_mut().zip(c1.into_iter().zip(c2)) {
            if let (Some(a), Some(b)) = (a, b) {
                *r = Some((a.min(b), a.max(b)));
            }
        }
        ZoneBox { number, ranges }
    }

    /// Whether the box has room: at least one named axis, and no named axis of zero
    /// width (an unset zone reads as all zeros `[inferred]`).
    pub fn is_defined(&self) -> bool {
        self.ranges.iter().any(Option::is_some)
            && self.ranges.iter().flatten().all(|(lo, hi)| hi > lo)
    }

    /// Whether the tool tip at `p` (base frame) is inside.
    #[inline]
    pub fn contains(&self, p: &Pose) -> bool {
        let v = [p.x, p.y, p.z, p.r];
        self.ranges
            .iter()
            .zip(v)
            .all(|(r, v)| r.is_none_or(|(lo, hi)| (lo..=hi).contains(&v)))
    }

    /// The X and Y bounds, for the plan view (`None` when either axis is not named).
    pub fn plan_rect(&self) -> Option<((f64, f64), (f64, f64))> {
        Some((self.ranges[0]?, self.ranges[1]?))
    }

    /// "zone 2 Z 0..150" (Z and R ranges where named), for labels.
    pub fn label(&self) -> String {
        let mut s = format!("zone {}", self.number);
        if let Some((lo, hi)) = self.ranges[2] {
            s += &format!(" Z {lo:.0}..{hi:.0}");
        }
        if let Some((lo, hi)) = self.ranges[3] {
            s += &format!(" R {lo:.0}..{hi:.0}");
        }
        s
    }
}

/// What is wrong at a point of a path.
#[derive(Clone, Debug, PartialEq)]
pub enum PathFault {
    /// A joint beyond its limit or the pose out of reach (the planner refuses the move).
    Joint(IkError),
    /// The arm nearly straight: J2 inside the singular band. A PTP move that flips the
    /// arm system passes through it (joint interpolation needs no inverse there); the
    /// flip asks for a second press already.
    Singular,
    /// The tool tip inside an interference zone (the pendant asks for a second press).
    Zone(u8),
}

impl std::fmt::Display for PathFault {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            PathFault::Joint(e) => write!(f, "{e}"),
            PathFault::Singular => f.write_str("crosses the singular band"),
            PathFault::Zone(n) => write!(f, "enters zone {n}"),
        }
    }
}

/// A point of a path where a check fails.
#[derive(Clone, Debug, PartialEq)]
pub struct PathMark {
    /// Sample number from 0 (the start).
    pub index: usize,
    /// The tool tip there, base frame.
    pub tip: Pose,
    pub fault: PathFault,
}

/// A path sampled and checked.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PathCheck {
    /// The tool tip at each sample, base frame, start and end included.
    pub tips: Vec<Pose>,
    /// The first sample that fails a check, if any.
    pub first: Option<PathMark>,
    /// The zones the tip is inside of after the start, in the order it first enters them.
    pub zones: Vec<u8>,
    /// The first sample inside the singular band, if any.
    pub singular: Option<usize>,
}

impl PathCheck {
    /// The first sample inside zone `n`.
    pub fn zone_entry(&self, zones: &[ZoneBox], n: u8) -> Option<&Pose> {
        let z = zones.iter().find(|z| z.number == n)?;
        self.tips.iter().skip(1).find(|t| z.contains(t))
    }
}

/// A bound of the tool tip's travel per unit of path fraction for the joint change `d`
/// (mm): J1 swings the whole arm and tool, J2 arm 2 and the tool, J4 the tool's offset.
fn ptp_tip_travel_bound(k: &Scara, d: &Joints, tool_xy: f64) -> f64 {
    let rad = |deg: f64| deg.abs().to_radians();
    rad(d.j1) * (k.l1 + k.l2 + tool_xy)
        + rad(d.j2) * (k.l2 + tool_xy)
        + rad(d.j4) * tool_xy
        + d.z.abs()
}

/// Samples and checks the whole path of `mv` with tool `tool` every `spacing_mm` of the
/// tip (at most [`MAX_PATH_SAMPLES`]): PTP at the joints interpolated linearly (as the
/// move runs), CP on its straight line. Zones not [`ZoneBox::is_defined`] are skipped.
pub fn sweep(
    k: &Scara,
    mv: &Move,
    tool: &CoordSystem,
    zones: &[ZoneBox],
    spacing_mm: f64,
) -> PathCheck {
    let spacing = if spacing_mm > 0.0 && spacing_mm.is_finite() {
        spacing_mm
    } else {
        PATH_SPACING_MM
    };
    let zones: Vec<&ZoneBox> = zones.iter().filter(|z| z.is_defined()).collect();
    let t = tool.offset();
    let tool_xy = t.x.hypot(t.y);
    let (start, end) = (mv.start(), mv.end());
    let n = match mv {
        Move::Ptp(_) => ptp_tip_travel_bound(k, &(end - start), tool_xy),
        Move::Cp(m) => {
            let turn = (m.tip_line().1.r - m.tip_line().0.r).abs().to_radians();
            m.length_mm() + tool_xy * turn
        }
    } / spacing;
    let n = (n.ceil() as usize).clamp(1, MAX_PATH_SAMPLES - 1);
    let mut out = PathCheck {
        tips: Vec::with_capacity(n + 1),
        ..PathCheck::default()
    };
    let d = end - start;
    for i in 0..=n {
        let u = i as f64 / n as f64;
        let (joints, tip) = match mv {
            Move::Ptp(_) => {
                let j = Joints::new(
                    start.j1 + d.j1 * u,
                    start.j2 + d.j2 * u,
                    start.z + d.z * u,
                    start.j4 + d.j4 * u,
                );
                (Ok(j), tip_of(k, &j, &t))
            }
            Move::Cp(m) => (m.joints_at_progress(u), m.tip_at_progress(u)),
        };
        out.tips.push(tip);
        let fault = match joints {
            Err(e) => Some(PathFault::Joint(e)),
            Ok(j) => match k.check_joints(&j) {
                Err(e) => Some(PathFault::Joint(e)),
                Ok(()) if k.arm_system(&j) == ArmSystem::Undetermined => {
                    out.singular.get_or_insert(i);
                    Some(PathFault::Singular)
                }
                Ok(()) => None,
            },
        };
        let mut fault = fault;
        if i > 0 {
            for z in &zones {
                if z.contains(&tip) {
                    if !out.zones.contains(&z.number) {
                        out.zones.push(z.number);
                    }
                    fault.get_or_insert(PathFault::Zone(z.number));
                }
            }
        }
        if let Some(fault) = fault
            && out.first.is_none()
        {
            out.first = Some(PathMark {
                index: i,
                tip,
                fault,
            });
        }
    }
    out
}

/// The tool tip of joints `j` with the tool offset `t` (mm, deg): the forward kinematics
/// and the tool in one, without the wire rounding of [`CoordSystem::flange_to_tip`].
#[inline]
fn tip_of(k: &Scara, j: &Joints, t: &Pose) -> Pose {
    let f = k.forward(j);
    let (s, c) = f.r.to_radians().sin_cos();
    Pose::new(
        f.x + c * t.x - s * t.y,
        f.y + s * t.x + c * t.y,
        f.z + t.z,
        f.r + t.r,
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::robot::{ArmPolicy, CpMove, CpParams, PtpMove, PtpParams, RobotModel};

    fn setup() -> (RobotModel, Scara) {
        let m = RobotModel::default_model();
        let k = Scara::new(&m);
        (m, k)
    }

    fn zone(n: u8, x: (f64, f64), y: (f64, f64)) -> ZoneBox {
        ZoneBox::from_corners(
            n,
            [Some(x.0), Some(y.0), Some(0.0), None],
            [Some(x.1), Some(y.1), Some(200.0), None],
        )
    }

    #[test]
    fn a_zone_contains_by_the_axes_it_names_and_an_all_zero_zone_is_not_defined() {
        let z = ZoneBox::from_corners(
            3,
            [Some(200.0), Some(100.0), Some(50.0), None],
            [Some(100.0), Some(-100.0), Some(0.0), None],
        );
        assert_eq!(z.ranges[0], Some((100.0, 200.0)), "corners sorted");
        assert!(
            z.contains(&Pose::new(150.0, 0.0, 25.0, 720.0)),
            "R is not named"
        );
        assert!(!z.contains(&Pose::new(150.0, 0.0, 60.0, 0.0)));
        assert!(z.is_defined());
        assert_eq!(z.label(), "zone 3 Z 0..50");
        let unset = ZoneBox::from_corners(4, [Some(0.0); 4], [Some(0.0); 4]);
        assert!(!unset.is_defined());
        assert!(!ZoneBox::from_corners(5, [None; 4], [None; 4]).is_defined());
    }

    #[test]
    fn a_ptp_path_is_sampled_at_most_a_millimetre_apart_and_finds_a_zone_between_its_ends() {
        let (m, k) = setup();
        let params = PtpParams::from_command(&m, 30, 30, 30);
        let start = Joints::new(-60.0, 90.0, 0.0, 0.0);
        let end = Joints::new(60.0, 90.0, 0.0, 0.0);
        let mv = Move::Ptp(PtpMove::joints(&k, start, end, &params).unwrap());
        // The tip swings through X ~ 354 at J1 = 45 (tip on the J1 + 45 deg ray).
        let mid = tip_of(&k, &Joints::new(0.0, 90.0, 0.0, 0.0), &Pose::default());
        let z = zone(2, (mid.x - 5.0, mid.x + 5.0), (mid.y - 5.0, mid.y + 5.0));
        let p = sweep(&k, &mv, &CoordSystem::ZERO, &[z], PATH_SPACING_MM);
        let gaps = p.tips.windows(2).map(|w| {
            let (a, b) = (w[0], w[1]);
            (a.x - b.x).hypot(a.y - b.y)
        });
        assert!(gaps.fold(0.0, f64::max) <= PATH_SPACING_MM + 1e-9);
        assert_eq!(p.zones, vec![2]);
        let first = p.first.clone().unwrap();
        assert_eq!(first.fault, PathFault::Zone(2));
        assert!(z.contains(&first.tip) && first.index > 0);
        assert!(p.tips.len() > 100);
        // The ends themselves are outside: only the whole path finds it.
        assert!(!z.contains(p.tips.first().unwrap()) && !z.contains(p.tips.last().unwrap()));
        assert_eq!(p.zone_entry(&[z], 2), Some(&first.tip));
    }

    #[test]
    fn a_ptp_flip_crosses_the_singular_band_and_a_cp_line_is_straight() {
        let (m, k) = setup();
        let params = PtpParams::from_command(&m, 30, 30, 30);
        let start = Joints::new(0.0, 60.0, 0.0, 0.0);
        let flange = k.forward(&start);
        let flipped = PtpMove::to_pose(&k, start, &flange, ArmPolicy::Left, &params).unwrap();
        let p = sweep(
            &k,
            &Move::Ptp(flipped),
            &CoordSystem::ZERO,
            &[],
            PATH_SPACING_MM,
        );
        assert!(p.singular.is_some());
        assert_eq!(p.first.map(|f| f.fault), Some(PathFault::Singular));

        let cp = CpParams::from_command(&m, 30, 30, 100);
        let to = Pose::new(flange.x + 40.0, flange.y - 30.0, flange.z, flange.r);
        let line = CpMove::plan(&k, start, &to, &CoordSystem::ZERO, &cp, 0.1).unwrap();
        let p = sweep(
            &k,
            &Move::Cp(Box::new(line)),
            &CoordSystem::ZERO,
            &[zone(1, (-50.0, 0.0), (-50.0, 0.0))],
            PATH_SPACING_MM,
        );
        assert_eq!(p.tips.len(), 51, "50 mm at 1 mm");
        assert!(p.first.is_none() && p.zones.is_empty());
        let mid = p.tips[25];
        assert!(
            (mid.x - (flange.x + 20.0)).abs() < 1e-6 && (mid.y - (flange.y - 15.0)).abs() < 1e-6
        );
    }

    #[test]
    fn a_huge_move_is_bounded_in_samples() {
        let (m, k) = setup();
        let params = PtpParams::from_command(&m, 30, 30, 30);
        let mv = PtpMove::joints(
            &k,
            Joints::new(-120.0, 140.0, 0.0, -350.0),
            Joints::new(120.0, -140.0, 200.0, 350.0),
            &params,
        )
        .unwrap();
        let tool = CoordSystem::from_wire([100_000, 0, 0, 0]);
        let p = sweep(&k, &Move::Ptp(mv), &tool, &[], 0.001);
        assert!(p.tips.len() <= MAX_PATH_SAMPLES);
    }
}
