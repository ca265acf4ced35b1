//! Every example frame of PROTOCOL.md 6.3 decodes to its meaning, and the computed-SC
//! frames re-encode byte for byte from their typed form; negative coordinates are exact.

use crate::vectors::*;
use xsel_pendant::protocol::*;

// ---------------------------------------------------------------- 6.3

#[test]
fn s6_3_test_call() {
    assert_eq!(cmd_vector("!9920025"), Command::TestCall(TestData::EMPTY));
    assert_eq!(reply_vector("#9920027"), Reply::TestCall(TestData::EMPTY));
    assert_eq!(
        cmd_vector("!99200012345678932"),
        Command::TestCall(TestData::new(b"0123456789").unwrap())
    );
}

#[test]
fn s6_3_version() {
    assert_eq!(
        cmd_vector("!99201000B6"),
        Command::Version(VersionQuery {
            unit: UnitType::MAIN_APPLICATION,
            device: 0
        })
    );
    assert_eq!(
        reply_vector("#992010001200011007E8030F0A141E46"),
        Reply::Version(VersionInfo {
            unit: UnitType(0),
            device: 0,
            model: 0x12,
            unit_code: 0,
            version: 0x0110,
            year: 2024,
            month: 3,
            day: 15,
            hour: 10,
            minute: 20,
            second: 30,
        })
    );
}

#[test]
fn s6_3_axis_status() {
    assert_eq!(
        cmd_vector("!992120189"),
        Command::AxisStatus {
            axes: AxisPattern(0x01)
        }
    );
    let Reply::AxisStatus(a) = reply_vector("#99212011C0000000000C350BA") else {
        panic!()
    };
    let s = a.get(Axis::A1).unwrap();
    assert!(s.status.servo_on());
    assert_eq!(s.status.home_state(), HomeState::Done);
    assert!(s.status.completed_normally());
    assert_eq!(s.position, t(50_000));

    assert_eq!(
        cmd_vector("!99212038B"),
        Command::AxisStatus {
            axes: AxisPattern(0x03)
        }
    );
    let Reply::AxisStatus(a) = reply_vector("#99212030D400000FFFFCFC70C0000000003D09073") else {
        panic!()
    };
    let a1 = a.get(Axis::A1).unwrap();
    assert!(a1.status.in_use());
    assert!(a1.sensor.home());
    assert_eq!(a1.error, ErrorCode::NONE);
    assert_eq!(a1.position, t(-12_345));
    let a2 = a.get(Axis::A2).unwrap();
    assert!(!a2.status.in_use());
    assert_eq!(a2.position, t(250_000));
}

#[test]
fn s6_3_system_status() {
    assert_eq!(cmd_vector("!992152B"), Command::SystemStatus);
    let Reply::SystemStatus(s) = reply_vector("#9921510000000000060004") else {
        panic!()
    };
    assert_eq!(s.mode, SystemMode::AUTO);
    assert_eq!(s.critical_error, ErrorCode::NONE);
    assert_eq!(s.latest_error, ErrorCode::NONE);
    assert!(s.status3.ready());
    assert!(s.status3.auto_operation());
    assert!(!s.status3.drive_cut_off());
    assert!(!s.status1.emergency_stop());
    assert!(s.motion_allowed());
}

#[test]
fn s6_3_servo() {
    assert_eq!(
        cmd_vector("!99232011BC"),
        Command::Servo(Servo {
            axes: AxisPattern(0x01),
            on: true
        })
    );
    assert_eq!(
        cmd_vector("!99232070C1"),
        Command::Servo(Servo {
            axes: AxisPattern(0x07),
            on: false
        })
    );
    assert_eq!(reply_vector("#992322C"), Reply::Ack(MessageId::SERVO));
}

#[test]
fn s6_3_home() {
    assert_eq!(
        cmd_vector("!9923301000000AC"),
        Command::Home(Home {
            axes: AxisPattern(0x01),
            ..Home::default()
        })
    );
    assert_eq!(
        cmd_vector("!9923307014003BA"),
        Command::Home(Home {
            axes: AxisPattern(0x07),
            search: MmPerSec(20),
            creep: MmPerSec(3)
        })
    );
    assert_eq!(reply_vector("#992332D"), Reply::Ack(MessageId::HOME));
}

