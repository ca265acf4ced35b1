//! Wire codes <-> robot types, the one home for both: arm policy (2D4H-2D6H operation
//! type bits 3-4), jog frame (236H bits 1-2), arm system (2A1H/2A3H common status),
//! table kind (2A0H/2A4H coordinate type) and interference zone (2A2H record).
//!
//! Sits above `protocol` (which knows the bits) and `robot` (which knows nothing of the
//! wire); the simulator uses it, and so will the pendant.

use crate::protocol;
use crate::robot;

impl From<protocol::ArmPolicy> for robot::ArmPolicy {
    fn from(p: protocol::ArmPolicy) -> Self {
        match p {
            protocol::ArmPolicy::KeepNoSwitch => robot::ArmPolicy::CurrentNoSwitch,
            protocol::ArmPolicy::KeepMaySwitch => robot::ArmPolicy::CurrentMaySwitch,
            protocol::ArmPolicy::Right => robot::ArmPolicy::Right,
            protocol::ArmPolicy::Left => robot::ArmPolicy::Left,
        }
    }
}

impl From<robot::ArmPolicy> for protocol::ArmPolicy {
    fn from(p: robot::ArmPolicy) -> Self {
        match p {
            robot::ArmPolicy::CurrentNoSwitch => protocol::ArmPolicy::KeepNoSwitch,
            robot::ArmPolicy::CurrentMaySwitch => protocol::ArmPolicy::KeepMaySwitch,
            robot::ArmPolicy::Right => protocol::ArmPolicy::Right,
            robot::ArmPolicy::Left => protocol::ArmPolicy::Left,
        }
    }
}

impl From<protocol::JogFrame> for robot::JogFrame {
    fn from(f: protocol::JogFrame) -> Self {
        match f {
            protocol::JogFrame::Base => robot::JogFrame::Base,
            protocol::JogFrame::Work => robot::JogFrame::Work,
            protocol::JogFrame::Tool => robot::JogFrame::Tool,
        }
    }
}

impl From<robot::JogFrame> for protocol::JogFrame {
    fn from(f: robot::JogFrame) -> Self {
        match f {
            robot::JogFrame::Base => protocol::JogFrame::Base,
            robot::JogFrame::Work => protocol::JogFrame::Work,
            robot::JogFrame::Tool => protocol::JogFrame::Tool,
        }
    }
}

impl From<protocol::ArmSystem> for robot::ArmSystem {
    fn from(a: protocol::ArmSystem) -> Self {
        match a {
            protocol::ArmSystem::Right => robot::ArmSystem::Right,
            protocol::ArmSystem::Left => robot::ArmSystem::Left,
            protocol::ArmSystem::Undetermined => robot::ArmSystem::Undetermined,
        }
    }
}

impl From<robot::ArmSystem> for protocol::ArmSystem {
    fn from(a: robot::ArmSystem) -> Self {
        match a {
            robot::ArmSystem::Right => protocol::ArmSystem::Right,
            robot::ArmSystem::Left => protocol::ArmSystem::Left,
            robot::ArmSystem::Undetermined => protocol::ArmSystem::Undetermined,
        }
    }
}

impl From<protocol::CoordKind> for robot::FrameKind {
    fn from(k: protocol::CoordKind) -> Self {
        match k {
            protocol::CoordKind::Work => robot::FrameKind::Work,
            protocol::CoordKind::Tool => robot::FrameKind::Tool,
        }
    }
}

impl From<robot::FrameKind> for protocol::CoordKind {
    fn from(k: robot::FrameKind) -> Self {
        match k {
            robot::FrameKind::Work => protocol::CoordKind::Work,
            robot::FrameKind::Tool => protocol::CoordKind::Tool,
        }
    }
}

