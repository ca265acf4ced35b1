//! The position table driven against the simulator's controller, sans-IO, on a virtual
//! clock: every command the pendant asks for is answered (or not) by the simulator or by
//! a fault the test injects, and every bad input lands on the rows concerned.

use std::time::Duration;

use super::write::Outcome;
use super::*;
use crate::link::{LinkEvent, Origin, RequestId};
use crate::pendant::sim_bench::{Bench, Fault};
use crate::pendant::{Intent, Request};
use crate::protocol::{
    Command, MessageId, PositionQueryKind, PositionRecord, RecordArm, Reply, ScMode, Station,
};
use crate::sim::SimSetup;

fn empty_setup() -> SimSetup {
    let mut s = SimSetup::default();
    s.positions.clear();
    s
}

fn record(n: u16, x: i32) -> PositionRecord {
    record_of_pose(n, [x, 100_000, 10_000, 0], RecordArm::Right)
}

#[test]
fn a_read_walks_the_table_in_buffer_sized_chunks_and_marks_empty_rows() {
    let mut setup = empty_setup();
    for n in [1u16, 7, 60, 61, 300] {
        setup.positions.insert(n, record(n, 250_000 + i32::from(n)));
    }
    let mut b = Bench::new(setup);
    b.apply(PositionsIntent::Read { from: 1, to: 300 });
    b.pump(|_| Fault::Pass);
    let pos = &b.p.positions;
    assert!(pos.read.is_none());
    assert_eq!(pos.row(7), &Row::Held(record(7, 250_007)));
    assert_eq!(pos.row(300), &Row::Held(record(300, 250_300)));
    assert_eq!(pos.row(2), &Row::Empty);
    assert_eq!(
        pos.row(301),
        &Row::Unread,
        "never asked: never shown as read"
    );
    // 22DH, sized for six axes: 29 numbers per query (PROTOCOL.md 3.24: 16 + 29 x 68 <= 2048).
    let queries: Vec<_> = b
        .sent
        .iter()
        .filter_map(|c| match c {
            Command::PositionQuery(q) => Some(*q),
            _ => None,
        })
        .collect();
    assert!(queries.iter().all(|q| q.kind == PositionQueryKind::Query3));
    assert_eq!(queries[0].count, 29);
    assert_eq!(queries.iter().map(|q| u32::from(q.count)).sum::<u32>(), 300);
    let used = pos.visible(&Filter {
        used_only: true,
        ..Filter::default()
    });
    assert_eq!(used, vec![1, 7, 60, 61, 300]);
}

#[test]
fn a_controller_that_refuses_22dh_is_read_with_21fh_then_209h() {
    let mut setup = empty_setup();
    setup.positions.insert(5, record(5, 250_000));
    let mut b = Bench::new(setup);
    b.apply(PositionsIntent::Read { from: 1, to: 40 });
    b.pump(|c| match c {
        Command::PositionQuery(q) if q.kind != PositionQueryKind::Query => Fault::Error(0xA01),
        _ => Fault::Pass,
    });
    let pos = &b.p.positions;
    assert_eq!(pos.kind, PositionQueryKind::Query);
    assert_eq!(pos.capacity(), 3000);
    // 209H carries no arm system: the record reads back without it.
    let Row::Held(r) = pos.row(5) else {
        panic!("{:?}", pos.row(5));
    };
    assert_eq!(r.coords, record(5, 250_000).coords);
    assert_eq!(pos.row(6), &Row::Empty);
}

