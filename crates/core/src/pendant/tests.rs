//! The pendant driven by scripted link events: no threads, no clock, no line.

use std::time::{Duration, Instant};

use super::*;
use crate::link::{LinkEvent, Origin, RequestId};
use crate::protocol::{
    ArmPolicy as WirePolicy, Axis, CoordKind, Direction, JogMotion, Milli, PerAxis, PositionSystem,
    ScaraMotion, SystemMode, SystemStatus, SystemStatus1,
};
use crate::robot::{Joints, RobotModel, Scara};

fn t0() -> Instant {
    Instant::now()
}

fn pendant() -> Pendant {
    Pendant::new(Settings::default(), RobotModel::default_model())
}

use super::script::{poll_reply as reply, ready_system, scara_status as scara};

/// A pendant connected to a ready, homed controller whose arm is at `joints` (work 0 and
/// tool 0 all zeros, so work = base = the flange).
fn ready_at(joints: Joints, now: Instant) -> Pendant {
    let mut p = pendant();
    let kin = Scara::new(&p.model);
    for event in super::script::ready_controller(&kin, joints) {
        p.handle_event(now, event);
    }
    p.take_requests();
    p
}

/// The controller's acknowledge of a command the user sent.
fn accepted(command: Command) -> LinkEvent {
    LinkEvent::Reply {
        id: RequestId(9),
        origin: Origin::User,
        reply: Reply::Ack(command.id()),
        command,
        round_trip: Duration::from_millis(2),
    }
}

fn start() -> Joints {
    Joints::new(30.0, 60.0, 50.0, 0.0)
}

/// The commands the pendant asked the link to submit (other requests left out).
pub(super) fn submitted(p: &mut Pendant) -> Vec<Command> {
    p.take_requests()
        .into_iter()
        .filter_map(|r| match r {
            Request::Submit(c) => Some(c),
            _ => None,
        })
        .collect()
}

#[test]
fn connecting_asks_for_the_version_both_tables_in_turn_the_alarm_history_and_the_zones() {
    let now = t0();
    let mut p = pendant();
    p.handle_event(
        now,
        LinkEvent::Connected {
            line: "pipe".into(),
        },
    );
    let r = p.take_requests();
    assert_eq!(
        r,
        vec![
            Request::Submit(controller::version_query()),
            Request::ReadTable(CoordKind::Work),
            // Its first record, in the line time the polls leave.
            Request::Spare(Command::ErrorDetail(
                crate::protocol::ErrorDetailQuery::ListRecord { record: 1 }
            )),
            // The zones, every number in one query (the reply says how many came).
            Request::Spare(Command::ZoneQuery(crate::protocol::ZoneQuery {
                first: 1,
                count: 10
            })),
        ]
    );
    assert!(p.line.is_up());
    p.handle_event(
        now,
        LinkEvent::TableDone {
            kind: CoordKind::Work,
            axes: crate::protocol::AxisPattern::SCARA_1,
            first: 0,
            records: vec![None, Some(PerAxis::new())],
            missing: std::iter::once(0..1).collect(),
        },
    );
    assert_eq!(p.take_requests(), vec![Request::ReadTable(CoordKind::Tool)]);
    // A record that could not be read stays unknown, never zero.
    let table = p.controller.work_table.as_ref().unwrap();
    assert_eq!(table.records[0], None);
    assert!(p.messages.iter().any(|m| m.level == Level::Warning));
}

#[test]
fn a_work_step_is_one_2d5h_with_the_step_on_its_axis() {
    let now = t0();
    let mut p = ready_at(start(), now);
    p.settings.jog.step = 10.0;
    p.jog_step(JogAxis::X, Direction::Positive, now);
    let sent = submitted(&mut p);
    assert_eq!(sent.len(), 1, "{sent:?}");
    let Command::ScaraMoveRelative(m) = sent[0] else {
        panic!("not a 2D5H: {:?}", sent[0]);
    };
    assert_eq!(m.targets.get(Axis::A1), Some(Milli(10_000)));
    assert_eq!(m.targets.pattern(), crate::protocol::AxisPattern(0x01));
    // The 20 % asked for is above the reduced jog speed: the capped % goes out.
    let capped = jog::speed_cap::ptp_percent_cap(&p.model, jog::speed_cap::REDUCED_SPEED_MM_S);
    assert!(capped < 20);
    assert_eq!(
        m.motion,
        ScaraMotion::Ptp {
            acc: crate::protocol::Percent(30),
            dec: crate::protocol::Percent(30),
            speed: crate::protocol::Percent(capped),
            arm: WirePolicy::KeepNoSwitch,
        }
    );
}

