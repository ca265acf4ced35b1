//! Scripted link events of a controller in a known state: what the pendant would hear
//! from a ready, homed SCARA at given joints. For tests, benches and image snapshots,
//! where the window must show the same thing every time.

use std::time::Duration;

use super::controller as state;
use crate::link::{LinkEvent, Origin, RequestId};
use crate::protocol::{
    Axis, AxisPattern, AxisState, AxisStatus, CommonStatus, CoordKind, HomeState, Milli, PerAxis,
    PositionSystem, Reply, ScaraStatus, SystemMode, SystemStatus, SystemStatus3, VersionInfo,
};
use crate::robot::{Joints, Scara};

/// A system status: AUTO, ready, no E-stop, no alarm.
pub fn ready_system() -> SystemStatus {
    SystemStatus {
        mode: SystemMode::AUTO,
        status3: SystemStatus3::default().with_ready(true),
        ..SystemStatus::default()
    }
}

/// A 2A1H reply in `system` with the four SCARA positions `values` (mm, deg).
pub fn scara_status(
    system: PositionSystem,
    values: [f64; 4],
    servo: bool,
    homed: bool,
) -> ScaraStatus {
    let status = AxisStatus::default()
        .with_servo_on(servo)
        .with_home_state(if homed {
            HomeState::Done
        } else {
            HomeState::NotDone
        });
    let axes = PerAxis::from_fn(AxisPattern::SCARA_1, |a: Axis| AxisState {
        status,
        position: Milli::from_units(values[a.index()]).unwrap_or_default(),
        ..AxisState::default()
    });
    ScaraStatus {
        work: 0,
        tool: 0,
        common: CommonStatus {
            arm: crate::protocol::ArmSystem::Right,
            system,
        },
        axes,
    }
}

/// The reply event to a poll.
pub fn poll_reply(command: crate::protocol::Command, reply: Reply) -> LinkEvent {
    LinkEvent::Reply {
        id: RequestId(1),
        origin: Origin::Poll,
        command,
        reply,
        round_trip: Duration::from_millis(3),
    }
}

/// Everything a pendant hears from connecting to a ready, homed controller whose arm is
/// at `joints`, with work 0 and tool 0 all zeros (so work = base = the flange).
pub fn ready_controller(kin: &Scara, joints: Joints) -> Vec<LinkEvent> {
    let tip = kin.forward(&joints).to_array();
    let polls = state::poll_commands();
    let mut events = vec![
        LinkEvent::Connected {
            line: "scripted controller".into(),
        },
        poll_reply(
            state::version_query(),
            Reply::Version(VersionInfo {
                version: 0x107,
                model: 0x15,
                year: 2024,
                month: 3,
                day: 15,
                ..VersionInfo::default()
            }),
        ),
        poll_reply(polls[1].clone(), Reply::SystemStatus(ready_system())),
    ];
    for (i, system, values) in [
        (0, PositionSystem::Work, tip),
        (2, PositionSystem::Joint, joints.to_array()),
        (3, PositionSystem::Base, tip),
    ] {
        let s = scara_status(system, values, true, true);
        events.push(poll_reply(polls[i].clone(), Reply::ScaraStatus(s)));
    }
    for kind in [CoordKind::Work, CoordKind::Tool] {
        events.push(LinkEvent::TableDone {
            kind,
            axes: AxisPattern::SCARA_1,
            first: 0,
            records: vec![Some(PerAxis::new()); 4],
            missing: vec![],
        });
    }
    events
}
