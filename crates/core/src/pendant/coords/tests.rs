use std::time::Instant;

use proptest::prelude::*;

use super::file::{self, TableFormat, TablePair};
use super::*;
use crate::link::LinkEvent;
use crate::pendant::{Pendant, Settings, teach::file::FileError};
use crate::protocol::{Axis, Milli, PerAxis};
use crate::robot::RobotModel;

fn cs(x: i32, y: i32, z: i32, r: i32) -> CoordSystem {
    CoordSystem::from_wire([x, y, z, r])
}

fn record(w: [i32; 4]) -> PerAxis<Milli> {
    let mut p = PerAxis::new();
    for (i, v) in w.into_iter().enumerate() {
        if let Some(a) = Axis::from_index(i as u8) {
            p.set(a, Milli(v));
        }
    }
    p
}

fn pendant() -> Pendant {
    Pendant::new(Settings::default(), RobotModel::default_model())
}

fn done(kind: CoordKind, first: u16, records: Vec<Option<PerAxis<Milli>>>) -> LinkEvent {
    let mut missing: Vec<Range<u16>> = Vec::new();
    for (i, r) in records.iter().enumerate() {
        let i = first + i as u16;
        if r.is_none() {
            match missing.last_mut() {
                Some(h) if h.end == i => h.end = i + 1,
                _ => missing.push(i..i + 1),
            }
        }
    }
    LinkEvent::TableDone {
        kind,
        axes: AxisPattern::SCARA_1,
        first,
        records,
        missing,
    }
}

#[test]
fn an_edit_shows_in_the_diff_and_undo_takes_it_back() {
    let now = Instant::now();
    let mut p = pendant();
    let mut recs = vec![Some(record([0; 4])); 32];
    recs[1] = Some(record([300_000, -100_000, 0, 30_000]));
    p.handle_event(now, done(CoordKind::Work, 0, recs));
    let ctrl = p.read_table(FrameKind::Work).unwrap().records.clone();
    assert_eq!(p.coords.work.get(1), Some(cs(300_000, -100_000, 0, 30_000)));
    assert!(diff(p.coords.work.rows(), &ctrl).is_empty());

    assert_eq!(
        p.coords
            .draft_mut(FrameKind::Work)
            .set_cell(1, Column::Y, "-99.5"),
        Ok(true)
    );
    let d = diff(p.coords.work.rows(), &ctrl);
    assert_eq!(d.len(), 1);
    assert_eq!((d[0].number, d[0].cells), (1, [false, true, false, false]));
    assert_eq!(d[0].controller, Some(cs(300_000, -100_000, 0, 30_000)));

    assert!(p.coords.draft_mut(FrameKind::Work).undo());
    assert!(diff(p.coords.work.rows(), &ctrl).is_empty());
    assert!(p.coords.draft_mut(FrameKind::Work).redo());
    assert_eq!(p.coords.work.get(1).unwrap().y.0, -99_500);
    // Reset the cell to the controller's value.
    assert_eq!(
        p.coords
            .draft_mut(FrameKind::Work)
            .reset_cell(1, Column::Y, &ctrl),
        Ok(true)
    );
    assert!(diff(p.coords.work.rows(), &ctrl).is_empty());
}

#[test]
fn invalid_entries_are_refused_and_change_nothing() {
    let mut t = DraftTable::new(FrameKind::Work, 32);
    t.set_cell(3, Column::X, "12.5").unwrap();
    let before = t.rows().clone();
    for (n, col, text) in [
        (3, Column::X, "12,5"),
        (3, Column::X, "1.0001"),
        (3, Column::R, "400"),
        (0, Column::Z, "1"),
        (32, Column::X, "1"),
    ] {
        assert!(t.set_cell(n, col, text).is_err(), "{text} accepted");
    }
    assert_eq!(t.rows(), &before);
    assert!(
        t.set_cell(0, Column::Z, "1")
            .unwrap_err()
            .contains("base frame")
    );
}