#[test]
fn each_arm_policy_and_cp_reach_the_command() {
    let now = t0();
    for wire in [
        WirePolicy::KeepNoSwitch,
        WirePolicy::KeepMaySwitch,
        WirePolicy::Right,
    ] {
        let mut p = ready_at(start(), now);
        p.settings.jog.arm = wire;
        p.jog_step(JogAxis::Y, Direction::Negative, now);
        let sent = submitted(&mut p);
        let Some(Command::ScaraMoveRelative(m)) = sent.first() else {
            panic!("{wire:?}: nothing sent: {:?}", p.jog.feedback);
        };
        assert!(matches!(m.motion, ScaraMotion::Ptp { arm, .. } if arm == wire));
        assert_eq!(m.targets.get(Axis::A2), Some(Milli(-1000)));
    }
    let mut p = ready_at(start(), now);
    p.settings.jog.interpolation = Interpolation::Cp;
    p.settings.jog.cp_speed_mm_s = 80;
    p.jog_step(JogAxis::Z, Direction::Positive, now);
    let sent = submitted(&mut p);
    let Some(Command::ScaraMoveRelative(m)) = sent.first() else {
        panic!("CP step not sent: {:?}", p.jog.feedback);
    };
    assert_eq!(m.motion.operation_type() & 1, 1, "CP bit");
    assert!(matches!(m.motion, ScaraMotion::Cp { speed, .. } if speed.0 == 80));
}

#[test]
fn a_step_beyond_reach_is_refused_and_nothing_is_sent() {
    let now = t0();
    // Arm stretched out along X: a further X+ step leaves the outer reach.
    let mut p = ready_at(Joints::new(0.0, 1.0, 50.0, 0.0), now);
    p.settings.jog.step = 50.0;
    p.jog_step(JogAxis::X, Direction::Positive, now);
    assert!(submitted(&mut p).is_empty());
    let feedback = p.jog.feedback.clone().unwrap();
    assert_eq!(feedback.level, Level::Warning);
    assert!(feedback.text.starts_with("refused"), "{}", feedback.text);
}

#[test]
fn a_joint_step_beyond_its_limit_is_refused() {
    let now = t0();
    let model = RobotModel::default_model();
    let mut p = ready_at(Joints::new(model.j1.max - 0.5, 60.0, 50.0, 0.0), now);
    p.settings.jog.step = 1.0;
    p.jog_step(JogAxis::J1, Direction::Positive, now);
    assert!(submitted(&mut p).is_empty());
    assert!(p.jog.feedback.unwrap().text.contains("J1"));
}

#[test]
fn a_joint_step_is_236h_inching_in_the_each_axis_system() {
    let now = t0();
    let mut p = ready_at(start(), now);
    p.settings.jog.step = 0.1;
    p.jog_step(JogAxis::J2, Direction::Negative, now);
    let sent = submitted(&mut p);
    let Some(Command::Jog(j)) = sent.first() else {
        panic!("no 236H: {:?}", p.jog.feedback);
    };
    assert_eq!(j.distance, Milli(100));
    assert_eq!(j.direction, Direction::Negative);
    assert_eq!(j.axes, crate::protocol::AxisPattern(0x02));
    assert!(matches!(j.motion, JogMotion::Joint { .. }));
}

#[test]
fn motion_waits_for_servo_homing_and_auto_and_says_why() {
    let now = t0();
    let mut p = pendant();
    p.jog_step(JogAxis::X, Direction::Positive, now);
    assert_eq!(p.motion_ready(now), Err(NotReady::LineDown));
    assert!(submitted(&mut p).is_empty());
    p.handle_event(now, LinkEvent::Connected { line: "t".into() });
    p.take_requests();
    assert_eq!(p.motion_ready(now), Err(NotReady::NoStatus));
    let polls = controller::poll_commands();
    let manual = SystemStatus {
        mode: SystemMode::MANUAL,
        ..ready_system()
    };
    p.handle_event(now, reply(polls[1].clone(), Reply::SystemStatus(manual)));
    for (i, sys) in [(0, PositionSystem::Work), (2, PositionSystem::Joint)] {
        let s = scara(sys, [0.0; 4], false, false);
        p.handle_event(now, reply(polls[i].clone(), Reply::ScaraStatus(s)));
    }
    assert_eq!(p.motion_ready(now), Err(NotReady::Manual));
    p.handle_event(
        now,
        reply(polls[1].clone(), Reply::SystemStatus(ready_system())),
    );
    assert_eq!(p.motion_ready(now), Err(NotReady::ServoOff));
    let estop = SystemStatus {
        status1: SystemStatus1::default().with_emergency_stop(true),
        ..ready_system()
    };
    p.handle_event(now, reply(polls[1].clone(), Reply::SystemStatus(estop)));
    assert_eq!(p.motion_ready(now), Err(NotReady::EmergencyStop));
    p.jog_step(JogAxis::X, Direction::Positive, now);
    assert!(submitted(&mut p).is_empty());
    assert!(p.jog.feedback.unwrap().text.contains("emergency stop"));
}

