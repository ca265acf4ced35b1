//! The frame log pane in the real window on the embedded simulator (egui_kittest): the
//! exact bytes of a jog step and its reply, a corrupted reply flagged, filter, pause,
//! save, open and raw send, each driven by clicks and typing. Waits have deadlines.

use std::time::Instant;

use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use xsel_pendant::pendant::frame_log::{Dir, FrameLog, Verdict};
use xsel_pendant::protocol::HomeState;
use xsel_pendant::protocol::describe::describe;
use xsel_pendant::sim::runner::Dir as SimDir;
use xsel_pendant::sim::{Fault, FaultSpec};
use xsel_pendant::ui::{PendantApp, StartOptions};

use crate::kittest_common::{
    click, press, replace_text, step_until, step_until_shown, type_into, wheel,
};

use crate::wire::frame as framed;

fn app<'a>() -> Harness<'a, PendantApp> {
    // Tall enough that the frame log, under the arm view by default, shows its tools and
    // several rows.
    Harness::builder()
        .with_size([1280.0, 1500.0])
        .build_eframe(|cc| PendantApp::new(cc, StartOptions::fresh_simulator()))
}

/// Whether some widget's label contains `text`.
fn shows(h: &Harness<'_, PendantApp>, text: &str) -> bool {
    h.query_all_by_label_contains(text).next().is_some()
}

fn log(a: &PendantApp) -> &FrameLog {
    &a.pendant().frame_log
}

/// Rows of the live log whose bytes have this message ID in columns 4-6.
fn rows_with_id(a: &PendantApp, dir: Dir, id: &str) -> Vec<u64> {
    let log = log(a);
    (0..log.len())
        .filter_map(|i| log.nth(i))
        .filter(|r| r.dir() == dir && r.bytes().get(3..6) == Some(id.as_bytes()))
        .map(|r| r.seq())
        .collect()
}

fn sim_frames(a: &PendantApp, dir: SimDir, id: &str) -> Vec<Vec<u8>> {
    a.sim()
        .map(|s| s.traffic())
        .unwrap_or_default()
        .into_iter()
        .filter(|t| t.dir == dir && t.bytes.get(3..6) == Some(id.as_bytes()))
        .map(|t| t.bytes)
        .collect()
}

fn ready(h: &mut Harness<'_, PendantApp>) {
    step_until(h, "the controller to accept commands", |a| {
        a.pendant().controller_ready(Instant::now()).is_ok()
    });
    click(h, "Servo ON");
    let axes_ok = |a: &PendantApp, f: &dyn Fn(&xsel_pendant::protocol::AxisState) -> bool| {
        a.pendant()
            .controller
            .axes()
            .is_some_and(|axes| axes.iter().all(|(_, s)| f(&s)))
    };
    step_until(h, "servo on", |a| {
        axes_ok(a, &|s| s.status.servo_on() && !s.status.in_use())
    });
    click(h, "Home");
    step_until(h, "homed", |a| {
        axes_ok(a, &|s| {
            s.status.home_state() == HomeState::Done && !s.status.in_use()
        })
    });
    step_until(h, "motion allowed", |a| {
        a.pendant().motion_ready(Instant::now()).is_ok()
    });
}

