//! The Programs view in the real window on the embedded simulator, driven headlessly with
//! egui_kittest, as the commissioning round asks: the demo's listing shown, the
//! demo run through the confirmation, paused, stepped three steps (the step number and
//! the arm followed), resumed and ended; then run again and stopped mid-move with Esc,
//! which ends the program (254H 00 on the line) and brakes the arm. Waits are bounded by
//! a deadline; nothing sleeps.

use egui::accesskit::Role;
use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use xsel_pendant::pendant::programs::ProgramState;
use xsel_pendant::sim::programs::TaskState;
use xsel_pendant::ui::PendantApp;

use crate::kittest_common::{click_button, show_tab, step_until, step_until_shown};
use crate::main_window::{app, ready, sim_in_frames};

/// The simulator's program 1: state and 213H's step.
fn sim_program(a: &PendantApp) -> (TaskState, u16) {
    a.sim()
        .expect("the built-in simulator")
        .with(|c| c.programs().state(1).map(|(s, step, _)| (s, step)))
        .unwrap_or_default()
}

fn arm_moving(a: &PendantApp) -> bool {
    a.sim().is_some_and(|s| s.with(|c| c.in_use() != 0))
}

/// The pendant's row of program 1: its state and step as last read.
fn shown(a: &PendantApp) -> (ProgramState, Option<u16>) {
    let r = a.pendant().programs.row(1);
    (r.state(), r.step())
}

/// Clicks `verb` in the confirmation window (the view's own button of the same name
/// comes first in the tree).
fn confirm(h: &mut Harness<'_, PendantApp>, verb: &str) {
    step_until_shown(h, "Automatic operation");
    h.get_all_by_role_and_label(Role::Button, verb)
        .last()
        .expect("the confirmation's button")
        .click_accesskit();
    h.step();
    h.step();
}

/// Clicks `label`; if the model asks first, confirms with the same word.
fn press(h: &mut Harness<'_, PendantApp>, label: &str) {
    click_button(h, label);
    if h.state().pendant().programs.proposal.is_some() {
        confirm(h, label);
    }
}

#[test]
fn run_pause_three_single_steps_resume_end_and_stop_mid_program() {
    let mut h = app();
    ready(&mut h);
    show_tab(&mut h, "Programs");
    click_button(&mut h, "Demo listing");
    step_until_shown(&mut h, "Program 1 pick and place");
    step_until_shown(&mut h, "MOVP  1");

    // The view reads program 1 first (Run is refused until its state is known).
    step_until(&mut h, "program 1's state read", |a| {
        a.pendant().programs.row(1).status.is_some()
    });
    // Run asks first, naming the program and that the jog speed cap does not apply.
    click_button(&mut h, "Run");
    step_until_shown(&mut h, "Automatic operation");
    let asked = h
        .state()
        .pendant()
        .programs
        .proposal
        .clone()
        .expect("asked");
    assert!(asked.text.contains("program 1"), "{}", asked.text);
    assert!(
        sim_program(h.state()).0 == TaskState::NotStarted,
        "nothing before Run"
    );
    confirm(&mut h, "Run");
    step_until(&mut h, "the demo running on the simulator", |a| {
        sim_program(a).0 == TaskState::Running
    });
    step_until(&mut h, "the view saying it runs", |a| {
        shown(a).0 == ProgramState::Running
    });
    assert_eq!(sim_in_frames(h.state(), "253").len(), 1, "sent once");

    // Pause: it holds between steps.
    press(&mut h, "Pause");
    step_until(&mut h, "the demo paused", |a| {
        sim_program(a).0 == TaskState::Paused
    });
    step_until(&mut h, "the view showing the paused step", |a| {
        shown(a) == (ProgramState::Paused, Some(sim_program(a).1))
    });

    // Single steps, at least three and on to a MOVP (steps 6 and 9 of the demo): each
    // runs the step the pointer shows and pauses on the next; a MOVP moves the arm.
    let (mut steps, mut moved) = (0, false);
    while steps < 3 || !moved {
        assert!(steps < 12, "no MOVP within 12 single steps");
        let before = sim_program(h.state()).1;
        let from = h.state().sim().unwrap().with(|c| c.joints());
        press(&mut h, "One step");
        step_until(&mut h, "the step to run and pause again", |a| {
            let (state, step) = sim_program(a);
            state == TaskState::Paused && step != before && !arm_moving(a)
        });
        let (_, after) = sim_program(h.state());
        let jumped = before == 14 && after == 5;
        assert!(after == before + 1 || jumped, "{before} -> {after}");
        step_until(&mut h, "the view following the step", |a| {
            shown(a) == (ProgramState::Paused, Some(after))
        });
        step_until_shown(&mut h, &format!("step {after}"));
        if before == 6 || before == 9 {
            let to = h.state().sim().unwrap().with(|c| c.joints());
            assert_ne!(from, to, "step {before} (MOVP) moved the arm");
            moved = true;
        }
        steps += 1;
    }
    assert_eq!(sim_in_frames(h.state(), "256").len(), steps);

    // Resume, then End.
    press(&mut h, "Resume");
    step_until(&mut h, "the demo running again", |a| {
        sim_program(a).0 == TaskState::Running
    });
    press(&mut h, "End");
    step_until(&mut h, "the demo ended", |a| {
        sim_program(a).0 == TaskState::NotStarted
    });
    step_until(&mut h, "the view saying it ended", |a| {
        shown(a).0 == ProgramState::NotStarted
    });
    step_until(&mut h, "the arm at rest", |a| !arm_moving(a));

    // Run again; STOP (Esc) while the arm moves: the arm brakes and the program ends.
    click_button(&mut h, "Run");
    confirm(&mut h, "Run");
    step_until(&mut h, "the arm moving under the program", arm_moving);
    h.key_press(egui::Key::Escape);
    h.step();
    step_until(&mut h, "the program ended and the arm at rest", |a| {
        sim_program(a).0 == TaskState::NotStarted && !arm_moving(a)
    });
    let ends = sim_in_frames(h.state(), "254");
    assert!(
        ends.iter().any(|f| f.starts_with("!9925400")),
        "254H 00 on the line: {ends:?}"
    );
}