#[test]
fn an_old_status_blocks_motion() {
    let now = t0();
    let mut p = ready_at(start(), now);
    let later = now + controller::STALE_AFTER + Duration::from_millis(1);
    assert_eq!(p.motion_ready(later), Err(NotReady::StatusStale));
    p.jog_step(JogAxis::X, Direction::Positive, later);
    assert!(submitted(&mut p).is_empty());
}

#[test]
fn stop_is_always_sent_even_with_the_line_down() {
    let now = t0();
    let mut p = pendant();
    p.stop(now);
    assert_eq!(p.take_requests(), vec![Request::Stop]);
}

#[test]
fn a_lost_line_forgets_the_status_and_refuses_motion() {
    let now = t0();
    let mut p = ready_at(start(), now);
    assert_eq!(p.motion_ready(now), Ok(()));
    p.handle_event(
        now,
        LinkEvent::Disconnected {
            reason: crate::link::LineDownReason::Closed,
        },
    );
    assert_eq!(p.motion_ready(now), Err(NotReady::LineDown));
    assert!(p.controller.work_position().is_none());
}

#[test]
fn a_base_frame_step_turns_with_the_work_frame() {
    let now = t0();
    let mut p = ready_at(start(), now);
    // Work No. 0 turned by 90 deg (as if work No. 1 were selected): a base X+ step is a
    // work-frame Y- step.
    let mut rec = PerAxis::new();
    rec.set(Axis::A4, Milli(90_000));
    p.handle_event(
        now,
        LinkEvent::TableDone {
            kind: CoordKind::Work,
            axes: crate::protocol::AxisPattern::SCARA_1,
            first: 0,
            records: vec![Some(rec)],
            missing: vec![],
        },
    );
    p.settings.jog.frame = crate::robot::JogFrame::Base;
    p.settings.jog.relative_to = crate::robot::RelativeTo::Actual;
    p.settings.jog.step = 5.0;
    let plan = p
        .preview_step(JogAxis::X, Direction::Positive, now)
        .unwrap();
    let Command::ScaraMoveRelative(m) = plan.command else {
        panic!()
    };
    assert_eq!(m.targets.get(Axis::A1).map(|t| t.0.abs()).unwrap_or(0), 0);
    assert_eq!(m.targets.get(Axis::A2), Some(Milli(-5000)));
}

#[test]
fn a_ptp_step_that_flips_the_arm_asks_for_a_second_press() {
    let now = t0();
    // Right arm, elbow nearly straight: a step to the left arm with policy "left arm".
    let mut p = ready_at(start(), now);
    p.settings.jog.arm = WirePolicy::Left;
    p.settings.jog.step = 0.01;
    p.jog_step(JogAxis::X, Direction::Positive, now);
    assert!(submitted(&mut p).is_empty(), "sent without confirmation");
    assert!(p.jog.feedback.as_ref().unwrap().text.contains("flips"));
    p.jog_step(
        JogAxis::X,
        Direction::Positive,
        now + Duration::from_secs(1),
    );
    assert_eq!(submitted(&mut p).len(), 1);
}

#[test]
fn steps_relative_to_command_chain_without_drift() {
    let now = t0();
    let mut p = ready_at(start(), now);
    p.settings.jog.step = 1.0;
    p.jog_step(JogAxis::X, Direction::Positive, now);
    let first = submitted(&mut p)[0].clone();
    p.handle_event(now, accepted(first));
    // The polls still say the start (the arm has not moved yet): the next step relative
    // to the command position still carries exactly 1 mm, added by the controller to
    // where the first step ends, and the plan ends 2 mm from the start.
    p.jog_step(JogAxis::X, Direction::Positive, now);
    let plan = p.followed_move().map(|m| m.end());
    let Command::ScaraMoveRelative(m) = submitted(&mut p)[0] else {
        panic!()
    };
    assert_eq!(m.targets.get(Axis::A1), Some(Milli(1000)));
    assert_eq!(
        m.targets.pattern(),
        crate::protocol::AxisPattern(0x01),
        "no drift"
    );
    let kin = Scara::new(&p.model);
    let x = |j: Joints| kin.forward(&j).x;
    let moved = x(plan.unwrap()) - x(start());
    assert!((moved - 2.0).abs() < 1e-6, "{moved}");
}