#[test]
fn an_error_or_silence_half_way_through_a_read_marks_only_its_rows() {
    let mut setup = empty_setup();
    for n in 1..=90u16 {
        setup.positions.insert(n, record(n, 200_000 + i32::from(n)));
    }
    let mut b = Bench::new(setup);
    b.apply(PositionsIntent::Read { from: 1, to: 90 });
    let mut k = 0;
    b.pump(|c| match c {
        Command::PositionQuery(_) => {
            k += 1;
            match k {
                2 => Fault::Error(0xA03),
                3 => Fault::Timeout,
                _ => Fault::Pass,
            }
        }
        _ => Fault::Pass,
    });
    let pos = &b.p.positions;
    assert_eq!(pos.row(1), &Row::Held(record(1, 200_001)));
    assert!(
        matches!(pos.row(31), Row::Failed(w) if w.contains("A03")),
        "{:?}",
        pos.row(31)
    );
    assert!(matches!(pos.row(61), Row::Failed(w) if w.contains("no valid reply")));
    assert!(matches!(pos.feedback, Some((Level::Warning, ref t)) if t.contains("58 not read")));
    // What was read before is kept.
    assert_eq!(pos.row(29), &Row::Held(record(29, 200_029)));
}

#[test]
fn a_record_outside_the_range_asked_fails_the_chunk_and_says_why() {
    let mut p = Positions::new();
    p.start_read(1..=10).unwrap();
    let cmds = p.take_commands();
    let Command::PositionQuery(q) = cmds[0].0.clone() else {
        panic!()
    };
    let data = crate::protocol::PositionData {
        kind: q.kind,
        records: vec![record(2, 1), record(99, 1)],
    };
    let said = p.handle_event(&LinkEvent::Reply {
        id: RequestId(1),
        origin: Origin::User,
        command: Command::PositionQuery(q),
        reply: Reply::Positions(data),
        round_trip: Duration::ZERO,
    });
    assert!(said.iter().any(|(_, t)| t.contains("No. 99")), "{said:?}");
    assert!(
        matches!(p.row(2), Row::Failed(_)),
        "nothing of a bad reply is taken"
    );
}

/// Teaches `n` at the arm's pose and writes it, confirming the preview.
fn teach_and_write(b: &mut Bench, n: u16) {
    b.apply(PositionsIntent::TeachHere {
        number: n,
        name: "pick".into(),
    });
    assert!(b.p.positions.differs(n));
    b.apply(PositionsIntent::PreviewWrite);
    let preview = b.p.positions.preview.clone().expect("a preview");
    assert_eq!(preview.rows.len(), 1);
    assert_eq!(preview.rows[0].check, Ok(()));
    b.apply(PositionsIntent::ConfirmWrite {
        take_the_risk: false,
    });
}

#[test]
fn teach_write_read_back_and_go_bring_the_arm_back_to_the_taught_pose() {
    let mut b = Bench::new(empty_setup());
    b.apply(PositionsIntent::Read { from: 1, to: 20 });
    b.pump(|_| Fault::Pass);
    let taught = b.sim.tip_work();
    teach_and_write(&mut b, 12);
    b.pump(|_| Fault::Pass);
    let pos = &b.p.positions;
    assert_eq!(pos.outcome(12), Some(&Outcome::Holds));
    assert!(!pos.differs(12), "the draft now equals the controller");
    assert!(matches!(pos.row(12), Row::Held(_)));
    assert!(
        b.sent
            .iter()
            .any(|c| c.id() == MessageId::POSITION_RANGE_WRITE_3)
    );
    let said = &pos.feedback.as_ref().unwrap().1;
    assert!(
        said.contains("holds 1 of 1") && said.contains("power-off"),
        "{said}"
    );
    // Jog away with a 2D5H step, then Go to No. 12.
    let now = b.now();
    b.p.apply(
        Intent::JogSettings(crate::pendant::JogSettings {
            step: 50.0,
            ..b.p.settings.jog.clone()
        }),
        now,
    );
    b.p.jog_step(
        crate::pendant::JogAxis::X,
        crate::protocol::Direction::Negative,
        now,
    );
    b.pump(|_| Fault::Pass);
    b.settle();
    assert!((b.sim.tip_work().x - taught.x).abs() > 10.0);
    b.apply(PositionsIntent::Go(12));
    b.pump(|_| Fault::Pass);
    let Some(Command::ScaraMovePosition(m)) = b.sent.iter().rev().find(|c| c.moves_arm()) else {
        panic!("no 2D6H: {:?}", b.p.jog.feedback);
    };
    assert_eq!(m.position, 12);
    // The acknowledge makes it the followed move: phase and command position follow it.
    assert!(
        b.p.jog
            .followed
            .as_ref()
            .is_some_and(|f| f.accepted.is_some())
    );
    assert!(b.p.jog.command_position.is_some());
    b.settle();
    let back = b.sim.tip_work();
    for (a, t) in [(back.x, taught.x), (back.y, taught.y), (back.z, taught.z)] {
        assert!((a - t).abs() <= 0.001, "{a} vs {t}");
    }
}