#[test]
fn a_jog_step_and_its_reply_show_with_exact_bytes_decode_and_latency() {
    let mut h = app();
    ready(&mut h);
    click(&mut h, "Frame log");
    click(&mut h, "X+");
    step_until(&mut h, "the 2D5H step and its reply in the log", |a| {
        rows_with_id(a, Dir::Sent, "2D5")
            .first()
            .is_some_and(|&s| log(a).reply_of(s).is_some())
    });
    let a = h.state();
    let sent = rows_with_id(a, Dir::Sent, "2D5")[0];
    let reply = log(a).reply_of(sent).unwrap();
    let (req_row, rep_row) = (log(a).row(sent).unwrap(), log(a).row(reply).unwrap());
    // The bytes the simulator received and answered, exactly.
    assert_eq!(
        req_row.bytes(),
        sim_frames(a, SimDir::In, "2D5")[0].as_slice()
    );
    assert_eq!(
        rep_row.bytes(),
        sim_frames(a, SimDir::Out, "2D5")[0].as_slice()
    );
    assert_eq!(rep_row.dir(), Dir::Received);
    assert_eq!(rep_row.verdict(), Verdict::Ok);
    assert!(rep_row.latency_us().is_some_and(|us| us > 0));
    assert_eq!(req_row.name(), "2D5H SCARA relative move");
    let d = describe(&req_row.bytes());
    assert!(
        d.is_ok() && d.fields.iter().any(|f| f.name.contains("axis")),
        "{d}"
    );
    // A press on a row selects it, as the user sees it, while the tail moves on.
    assert!(h.state().frame_log_panel().selected().is_none());
    // The middle one of the sent rows in the tree (the first and last may be cut by the
    // edges of the view).
    let rows: Vec<egui::Rect> = h
        .query_all_by_label_contains(">>")
        .map(|n| n.rect())
        .collect();
    assert!(rows.len() >= 3, "{} sent rows in view", rows.len());
    let rect = rows[rows.len() / 2];
    press(&mut h, egui::pos2(rect.left() + 40.0, rect.center().y));
    assert!(h.state().frame_log_panel().selected().is_some());
    click(&mut h, "Close decode");
    // Filter to the step, select it: the decode shows, and the jump to the reply works.
    type_into(&mut h, "ID", "2D5");
    step_until(&mut h, "the filter to finish", |a| {
        !a.frame_log_panel().filtering() && a.frame_log_panel().shown(a.pendant()) == 2
    });
    let ascii = h.state().pendant().frame_log.row(sent).unwrap().ascii();
    // The row is wider than the pane: click it as assistive technology would.
    h.get_by_label_contains(&ascii).click_accesskit();
    h.step();
    h.step();
    assert_eq!(h.state().frame_log_panel().selected(), Some(sent));
    assert!(shows(&h, "SCARA relative move - command"));
    click(&mut h, "Go to reply");
    assert_eq!(h.state().frame_log_panel().selected(), Some(reply));
    assert!(shows(&h, "SCARA relative move - reply"));
    assert!(shows(&h, &format!("Row {reply}:")));
}

#[test]
fn a_corrupted_reply_is_flagged_with_its_raw_bytes() {
    let mut h = app();
    step_until(&mut h, "connected", |a| a.pendant().line.is_up());
    click(&mut h, "Frame log");
    let spec = FaultSpec::none().with(Fault::Corrupt, 1.0).seeded(3);
    h.state().sim().unwrap().set_faults(spec);
    // A whole corrupted reply: from its header to its CR LF (a corrupted byte may also
    // cut a reply into fragments, which are garbage of their own).
    let whole_bad = |r: &xsel_pendant::pendant::frame_log::Row<'_>| {
        r.dir() == Dir::Garbage
            && r.verdict() == Verdict::Bad
            && r.bytes().first() == Some(&b'#')
            && r.bytes().ends_with(b"\r\n")
    };
    step_until(&mut h, "a corrupted reply in the log", |a| {
        let log = log(a);
        (0..log.len())
            .filter_map(|i| log.nth(i))
            .any(|r| whole_bad(&r))
    });
    h.state().sim().unwrap().set_faults(FaultSpec::none());
    let a = h.state();
    let log = log(a);
    let bad = (0..log.len())
        .filter_map(|i| log.nth(i))
        .find(|r| whole_bad(r))
        .unwrap();
    assert!(bad.is_problem());
    assert!(!bad.note().is_empty());
    // Exactly what the simulator sent.
    let out: Vec<Vec<u8>> = a
        .sim()
        .unwrap()
        .traffic()
        .into_iter()
        .filter(|t| t.dir == SimDir::Out)
        .map(|t| t.bytes)
        .collect();
    assert!(out.iter().any(|o| bad.bytes() == o.as_slice()));
    let (ascii, seq) = (bad.ascii(), bad.seq());
    // "Errors only" has it; the tail it follows may be other errors, so it is brought
    // into view as a jump would.
    h.get_by_label("Errors only").click();
    step_until(&mut h, "the errors-only filter", |a| {
        !a.frame_log_panel().filtering() && a.frame_log_panel().shown(a.pendant()) >= 1
    });
    h.state_mut().frame_log_panel_mut().reveal(seq);
    h.run_steps(2);
    let rows = h
        .query_all(
            egui_kittest::kittest::By::new()
                .role(egui::accesskit::Role::Button)
                .label_contains(&ascii),
        )
        .count();
    assert_eq!(rows, 1, "row {ascii} not shown among the errors");
}