#[test]
fn a_new_read_keeps_edited_rows_and_takes_the_others() {
    let now = Instant::now();
    let mut p = pendant();
    p.handle_event(
        now,
        done(CoordKind::Tool, 0, vec![Some(record([0; 4])); 128]),
    );
    p.coords
        .draft_mut(FrameKind::Tool)
        .set_cell(5, Column::Z, "-35")
        .unwrap();
    let mut recs = vec![Some(record([1_000, 0, 0, 0])); 128];
    recs[7] = None;
    p.handle_event(now, done(CoordKind::Tool, 0, recs));
    assert_eq!(p.coords.tool.get(5), Some(cs(0, 0, -35_000, 0)));
    assert_eq!(p.coords.tool.get(6), Some(cs(1_000, 0, 0, 0)));
    // Record 7 was not read this time: the controller shows it unread, the draft keeps
    // the old value, and only it is asked for again.
    assert_eq!(p.read_table(FrameKind::Tool).unwrap().records[7], None);
    assert_eq!(p.unread_ranges(FrameKind::Tool), vec![7..8]);
    p.line = crate::pendant::LineState::Up {
        line: "test".into(),
        since: now,
    };
    p.take_requests();
    p.retry_unread(CoordKind::Tool, now);
    assert_eq!(
        p.take_requests(),
        vec![Request::ReadRecords(CoordKind::Tool, 7..8)]
    );
    p.handle_event(
        now,
        done(CoordKind::Tool, 7, vec![Some(record([2_000, 0, 0, 0]))]),
    );
    assert!(p.unread_ranges(FrameKind::Tool).is_empty());
    assert_eq!(
        p.read_table(FrameKind::Tool).unwrap().records[7],
        Some(cs(2_000, 0, 0, 0))
    );
}

#[test]
fn frames_over_arm_use_the_draft() {
    let now = Instant::now();
    let mut p = pendant();
    p.handle_event(
        now,
        done(CoordKind::Work, 0, vec![Some(record([5_000, 0, 0, 0])); 32]),
    );
    p.coords.set_over_arm(FrameKind::Work, 2, true);
    p.coords.set_over_arm(FrameKind::Tool, 1, true); // never read: left out
    p.coords
        .draft_mut(FrameKind::Work)
        .set_cell(2, Column::X, "7")
        .unwrap();
    assert_eq!(
        p.frames_over_arm(),
        vec![(FrameKind::Work, 2, cs(7_000, 0, 0, 0))]
    );
}

#[test]
fn autosaved_drafts_come_back() {
    let mut p = pendant();
    p.coords
        .draft_mut(FrameKind::Tool)
        .set_cell(9, Column::R, "-12.345")
        .unwrap();
    p.coords.set_over_arm(FrameKind::Tool, 9, true);
    let text = serde_json::to_string(&p.coords.saved()).unwrap();
    let mut q = pendant();
    assert!(q.coords.restore(&serde_json::from_str(&text).unwrap()));
    assert_eq!(q.coords.tool.rows(), p.coords.tool.rows());
    assert!(q.coords.is_over_arm(FrameKind::Tool, 9));
    assert!(!q.coords.restore(&SavedDrafts::default()));
}

fn csv_error(text: &[u8]) -> FileError {
    let mut p = pendant();
    p.coords
        .draft_mut(FrameKind::Work)
        .set_cell(1, Column::X, "1")
        .unwrap();
    let before = p.coords.tables();
    let e = p.import_tables(text, TableFormat::Csv).unwrap_err();
    assert_eq!(
        p.coords.tables(),
        before,
        "a failed import changed the draft"
    );
    e
}

#[test]
fn a_broken_csv_changes_nothing_and_names_line_and_field() {
    let h = "table,number,x_mm,y_mm,z_mm,r_deg\n";
    let e = csv_error(format!("{h}work,1,1.000,2.000,3.000,4.000\ntool,2,1.0,x1,0,0\n").as_bytes());
    assert_eq!((e.line, e.field.as_deref()), (3, Some("y_mm")));
    assert!(e.to_string().contains("not a number"), "{e}");
    // A missing column (a short row, and a header without it).
    let e = csv_error(format!("{h}work,1,1.000,2.000,3.000\n").as_bytes());
    assert_eq!((e.line, e.field.as_deref()), (2, Some("r_deg")));
    let e = csv_error(b"table,number,x_mm,y_mm,r_deg\nwork,1,1,2,3\n");
    assert_eq!((e.line, e.field.as_deref()), (1, Some("z_mm")));
    // An extra row: beyond the table, or listed twice.
    let e = csv_error(format!("{h}work,32,0,0,0,0\n").as_bytes());
    assert_eq!((e.line, e.field.as_deref()), (2, Some("number")));
    assert!(e.message.contains("0 to 31"), "{e}");
    let e = csv_error(format!("{h}tool,4,0,0,0,0\n\ntool,4,1,0,0,0\n").as_bytes());
    assert_eq!((e.line, e.field.as_deref()), (4, Some("number")));
    // An extra field.
    let e = csv_error(format!("{h}tool,4,0,0,0,0,9\n").as_bytes());
    assert_eq!(e.line, 2);
    // Wrong encoding: Latin-1 bytes in the third field of line 2.
    let mut bytes = h.as_bytes().to_vec();
    bytes.extend_from_slice(b"tool,4,\xb51,0,0,0\n");
    let e = csv_error(&bytes);
    assert_eq!((e.line, e.field.as_deref()), (2, Some("x_mm")));
    assert!(e.message.contains("UTF-8"));
    // Work No. 0 stays the base frame.
    let e = csv_error(format!("{h}work,0,0,0,5,0\n").as_bytes());
    assert_eq!((e.line, e.field.as_deref()), (2, Some("z_mm")));
}