#[test]
fn a_write_refused_half_way_says_exactly_which_numbers_the_controller_holds() {
    let mut b = Bench::new(empty_setup());
    b.apply(PositionsIntent::Read { from: 1, to: 200 });
    b.pump(|_| Fault::Pass);
    let rows: Vec<_> = (1..=100u16)
        .map(|n| (record(n, 200_000 + i32::from(n)), None))
        .collect();
    b.apply(PositionsIntent::Import {
        path: "t.csv".into(),
        read: Ok(rows),
    });
    b.apply(PositionsIntent::PreviewWrite);
    b.apply(PositionsIntent::ConfirmWrite {
        take_the_risk: false,
    });
    let mut frames = 0;
    b.pump(|c| match c {
        Command::PositionWrite(_) => {
            frames += 1;
            if frames == 2 {
                Fault::Error(0xA03)
            } else {
                Fault::Pass
            }
        }
        _ => Fault::Pass,
    });
    let pos = &b.p.positions;
    assert_eq!(frames, 2, "nothing is sent after the refusal");
    assert_eq!(pos.outcome(1), Some(&Outcome::Holds));
    assert_eq!(pos.outcome(42), Some(&Outcome::Holds));
    assert!(matches!(pos.outcome(43), Some(Outcome::NotWritten(w)) if w.contains("A03")));
    assert!(matches!(pos.outcome(100), Some(Outcome::NotWritten(_))));
    assert!(pos.differs(43) && !pos.differs(42));
    let said = &pos.feedback.as_ref().unwrap().1;
    assert!(
        said.contains("holds 42 of 100") && said.contains("58 not written"),
        "{said}"
    );
}

#[test]
fn a_write_that_times_out_is_read_back_to_know_what_the_controller_holds() {
    let mut b = Bench::new(empty_setup());
    b.apply(PositionsIntent::Read { from: 1, to: 10 });
    b.pump(|_| Fault::Pass);
    b.p.positions.put(record(3, 123_456)).unwrap();
    b.apply(PositionsIntent::PreviewWrite);
    b.apply(PositionsIntent::ConfirmWrite {
        take_the_risk: false,
    });
    // The frame reaches the simulator but its answer is lost.
    let mut sim_took_it = false;
    let requests = b.p.take_requests();
    for r in requests {
        if let Request::Submit(c @ Command::PositionWrite(_)) = r {
            let frame = c.to_bytes(Station::DEFAULT, ScMode::Computed).unwrap();
            sim_took_it = b.sim.handle(&frame, b.t).is_some();
            b.exchange(c, Origin::User, Fault::Timeout);
        }
    }
    assert!(sim_took_it);
    assert!(matches!(
        b.p.positions.outcome(3),
        Some(Outcome::Unknown(_))
    ));
    b.pump(|_| Fault::Pass);
    assert_eq!(b.p.positions.outcome(3), Some(&Outcome::Holds));
}

#[test]
fn stop_keeps_a_queued_write_frame_from_the_controller() {
    let mut b = Bench::new(empty_setup());
    b.apply(PositionsIntent::Read { from: 1, to: 10 });
    b.pump(|_| Fault::Pass);
    b.p.positions.put(record(4, 111_000)).unwrap();
    b.apply(PositionsIntent::PreviewWrite);
    b.apply(PositionsIntent::ConfirmWrite {
        take_the_risk: false,
    });
    b.pump(|c| match c {
        Command::PositionWrite(_) => Fault::NotSent(crate::link::NotSentReason::StopCameFirst),
        _ => Fault::Pass,
    });
    let pos = &b.p.positions;
    assert!(matches!(pos.outcome(4), Some(Outcome::NotWritten(w)) if w.contains("STOP")));
    assert!(pos.differs(4), "the draft keeps what was not written");
    assert_eq!(b.sim.positions.len(), 0);
}