#[test]
fn a_step_relative_to_actual_follows_the_polled_arm() {
    let now = t0();
    let mut p = ready_at(start(), now);
    p.settings.jog.step = 1.0;
    p.jog_step(JogAxis::X, Direction::Positive, now);
    let first = submitted(&mut p)[0].clone();
    p.handle_event(now, accepted(first));
    // Relative to actual, with the arm still at the start: 1 mm from where it stands,
    // which is 1 mm short of where the controller's first step ends.
    p.settings.jog.relative_to = crate::robot::RelativeTo::Actual;
    p.jog_step(JogAxis::X, Direction::Positive, now);
    let Command::ScaraMoveRelative(m) = submitted(&mut p)[0] else {
        panic!()
    };
    assert_eq!(m.targets.get(Axis::A1), Some(Milli(0)));
}

#[test]
fn a_port_that_fails_to_open_says_why_and_what_to_do() {
    use crate::link::{IoFailure, LineDownReason};
    let now = t0();
    let mut p = pendant();
    let failed = |kind, detail: &str| LinkEvent::Disconnected {
        reason: LineDownReason::OpenFailed(IoFailure {
            kind,
            detail: detail.into(),
        }),
    };
    p.handle_event(
        now,
        failed(std::io::ErrorKind::PermissionDenied, "Permission denied"),
    );
    let LineState::Down { reason, .. } = &p.line else {
        panic!("{:?}", p.line)
    };
    assert!(
        reason.contains("Permission denied") && reason.contains("no permission"),
        "{reason}"
    );
    #[cfg(target_os = "linux")]
    assert!(reason.contains("dialout"), "{reason}");
    p.handle_event(
        now,
        failed(std::io::ErrorKind::NotFound, "No such file or directory"),
    );
    assert!(p.line.to_string().contains("does not exist"), "{}", p.line);
    p.handle_event(
        now,
        failed(std::io::ErrorKind::Other, "Device or resource busy"),
    );
    assert!(p.line.to_string().contains("another program"), "{}", p.line);
}

#[test]
fn a_recorded_point_is_gone_to_with_2d4h_in_its_own_frame() {
    let now = t0();
    let mut p = ready_at(start(), now);
    p.teach_record("", now);
    assert_eq!(p.teach.list().len(), 1);
    assert_eq!(p.teach.list().get(0).unwrap().name, "P1");
    // Away from the point, "Go" sends one 2D4H to the recorded pose.
    let mut p2 = ready_at(Joints::new(20.0, 70.0, 40.0, 10.0), now);
    p2.teach.set(p.teach.list().clone());
    p2.teach_go(0, now);
    let sent = submitted(&mut p2);
    let Some(Command::ScaraMoveAbsolute(m)) = sent.first() else {
        panic!("no 2D4H: {:?}", p2.jog.feedback);
    };
    let pose = p.teach.list().get(0).unwrap().pose;
    for (i, axis) in [Axis::A1, Axis::A2, Axis::A3, Axis::A4]
        .into_iter()
        .enumerate()
    {
        assert_eq!(m.targets.get(axis), Some(Milli(pose[i])));
    }
    // Taught in another work frame: refused, nothing sent.
    let mut other = p.teach.list().clone();
    let mut point = other.remove(0).unwrap();
    point.work = 3;
    other.insert(0, point).unwrap();
    p2.teach.set(other);
    p2.take_requests();
    p2.jog.followed = None;
    p2.teach_go(0, now);
    assert!(submitted(&mut p2).is_empty());
    assert!(p2.jog.feedback.unwrap().text.contains("work frame 3"));
}

