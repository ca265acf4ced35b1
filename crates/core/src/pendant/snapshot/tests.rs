//! Snapshots: taken through the pendant on the simulator (progress, the parts read by the
//! positions and alarms sub-models), compared, files of a newer format or cut short.

use std::time::{Duration, SystemTime};

use super::*;
use crate::pendant::sim_bench::{Bench, Fault};
use crate::pendant::{Intent, positions::PositionsIntent};

/// Takes a snapshot through the pendant, running the line until it is done.
fn take(b: &mut Bench) -> Snapshot {
    b.apply(Intent::Snapshot(SnapshotIntent::Take));
    for _ in 0..10_000 {
        let now = b.now();
        b.p.tick(now);
        b.pump(|_| Fault::Pass);
        b.t += Duration::from_millis(10);
        if b.p.snapshots.part().is_none() {
            break;
        }
    }
    assert!(b.p.snapshots.part().is_none(), "the snapshot never ended");
    b.p.snapshots.latest.clone().expect("a snapshot")
}

#[test]
fn two_snapshots_around_a_change_show_exactly_that_change() {
    let mut b = Bench::new(crate::sim::SimSetup::default());
    let first = take(&mut b);
    assert_eq!(first.versions.len(), 4, "{:?}", first.missing);
    assert!(first.missing.is_empty(), "{:?}", first.missing);
    assert_eq!(first.positions.len(), b.sim.positions().len());
    assert!(!first.work.is_empty());
    // Change one position and one integer variable on the controller, and raise and
    // clear an alarm.
    let mut p2 = b.sim.positions()[&2];
    p2.coords.set(
        crate::protocol::Axis::new(1).unwrap(),
        crate::protocol::Milli(123_456),
    );
    b.sim.positions_mut().insert(2, p2);
    b.sim.signals_mut().set_int(250, 0, -7).unwrap();
    let second = take(&mut b);
    let c = compare(&first, &second);
    assert_eq!(c.warning, None);
    let rows: Vec<(&str, &str)> = c
        .differences
        .iter()
        .map(|d| (d.table, d.row.as_str()))
        .collect();
    assert_eq!(
        rows,
        [("positions", "No. 00002"), ("integer variables", "250")]
    );
    assert!(
        c.differences[0].new.contains("axis 1 123.456"),
        "{:?}",
        c.differences[0]
    );
    assert_eq!(
        (c.differences[1].old.as_str(), c.differences[1].new.as_str()),
        ("-", "-7")
    );
    // Compare through the model: the last two.
    b.apply(Intent::Snapshot(SnapshotIntent::CompareLast));
    assert_eq!(b.p.snapshots.comparison.as_ref(), Some(&c));
    // The positions view saw the read too.
    assert!(b.p.positions.read.is_none());

    // Restore: the older snapshot's positions go into the Positions draft, and only
    // the position changed since differs from the controller; nothing is sent.
    let sent = b.sent.len();
    b.apply(Intent::Snapshot(SnapshotIntent::RestorePositions));
    assert_eq!(b.sent.len(), sent, "a restore sends nothing");
    let changed = b.p.positions.changed();
    assert_eq!(changed.len(), 1, "{changed:?}");
    assert_eq!(changed[0].number, 2);
    assert_eq!(
        crate::pendant::snapshot::Position::from(&changed[0]),
        first
            .positions
            .iter()
            .find(|p| p.number == 2)
            .unwrap()
            .clone()
    );
    assert!(b.p.positions.can_undo());

    // The zones are part of it: a zone moved on the controller is one more row.
    assert_eq!(
        second.zones.len(),
        b.sim.zones().len(),
        "{:?}",
        second.missing
    );
    let mut zone = b.sim.zones()[&1].clone();
    zone.corner2.set(
        crate::protocol::Axis::new(1).unwrap(),
        crate::protocol::Milli(250_000),
    );
    b.sim.zones.insert(1, zone);
    let third = take(&mut b);
    let c = compare(&second, &third);
    let rows: Vec<(&str, &str)> = c
        .differences
        .iter()
        .map(|d| (d.table, d.row.as_str()))
        .collect();
    assert_eq!(rows, [("zones", "zone 1")]);
    assert!(
        c.differences[0].new.contains("axis 1 250.000"),
        "{:?}",
        c.differences[0]
    );
}