#[test]
fn a_write_while_a_program_runs_needs_the_risk_confirmed() {
    let mut p = Positions::new();
    p.put(record(1, 1)).unwrap();
    p.preview(true, |_| Ok(())).unwrap();
    assert!(p.preview.as_ref().unwrap().program_running);
    let e = p.confirm_write(true, false).unwrap_err();
    assert!(e.contains("program is running"), "{e}");
    assert!(p.take_commands().is_empty());
    assert!(
        p.preview.is_some(),
        "the preview stays for the confirmation"
    );
    assert_eq!(p.confirm_write(true, true), Ok(1));
    assert!(matches!(
        p.take_commands().as_slice(),
        [(Command::PositionWrite(_), true)]
    ));
}

#[test]
fn cells_are_checked_like_the_coordinate_tables_and_undo_redo_walk_the_draft() {
    let mut p = Positions::new();
    let x = Column::Axis(crate::protocol::Axis::A1);
    assert!(
        p.set_cell(5, x, "12.3456")
            .unwrap_err()
            .contains("3 decimals")
    );
    assert!(
        p.set_cell(5, x, "abc")
            .unwrap_err()
            .contains("not a number")
    );
    assert!(
        p.set_cell(5, x, "100000")
            .unwrap_err()
            .contains("out of range")
    );
    for typed in ["1e-4", "inf", "NaN", "1.2.3", "-", "0x10", "1,5"] {
        assert!(p.set_cell(5, x, typed).is_err(), "{typed}");
    }
    assert!(p.set_cell(0, x, "1").is_err());
    assert!(p.set_cell(20_001, x, "1").is_err());
    assert!(p.set_cell(5, Column::Arm, "up").is_err());
    p.set_cell(5, x, "-12.345").unwrap();
    p.set_cell(5, Column::Arm, "left").unwrap();
    assert_eq!(
        p.shown(5).unwrap().coords.get(crate::protocol::Axis::A1),
        Some(crate::protocol::Milli(-12_345))
    );
    assert_eq!(Column::Arm.text(&p.shown(5).unwrap()), "left");
    assert!(p.differs(5));
    assert!(p.undo());
    assert_eq!(Column::Arm.text(&p.shown(5).unwrap()), "");
    assert!(p.undo());
    assert!(p.shown(5).is_none());
    assert!(!p.undo());
    assert!(p.redo() && p.redo());
    assert_eq!(Column::Arm.text(&p.shown(5).unwrap()), "left");
    // Removing the only coordinate is refused: a row keeps at least one.
    assert!(p.set_cell(5, x, "").is_err());
}

#[test]
fn go_refuses_a_row_not_read_or_empty_and_sends_nothing() {
    let mut b = Bench::new(empty_setup());
    b.apply(PositionsIntent::Go(3));
    assert!(b.p.take_requests().is_empty());
    assert!(
        b.p.jog
            .feedback
            .as_ref()
            .unwrap()
            .text
            .contains("not been read")
    );
    b.apply(PositionsIntent::Read { from: 1, to: 5 });
    b.pump(|_| Fault::Pass);
    b.apply(PositionsIntent::Go(3));
    assert!(b.p.take_requests().is_empty());
    assert!(
        b.p.jog
            .feedback
            .as_ref()
            .unwrap()
            .text
            .contains("holds no data")
    );
}