#[test]
fn s6_3_absolute_and_relative_moves() {
    assert_eq!(
        cmd_vector("!9923401001E001E00640000C3509E"),
        Command::MoveAbsolute(AxisMove {
            acc: CentiG(30),
            dec: CentiG(30),
            speed: MmPerSec(100),
            targets: axes(&[(1, t(50_000))]),
        })
    );
    assert_eq!(
        cmd_vector("!99234030000000000C8FFFFCFC7000186A0A5"),
        Command::MoveAbsolute(AxisMove {
            acc: CentiG(0),
            dec: CentiG(0),
            speed: MmPerSec(200),
            targets: axes(&[(1, t(-12_345)), (2, t(100_000))]),
        })
    );
    assert_eq!(
        reply_vector("#992342E"),
        Reply::Ack(MessageId::MOVE_ABSOLUTE)
    );
    assert_eq!(
        cmd_vector("!9923501000000000032FFFFD8F0DD"),
        Command::MoveRelative(AxisMove {
            acc: CentiG(0),
            dec: CentiG(0),
            speed: MmPerSec(50),
            targets: axes(&[(1, t(-10_000))]),
        })
    );
    assert_eq!(
        reply_vector("#992352F"),
        Reply::Ack(MessageId::MOVE_RELATIVE)
    );
}

#[test]
fn s6_3_jog_and_inching() {
    let cart = |frame, speed| JogMotion::Cartesian {
        frame,
        acc: CentiG(0),
        dec: CentiG(0),
        speed: MmPerSec(speed),
    };
    assert_eq!(
        cmd_vector("!992360100000000000A00000000191"),
        Command::Jog(Jog {
            axes: AxisPattern(0x01),
            direction: Direction::Positive,
            distance: t(0),
            motion: cart(JogFrame::Base, 10),
        })
    );
    assert_eq!(
        cmd_vector("!992360200000000000A000003E80B1"),
        Command::Jog(Jog {
            axes: AxisPattern(0x02),
            direction: Direction::Negative,
            distance: t(1000),
            motion: cart(JogFrame::Base, 10),
        })
    );
    assert_eq!(
        cmd_vector("!9923601000000000005000001F43A2"),
        Command::Jog(Jog {
            axes: AxisPattern(0x01),
            direction: Direction::Positive,
            distance: t(500),
            motion: cart(JogFrame::Work, 5),
        })
    );
    assert_eq!(reply_vector("#9923630"), Reply::Ack(MessageId::JOG));
}

#[test]
fn s6_3_stop() {
    let c = cmd_vector("!992380100F1");
    assert_eq!(
        c,
        Command::Stop(Stop {
            axes: AxisPattern(0x01),
            cancel_held_outputs: false
        })
    );
    assert!(c.is_stop() && !c.is_motion());
    assert_eq!(
        cmd_vector("!99238FF001C"),
        Command::Stop(Stop {
            axes: AxisPattern::ALL,
            cancel_held_outputs: false
        })
    );
    assert_eq!(reply_vector("#9923832"), Reply::Ack(MessageId::STOP));
}

#[test]
fn s6_3_alarm_reset_software_reset_speed_change() {
    assert_eq!(cmd_vector("!992522C"), Command::AlarmReset);
    assert_eq!(reply_vector("#992522E"), Reply::Ack(MessageId::ALARM_RESET));
    assert_eq!(cmd_vector("!9925B3C"), Command::SoftwareReset);
    assert_eq!(
        reply_vector("#9925B3E"),
        Reply::Ack(MessageId::SOFTWARE_RESET)
    );
    let c = cmd_vector("!9926201003253");
    assert_eq!(
        c,
        Command::SpeedChange(SpeedChange {
            axes: AxisPattern(0x01),
            speed: MmPerSec(50)
        })
    );
    assert!(c.is_motion());
    assert_eq!(
        reply_vector("#992622F"),
        Reply::Ack(MessageId::SPEED_CHANGE)
    );
}

