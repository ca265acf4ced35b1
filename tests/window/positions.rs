//! The Positions view in the real window on the embedded simulator, driven headlessly
//! with egui_kittest: read the controller's table, teach the pose into No. 12, write it
//! after the preview, read it back, jog away and Go to No. 12; and the preview's risk
//! checkbox while a program runs. Waits are bounded by a deadline; nothing sleeps.

use std::time::Instant;

use egui::Key;
use egui_kittest::Harness;
use egui_kittest::kittest::{NodeT, Queryable};
use xsel_pendant::pendant::MotionPhase;
use xsel_pendant::pendant::positions::write::Outcome;
use xsel_pendant::pendant::positions::{Positions, Preview, PreviewRow, Row, record_of_pose};
use xsel_pendant::protocol::{Axis, PositionWriteKind, RecordArm};
use xsel_pendant::robot::Pose;
use xsel_pendant::ui::{PendantApp, StartOptions};

use crate::kittest_common::{click, replace_text, show_tab, step_until, step_until_shown};
use crate::main_window::{app, ready, sim_busy, sim_in_frames};

/// The simulator's tool tip in its selected work frame (mm, deg).
fn sim_pose(app: &PendantApp) -> Pose {
    app.sim().expect("the built-in simulator").with(|c| {
        let snap = c.snapshot();
        let work = c.coords().work.get(snap.work).copied().unwrap_or_default();
        work.base_to_work(&snap.tip_base)
    })
}

/// The move asked for has run to its end on the simulator and the pendant has seen it.
fn moved_and_still(a: &PendantApp) -> bool {
    !sim_busy(a)
        && a.pendant().motion_phase(Instant::now()) == MotionPhase::Done
        && a.pendant().motion_ready(Instant::now()).is_ok()
}

/// The pendant's polled work position has caught up with the simulator's (0.001 mm).
fn pose_caught_up(a: &PendantApp) -> bool {
    let (Some(p), s) = (a.pendant().controller.work_position(), sim_pose(a)) else {
        return false;
    };
    (p.x - s.x).abs() < 0.0015 && (p.y - s.y).abs() < 0.0015 && (p.z - s.z).abs() < 0.0015
}

/// One 10 mm step in X+ from the pad, waited for to its end.
fn step_x(h: &mut Harness<'_, PendantApp>) {
    let sent = sim_in_frames(h.state(), "2D5").len();
    click(h, "10");
    click(h, "X+");
    step_until(h, "the step to reach the simulator", |a| {
        sim_in_frames(a, "2D5").len() == sent + 1
    });
    step_until(h, "the step to end", moved_and_still);
    step_until(h, "the position to be polled", pose_caught_up);
}

fn read_done(a: &PendantApp) -> bool {
    let p = &a.pendant().positions;
    p.read.is_none() && !matches!(p.row(1), Row::Unread)
}