/// The box of 2A2H record `rec` of zone `number`: axes 1-4 are the SCARA's X, Y, Z
/// (0.001 mm) and R (0.001 deg) in the base frame (PROTOCOL.md 3.46); other axes of the
/// pattern are not the arm's and are left out.
pub fn zone_box(number: u8, rec: &protocol::ZoneRecord) -> robot::ZoneBox {
    let axis = |c: &protocol::PerAxis<protocol::Milli>| {
        [1u8, 2, 3, 4].map(|n| {
            protocol::Axis::new(n)
                .and_then(|a| c.get(a))
                .map(|v| v.units())
        })
    };
    robot::ZoneBox::from_corners(number, axis(&rec.corner1), axis(&rec.corner2))
}

/// The frame a 236H jog moves in, or `None` for the each-axis (joint) system.
pub fn jog_frame(motion: &protocol::JogMotion) -> Option<robot::JogFrame> {
    match *motion {
        protocol::JogMotion::Cartesian { frame, .. } => Some(frame.into()),
        protocol::JogMotion::Joint { .. } => None,
    }
}

/// A PTP move's arm policy, or `None` for a CP move (which keeps the current arm).
pub fn arm_policy(motion: &protocol::ScaraMotion) -> Option<robot::ArmPolicy> {
    match *motion {
        protocol::ScaraMotion::Ptp { arm, .. } => Some(arm.into()),
        protocol::ScaraMotion::Cp { .. } => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::protocol::{CentiG, MmPerSec, Percent};

    #[test]
    fn every_arm_policy_code_round_trips() {
        let names = [
            (0, robot::ArmPolicy::CurrentNoSwitch),
            (1, robot::ArmPolicy::CurrentMaySwitch),
            (2, robot::ArmPolicy::Right),
            (3, robot::ArmPolicy::Left),
        ];
        for (code, policy) in names {
            let wire = protocol::ArmPolicy::from_code(code).expect("codes 0-3 exist");
            assert_eq!(robot::ArmPolicy::from(wire), policy, "code {code}");
            assert_eq!(protocol::ArmPolicy::from(policy).code(), code);
        }
    }

    #[test]
    fn every_jog_frame_round_trips() {
        for (wire, frame) in [
            (protocol::JogFrame::Base, robot::JogFrame::Base),
            (protocol::JogFrame::Work, robot::JogFrame::Work),
            (protocol::JogFrame::Tool, robot::JogFrame::Tool),
        ] {
            assert_eq!(robot::JogFrame::from(wire), frame);
            assert_eq!(protocol::JogFrame::from(frame), wire);
            let motion = protocol::JogMotion::Cartesian {
                frame: wire,
                acc: CentiG(0),
                dec: CentiG(0),
                speed: MmPerSec(0),
            };
            assert_eq!(jog_frame(&motion), Some(frame));
        }
        let joint = protocol::JogMotion::Joint {
            acc: Percent(0),
            dec: Percent(0),
            speed: Percent(0),
        };
        assert_eq!(jog_frame(&joint), None, "each-axis system has no frame");
    }

    #[test]
    fn both_table_kinds_round_trip() {
        for (wire, kind) in [
            (protocol::CoordKind::Work, robot::FrameKind::Work),
            (protocol::CoordKind::Tool, robot::FrameKind::Tool),
        ] {
            assert_eq!(robot::FrameKind::from(wire), kind);
            assert_eq!(protocol::CoordKind::from(kind), wire);
        }
    }

    #[test]
    fn every_arm_system_round_trips_through_both_status_tables() {
        for arm in [
            robot::ArmSystem::Right,
            robot::ArmSystem::Left,
            robot::ArmSystem::Undetermined,
        ] {
            let wire = protocol::ArmSystem::from(arm);
            assert_eq!(robot::ArmSystem::from(wire), arm);
            let via_2a1 = protocol::ArmSystem::from_2a1(wire.to_2a1()).map(robot::ArmSystem::from);
            let via_2a3 = protocol::ArmSystem::from_2a3(wire.to_2a3()).map(robot::ArmSystem::from);
            assert_eq!((via_2a1, via_2a3), (Some(arm), Some(arm)));
        }
    }
}
