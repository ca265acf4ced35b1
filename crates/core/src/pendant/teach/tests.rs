//! Tests of `teach.rs`.

use super::*;
use crate::protocol::{CentiG, MmPerSec, Percent, ScMode, Station};

fn at(x: i32, work: u8, tool: u8) -> TaughtPose {
    TaughtPose {
        pose: [x, -x, 20_000, 45_000],
        arm: ArmSystem::Right,
        work,
        tool,
    }
}

fn names(l: &TeachList) -> Vec<&str> {
    l.iter().map(|p| p.name.as_str()).collect()
}

fn abc() -> TeachList {
    let mut l = TeachList::new();
    for (i, n) in ["A", "B", "C"].into_iter().enumerate() {
        assert_eq!(l.record(n, at(i as i32, 0, 0)), Ok(i));
    }
    l
}

#[test]
fn record_stores_the_pose_under_a_trimmed_name() {
    let mut l = TeachList::new();
    assert!(l.is_empty());
    let pose = TaughtPose {
        pose: [300_000, -150_000, 20_000, 45_000],
        arm: ArmSystem::Left,
        work: 3,
        tool: 2,
    };
    assert_eq!(l.record("  pick  ", pose), Ok(0));
    let p = l.get(0).unwrap();
    assert_eq!(p.name, "pick");
    assert_eq!(p.taught(), pose);
    assert_eq!(l.len(), 1);
    assert_eq!(l.position(" pick"), Some(0));
    assert!(l.get(1).is_none());
}

#[test]
fn record_refuses_bad_names_and_frames_and_changes_nothing() {
    let mut l = abc();
    let before = l.clone();
    assert_eq!(l.record("   ", at(0, 0, 0)), Err(TeachError::EmptyName));
    let long = "x".repeat(33);
    assert_eq!(
        l.record(&long, at(0, 0, 0)),
        Err(TeachError::NameTooLong { chars: 33 })
    );
    assert!(l.record(&"é".repeat(32), at(0, 0, 0)).is_ok());
    l.remove(3).unwrap();
    assert_eq!(l.record("a\tb", at(0, 0, 0)), Err(TeachError::NameControl));
    assert_eq!(
        l.record("w", at(0, 255, 0)),
        Err(TeachError::WorkOutOfRange(255))
    );
    assert_eq!(
        l.record("t", at(0, 0, 255)),
        Err(TeachError::ToolOutOfRange(255))
    );
    assert!(l.record("edge", at(0, 254, 254)).is_ok());
    l.remove(3).unwrap();
    let dup = l.record(" B ", at(0, 0, 0)).unwrap_err();
    assert_eq!(
        dup,
        TeachError::DuplicateName {
            name: "B".into(),
            existing: 1,
            suggestion: "B1".into()
        }
    );
    assert_eq!(
        dup.to_string(),
        "the name \"B\" is already used by point 2; choose another, e.g. \"B1\""
    );
    assert_eq!(dup.field(), Some("name"));
    assert_eq!(l, before);
}

#[test]
fn unique_name_counts_up_and_fits() {
    let mut l = TeachList::new();
    assert_eq!(l.unique_name("P"), "P1");
    l.record("P1", at(0, 0, 0)).unwrap();
    l.record("P3", at(0, 0, 0)).unwrap();
    assert_eq!(l.unique_name("P"), "P2");
    l.record("P2", at(0, 0, 0)).unwrap();
    assert_eq!(l.unique_name(" P "), "P4");
    assert_eq!(l.unique_name(""), "P4");
    assert_eq!(l.unique_name("\n"), "P4");
    assert_eq!(l.unique_name("a\nb"), "ab1");
    let base = "y".repeat(40);
    let n = l.unique_name(&base);
    assert_eq!(n.chars().count(), 32);
    assert!(n.ends_with('1'));
    assert!(l.record(&n, at(0, 0, 0)).is_ok());
}

#[test]
fn rename_checks_like_record() {
    let mut l = abc();
    l.rename(1, " Bee ").unwrap();
    assert_eq!(names(&l), ["A", "Bee", "C"]);
    l.rename(1, "Bee").unwrap();
    assert!(matches!(
        l.rename(1, "A"),
        Err(TeachError::DuplicateName { existing: 0, .. })
    ));
    assert_eq!(l.rename(1, ""), Err(TeachError::EmptyName));
    assert_eq!(
        l.rename(3, "D"),
        Err(TeachError::NoSuchPoint { index: 3, len: 3 })
    );
    assert_eq!(names(&l), ["A", "Bee", "C"]);
}

#[test]
fn reorder_and_remove() {
    let mut l = abc();
    assert_eq!(l.move_up(0), Ok(0));
    assert_eq!(l.move_down(2), Ok(2));
    assert_eq!(names(&l), ["A", "B", "C"]);
    assert_eq!(l.move_up(2), Ok(1));
    assert_eq!(names(&l), ["A", "C", "B"]);
    assert_eq!(l.move_down(0), Ok(1));
    assert_eq!(names(&l), ["C", "A", "B"]);
    assert!(l.move_up(3).is_err());
    assert!(l.move_down(3).is_err());
    assert_eq!(l.remove(1).unwrap().name, "A");
    assert_eq!(names(&l), ["C", "B"]);
    assert_eq!(
        l.remove(2),
        Err(TeachError::NoSuchPoint { index: 2, len: 2 })
    );
    assert_eq!(
        TeachError::NoSuchPoint { index: 2, len: 2 }.to_string(),
        "there is no point 3 (the list has 2)"
    );
    // The name of a removed point is free again.
    assert_eq!(l.record("A", at(0, 0, 0)), Ok(2));
}