#[test]
fn go_is_2d6h_at_the_capped_jog_speed_after_the_checks_of_a_step() {
    let mut setup = empty_setup();
    // Out of reach: refused before anything leaves.
    setup.positions.insert(8, record(8, 900_000));
    setup.positions.insert(9, record(9, 300_000));
    let mut b = Bench::new(setup);
    b.apply(PositionsIntent::Read { from: 1, to: 10 });
    b.pump(|_| Fault::Pass);
    b.apply(PositionsIntent::Go(8));
    assert!(b.p.take_requests().is_empty());
    assert!(b.p.jog.feedback.as_ref().unwrap().text.contains("refused"));
    let sent = b.p.jog_sent();
    b.apply(PositionsIntent::Go(9));
    let requests = b.p.take_requests();
    let [Request::Submit(Command::ScaraMovePosition(m))] = requests.as_slice() else {
        panic!("{requests:?}");
    };
    assert_eq!(m.position, 9);
    match m.motion {
        crate::protocol::ScaraMotion::Ptp { speed, .. } => {
            assert_eq!(speed.0, sent.ptp_speed_pct, "the speed the panel shows")
        }
        crate::protocol::ScaraMotion::Cp { speed, .. } => {
            assert_eq!(speed.0, sent.cp_speed_mm_s)
        }
    }
}

#[test]
fn a_reply_cut_short_by_the_buffer_is_read_on_from_its_last_record() {
    // The simulator's buffer is the small one; the pendant sizes for the large one.
    let mut setup = empty_setup();
    setup.config.reply_buffer = crate::protocol::SMALL_REPLY_BUFFER;
    for n in 1..=60u16 {
        setup.positions.insert(n, record(n, 200_000 + i32::from(n)));
    }
    let mut b = Bench::new(setup);
    b.apply(PositionsIntent::Read { from: 1, to: 60 });
    b.pump(|_| Fault::Pass);
    let pos = &b.p.positions;
    for n in 1..=60u16 {
        assert_eq!(
            pos.row(n),
            &Row::Held(record(n, 200_000 + i32::from(n))),
            "No. {n}"
        );
    }
    assert!(matches!(pos.feedback, Some((Level::Info, ref t)) if t.contains("60 used")));
}

#[test]
fn the_draft_and_the_names_come_back_in_the_next_run_exactly() {
    let mut p = Positions::new();
    p.put(record(12, 301_234)).unwrap();
    p.put(record_of_pose(20_000, [-1, 2, -3, 4], RecordArm::Left))
        .unwrap();
    p.set_name(12, Some("pick, \"left\" bin".into()));
    p.set_name(7, Some("held by the controller".into()));
    let before = p.work_revision();
    let bytes = p.saved();
    let mut q = Positions::new();
    assert_eq!(q.restore(RestoredWork::parse(&bytes).unwrap()), (2, 1));
    assert_eq!(q.draft(12), p.draft(12));
    assert_eq!(q.draft(20_000), p.draft(20_000));
    assert_eq!(q.names, p.names);
    assert!(!q.can_undo(), "a restored draft is not an edit to undo");
    // Saving reads nothing back into the revision; an edit moves it.
    assert_eq!(p.work_revision(), before);
    p.set_cell(12, Column::Arm, "left").unwrap();
    assert!(p.work_revision() > before);
    // A damaged file is refused whole (the work files set it aside), with the reason.
    let cut = &bytes[..bytes.len() / 2];
    assert!(RestoredWork::parse(cut).is_err());
    let other = String::from_utf8(bytes.clone())
        .unwrap()
        .replace("xsel-positions-work 1", "something else");
    assert!(
        RestoredWork::parse(other.as_bytes())
            .unwrap_err()
            .contains("format")
    );
}

#[test]
fn a_lost_line_forgets_what_was_read_and_go_waits_for_a_new_read() {
    let mut setup = empty_setup();
    setup.positions.insert(9, record(9, 300_000));
    let mut b = Bench::new(setup);
    b.apply(PositionsIntent::Read { from: 1, to: 10 });
    b.pump(|_| Fault::Pass);
    b.p.positions.put(record(4, 111_000)).unwrap();
    assert!(matches!(b.p.positions.row(9), Row::Held(_)));
    let now = b.now();
    b.p.handle_event(
        now,
        LinkEvent::Disconnected {
            reason: crate::link::LineDownReason::Closed,
        },
    );
    assert_eq!(
        b.p.positions.row(9),
        &Row::Unread,
        "another controller may answer next"
    );
    assert!(b.p.positions.draft(4).is_some(), "the draft stays");
    b.apply(PositionsIntent::Go(9));
    assert!(b.p.take_requests().is_empty());
}