#[test]
fn s6_3_coordinate_tables() {
    assert_eq!(
        cmd_vector("!992A00010128"),
        Command::CoordQuery(CoordQuery {
            kind: CoordKind::Work,
            first: 1,
            count: 1
        })
    );
    assert_eq!(
        reply_vector("#992A000101000186A0FFFF3CB00000000000015F90EF"),
        Reply::CoordTable(CoordTable {
            kind: CoordKind::Work,
            first: 1,
            records: vec![XyzR {
                x: t(100_000),
                y: t(-50_000),
                z: t(0),
                r: t(90_000)
            }],
        })
    );
    assert_eq!(
        cmd_vector("!992A40F10001A2"),
        Command::CoordQuery2(CoordQuery2 {
            axes: AxisPattern::SCARA_1,
            kind: CoordKind::Tool,
            first: 0,
            count: 1
        })
    );
    assert_eq!(
        reply_vector("#992A40F100010000000000000000000088B800000000CE"),
        Reply::CoordTable2(CoordTable2 {
            axes: AxisPattern::SCARA_1,
            kind: CoordKind::Tool,
            first: 0,
            records: vec![axes(&[(1, t(0)), (2, t(0)), (3, t(35_000)), (4, t(0))])],
        })
    );
    let d = describe(&wire("#992A000101000186A0FFFF3CB00000000000015F90EF"));
    assert!(
        d.fields
            .iter()
            .any(|f| f.name == "record 1 R offset" && f.value == "90.000 deg")
    );
    assert!(
        d.fields
            .iter()
            .any(|f| f.name == "record 1 Y offset" && f.value == "-50.000 mm")
    );
}

fn scara_axes() -> PerAxis<AxisState> {
    let st = AxisStatus(0x1C);
    let blk = |p| AxisState {
        status: st,
        position: t(p),
        ..AxisState::default()
    };
    axes(&[
        (1, blk(300_000)),
        (2, blk(-150_000)),
        (3, blk(20_000)),
        (4, blk(45_000)),
    ])
}

#[test]
fn s6_3_scara_status() {
    assert_eq!(
        cmd_vector("!992A10F0DD"),
        Command::ScaraStatus(ScaraStatusQuery {
            axes: AxisPattern::SCARA_1,
            system: PositionSystem::Base
        })
    );
    let r = reply_vector(
        "#992A10100000F1C000000000493E01C000000FFFDB6101C00000000004E201C0000000000AFC811",
    );
    assert_eq!(
        r,
        Reply::ScaraStatus(ScaraStatus {
            work: 1,
            tool: 0,
            common: CommonStatus {
                arm: ArmSystem::Right,
                system: PositionSystem::Base
            },
            axes: scara_axes(),
        })
    );
    let d = describe(&wire(
        "#992A10100000F1C000000000493E01C000000FFFDB6101C00000000004E201C0000000000AFC811",
    ));
    assert!(
        d.fields
            .iter()
            .any(|f| f.name == "axis 4 position" && f.value == "45.000 deg"),
        "{d}"
    );
}

#[test]
fn s6_3_scara_status_2_uses_its_own_arm_codes() {
    assert_eq!(
        cmd_vector("!992A30F000F"),
        Command::ScaraStatus2(ScaraStatusQuery2 {
            axes: AxisPattern::SCARA_1,
            system_1_4: PositionSystem::Base,
            system_5_8: PositionSystem::Base
        })
    );
    let Reply::ScaraStatus2(s) = reply_vector(
        "#992A30F0100010000000F1C000000000493E01C000000FFFDB6101C00000000004E201C0000000000AFC8AA",
    ) else {
        panic!()
    };
    assert_eq!(s.scara_axes, AxisPattern::SCARA_1);
    assert_eq!(s.unit1.work, 1);
    assert_eq!(s.unit1.tool, 0);
    // Code 01 means right arm in 2A3H (in 2A1H it would mean left).
    assert_eq!(s.unit1.common.arm, ArmSystem::Right);
    assert_eq!(s.unit2.common.arm, ArmSystem::Undetermined);
    assert_eq!(s.axes, scara_axes());
}