#[test]
fn cancel_keeps_nothing_and_a_lost_line_drops_it() {
    let mut b = Bench::new(crate::sim::SimSetup::default());
    b.apply(Intent::Snapshot(SnapshotIntent::Take));
    assert_eq!(b.p.snapshots.part(), Some(Part::Versions));
    b.apply(Intent::Snapshot(SnapshotIntent::Cancel));
    b.pump(|_| Fault::Pass);
    assert!(b.p.snapshots.part().is_none() && b.p.snapshots.latest.is_none());
    // Refusals are kept as what was not read.
    b.apply(Intent::Snapshot(SnapshotIntent::Take));
    for _ in 0..2000 {
        let now = b.now();
        b.p.tick(now);
        b.pump(|c| match c {
            Command::VarQuery(_) => Fault::Error(0xA01),
            _ => Fault::Pass,
        });
        if b.p.snapshots.part().is_none() {
            break;
        }
    }
    let s = b.p.snapshots.latest.clone().unwrap();
    assert_eq!(s.missing.len(), 2, "{:?}", s.missing);
    assert!(s.missing[0].starts_with("integer variables (20EH): refused: error A01"));
    // The position table is read again by its own view: the snapshot's read is not
    // disturbed by a user read (refused while one runs).
    b.apply(PositionsIntent::Read { from: 1, to: 10 });
}

#[test]
fn files_round_trip_and_newer_or_cut_files_are_named() {
    let mut s = Snapshot::begun("bench", SystemTime::UNIX_EPOCH);
    s.integers.insert(200, 5);
    s.flags_on.push(600);
    let bytes = s.to_json();
    assert_eq!(Snapshot::from_json(&bytes), Ok(s.clone()));
    assert!(s.taken.starts_with("1970-01-01T00:00:00"));
    let cut = Snapshot::from_json(&bytes[..bytes.len() / 2]).unwrap_err();
    assert!(cut.starts_with("cut short"), "{cut}");
    let newer =
        String::from_utf8(bytes.clone())
            .unwrap()
            .replacen("\"format\": 1", "\"format\": 2", 1);
    let e = Snapshot::from_json(newer.as_bytes()).unwrap_err();
    assert!(e.contains("newer xsel-pendant (format 2"), "{e}");
    assert!(
        Snapshot::from_json(b"[1, 2]")
            .unwrap_err()
            .starts_with("not a snapshot")
    );
}

#[test]
fn different_versions_are_said_first_and_alarm_lists_compare_by_their_tops() {
    let mut a = Snapshot::begun("a", SystemTime::UNIX_EPOCH);
    a.versions.push(Version {
        unit: 0,
        version: 0x107,
        ..Version::default()
    });
    let alarm = |code: u16, record: u16| AlarmEntry {
        record,
        code,
        ..AlarmEntry::default()
    };
    a.alarms = vec![alarm(0xC74, 1)];
    let mut b = a.clone();
    b.versions[0].version = 0x108;
    b.alarms = vec![alarm(0xB07, 1), alarm(0xC74, 2)];
    let c = compare(&a, &b);
    assert!(
        c.summary().starts_with("the versions differ"),
        "{}",
        c.summary()
    );
    let tables: Vec<&str> = c.differences.iter().map(|d| d.table).collect();
    assert_eq!(tables, ["versions", "alarm history"]);
    assert_eq!(c.differences[1].new, "B07 ");
    b.alarms = vec![alarm(0xB07, 1)];
    let c = compare(&a, &b);
    assert_eq!(c.differences[1].row, "the list");
}

#[test]
fn a_position_changed_into_nonsense_in_a_file_is_named_not_restored() {
    let mut p = Position {
        number: 7,
        arm: "right".into(),
        ..Position::default()
    };
    p.axes.insert("axis 1".into(), 12.5);
    let r = p.to_record().expect("a good row");
    assert_eq!(Position::from(&r), p);
    p.axes.insert("axis 9".into(), 1.0);
    assert_eq!(p.to_record().unwrap_err(), "No. 7: `axis 9` is not an axis");
    p.axes.remove("axis 9");
    p.axes.insert("axis 2".into(), 1e12);
    assert!(p.to_record().unwrap_err().contains("out of range"));
    p.axes.remove("axis 2");
    p.arm = "middle".into();
    assert!(p.to_record().unwrap_err().contains("not an arm system"));
}
