//! The coordinate-table editor in the real window on the embedded simulator, driven
//! headlessly with egui_kittest: both tables read and compared cell by cell with the
//! simulator's own, a read with dropped replies, editing with diff and undo, a refused
//! entry; and the operator's work in files of its own (drafts, teach list, settings),
//! back after the window is gone. Waits are bounded by a deadline; nothing sleeps a fixed
//! time before asserting.

use std::time::Duration;

use egui::Key;
use egui_kittest::Harness;
use egui_kittest::kittest::{NodeT, Queryable};
use xsel_pendant::pendant::coords::{Column, diff};
use xsel_pendant::robot::{CoordSystem, CoordTables, FrameKind};
use xsel_pendant::sim::runner::Dir;
use xsel_pendant::sim::{Fault, FaultSpec};
use xsel_pendant::ui::{PendantApp, StartOptions};

use crate::kittest_common::{click, replace_text, show_tab, step_until, step_until_shown, wheel};

fn app<'a>() -> Harness<'a, PendantApp> {
    Harness::builder()
        .with_size([1280.0, 900.0])
        .build_eframe(|cc| PendantApp::new(cc, StartOptions::fresh_simulator()))
}

fn sim_tables(app: &PendantApp) -> CoordTables {
    app.sim()
        .expect("the built-in simulator")
        .with(|c| c.coords().clone())
}

fn both_read(app: &PendantApp) -> bool {
    let p = app.pendant();
    p.read_table(FrameKind::Work).is_some()
        && p.read_table(FrameKind::Tool).is_some()
        && p.coords.reading().is_none()
}

/// Opens the coordinate tables pane.
fn open_pane(h: &mut Harness<'_, PendantApp>) {
    h.get_by_label("Coordinate tables").click();
    h.step();
    h.step();
}

#[test]
fn both_tables_are_read_and_match_the_simulator_cell_by_cell() {
    let mut h = app();
    step_until(&mut h, "both tables read", both_read);
    open_pane(&mut h);
    let sim = sim_tables(h.state());
    let p = h.state().pendant();
    for (kind, table) in [(FrameKind::Work, &sim.work), (FrameKind::Tool, &sim.tool)] {
        let read = &p.read_table(kind).unwrap().records;
        assert_eq!(read.len(), table.len(), "{kind} table size");
        for (n, want) in table.entries().iter().enumerate() {
            assert_eq!(read[n], Some(*want), "{kind} No. {n} as read");
            assert_eq!(
                p.coords.draft(kind).get(n),
                Some(*want),
                "{kind} No. {n} in the draft"
            );
        }
    }
    // The example has a non-zero work No. 1: the window shows its values.
    let x = sim.work.get(1).unwrap().x.0;
    assert_ne!(x, 0);
    let shown = h.get_by_label("work 1 X mm").value();
    assert_eq!(
        shown.as_deref(),
        Some(format!("{:.3}", f64::from(x) / 1000.0).as_str())
    );
}

/// The definition numbers the simulator's delivered (not dropped) 2A4H replies carried.
fn delivered(app: &PendantApp, type_digit: char, since: Duration) -> Vec<bool> {
    let mut got = vec![false; 128];
    for t in app
        .sim()
        .unwrap()
        .traffic()
        .into_iter()
        .filter(|t| t.at >= since)
    {
        let f = String::from_utf8_lossy(&t.bytes).into_owned();
        if t.dir != Dir::Out
            || t.fault.is_some()
            || f.get(0..1) != Some("#")
            || f.get(3..6) != Some("2A4")
        {
            continue;
        }
        if f.get(8..9).and_then(|s| s.chars().next()) != Some(type_digit) {
            continue;
        }
        let hex =
            |r: std::ops::Range<usize>| f.get(r).and_then(|s| usize::from_str_radix(s, 16).ok());
        if let (Some(first), Some(count)) = (hex(9..11), hex(11..13)) {
            for n in first..first + count {
                if let Some(g) = got.get_mut(n) {
                    *g = true;
                }
            }
        }
    }
    got
}