#[test]
fn a_broken_json_changes_nothing_and_names_line_and_field() {
    let mut p = pendant();
    let before = p.coords.tables();
    let text = "{\n  \"work\": [\n    {\"number\": 1, \"x\": 1, \"y\": 2, \"z\": 3, \"r\": 4},\n    {\"number\": 2, \"x\": 1, \"y\": 2, \"r\": 4}\n  ]\n}\n";
    let e = p
        .import_tables(text.as_bytes(), TableFormat::Json)
        .unwrap_err();
    assert_eq!((e.line, e.field.as_deref()), (4, Some("z")), "{e}");
    let text = "{\"tool\": [\n{\"number\": 1, \"x\": 1, \"y\": 2, \"z\": 3, \"r\": 999999}]}";
    let e = p
        .import_tables(text.as_bytes(), TableFormat::Json)
        .unwrap_err();
    assert_eq!((e.line, e.field.as_deref()), (2, Some("r")), "{e}");
    assert_eq!(p.coords.tables(), before);
}

#[test]
fn the_simulator_file_round_trips_and_fills_unread_rows_with_zeros() {
    let model = RobotModel::default_model();
    let mut t = TablePair::empty(32, 128);
    t.work[3] = Some(cs(1, -2, 3, -4));
    t.tool[127] = Some(cs(0, 0, -35_000, 0));
    let back = file::from_sim_toml(file::to_sim_toml(&t).as_bytes(), &model).unwrap();
    assert_eq!(back.work[3], t.work[3]);
    assert_eq!(back.tool[127], t.tool[127]);
    assert_eq!(back.tool[5], Some(CoordSystem::ZERO));
}

fn value(limit: i32) -> impl Strategy<Value = i32> {
    -limit..=limit
}

fn row() -> impl Strategy<Value = Option<CoordSystem>> {
    proptest::option::of(
        (
            value(99_999_999),
            value(99_999_999),
            value(99_999_999),
            value(360_000),
        )
            .prop_map(|(x, y, z, r)| cs(x, y, z, r)),
    )
}

fn tables() -> impl Strategy<Value = TablePair> {
    (
        proptest::collection::vec(row(), 32),
        proptest::collection::vec(row(), 128),
    )
        .prop_map(|(mut work, tool)| {
            work[0] = work[0].map(|_| CoordSystem::ZERO);
            TablePair { work, tool }
        })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]
    #[test]
    fn export_then_import_round_trips_exactly(t in tables()) {
        let csv = file::to_csv(&t);
        prop_assert_eq!(&file::from_csv(csv.as_bytes(), 32, 128).unwrap(), &t);
        let json = file::to_json(&t);
        prop_assert_eq!(&file::from_json(json.as_bytes(), 32, 128).unwrap(), &t);
    }
}

#[test]
fn a_read_cut_short_by_a_lost_line_leaves_no_progress_bar() {
    let now = Instant::now();
    let mut p = pendant();
    p.line = crate::pendant::LineState::Up {
        line: "test".into(),
        since: now,
    };
    p.reload_table(CoordKind::Tool, now);
    assert!(p.coords.reading().is_some());
    assert_eq!(p.take_requests(), vec![Request::ReadTable(CoordKind::Tool)]);
    p.disconnect(now);
    assert_eq!(p.coords.reading(), None);
}

#[test]
fn a_retry_from_record_0_fills_in_and_keeps_the_rest_of_the_table() {
    let mut p = pendant();
    let now = Instant::now();
    // The whole tool table read, records 0-2 and 100 missing.
    let whole: Vec<_> = (0..128)
        .map(|n| (!matches!(n, 0..=2 | 100)).then(|| record([n * 1000, 0, 0, 0])))
        .collect();
    p.handle_event(now, done(CoordKind::Tool, 0, whole));
    // The retry of 0-2 starts at record 0 and answers 3 records.
    let retry = (0..3).map(|n| Some(record([n * 1000, 0, 0, 0]))).collect();
    p.handle_event(now, done(CoordKind::Tool, 0, retry));
    let read = &p.read_table(FrameKind::Tool).unwrap().records;
    assert_eq!(read.len(), 128, "the rest of the table is kept");
    assert_eq!(read[1], Some(cs(1000, 0, 0, 0)));
    assert_eq!(read[50], Some(cs(50_000, 0, 0, 0)));
    assert_eq!(read[100], None, "still unread");
}