#[test]
fn filter_pause_save_open_and_raw_send_through_the_window() {
    let dir = std::env::temp_dir().join(format!("xsel-frame-log-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("capture.jsonl");
    let mut h = app();
    step_until(&mut h, "connected and polled", |a| {
        a.pendant().controller_ready(Instant::now()).is_ok()
    });
    click(&mut h, "Frame log");
    // Raw send: a version query typed as its body.
    type_into(&mut h, "Raw frame", "99201000");
    click(&mut h, "Send raw");
    step_until(&mut h, "the raw 201H and its reply", |a| {
        rows_with_id(a, Dir::Sent, "201").iter().any(|&s| {
            log(a).row(s).unwrap().bytes() == framed("!99201000").as_slice()
                && log(a).reply_of(s).is_some()
        })
    });
    assert!(
        sim_frames(h.state(), SimDir::In, "201")
            .iter()
            .filter(|f| f.as_slice() == framed("!99201000").as_slice())
            .count()
            >= 1
    );
    // A typo is answered where the user looks, and nothing is sent.
    replace_text(&mut h, "Raw frame", "zz");
    click(&mut h, "Send raw");
    assert!(shows(&h, "Not sent:"));
    // Motion by raw frame obeys the jog panel's readiness (servo is off).
    let before = sim_frames(h.state(), SimDir::In, "2D5").len();
    replace_text(&mut h, "Raw frame", "992D501001E001E00140200002710");
    click(&mut h, "Send raw");
    assert!(shows(&h, "is motion"));
    assert_eq!(sim_frames(h.state(), SimDir::In, "2D5").len(), before);
    // Pause: the view holds still while rows keep arriving.
    click(&mut h, "Pause");
    let shown = h.state().frame_log_panel().shown(h.state().pendant());
    let len = log(h.state()).len();
    step_until(&mut h, "more rows behind the pause", |a| {
        log(a).len() > len + 4
    });
    assert_eq!(
        h.state().frame_log_panel().shown(h.state().pendant()),
        shown
    );
    click(&mut h, "Resume");
    assert!(h.state().frame_log_panel().shown(h.state().pendant()) > shown);
    // Filter by text: only the version query and its reply.
    type_into(&mut h, "Filter text", "version");
    step_until(&mut h, "the text filter", |a| {
        !a.frame_log_panel().filtering() && a.frame_log_panel().shown(a.pendant()) >= 2
    });
    let shown = h.state().frame_log_panel().shown(h.state().pendant());
    assert!(
        shown < log(h.state()).len() / 2,
        "{shown} rows pass 'version'"
    );
    // Save the filtered rows as JSON Lines, then open them read-only.
    h.get_by_label("filtered rows only").click();
    h.step();
    replace_text(&mut h, "File", &path.display().to_string());
    click(&mut h, "Save JSONL");
    step_until_shown(&mut h, "saved");
    let text = std::fs::read_to_string(&path).unwrap();
    assert_eq!(text.lines().count(), shown + 1, "{text}");
    let hex: String = framed("!99201000")
        .iter()
        .map(|b| format!("{b:02X}"))
        .collect();
    assert!(text.contains(&hex), "{text}");
    click(&mut h, "Open JSONL");
    step_until_shown(&mut h, "(read-only)");
    click(&mut h, "Back to live");
    assert!(shows(&h, "Live"));
    std::fs::remove_dir_all(&dir).ok();
}

/// Fills the live log with `n` synthetic rows: status queries and replies, every 1000th
/// reply an error.
fn synthetic(a: &mut PendantApp, n: u64) {
    a.pendant_mut().frame_log.fill_synthetic(n);
}

#[test]
fn a_million_rows_scroll_to_any_row_and_filter() {
    let mut h = Harness::builder()
        .with_size([1280.0, 900.0])
        .build_eframe(|cc| PendantApp::new(cc, StartOptions::fresh_offline()));
    synthetic(h.state_mut(), 1_000_000);
    click(&mut h, "Frame log");
    assert_eq!(
        h.state().frame_log_panel().shown(h.state().pendant()),
        1_000_000
    );
    for seq in [0u64, 1, 499_999, 777_777, 999_999] {
        h.state_mut().frame_log_panel_mut().reveal(seq);
        h.step();
        h.step();
        let ascii = h.state().pendant().frame_log.row(seq).unwrap().ascii();
        assert!(shows(&h, &format!("Row {seq}:")), "row {seq} not decoded");
        assert!(shows(&h, &ascii), "row {seq} not in view");
    }
    click(&mut h, "Close decode");
    // A pane this short shows rows first: the filter rows come with a click.
    assert!(h.query_by_label("Errors only").is_none());
    h.get_by_label("Filter, files, raw").click();
    h.step();
    h.step();
    h.get_by_label("Errors only").click();
    step_until(&mut h, "the errors-only filter over a million rows", |a| {
        !a.frame_log_panel().filtering() && a.frame_log_panel().shown(a.pendant()) == 500
    });
    type_into(&mut h, "Filter text", "&99C1F");
    step_until(&mut h, "the text filter over a million rows", |a| {
        !a.frame_log_panel().filtering() && a.frame_log_panel().shown(a.pendant()) == 500
    });
    replace_text(&mut h, "Filter text", "no such bytes");
    step_until(&mut h, "nothing to pass", |a| {
        !a.frame_log_panel().filtering() && a.frame_log_panel().shown(a.pendant()) == 0
    });
}

#[test]
fn open_refuses_a_fifo_and_an_endless_line_and_the_live_log_goes_on() {
    let dir = std::env::temp_dir().join(format!("xsel-frame-log-bad-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let mut h = app();
    step_until(&mut h, "connected and polled", |a| {
        a.pendant().controller_ready(Instant::now()).is_ok()
    });
    click(&mut h, "Frame log");
    let open = |h: &mut Harness<'_, PendantApp>, file: &std::path::Path, why: &str| {
        replace_text(h, "File", &file.display().to_string());
        click(h, "Open JSONL");
        step_until_shown(h, why);
        assert!(shows(h, "Live"), "the live log was replaced");
    };
    // A header, then one line of 4 MB with no end: refused at the bound, not read whole.
    let long = dir.join("long.jsonl");
    let mut text = b"{\"xsel_pendant_frame_log\":1,\"start_unix_us\":0}\n".to_vec();
    text.extend(std::iter::repeat_n(b'x', 4 << 20));
    std::fs::write(&long, text).unwrap();
    open(&mut h, &long, "a line longer than any this program writes");
    #[cfg(unix)]
    {
        let fifo = dir.join("pipe.jsonl");
        let made = std::process::Command::new("mkfifo").arg(&fifo).status();
        assert!(made.is_ok_and(|s| s.success()), "mkfifo");
        open(&mut h, &fifo, "not a regular file");
    }
    // The live log keeps growing (and Open answered twice: it is never greyed out).
    let rows = log(h.state()).len();
    step_until(&mut h, "more live rows", |a| log(a).len() > rows);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_filter_with_follow_tail_on_fills_the_view_with_matching_rows() {
    // More matching rows than the pane holds: the view is full of them, down to the
    // newest (it once showed the last two, and the wheel did nothing).
    let mut h = Harness::builder()
        .with_size([1280.0, 900.0])
        .build_eframe(|cc| PendantApp::new(cc, StartOptions::fresh_offline()));
    synthetic(h.state_mut(), 60_000);
    click(&mut h, "Frame log");
    h.get_by_label("Filter, files, raw").click();
    h.run_steps(2);
    type_into(&mut h, "Filter text", "&99C1F");
    step_until(&mut h, "the text filter", |a| {
        !a.frame_log_panel().filtering() && a.frame_log_panel().shown(a.pendant()) == 30
    });
    h.run_steps(3);
    let drawn = |h: &Harness<'_, PendantApp>| {
        h.query_all(
            egui_kittest::kittest::By::new()
                .role(egui::accesskit::Role::Button)
                .label_contains("&99C1F"),
        )
        .count()
    };
    assert!(
        drawn(&h) >= 4,
        "30 rows pass the filter, {} drawn",
        drawn(&h)
    );
}

#[test]
fn the_splitter_between_rows_and_decode_moves_with_the_pointer() {
    let mut h = app();
    step_until(&mut h, "a few rows", |a| log(a).len() >= 6);
    click(&mut h, "Frame log");
    click(&mut h, "Pause");
    // The tools rows hidden: room for the rows and the decode.
    if h.state().frame_log_panel().tools_shown() {
        click(&mut h, "Filter, files, raw");
    }
    // A sent row in view selected as assistive technology selects it.
    let shown = h.query_all_by_label_contains(">>").count();
    assert!(shown >= 1, "no sent row in view");
    h.query_all_by_label_contains(">>")
        .nth(shown / 2)
        .unwrap()
        .click_accesskit();
    h.step();
    h.step();
    assert!(h.state().frame_log_panel().selected().is_some());
    let top = |h: &Harness<'_, PendantApp>| h.get_by_label("Close decode").rect().top();
    let before = top(&h);
    // Drag the splitter up by 50 px.
    let from = h.get_by_label("Rows and decode splitter").rect().center();
    h.event(egui::Event::PointerMoved(from));
    h.step();
    h.event(egui::Event::PointerButton {
        pos: from,
        button: egui::PointerButton::Primary,
        pressed: true,
        modifiers: egui::Modifiers::NONE,
    });
    h.step();
    for k in 1..=5 {
        h.event(egui::Event::PointerMoved(
            from - egui::vec2(0.0, 10.0 * k as f32),
        ));
        h.step();
    }
    h.event(egui::Event::PointerButton {
        pos: from - egui::vec2(0.0, 50.0),
        button: egui::PointerButton::Primary,
        pressed: false,
        modifiers: egui::Modifiers::NONE,
    });
    h.step();
    assert!(h.state().frame_log_panel().decode_height().is_some());
    let after = top(&h);
    assert!(
        (before - after - 50.0).abs() < 12.0,
        "the decode's top moved from {before} to {after}"
    );
}

#[test]
fn the_header_scrolls_sideways_with_the_rows() {
    let mut h = app();
    step_until(&mut h, "a few rows", |a| log(a).len() >= 6);
    click(&mut h, "Frame log");
    click(&mut h, "Pause");
    h.run_steps(2);
    let header = |h: &Harness<'_, PendantApp>| h.get_by_label_contains("+prev ms").rect();
    // The first sent row under the header (the filters have ">>" words too).
    let row = |h: &Harness<'_, PendantApp>| {
        let below = header(h).bottom();
        h.query_all_by_label_contains(">>")
            .map(|n| n.rect())
            .find(|r| r.top() >= below)
            .expect("a sent row in view")
    };
    let (header_before, row_before) = (header(&h).left(), row(&h).left());
    let at = row(&h).left_center() + egui::vec2(20.0, 0.0);
    wheel(&mut h, at, egui::vec2(-150.0, 0.0));
    let (header_moved, row_moved) = (
        header_before - header(&h).left(),
        row_before - row(&h).left(),
    );
    assert!(
        row_moved > 50.0,
        "the rows did not scroll sideways ({row_moved})"
    );
    assert!(
        (header_moved - row_moved).abs() < 0.5,
        "the header moved {header_moved} px, the rows {row_moved} px"
    );
}