#[test]
fn teach_write_read_back_and_go_to_no_12_on_the_simulator() {
    let mut h = app();
    ready(&mut h);
    show_tab(&mut h, "Positions");
    replace_text(&mut h, "to No.", "100");
    click(&mut h, "Read");
    step_until(&mut h, "positions 1-100 read", read_done);
    assert!(
        (1..=100).all(|n| !matches!(h.state().pendant().positions.row(n), Row::Unread)),
        "every row of 1-100 read"
    );

    // Somewhere else than home, then taught as No. 12.
    step_x(&mut h);
    let taught = h.state().pendant().controller.work_position().unwrap();
    replace_text(&mut h, "No.", "12");
    replace_text(&mut h, "Name", "pick");
    click(&mut h, "Teach current pose into No. 12");
    step_until(&mut h, "No. 12 in the draft", |a| {
        a.pendant().positions.draft(12).is_some()
    });
    let draft = *h.state().pendant().positions.draft(12).unwrap();
    assert_eq!(
        h.state()
            .pendant()
            .positions
            .names
            .get(&12)
            .map(String::as_str),
        Some("pick")
    );
    let wire = |v: f64| (v * 1000.0).round() as i32;
    assert_eq!(
        draft.coords.get(Axis::A1).map(|m| m.0),
        Some(wire(taught.x)),
        "X taught"
    );
    assert_eq!(
        draft.coords.get(Axis::A2).map(|m| m.0),
        Some(wire(taught.y))
    );

    // Write: the preview, then the write itself and its read-back.
    click(&mut h, "Write...");
    step_until(&mut h, "the preview", |a| {
        a.pendant().positions.preview.is_some()
    });
    step_until_shown(&mut h, "No. 12: ");
    assert!(
        !h.state()
            .pendant()
            .positions
            .preview
            .as_ref()
            .unwrap()
            .program_running,
        "the simulator runs no program"
    );
    click(&mut h, "Write");
    step_until(&mut h, "the write and its read-back", |a| {
        let p = &a.pendant().positions;
        p.write.is_none() && p.outcome(12) == Some(&Outcome::Holds)
    });
    assert!(
        h.state().pendant().positions.preview.is_none(),
        "the preview closes"
    );
    // The simulator's own table holds it.
    let held = h
        .state()
        .sim()
        .unwrap()
        .with(|c| c.positions_mut().get(&12).copied())
        .expect("the simulator holds No. 12");
    assert_eq!(held.coords, draft.coords);
    // A read of the table again shows No. 12 as taught, and the outcome is said.
    click(&mut h, "Read");
    step_until(&mut h, "the table read again", |a| {
        a.pendant().positions.read.is_none()
            && matches!(a.pendant().positions.row(12), Row::Held(_))
    });
    match h.state().pendant().positions.row(12) {
        Row::Held(r) => assert_eq!(r.coords, draft.coords, "No. 12 read back"),
        other => panic!("No. 12 read back as {other:?}"),
    }
    h.get_by_label("Used only").click();
    h.step();
    step_until_shown(&mut h, "the controller holds it");

    // Away, and back with Go to No. 12.
    step_x(&mut h);
    let away = sim_pose(h.state());
    assert!((away.x - taught.x).abs() > 5.0, "the arm went away");
    let gone = sim_in_frames(h.state(), "2D6").len();
    click(&mut h, "Go to No. 12");
    step_until(&mut h, "2D6H to reach the simulator", |a| {
        sim_in_frames(a, "2D6").len() == gone + 1
    });
    // The arm still on the simulator, the pendant's poll caught up with it. (The
    // pendant's motion phase is not waited for: it follows 2D6H's profile only once the
    // model marks a Go accepted.)
    step_until(&mut h, "the Go to end", |a| {
        let near = (sim_pose(a).x - taught.x).abs() < 1.0;
        near && !sim_busy(a)
            && a.pendant().motion_ready(Instant::now()).is_ok()
            && pose_caught_up(a)
    });
    let back = sim_pose(h.state());
    for (what, got, want) in [
        ("X", back.x, taught.x),
        ("Y", back.y, taught.y),
        ("Z", back.z, taught.z),
    ] {
        assert!(
            (got - want).abs() <= 0.001,
            "{what}: back at {got:.4}, taught {want:.4}"
        );
    }
}

#[test]
fn a_preview_while_a_program_runs_needs_the_risk_checkbox() {
    let mut h = app();
    ready(&mut h);
    show_tab(&mut h, "Positions");
    // The simulator runs no program: the preview the model made with 215H's "running"
    // is put in place as the pendant would have made it.
    let rec = record_of_pose(7, [100_000, 50_000, 0, 0], RecordArm::Right);
    {
        let p = &mut h.state_mut().pendant_mut().positions;
        p.put(rec).unwrap();
        p.preview = Some(Preview {
            rows: vec![PreviewRow {
                number: 7,
                old: Row::Unread,
                new: rec,
                check: Err("beyond reach".into()),
            }],
            kind: PositionWriteKind::Range3,
            program_running: true,
        });
    }
    h.step();
    h.step();
    step_until_shown(&mut h, "215H reports a program running");
    step_until_shown(&mut h, "the arm could not go there: beyond reach");
    step_until_shown(&mut h, "not known from the protocol (PROTOCOL.md 3.48)");
    let write = |h: &Harness<'_, PendantApp>| {
        h.get_by_role_and_label(egui::accesskit::Role::Button, "Write")
            .accesskit_node()
            .is_disabled()
    };
    assert!(write(&h), "Write waits for the risk to be taken");
    h.get_by_label("I take the risk: write while a program runs")
        .click();
    h.step();
    h.step();
    assert!(!write(&h), "Write with the risk taken");
    click(&mut h, "Cancel");
    step_until(&mut h, "the preview closed", |a| {
        a.pendant().positions.preview.is_none()
    });
    assert!(
        h.state().pendant().positions.write.is_none(),
        "nothing written"
    );
}