#[test]
fn link_health_counts_faults_over_the_last_minute() {
    use crate::link::health::LinkHealth;
    let now = t0();
    let mut p = pendant();
    let health = |timeouts, bad_frames| {
        LinkEvent::Health(LinkHealth {
            timeouts,
            bad_frames,
            ..LinkHealth::default()
        })
    };
    p.handle_event(now, health(2, 1));
    p.handle_event(now + Duration::from_secs(30), health(5, 1));
    assert_eq!(p.faults_last_minute(), Some((3, 0)));
    // A minute later the early reports have left the window.
    p.handle_event(now + Duration::from_secs(95), health(6, 4));
    assert_eq!(p.faults_last_minute(), Some((1, 3)));
}

#[test]
fn a_stop_after_the_move_ended_leaves_it_done_and_one_before_cuts_it_short() {
    let ms = Duration::from_millis;
    for (stop_after, phase) in [
        (ms(10), MotionPhase::Stopped),
        (ms(30_000), MotionPhase::Done),
    ] {
        let now = t0();
        let mut p = ready_at(start(), now);
        p.settings.jog.step = 10.0;
        p.jog_step(JogAxis::X, Direction::Positive, now);
        let step = submitted(&mut p).remove(0);
        p.handle_event(now, accepted(step));
        p.stop(now + stop_after);
        assert_eq!(
            p.motion_phase(now + stop_after + ms(1)),
            phase,
            "{stop_after:?}"
        );
    }
}

/// The RMC connected beside the arm, axis 1 enabled at Command Position `at`, axis 2
/// disabled at 0.
fn rmc_ready(p: &mut Pendant, at: f32, now: Instant) {
    use crate::rmc::{AxisId, AxisStatus, RmcEvent, StatusBits};
    p.handle_axes_event(
        now,
        RmcEvent::LineUp {
            name: "sim".into(),
            at: now,
        },
    );
    for (i, enabled, position) in [(0, true, at), (1, false, 0.0)] {
        let status = AxisStatus {
            bits: StatusBits(0).with(StatusBits::ENABLED, enabled),
            command_position: position,
            ..Default::default()
        };
        p.handle_axes_event(
            now,
            RmcEvent::Status {
                axis: AxisId::new(i).unwrap(),
                status,
                trusted: true,
                at: now,
            },
        );
    }
}

#[test]
fn a_point_taught_with_rmc_axes_goes_there_with_move_absolute_or_not_at_all() {
    use crate::pendant::axes::AxisCall;
    use crate::rmc::{AxisId, Command as RmcCommand};
    let now = t0();
    let mut p = ready_at(start(), now);
    rmc_ready(&mut p, 12.345, now);
    p.settings.rmc.teach_axes = true;
    p.teach_record("", now);
    let point = p.teach.list().get(0).unwrap().clone();
    assert_eq!(point.axes, vec![12_345, 0], "Command Positions in 0.001 pu");
    // The CSV and JSON files keep them.
    let csv = p.teach.list().to_csv();
    assert!(
        csv.starts_with("\u{feff}name,x_mm,y_mm,z_mm,r_deg,arm,work,tool,axis1_pu,axis2_pu\r\n")
    );
    assert_eq!(
        crate::pendant::teach::TeachList::from_csv(&csv).unwrap(),
        *p.teach.list()
    );
    let json = p.teach.list().to_json();
    assert_eq!(
        crate::pendant::teach::TeachList::from_json(&json).unwrap(),
        *p.teach.list()
    );
    // Axis 2 is disabled: Go is refused whole, the arm included.
    let mut p2 = ready_at(Joints::new(20.0, 70.0, 40.0, 10.0), now);
    rmc_ready(&mut p2, 0.0, now);
    p2.teach.set(p.teach.list().clone());
    p2.teach_go(0, now);
    assert!(p2.take_requests().is_empty());
    assert!(
        p2.jog
            .feedback
            .as_ref()
            .unwrap()
            .text
            .contains("Axis 2 is not enabled")
    );
    // With axis 1 only: the arm's 2D4H, then Move Absolute to 12.345.
    let mut one = p.teach.list().clone();
    let mut q = one.remove(0).unwrap();
    q.axes.truncate(1);
    one.insert(0, q).unwrap();
    p2.teach.set(one);
    p2.teach_go(0, now);
    let requests = p2.take_requests();
    assert!(matches!(
        requests.first(),
        Some(Request::Submit(Command::ScaraMoveAbsolute(_)))
    ));
    let moves: Vec<_> = requests
        .iter()
        .filter_map(|r| match r {
            Request::Axes(AxisCall::Send(a, RmcCommand::MoveAbsolute(m))) => Some((*a, m.position)),
            _ => None,
        })
        .collect();
    assert_eq!(moves, vec![(AxisId::new(0).unwrap(), 12.345)]);
}