#[test]
fn a_read_with_dropped_replies_marks_exactly_the_missing_records_and_retries_only_those() {
    let mut h = app();
    step_until(&mut h, "both tables read", both_read);
    open_pane(&mut h);
    click(&mut h, "Tool table");
    let sim = h.state().sim().unwrap().watch();
    let sim_now = |a: &PendantApp| a.sim().unwrap().with_core(|c| c.now());
    // Most replies dropped: a chunk whose every try is dropped stays unread. A read that
    // happens to lose none is made again (five reads all complete: about 1 in 10^8).
    let (mut unread, mut expected) = (Vec::new(), Vec::new());
    for seed in 11..16 {
        h.state()
            .sim()
            .unwrap()
            .set_faults(FaultSpec::none().with(Fault::Drop, 0.9).seeded(seed));
        // Only this read's replies count.
        let since = sim_now(h.state());
        click(&mut h, "Read from controller");
        step_until(&mut h, "the tool table read to end", |a| {
            a.pendant().coords.reading().is_none()
        });
        h.state().sim().unwrap().set_faults(FaultSpec::none());
        let got = delivered(h.state(), '1', since);
        let read = h
            .state()
            .pendant()
            .read_table(FrameKind::Tool)
            .unwrap()
            .records
            .clone();
        unread = (0..128).filter(|&n| read[n].is_none()).collect();
        expected = (0..128).filter(|&n| !got[n]).collect::<Vec<usize>>();
        assert_eq!(
            unread, expected,
            "unread records against the replies delivered"
        );
        if !unread.is_empty() {
            break;
        }
    }
    assert!(!unread.is_empty(), "no read lost a record");
    // The window says so.
    assert!(h.query_by_label_contains("records unread").is_some());
    let total: usize = unread.len();
    {
        let since = sim_now(h.state());
        click(&mut h, &format!("Retry unread ({total})"));
        step_until(&mut h, "the retry to end", |a| {
            a.pendant().coords.reading().is_none()
                && a.pendant().unread_ranges(FrameKind::Tool).is_empty()
        });
        // Only the missing records were asked for.
        let asked: Vec<usize> = sim
            .traffic()
            .into_iter()
            .filter(|t| t.dir == Dir::In && t.at >= since)
            .map(|t| String::from_utf8_lossy(&t.bytes).into_owned())
            .filter(|f| f.get(3..6) == Some("2A4"))
            .flat_map(|f| {
                let hex = |r: std::ops::Range<usize>| {
                    f.get(r)
                        .and_then(|s| usize::from_str_radix(s, 16).ok())
                        .unwrap_or(0)
                };
                let first = hex(9..11);
                first..first + hex(11..13)
            })
            .collect();
        let mut asked_sorted = asked.clone();
        asked_sorted.sort_unstable();
        asked_sorted.dedup();
        assert_eq!(
            asked_sorted, expected,
            "the retry asked for exactly the unread records"
        );
    }
    let sim_tool = sim_tables(h.state()).tool;
    let read = &h
        .state()
        .pendant()
        .read_table(FrameKind::Tool)
        .unwrap()
        .records;
    for (n, want) in sim_tool.entries().iter().enumerate() {
        assert_eq!(read[n], Some(*want), "tool No. {n} after the retry");
    }
}

/// Types `text` into a cell and ends the entry with Enter.
fn type_into(h: &mut Harness<'_, PendantApp>, label: &str, text: &str) {
    replace_text(h, label, text);
    h.key_press(Key::Enter);
    h.step();
    h.step();
}

