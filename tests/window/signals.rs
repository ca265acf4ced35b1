//! The Signals view in the real window, driven headlessly with egui_kittest: the default
//! watch list, a filter, a rename and a plotted row offline; on the embedded simulator an
//! output forced through the confirmation and an integer variable edited, each read back,
//! a mistyped value refused at its row, and the running program's risk gating Send.
//! Waits are bounded by a deadline; nothing sleeps.

use std::time::Instant;

use egui::Key;
use egui::accesskit::Role;
use egui_kittest::Harness;
use egui_kittest::kittest::{NodeT, Queryable};
use xsel_pendant::pendant::samples::view::TraceChoice;
use xsel_pendant::pendant::signals::{Proposal, Signal, SignalKind, Value};
use xsel_pendant::protocol::BitSpace;
use xsel_pendant::ui::{PendantApp, StartOptions};

use crate::kittest_common::{click, replace_text, show_tab, step_until, step_until_shown};
use crate::main_window::app;

const OUTPUT_300: Signal = Signal::new(SignalKind::Output, 0, 300);
const OUTPUT_301: Signal = Signal::new(SignalKind::Output, 0, 301);
const INTEGER_250: Signal = Signal::new(SignalKind::Integer, 0, 250);

fn value(a: &PendantApp, s: &Signal) -> Option<Value> {
    a.pendant().signals.state(s).and_then(|st| st.value.clone())
}

/// The view's last word is `text`.
fn said(a: &PendantApp, text: &str) -> bool {
    a.pendant()
        .signals
        .feedback
        .as_ref()
        .is_some_and(|(_, t)| t == text)
}

fn sim_output(a: &PendantApp, n: u16) -> Option<bool> {
    a.sim()
        .expect("the built-in simulator")
        .with(|c| c.signals().bit(BitSpace::Output, 0, n))
}

/// The window on the built-in simulator, the controller answering, the Signals tab in
/// front and its outputs read.
fn on_the_simulator<'a>() -> Harness<'a, PendantApp> {
    let mut h = app();
    step_until(&mut h, "the controller to accept commands", |a| {
        a.pendant().controller_ready(Instant::now()).is_ok()
    });
    show_tab(&mut h, "Signals");
    step_until(&mut h, "Output 300 read", |a| {
        value(a, &OUTPUT_300).is_some()
    });
    h
}

/// Clicks a control of the table through its accessible action (a narrow pane may have
/// scrolled it out of sight sideways), then lets the layout settle.
fn press(h: &mut Harness<'_, PendantApp>, label: &str) {
    h.get_by_label(label).click_accesskit();
    h.step();
    h.step();
}

fn send_disabled(h: &Harness<'_, PendantApp>) -> bool {
    h.get_by_role_and_label(Role::Button, "Send")
        .accesskit_node()
        .is_disabled()
}

