//! The frames of PROTOCOL.md 6.1 and 6.2 (observed in real host code) decode to the
//! meaning given there; malformed ones are reported as such.

use crate::vectors::*;
use xsel_pendant::protocol::*;

// ---------------------------------------------------------------- 6.1

#[test]
fn s6_1_servo_ack() {
    assert_eq!(reply_vector("#992322C"), Reply::Ack(MessageId::SERVO));
}

#[test]
fn s6_1_axis_status_fixture() {
    let Reply::AxisStatus(a) = reply_vector("#99212021C00000000002715AF") else {
        panic!()
    };
    assert_eq!(a.pattern(), AxisPattern(0x02));
    let s = a.get(Axis::A2).unwrap();
    assert_eq!(s.status, AxisStatus(0x1C));
    assert!(s.status.servo_on() && s.status.completed_normally());
    assert_eq!(s.status.home_state(), HomeState::Done);
    assert_eq!(s.position, t(10_005));
}

#[test]
fn s6_1_hand_edited_fixture_is_a_checksum_error() {
    let e = Frame::parse(&wire("#9921202040000000000270EAF")).unwrap_err();
    assert_eq!(
        e.kind,
        FrameErrorKind::Checksum {
            found: 0xAF,
            computed: 0xAE,
            column: 25
        }
    );
    assert_eq!(
        e.to_string(),
        "checksum is AF, but the frame's bytes sum to AE (column 25)"
    );
    let mut d = StreamDecoder::new();
    d.push(&wire("#9921202040000000000270EAF"));
    assert!(matches!(
        d.pull(),
        Some(Err(DecodeError::Frame(FrameError {
            kind: FrameErrorKind::Checksum { .. },
            ..
        })))
    ));
    let desc = describe(&wire("#9921202040000000000270EAF"));
    assert_eq!(
        desc.checksum,
        ChecksumVerdict::Wrong {
            found: 0xAF,
            computed: 0xAE
        }
    );
    assert!(!desc.is_ok());
}

// ---------------------------------------------------------------- 6.2

#[test]
fn s6_2_servo_on_axes_1_to_3() {
    let c = at_at_vector("!99232071@@", "C2");
    assert_eq!(
        c,
        Command::Servo(Servo {
            axes: AxisPattern(0x07),
            on: true
        })
    );
}

#[test]
fn s6_2_not_a_vector_232_one_char_too_long() {
    let f = frame("!992320101@@");
    assert_eq!(f.sc(), Sc::AtAt);
    let e = Command::decode(&f).unwrap_err();
    assert_eq!(
        e.to_string(),
        "232H command: unexpected extra data '1' at column 10 after the last field"
    );
    assert_eq!(checksum(b"!992320101"), 0xEC);
}

#[test]
fn s6_2_home() {
    assert_eq!(
        at_at_vector("!9923307000000@@", "B2"),
        Command::Home(Home {
            axes: AxisPattern(0x07),
            search: MmPerSec(0),
            creep: MmPerSec(0)
        })
    );
    assert_eq!(
        at_at_vector("!9923301040000@@", "B0"),
        Command::Home(Home {
            axes: AxisPattern(0x01),
            search: MmPerSec(64),
            creep: MmPerSec(0)
        })
    );
}

#[test]
fn s6_2_axis_status_queries() {
    assert_eq!(
        at_at_vector("!9921201@@", "89"),
        Command::AxisStatus {
            axes: AxisPattern(0x01)
        }
    );
    assert_eq!(
        at_at_vector("!9921207@@", "8F"),
        Command::AxisStatus {
            axes: AxisPattern(0x07)
        }
    );
}

#[test]
fn s6_2_absolute_moves() {
    assert_eq!(
        at_at_vector("!9923401001E001E00640000C350@@", "9E"),
        Command::MoveAbsolute(AxisMove {
            acc: CentiG(30),
            dec: CentiG(30),
            speed: MmPerSec(100),
            targets: axes(&[(1, t(50_000))]),
        })
    );
    assert_eq!(
        at_at_vector("!992340100640064006400000000@@", "6B"),
        Command::MoveAbsolute(AxisMove {
            acc: CentiG(100),
            dec: CentiG(100),
            speed: MmPerSec(100),
            targets: axes(&[(1, t(0))]),
        })
    );
}

#[test]
fn s6_2_test_call_alarm_and_software_reset() {
    assert_eq!(
        at_at_vector("!992000123456789@@", "32"),
        Command::TestCall(TestData::new(b"0123456789").unwrap())
    );
    assert_eq!(at_at_vector("!99252@@", "2C"), Command::AlarmReset);
    assert_eq!(at_at_vector("!9925B@@", "3C"), Command::SoftwareReset);
}

/// The observed host's constant (PROTOCOL.md 3.34: start port 10h = 16, one port): known
/// since the signal messages, it decodes and is described field by field.
#[test]
fn s6_2_input_port_query_of_an_observed_host_decodes() {
    let f = frame("!9920B00100001@@");
    assert_eq!(f.id(), Some(MessageId(0x20B)));
    assert_eq!(
        Command::decode(&f).unwrap(),
        Command::BitQuery(BitQuery {
            space: BitSpace::Input,
            program: 0,
            start: 16,
            count: 1,
        })
    );
    let d = describe(&wire("!9920B00100001@@"));
    assert!(d.is_ok(), "{d}");
    assert_eq!(d.checksum, ChecksumVerdict::AtAt { computed: 0xB9 });
    assert!(
        d.fields
            .iter()
            .any(|f| f.name == "query start number" && f.value == "16")
    );
}

#[test]
fn s6_2_stop_without_appended_byte_is_refused() {
    let f = frame("!9923807@@");
    let e = Command::decode(&f).unwrap_err();
    assert_eq!(
        e.to_string(),
        "238H command: field 'appended command byte' at columns 9-10 is missing — the data has only 2 characters"
    );
    assert_eq!(checksum(b"!9923807"), 0x97);
    let d = describe(&wire("!9923807@@"));
    assert_eq!(d.problems[0].column, 9);
    assert!(
        d.fields
            .iter()
            .any(|f| f.name == "stop axis pattern" && f.value == "07 (axes 1, 2, 3)")
    );
}

#[test]
fn s6_2_mock_reply_with_at_at() {
    let f = frame("#99212010C000000000049B2@@");
    assert_eq!(f.sc(), Sc::AtAt);
    let Reply::AxisStatus(a) = reply("#99212010C000000000049B2@@") else {
        panic!()
    };
    let s = a.get(Axis::A1).unwrap();
    assert_eq!(s.status, AxisStatus(0x0C));
    assert_eq!(s.position, t(18_866));
    assert_eq!(
        describe(&wire("#99212010C000000000049B2@@")).checksum,
        ChecksumVerdict::AtAt { computed: 0xBF }
    );
}

#[test]
fn s6_2_other_protocols_are_not_format_b() {
    for s in ["?99TST0123456789@@", ":0103000000027A"] {
        let e = Frame::parse(&wire(s)).unwrap_err();
        assert!(matches!(e.kind, FrameErrorKind::BadHeader { .. }), "{s}");
        assert!(!describe(&wire(s)).is_ok());
    }
    let e = Frame::parse(&wire("!99MOV 1 2")).unwrap_err();
    assert_eq!(e.kind, FrameErrorKind::BadMessageId);
    assert_eq!(
        e.to_string(),
        "message ID is 'MOV', expected 3 hex digits (column 4)"
    );
}