#[test]
fn an_edit_shows_in_the_diff_and_undo_takes_it_back_and_a_bad_entry_is_refused() {
    let mut h = app();
    step_until(&mut h, "both tables read", both_read);
    open_pane(&mut h);
    let controller = |a: &PendantApp| {
        a.pendant()
            .read_table(FrameKind::Work)
            .unwrap()
            .records
            .clone()
    };
    let draft = |a: &PendantApp| a.pendant().coords.draft(FrameKind::Work).rows().clone();
    assert!(diff(&draft(h.state()), &controller(h.state())).is_empty());

    type_into(&mut h, "work 2 Y mm", "-12.345");
    let d = diff(&draft(h.state()), &controller(h.state()));
    assert_eq!(d.len(), 1, "one row differs: {d:?}");
    assert_eq!((d[0].number, d[0].cells), (2, [false, true, false, false]));
    assert_eq!(d[0].draft.map(|c| Column::Y.get(&c)), Some(-12_345));
    // Side by side: the controller's column appears with the diff on.
    h.get_by_label("Diff with controller").click();
    h.step();
    h.step();
    assert!(h.query_by_label("1 row differs: No. 2").is_some());

    // A bad number is refused inline, the draft unchanged.
    let before = draft(h.state());
    type_into(&mut h, "work 3 X mm", "12,5");
    assert_eq!(
        draft(h.state()),
        before,
        "a refused entry changed the draft"
    );
    assert!(
        h.query_by_label_contains("Refused, the draft is unchanged: work No. 3, X mm")
            .is_some(),
        "the refusal is shown"
    );
    // Work No. 0 is read-only.
    h.get_by_label_contains("work 0 Z mm").focus();
    h.step();
    h.get_by_label_contains("work 0 Z mm").type_text("5");
    h.step();
    h.key_press(Key::Enter);
    h.step();
    assert_eq!(draft(h.state())[0], Some(CoordSystem::ZERO));

    click(&mut h, "Undo");
    assert!(
        diff(&draft(h.state()), &controller(h.state())).is_empty(),
        "undo"
    );
    click(&mut h, "Redo");
    assert_eq!(
        diff(&draft(h.state()), &controller(h.state())).len(),
        1,
        "redo"
    );
}

#[test]
fn the_draft_goes_to_the_simulator_in_one_click() {
    let mut h = app();
    step_until(&mut h, "both tables read", both_read);
    open_pane(&mut h);
    click(&mut h, "Tool table");
    type_into(&mut h, "tool 4 Z mm", "-40");
    click(&mut h, "Try on simulator");
    // The simulator's own thread takes the draft from its front panel, between frames.
    step_until(&mut h, "the simulator has the draft", |a| {
        sim_tables(a).tool.get(4).map(|c| c.z.0) == Some(-40_000)
    });
    // Read back from the simulator: the draft and the controller agree again.
    click(&mut h, "Read from controller");
    step_until(&mut h, "the tool table read again", |a| {
        a.pendant().coords.reading().is_none()
            && a.pendant().read_table(FrameKind::Tool).unwrap().records[4].map(|c| c.z.0)
                == Some(-40_000)
    });
    let p = h.state().pendant();
    assert!(
        diff(
            p.coords.tool.rows(),
            &p.read_table(FrameKind::Tool).unwrap().records
        )
        .is_empty()
    );
}

#[test]
fn drafts_are_autosaved_on_every_change_and_come_back_after_a_close() {
    let dir = std::env::temp_dir().join(format!("xsel-pendant-drafts-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let start = |dir: &std::path::Path| {
        let options = StartOptions {
            data_dir: Some(dir.to_path_buf()),
            ..StartOptions::fresh_simulator()
        };
        Harness::builder()
            .with_size([1280.0, 900.0])
            .build_eframe(move |cc| PendantApp::new(cc, options))
    };
    let mut h = start(&dir);
    step_until(&mut h, "both tables read", both_read);
    open_pane(&mut h);
    type_into(&mut h, "work 5 R deg", "45.5");
    // Written within frames, before any close (the write is a job: the window does not
    // wait for the disk).
    let file = dir.join("coords-drafts.json");
    step_until(&mut h, "the edit in the drafts file", |_| {
        std::fs::read_to_string(&file).is_ok_and(|text| text.contains("45500"))
    });
    drop(h);
    // A new window (as after a crash) has the edit back before anything is read.
    let h = start(&dir);
    let p = h.state().pendant();
    assert_eq!(
        p.coords.draft(FrameKind::Work).get(5).map(|c| c.r.0),
        Some(45_500)
    );
    let _ = std::fs::remove_dir_all(&dir);
}

fn start_in(dir: &std::path::Path, fresh: bool) -> Harness<'static, PendantApp> {
    let options = StartOptions {
        data_dir: Some(dir.to_path_buf()),
        fresh,
        ..StartOptions::fresh_simulator()
    };
    Harness::builder()
        .with_size([1280.0, 900.0])
        .build_eframe(move |cc| PendantApp::new(cc, options))
}