#[test]
fn the_tab_shows_the_default_rows_filters_renames_and_plots_offline() {
    let mut h = Harness::builder()
        .with_size([1280.0, 900.0])
        .build_eframe(|cc| PendantApp::new(cc, StartOptions::fresh_offline()));
    h.step();
    show_tab(&mut h, "Signals");
    step_until_shown(&mut h, "96 rows");
    step_until_shown(&mut h, "Input 0 value: ?");
    step_until_shown(&mut h, "not read: not connected");
    assert_eq!(h.state().pendant().signals.rows().len(), 96);

    // The filter by number.
    replace_text(&mut h, "Filter", "305");
    step_until_shown(&mut h, "1 of 96 rows");
    step_until_shown(&mut h, "Output 305 value: ?");
    assert!(
        h.query_all_by_label_contains("Input 0 value")
            .next()
            .is_none(),
        "rows the filter leaves out are not drawn"
    );
    replace_text(&mut h, "Filter", "");
    step_until_shown(&mut h, "96 rows");

    // A rename: the name cell clicked, typed over, Enter.
    replace_text(&mut h, "Filter", "output 300");
    step_until_shown(&mut h, "1 of 96 rows");
    h.get_by_label("Output 300 name, empty").click();
    h.step();
    h.step();
    replace_text(&mut h, "Output 300 name", "gripper close");
    h.key_press(Key::Enter);
    h.step();
    step_until(&mut h, "the row renamed", |a| {
        a.pendant()
            .signals
            .rows()
            .iter()
            .any(|r| r.signal == OUTPUT_300 && r.name == "gripper close")
    });
    step_until_shown(&mut h, "Output 300 name: gripper close");

    // Plot ticked: the row plotted and its trace in a free slot of the Plots pane;
    // unticked: both gone.
    // The trace is named by the signal alone: a rename leaves it where it is.
    let trace = TraceChoice::new("Output 300", "state");
    press(&mut h, "Plot: Output 300");
    step_until(&mut h, "the row plotted", |a| {
        a.pendant()
            .signals
            .rows()
            .iter()
            .any(|r| r.signal == OUTPUT_300 && r.plot)
    });
    h.step();
    assert!(
        h.state()
            .plots_panel()
            .traces
            .contains(&Some(trace.clone())),
        "the trace in a slot: {:?}",
        h.state().plots_panel().traces
    );
    press(&mut h, "Plot: Output 300");
    step_until(&mut h, "the row no longer plotted", |a| {
        a.pendant().signals.rows().iter().all(|r| !r.plot)
    });
    h.step();
    assert!(
        !h.state().plots_panel().traces.contains(&Some(trace)),
        "the trace taken out"
    );

    // Out to a CSV file, cleared, and back in from it; Defaults.
    let dir = std::env::temp_dir().join(format!("xsel-pendant-signals-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("watch");
    let _ = std::fs::remove_file(dir.join("watch.csv"));
    replace_text(&mut h, "File", &path.display().to_string());
    click(&mut h, "Export CSV");
    step_until_shown(&mut h, "exported 96 rows");
    let text = std::fs::read_to_string(dir.join("watch.csv")).unwrap();
    assert!(text.contains("output,0,300,gripper close,,"), "{text}");
    click(&mut h, "Clear");
    step_until_shown(&mut h, "Nothing watched");
    replace_text(&mut h, "File", &dir.join("watch.csv").display().to_string());
    click(&mut h, "Import");
    step_until(&mut h, "the list imported", |a| {
        a.pendant().signals.rows().len() == 96
    });
    assert!(
        h.state()
            .pendant()
            .signals
            .rows()
            .iter()
            .any(|r| r.signal == OUTPUT_300 && r.name == "gripper close"),
        "the name came back with the file"
    );
    click(&mut h, "Clear");
    step_until_shown(&mut h, "Nothing watched");
    click(&mut h, "Defaults");
    step_until_shown(&mut h, "96 rows");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Output 300 forced ON through the confirmation, waited for until the pendant reads it
/// back ON with the change ended.
fn force_output_300(h: &mut Harness<'_, PendantApp>) {
    step_until_shown(h, "refreshed");
    replace_text(h, "Filter", "output 300");
    assert_eq!(value(h.state(), &OUTPUT_300), Some(Value::Bit(false)));
    press(h, "Set ON: Output 300");
    step_until_shown(h, "Output 300 OFF -> ON");
    assert!(!send_disabled(h), "no program runs: Send is enabled");
    assert_eq!(sim_output(h.state(), 300), Some(false), "nothing sent yet");
    click(h, "Send");
    step_until(h, "Output 300 read back ON", |a| {
        value(a, &OUTPUT_300) == Some(Value::Bit(true)) && !a.pendant().signals.change_pending()
    });
}

#[test]
fn an_output_forced_through_the_confirmation_is_read_back_on() {
    let mut h = on_the_simulator();
    force_output_300(&mut h);
    assert_eq!(
        sim_output(h.state(), 300),
        Some(true),
        "the simulator's output"
    );
    assert!(h.state().pendant().signals.proposal.is_none());
    step_until_shown(&mut h, "Output 300 value: ON");
    // The toggle now offers the other way.
    step_until_shown(&mut h, "Set OFF: Output 300");
}

/// The read-back's verdict in the view's words.
#[test]
fn the_read_back_of_a_forced_output_is_said_under_the_toolbar() {
    let mut h = on_the_simulator();
    force_output_300(&mut h);
    step_until(&mut h, "the read-back said", |a| {
        said(a, "Output 300 is ON (read back)")
    });
    step_until_shown(&mut h, "Output 300 is ON (read back)");
}

#[test]
fn an_integer_variable_is_edited_and_read_back_and_a_typo_is_refused_at_its_row() {
    let mut h = on_the_simulator();
    // Add global integer 250 from the toolbar.
    h.get_by_role_and_label(Role::ComboBox, "Kind").click();
    h.step();
    h.step();
    h.get_by_label("Integer").click();
    h.step();
    h.step();
    replace_text(&mut h, "Number", "250");
    replace_text(&mut h, "Name", "count");
    click(&mut h, "Add");
    replace_text(&mut h, "Filter", "250");
    step_until(&mut h, "Integer 250 read", |a| {
        value(a, &INTEGER_250) == Some(Value::Int(0))
    });
    step_until_shown(&mut h, "Integer 250 value: 0");

    // A typo: the model's words at the row and under the toolbar; nothing to confirm.
    replace_text(&mut h, "Integer 250 new value", "12x");
    press(&mut h, "Set: Integer 250");
    step_until_shown(
        &mut h,
        "Integer 250 note: Integer 250 'count': `12x` is not an integer",
    );
    assert!(h.state().pendant().signals.proposal.is_none());
    let refused = h.state().pendant().signals.feedback.clone().unwrap().1;
    assert!(refused.contains("`12x` is not an integer"), "{refused}");
    assert!(h.query_all_by_label_contains(&refused).next().is_some());

    // The value, confirmed, sent and read back.
    replace_text(&mut h, "Integer 250 new value", "1234");
    press(&mut h, "Set: Integer 250");
    step_until_shown(&mut h, "Integer 250 'count' 0 -> 1234");
    click(&mut h, "Send");
    step_until(&mut h, "Integer 250 read back", |a| {
        value(a, &INTEGER_250) == Some(Value::Int(1234)) && !a.pendant().signals.change_pending()
    });
    let held = h
        .state()
        .sim()
        .unwrap()
        .with(|c| c.signals().int(250, 0))
        .unwrap();
    assert_eq!(held, 1234, "the simulator's variable");
    step_until_shown(&mut h, "Integer 250 value: 1234");
    step_until(&mut h, "the read-back said", |a| {
        said(a, "Integer 250 'count' is 1234 (read back)")
    });
}

#[test]
fn with_a_program_running_send_waits_for_the_risk_checkbox() {
    let mut h = on_the_simulator();
    // The simulator runs no program: the proposal the model makes when 215H says one
    // runs is put in place as the model would have made it.
    h.state_mut().pendant_mut().signals.proposal = Some(Proposal {
        signal: OUTPUT_301,
        label: "Output 301".into(),
        from: Some(Value::Bit(false)),
        to: Value::Bit(true),
        program_running: true,
    });
    replace_text(&mut h, "Filter", "301");
    step_until_shown(&mut h, "Output 301 OFF -> ON");
    step_until_shown(&mut h, "215H reports a program running");
    assert!(send_disabled(&h), "Send waits for the risk to be taken");
    h.get_by_label("A program is running: I accept the risk")
        .click();
    h.step();
    h.step();
    assert!(!send_disabled(&h), "Send with the risk taken");
    click(&mut h, "Send");
    step_until(&mut h, "Output 301 read back ON", |a| {
        value(a, &OUTPUT_301) == Some(Value::Bit(true)) && !a.pendant().signals.change_pending()
    });
    assert_eq!(sim_output(h.state(), 301), Some(true));

    // Esc closes a confirmation unsent.
    h.state_mut().pendant_mut().signals.proposal = Some(Proposal {
        signal: OUTPUT_301,
        label: "Output 301".into(),
        from: Some(Value::Bit(true)),
        to: Value::Bit(false),
        program_running: false,
    });
    step_until_shown(&mut h, "Output 301 ON -> OFF");
    h.key_press(Key::Escape);
    step_until(&mut h, "the confirmation closed", |a| {
        a.pendant().signals.proposal.is_none()
    });
    assert_eq!(sim_output(h.state(), 301), Some(true), "nothing sent");
}