#[test]
fn s6_3_scara_moves() {
    let c = cmd_vector("!992D40F00000000001E02000493E0FFFDB61000004E200000AFC85C");
    assert_eq!(
        c,
        Command::ScaraMoveAbsolute(ScaraMove {
            motion: ScaraMotion::Ptp {
                acc: Percent(0),
                dec: Percent(0),
                speed: Percent(30),
                arm: ArmPolicy::KeepNoSwitch
            },
            targets: axes(&[
                (1, t(300_000)),
                (2, t(-150_000)),
                (3, t(20_000)),
                (4, t(45_000))
            ]),
        })
    );
    assert!(c.is_motion());
    assert_eq!(
        reply_vector("#992D43F"),
        Reply::Ack(MessageId::SCARA_MOVE_ABSOLUTE)
    );
    assert_eq!(
        cmd_vector("!992D50F0000000000320300000000FFFFEC780000000000000000EB"),
        Command::ScaraMoveRelative(ScaraMove {
            motion: ScaraMotion::Cp {
                acc: CentiG(0),
                dec: CentiG(0),
                speed: MmPerSec(50)
            },
            targets: axes(&[(1, t(0)), (2, t(-5000)), (3, t(0)), (4, t(0))]),
        })
    );
    assert_eq!(
        reply_vector("#992D540"),
        Reply::Ack(MessageId::SCARA_MOVE_RELATIVE)
    );
    assert_eq!(
        cmd_vector("!992D60F00000000000002000C2A"),
        Command::ScaraMovePosition(ScaraPositionMove {
            axes: AxisPattern::SCARA_1,
            motion: ScaraMotion::default(),
            position: 12
        })
    );
    assert_eq!(
        reply_vector("#992D641"),
        Reply::Ack(MessageId::SCARA_MOVE_POSITION)
    );
    let d = describe(&wire(
        "!992D40F00000000001E02000493E0FFFDB61000004E200000AFC85C",
    ));
    assert!(
        d.fields
            .iter()
            .any(|f| f.name == "speed" && f.value == "30 %"),
        "{d}"
    );
    assert!(
        d.fields
            .iter()
            .any(|f| f.name == "axis 4 target" && f.value == "45.000 deg"),
        "{d}"
    );
}

#[test]
fn s6_3_error_reply() {
    let r = reply_vector("&99CC14F");
    assert_eq!(r, Reply::Error(ErrorCode::SPEED_CHANGE_CONDITION));
    assert_eq!(r.id(), None);
}

// ---------------------------------------------------------------- signed coordinates

#[test]
fn negative_coordinates_encode_and_decode_exactly() {
    for (v, hex) in [
        (-5000, "FFFFEC78"),
        (-1, "FFFFFFFF"),
        (-12_345, "FFFFCFC7"),
        (i32::MIN, "80000000"),
        (i32::MAX, "7FFFFFFF"),
    ] {
        let c = Command::ScaraMoveRelative(ScaraMove {
            motion: ScaraMotion::Cp {
                acc: CentiG(0),
                dec: CentiG(0),
                speed: MmPerSec(50),
            },
            targets: axes(&[(2, t(v))]),
        });
        let bytes = c.to_bytes(Station::DEFAULT, ScMode::Computed).unwrap();
        let text = String::from_utf8(bytes.clone()).unwrap();
        assert_eq!(&text[22..30], hex, "{text}");
        assert_eq!(Command::decode(&Frame::parse(&bytes).unwrap()).unwrap(), c);
    }
    // Lower-case hex decodes to the same value.
    let lower = {
        let body = "!992D50200000000003203ffffec78";
        let mut v = body.as_bytes().to_vec();
        let sc = checksum(&v);
        v.extend_from_slice(format!("{sc:02X}\r\n").as_bytes());
        v
    };
    let Command::ScaraMoveRelative(m) = Command::decode(&Frame::parse(&lower).unwrap()).unwrap()
    else {
        panic!()
    };
    assert_eq!(m.targets.get(Axis::A2), Some(t(-5000)));
}

#[test]
fn reserved_codes_in_status_replies_do_not_cost_the_status_poll() {
    // 2A3H with the [inferred] second-unit common status set to 0B (arm code 3 and
    // coordinate system 2, both reserved): the reply still decodes.
    let body =
        "#992A30F01000100000B0F1C000000000493E01C000000FFFDB6101C00000000004E201C0000000000AFC8";
    let Reply::ScaraStatus2(s) = reply(&format!("{body}{:02X}", checksum(body.as_bytes()))) else {
        panic!("2A3H reply expected")
    };
    assert_eq!(s.unit1.common.arm, ArmSystem::Right);
    assert_eq!(s.unit2.common.arm, ArmSystem::Undetermined);
    assert_eq!(s.unit2.common.system, PositionSystem::Base);
    // 2A1H with the reserved arm code 3: undetermined, positions intact.
    let body = "#992A10100030F1C000000000493E01C000000FFFDB6101C00000000004E201C0000000000AFC8";
    let Reply::ScaraStatus(s) = reply(&format!("{body}{:02X}", checksum(body.as_bytes()))) else {
        panic!("2A1H reply expected")
    };
    assert_eq!(s.common.arm, ArmSystem::Undetermined);
    assert_eq!(
        s.axes.get(Axis::A1).map(|a| a.position),
        Some(Milli(300_000))
    );
}