/// The model's rule under the view: with a program running a write needs the risk taken;
/// refused, the preview stays.
#[test]
fn the_model_refuses_a_write_while_a_program_runs_unless_the_risk_is_taken() {
    let mut p = Positions::new();
    p.put(record_of_pose(3, [1_000, 2_000, 0, 0], RecordArm::Left))
        .unwrap();
    p.preview(true, |_| Ok(())).unwrap();
    assert!(p.preview.as_ref().unwrap().program_running);
    let refused = p.confirm_write(true, false).unwrap_err();
    assert!(refused.contains("program is running"), "{refused}");
    assert!(p.preview.is_some(), "the preview stays");
    assert!(p.write.is_none());
    assert_eq!(p.confirm_write(true, true), Ok(1));
    assert!(p.write.is_some(), "written with the risk taken");
    assert!(!p.take_commands().is_empty(), "the write's frame goes out");
}

/// The positions pane of a window that opens no line (the draft needs none).
fn offline<'a>() -> Harness<'a, PendantApp> {
    let mut h = Harness::builder()
        .with_size([1280.0, 900.0])
        .build_eframe(|cc| PendantApp::new(cc, StartOptions::fresh_offline()));
    h.step();
    show_tab(&mut h, "Positions");
    h
}

/// Clicks the cell whose accessible name begins with `cell` and types `text` over it,
/// ending with `end` (Enter keeps it, Escape forgets it).
fn type_cell(h: &mut Harness<'_, PendantApp>, cell: &str, text: &str, end: Key) {
    h.query_all_by_label_contains(cell)
        .next()
        .unwrap_or_else(|| panic!("no cell {cell}"))
        .click();
    h.step();
    h.step();
    h.key_press_modifiers(egui::Modifiers::COMMAND, Key::A);
    h.event(egui::Event::Text(text.into()));
    h.step();
    h.key_press(end);
    h.step();
    h.step();
}

#[test]
fn cells_are_edited_in_place_checked_undone_and_go_through_a_file() {
    let mut h = offline();
    type_cell(&mut h, "No. 3 X mm", "12.5", Key::Enter);
    let x = |a: &PendantApp| {
        a.pendant()
            .positions
            .draft(3)
            .and_then(|r| r.coords.get(Axis::A1))
            .map(|m| m.0)
    };
    assert_eq!(x(h.state()), Some(12_500), "X of No. 3 in the draft");
    assert!(h.state().pendant().positions.differs(3));
    step_until_shown(&mut h, "1 row differs");
    step_until_shown(&mut h, "No. 3 X mm: 12.500");
    // Escape forgets what was typed; a bad number changes nothing and says why.
    type_cell(&mut h, "No. 3 X mm", "99", Key::Escape);
    assert_eq!(x(h.state()), Some(12_500), "Escape forgets the typing");
    type_cell(&mut h, "No. 3 Y mm", "1.2345", Key::Enter);
    step_until_shown(&mut h, "more than 3 decimals");
    assert!(
        h.state()
            .pendant()
            .positions
            .draft(3)
            .is_some_and(|r| r.coords.get(Axis::A2).is_none()),
        "the refused Y is not in the draft"
    );
    // Out to a file, undone, and back in from it.
    let dir = std::env::temp_dir().join(format!("xsel-pendant-positions-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("positions.csv");
    let _ = std::fs::remove_file(&path);
    replace_text(&mut h, "File", &path.display().to_string());
    click(&mut h, "Export");
    step_until_shown(&mut h, "exported 1 rows");
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(text.contains("3,,12.500"), "{text}");
    click(&mut h, "Undo");
    step_until(&mut h, "the draft empty", |a| {
        a.pendant().positions.draft(3).is_none()
    });
    click(&mut h, "Import");
    step_until(&mut h, "No. 3 imported", |a| x(a) == Some(12_500));
    click(&mut h, "Undo");
    click(&mut h, "Redo");
    assert_eq!(x(h.state()), Some(12_500), "Redo brings the import back");
    let _ = std::fs::remove_dir_all(&dir);
}