/// Records the current pose as `name` from the Teach list tab, as an operator does: on a
/// fresh position, and again if the position went out of date before the click landed (a
/// busy machine can delay a poll past the staleness limit; the pendant then refuses).
fn record(h: &mut Harness<'_, PendantApp>, name: &str) {
    show_tab(h, "Teach list");
    type_into(h, "Name", name);
    let refusals = |a: &PendantApp| {
        a.pendant()
            .messages
            .iter()
            .filter(|m| m.text.contains("not recorded"))
            .count()
    };
    let deadline = std::time::Instant::now() + crate::kittest_common::DEADLINE;
    loop {
        step_until(h, "a fresh position to record", |a| {
            let c = &a.pendant().controller;
            c.work.is_some() && !c.is_stale(std::time::Instant::now())
        });
        let before = refusals(h.state());
        click(h, "Record");
        step_until(h, "the point recorded or refused", |a| {
            a.pendant().teach.list().position(name).is_some() || refusals(a) > before
        });
        if h.state().pendant().teach.list().position(name).is_some() {
            return;
        }
        assert!(
            std::time::Instant::now() < deadline,
            "never recorded: {:?}",
            h.state().pendant().messages.back()
        );
    }
}

#[test]
fn a_recorded_point_is_in_its_file_at_once_and_back_after_the_window_is_gone() {
    let dir = std::env::temp_dir().join(format!("xsel-pendant-teach-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let mut h = start_in(&dir, true);
    record(&mut h, "PICK1");
    // On disk within frames, before any close, as a SIGKILL a moment later would find
    // it (the write is a job: the window does not wait for the disk).
    let file = dir.join("teach-list.json");
    step_until(&mut h, "the point written to its file", |_| {
        std::fs::read_to_string(&file).is_ok_and(|t| t.contains("PICK1"))
    });
    drop(h);
    let h = start_in(&dir, true);
    assert!(
        h.state().pendant().teach.list().position("PICK1").is_some(),
        "the point is lost"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn truncated_settings_are_kept_aside_with_a_message_and_the_teach_list_is_untouched() {
    let dir = std::env::temp_dir().join(format!("xsel-pendant-settings-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let mut h = start_in(&dir, false);
    record(&mut h, "PLACE2");
    click(&mut h, "Light theme");
    h.step();
    drop(h);
    let path = dir.join("settings.json");
    let text = std::fs::read(&path).expect("settings saved");
    std::fs::write(&path, &text[..text.len() / 2]).unwrap();
    let h = start_in(&dir, false);
    let p = h.state().pendant();
    let said: Vec<&str> = p.messages.iter().map(|m| m.text.as_str()).collect();
    assert!(
        said.iter()
            .any(|t| t.contains("settings could not be read") && t.contains("kept as")),
        "no word of the unreadable settings: {said:?}"
    );
    assert!(
        p.teach.list().position("PLACE2").is_some(),
        "the teach list suffered"
    );
    let kept = std::fs::read_dir(&dir)
        .unwrap()
        .flatten()
        .find(|e| {
            e.file_name()
                .to_string_lossy()
                .starts_with("settings.json.unreadable")
        })
        .expect("the unreadable settings kept");
    assert_eq!(std::fs::read(kept.path()).unwrap(), &text[..text.len() / 2]);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_teach_load_never_empties_the_list_never_blocks_and_replaces_only_when_told() {
    let dir = std::env::temp_dir().join(format!("xsel-pendant-load-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let mut h = start_in(&dir.join("data"), true);
    record(&mut h, "KEEP");
    // The read is a job: the window keeps drawing until the pendant has its answer.
    let load = |h: &mut Harness<'_, PendantApp>, file: &std::path::Path| {
        let before = h.state().pendant().teach.feedback().cloned();
        replace_text(h, "File", &file.display().to_string());
        click(h, "Load");
        step_until(h, "the load answered", |a| {
            a.pendant().teach.feedback().cloned() != before || a.pendant().teach.pending().is_some()
        });
    };
    let said = |h: &Harness<'_, PendantApp>| {
        h.state()
            .pendant()
            .messages
            .back()
            .map(|m| m.text.clone())
            .unwrap_or_default()
    };
    // An object that is no teach list.
    let empty = dir.join("empty.json");
    std::fs::write(&empty, "{}").unwrap();
    load(&mut h, &empty);
    assert!(
        said(&h).contains("points") && said(&h).contains("nothing changed"),
        "{}",
        said(&h)
    );
    assert_eq!(h.state().pendant().teach.list().len(), 1);
    // A FIFO: refused at once, the window still drawing.
    #[cfg(unix)]
    {
        let fifo = dir.join("points.csv");
        let made = std::process::Command::new("mkfifo").arg(&fifo).status();
        assert!(made.is_ok_and(|s| s.success()), "mkfifo");
        load(&mut h, &fifo);
        assert!(said(&h).contains("not a regular file"), "{}", said(&h));
    }
    // A real list: it waits for Replace, and Undo load brings the old one back.
    let other = dir.join("two.json");
    let mut two = xsel_pendant::pendant::teach::TeachList::new();
    for n in ["A", "B"] {
        let at = h.state().pendant().teach.list().get(0).unwrap().taught();
        two.record(n, at).unwrap();
    }
    std::fs::write(&other, two.to_json()).unwrap();
    load(&mut h, &other);
    h.get_by_label_contains("Replace the 1 points of the list with the 2 points");
    assert_eq!(
        h.state().pendant().teach.list().len(),
        1,
        "replaced unasked"
    );
    click(&mut h, "Replace");
    assert_eq!(h.state().pendant().teach.list().len(), 2);
    click(&mut h, "Undo load");
    assert!(h.state().pendant().teach.list().position("KEEP").is_some());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_save_over_a_file_that_is_there_asks_first_and_says_the_full_path_and_time() {
    let dir = std::env::temp_dir().join(format!("xsel-pendant-overwrite-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let mut h = start_in(&dir.join("data"), true);
    record(&mut h, "KEEP");
    let target = dir.join("points.csv");
    std::fs::write(&target, "the operator's own file").unwrap();
    let save = |h: &mut Harness<'_, PendantApp>| {
        replace_text(h, "File", &target.display().to_string());
        click(h, "Save");
    };
    save(&mut h);
    step_until_shown(&mut h, "already exists");
    click(&mut h, "Keep it");
    assert_eq!(
        std::fs::read_to_string(&target).unwrap(),
        "the operator's own file",
        "overwritten unasked"
    );
    save(&mut h);
    step_until_shown(&mut h, "already exists");
    click(&mut h, "Replace");
    step_until_shown(&mut h, "saved 1 point to");
    let said = format!("saved 1 point to {}", target.display());
    h.get_by_label_contains(&said);
    h.get_by_label_contains("UTC");
    assert!(std::fs::read_to_string(&target).unwrap().contains("KEEP"));
    // A bare name goes into the folder of the last file used, not the working directory.
    replace_text(&mut h, "File", "second.csv");
    click(&mut h, "Save");
    step_until_shown(&mut h, "saved 1 point to");
    assert!(
        dir.join("second.csv").exists(),
        "not in the last folder used"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_list_of_ten_thousand_points_loads_off_the_ui_thread_and_draws_only_what_is_seen() {
    use xsel_pendant::pendant::teach::{MAX_POINTS, TeachList};
    let dir = std::env::temp_dir().join(format!("xsel-pendant-10k-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let mut h = start_in(&dir.join("data"), true);
    record(&mut h, "FIRST");
    let at = h.state().pendant().teach.list().get(0).unwrap().taught();
    let mut big = TeachList::new();
    for i in 0..MAX_POINTS {
        big.record(&format!("P{i}"), at).unwrap();
    }
    let file = dir.join("big.csv");
    std::fs::write(&file, big.to_csv()).unwrap();
    replace_text(&mut h, "File", &file.display().to_string());
    click(&mut h, "Load");
    step_until(&mut h, "the 10,000 points read", |a| {
        a.pendant().teach.pending().is_some()
    });
    click(&mut h, "Replace");
    assert_eq!(h.state().pendant().teach.list().len(), MAX_POINTS);
    h.run_steps(2);
    // The first rows are drawn; the last one is not laid out until scrolled to.
    h.get_by_label("P0");
    assert!(
        h.query_by_label("P9999").is_none(),
        "all 10,000 rows were laid out"
    );
    // A full list refuses another point with the reason.
    type_into(&mut h, "Name", "ONE MORE");
    click(&mut h, "Record");
    step_until_shown(&mut h, "the list is full");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn hostile_files_for_import_change_nothing_and_say_why() {
    let dir = std::env::temp_dir().join(format!("xsel-pendant-import-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let mut h = app();
    step_until(&mut h, "both tables read", both_read);
    open_pane(&mut h);
    let draft = |h: &Harness<'_, PendantApp>| h.state().pendant().coords.saved();
    let before = draft(&h);
    let import = |h: &mut Harness<'_, PendantApp>, file: &std::path::Path| {
        let shown = h.state().pendant().coords.file_result.clone();
        replace_text(h, "File", &file.display().to_string());
        click(h, "Import");
        step_until(h, "the import answered", |a| {
            a.pendant().coords.file_result != shown
        });
        let out = h.state().pendant().coords.file_result.clone().unwrap();
        assert!(!out.ok, "{}", out.text);
        out.text
    };
    let huge = dir.join("huge.csv");
    std::fs::write(&huge, vec![b','; 9 * 1024 * 1024]).unwrap();
    let said = import(&mut h, &huge);
    assert!(
        said.contains("huge.csv") && said.contains("not read"),
        "{said}"
    );
    let binary = dir.join("picture.csv");
    std::fs::write(&binary, b"\x89PNG\r\n\x1a\n\0\0\0\rIHDR\xff\xfe").unwrap();
    let said = import(&mut h, &binary);
    assert!(said.contains("picture.csv"), "{said}");
    #[cfg(unix)]
    {
        let fifo = dir.join("tables.csv");
        let made = std::process::Command::new("mkfifo").arg(&fifo).status();
        assert!(made.is_ok_and(|s| s.success()), "mkfifo");
        let said = import(&mut h, &fifo);
        assert!(said.contains("not a regular file"), "{said}");
    }
    assert_eq!(draft(&h), before, "a refused import changed the draft");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_save_that_fails_is_said_in_red_retried_and_its_recovery_said() {
    let dir = std::env::temp_dir().join(format!("xsel-pendant-full-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    // A folder where the new file must go: every write of the list fails, as on a full
    // disk, and the last good copy stays.
    let mut h = start_in(&dir, true);
    record(&mut h, "FIRST");
    let file = dir.join("teach-list.json");
    step_until(&mut h, "the first point saved", |_| {
        std::fs::read_to_string(&file).is_ok_and(|t| t.contains("FIRST"))
    });
    let blocker = dir.join("teach-list.json.new");
    std::fs::create_dir_all(&blocker).unwrap();
    record(&mut h, "SECOND");
    let said = |a: &PendantApp, words: &str| {
        a.pendant()
            .messages
            .iter()
            .any(|m| m.level == xsel_pendant::pendant::Level::Error && m.text.contains(words))
    };
    step_until(&mut h, "the failed save said", |a| {
        said(a, "could not be saved")
    });
    let kept = std::fs::read_to_string(&file).unwrap();
    assert!(kept.contains("FIRST") && !kept.contains("SECOND"), "{kept}");
    std::fs::remove_dir(&blocker).unwrap();
    step_until(&mut h, "the retry that works", |a| {
        a.pendant()
            .messages
            .iter()
            .any(|m| m.text.contains("saved again"))
    });
    assert!(std::fs::read_to_string(&file).unwrap().contains("SECOND"));
    let _ = std::fs::remove_dir_all(&dir);
}

/// The record number drawn in the frozen No. column level with `cell` (`work 7 X mm`).
fn number_beside(h: &Harness<'_, PendantApp>, cell: egui::Rect) -> Option<String> {
    let no = h.get_by_label("No.").rect();
    // Only labels inside the pane: the left column's numbers (station, baud) may stand
    // level with a row too.
    let pane = h
        .state()
        .pane_rect(xsel_pendant::ui::Tab::Coords)
        .expect("the coordinate tables are shown");
    h.query_all(egui_kittest::kittest::by()).find_map(|n| {
        let node = n.accesskit_node();
        // Pixels are points here (1 px/pt).
        let b = node.bounding_box()?;
        let level = ((b.y0 + b.y1) / 2.0 - f64::from(cell.center().y)).abs() < 3.0;
        let centre = (b.x0 + b.x1) / 2.0;
        let in_column = centre > f64::from(pane.left()) && centre < f64::from(no.right()) + 1.0;
        // A label's text is its value in AccessKit.
        (level && in_column)
            .then(|| node.value().or_else(|| node.label()))
            .flatten()
            .filter(|l| l.parse::<usize>().is_ok())
    })
}

#[test]
fn in_a_narrow_pane_the_no_column_stays_while_the_values_scroll_and_diff_sits_beside() {
    // The default layout's right column: too narrow for the values and the diff.
    let mut h = Harness::builder()
        .with_size([1280.0, 1000.0])
        .build_eframe(|cc| PendantApp::new(cc, StartOptions::fresh_simulator()));
    step_until(&mut h, "both tables read", both_read);
    show_tab(&mut h, "Coordinate tables");
    h.get_by_label("Diff with controller").click();
    h.run_steps(3);
    // Each controller column right after its draft column.
    let x = |h: &Harness<'_, PendantApp>, l: &str| h.get_by_label(l).rect();
    for (draft, ctrl, next) in [
        ("X mm", "ctrl X mm", "Y mm"),
        ("Y mm", "ctrl Y mm", "Z mm"),
        ("Z mm", "ctrl Z mm", "R deg"),
    ] {
        let (d, c, n) = (x(&h, draft), x(&h, ctrl), x(&h, next));
        assert!(
            d.left() < c.left() && c.left() < n.left(),
            "{ctrl} at {c:?} is not between {draft} {d:?} and {next} {n:?}"
        );
    }
    let no = x(&h, "No.");
    let first_x = x(&h, "work 1 X mm");
    assert_eq!(number_beside(&h, first_x).as_deref(), Some("1"));
    // Sideways: the values move, the No. column does not.
    wheel(&mut h, first_x.center(), egui::vec2(-200.0, 0.0));
    let moved = x(&h, "X mm");
    assert!(
        moved.left() < first_x.left() - 50.0,
        "the values did not scroll sideways: X mm at {moved:?}"
    );
    assert_eq!(x(&h, "No."), no, "the No. column moved");
    // Down: both tables follow the wheel together, each number level with its row.
    let r_cell = x(&h, "work 1 R deg");
    wheel(
        &mut h,
        egui::pos2(r_cell.left() + 5.0, r_cell.center().y),
        egui::vec2(0.0, -200.0),
    );
    let visible = h.state().pane_rect(xsel_pendant::ui::Tab::Coords).unwrap();
    let rows: Vec<(usize, egui::Rect)> = (0..32)
        .filter_map(|n| {
            // The field, not the tooltip the pointer raises over it.
            h.query_by_role_and_label(egui::accesskit::Role::TextInput, &format!("work {n} R deg"))
                .map(|c| (n, c.rect()))
        })
        .filter(|(_, r)| r.top() > no.bottom() && r.bottom() < visible.bottom())
        .collect();
    assert!(
        rows.first().is_some_and(|(n, _)| *n > 3),
        "the table did not scroll down: {rows:?}"
    );
    for (n, cell) in rows {
        assert_eq!(
            number_beside(&h, cell),
            Some(n.to_string()),
            "row {n} and its number are not level"
        );
    }
}