#[test]
fn insert_and_update() {
    let mut l = abc();
    let p = TeachPoint::new("Z", at(7, 1, 1));
    assert_eq!(l.insert(1, p.clone()), Ok(1));
    assert_eq!(names(&l), ["A", "Z", "B", "C"]);
    assert!(l.insert(9, TeachPoint::new("Y", at(0, 0, 0))).is_err());
    assert!(l.insert(0, p).is_err());
    l.update(1, at(99, 2, 3)).unwrap();
    assert_eq!(l.get(1).unwrap().name, "Z");
    assert_eq!(l.get(1).unwrap().taught(), at(99, 2, 3));
    assert_eq!(
        l.update(1, at(0, 255, 0)),
        Err(TeachError::WorkOutOfRange(255))
    );
    assert!(l.update(9, at(0, 0, 0)).is_err());
    assert_eq!(l.get(1).unwrap().taught(), at(99, 2, 3));
}

#[test]
fn arm_words_and_policy() {
    for a in [ArmSystem::Right, ArmSystem::Left, ArmSystem::Undetermined] {
        assert_eq!(parse_arm_word(arm_word(a)), Some(a));
        assert_eq!(
            parse_arm_word(&format!(" {} ", arm_word(a).to_uppercase())),
            Some(a)
        );
    }
    assert_eq!(parse_arm_word("r"), None);
    let mut p = TeachPoint::new("p", at(0, 0, 0));
    assert_eq!(p.arm_policy(), ArmPolicy::Right);
    p.arm = ArmSystem::Left;
    assert_eq!(p.arm_policy(), ArmPolicy::Left);
    p.arm = ArmSystem::Undetermined;
    assert_eq!(p.arm_policy(), ArmPolicy::KeepNoSwitch);
}

/// A hand-built frame: the SC summed here, independently of the codec.
fn frame(body: &str) -> String {
    let sc = body.bytes().fold(0u8, u8::wrapping_add);
    format!("{body}{sc:02X}\r\n")
}

fn encoded(c: &Command) -> String {
    let mut buf = Vec::new();
    c.encode_into(Station::DEFAULT, ScMode::Computed, &mut buf)
        .unwrap();
    String::from_utf8(buf).unwrap()
}

#[test]
fn go_encodes_the_2d4h_example_of_protocol_3_19() {
    let p = TeachPoint::new(
        "P1",
        TaughtPose {
            pose: [300_000, -150_000, 20_000, 45_000],
            arm: ArmSystem::Right,
            work: 0,
            tool: 0,
        },
    );
    let ptp = ScaraMotion::Ptp {
        acc: Percent(0),
        dec: Percent(0),
        speed: Percent(30),
        arm: ArmPolicy::KeepNoSwitch,
    };
    let expected = "!992D40F00000000001E02000493E0FFFDB61000004E200000AFC85C\r\n";
    assert_eq!(encoded(&go_command(&p, ptp)), expected);
    // The hand-built frame's SC is the byte sum of everything before it.
    assert_eq!(
        frame("!992D40F00000000001E02000493E0FFFDB61000004E200000AFC8"),
        expected
    );
}

#[test]
fn go_encodes_cp_and_arm_policy_and_extreme_positions() {
    let mut p = TeachPoint::new(
        "edge",
        TaughtPose {
            pose: [i32::MIN, i32::MAX, -1, 0],
            arm: ArmSystem::Left,
            work: 5,
            tool: 1,
        },
    );
    let cp = ScaraMotion::Cp {
        acc: CentiG(30),
        dec: CentiG(20),
        speed: MmPerSec(100),
    };
    assert_eq!(
        encoded(&go_command(&p, cp)),
        frame("!992D40F001E0014006403800000007FFFFFFFFFFFFFFF00000000")
    );
    let ptp = ScaraMotion::Ptp {
        acc: Percent(50),
        dec: Percent(50),
        speed: Percent(100),
        arm: p.arm_policy(),
    };
    p.pose = [1, 2, 3, 4];
    // Left arm policy = 3 in bits 3-4: 0b11010 = 1A.
    assert_eq!(
        encoded(&go_command(&p, ptp)),
        frame("!992D40F0032003200641A00000001000000020000000300000004")
    );
}

#[test]
fn check_go_refuses_another_frame_and_names_both() {
    let p = TeachPoint::new("pick", at(0, 2, 1));
    assert_eq!(check_go(&p, 2, 1), Ok(()));
    let e = check_go(&p, 0, 1).unwrap_err();
    assert_eq!(
        e.to_string(),
        "\"pick\" was taught in work frame 2 but work frame 0 is selected now; \
         select work frame 2 to go there"
    );
    assert_eq!(e.selected_work, 0);
    let e = check_go(&p, 2, 3).unwrap_err();
    assert_eq!(
        e.to_string(),
        "\"pick\" was taught in tool frame 1 but tool frame 3 is selected now; \
         select tool frame 1 to go there"
    );
    let e = check_go(&p, 4, 0).unwrap_err();
    assert_eq!(
        e.to_string(),
        "\"pick\" was taught in work frame 2 / tool frame 1 but work frame 4 / tool frame 0 \
         is selected now; select work frame 2 and tool frame 1 to go there"
    );
}
