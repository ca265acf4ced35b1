//! The programs' model on a virtual clock, the link's events made by hand: what each
//! operation is refused for, what asks first, what the rows remember, what is said.

use std::time::{Duration, Instant};

use super::*;
use crate::link::{Origin, RequestId};

fn ready() -> ProgramsCx {
    ProgramsCx {
        ready: Ok(()),
        motion: Ok(()),
        jogging: None,
    }
}

fn status(program: u8, started: bool, step: u16, error: u16, error_step: u16) -> ProgramStatus {
    ProgramStatus {
        program,
        flags: crate::protocol::ProgramFlags::default().with_started(started),
        step,
        error: ErrorCode(error),
        error_step,
    }
}

fn answer(p: &mut Programs, s: ProgramStatus, now: Instant) -> Vec<(Level, String)> {
    p.handle_event(
        &LinkEvent::Reply {
            id: RequestId(1),
            origin: Origin::User,
            command: Command::ProgramStatus(ProgramStatusQuery { program: s.program }),
            reply: Reply::ProgramStatus(s),
            round_trip: Duration::from_millis(3),
        },
        now,
    )
}

fn sent(p: &mut Programs) -> Vec<Command> {
    p.take_commands()
        .into_iter()
        .filter(|(_, user)| *user)
        .map(|(c, _)| c)
        .collect()
}

fn call(action: ProgramAction, program: u8) -> Command {
    Command::Program(ProgramCall { action, program })
}

#[test]
fn run_asks_first_naming_the_program_and_the_speed_then_sends_once() {
    let t0 = Instant::now();
    let mut p = Programs::default();
    answer(&mut p, status(1, false, 0, 0, 0), t0);
    assert_eq!(
        p.apply(ProgramsIntent::Ask(ProgramAction::Run, 1), &ready(), t0),
        None
    );
    let q = p.proposal.clone().expect("a question");
    assert!(q.text.contains("program 1"), "{}", q.text);
    assert!(
        q.text.contains("reduced jog speed does not apply"),
        "{}",
        q.text
    );
    assert!(sent(&mut p).is_empty(), "nothing before the confirmation");
    let said = p.apply(ProgramsIntent::Confirm, &ready(), t0).unwrap();
    assert_eq!(said.1, "program 1: run sent");
    assert_eq!(sent(&mut p), [call(ProgramAction::Run, 1)]);
    assert_eq!(
        p.apply(ProgramsIntent::Confirm, &ready(), t0),
        None,
        "sent once"
    );
    assert!(sent(&mut p).is_empty());
}

#[test]
fn each_operation_is_refused_with_its_reason() {
    let t0 = Instant::now();
    let mut p = Programs::default();
    let refused = |p: &mut Programs, a, n, cx: &ProgramsCx| {
        let (level, text) = p.apply(ProgramsIntent::Ask(a, n), cx, t0).expect("said");
        assert_eq!(level, Level::Warning, "{text}");
        assert!(p.proposal.is_none());
        assert!(sent(p).is_empty(), "{text}");
        text
    };
    assert!(refused(&mut p, ProgramAction::Run, 65, &ready()).contains("does not exist"));
    assert!(refused(&mut p, ProgramAction::Run, 0, &ready()).contains("numbered 1-64"));
    assert!(refused(&mut p, ProgramAction::Run, 1, &ready()).contains("not read yet"));
    answer(&mut p, status(1, false, 0, 0, 0), t0);
    let down = ProgramsCx {
        ready: Err("the line is down".into()),
        ..ready()
    };
    assert!(refused(&mut p, ProgramAction::Run, 1, &down).contains("the line is down"));
    let servo = ProgramsCx {
        motion: Err("servo is off: switch it on first".into()),
        ..ready()
    };
    assert!(refused(&mut p, ProgramAction::Run, 1, &servo).contains("servo is off"));
    let jog = ProgramsCx {
        jogging: Some("a jog or move of this window runs".into()),
        ..ready()
    };
    assert!(refused(&mut p, ProgramAction::Run, 1, &jog).contains("jog"));
    assert!(refused(&mut p, ProgramAction::Pause, 1, &ready()).contains("not started"));
    assert!(refused(&mut p, ProgramAction::Resume, 1, &ready()).contains("not paused"));
    answer(&mut p, status(1, true, 3, 0, 0), t0);
    assert!(refused(&mut p, ProgramAction::Run, 1, &ready()).contains("running already"));
    assert!(refused(&mut p, ProgramAction::Step, 1, &ready()).contains("pause it first"));
    // Pausing and ending need only the line: servo off does not hold them back.
    p.apply(ProgramsIntent::Ask(ProgramAction::Pause, 1), &servo, t0);
    assert_eq!(sent(&mut p), [call(ProgramAction::Pause, 1)]);
    p.apply(ProgramsIntent::Ask(ProgramAction::End, 1), &servo, t0);
    assert_eq!(sent(&mut p), [call(ProgramAction::End, 1)]);
}

#[test]
fn a_confirmation_checked_again_when_given_and_taken_back_by_stop() {
    let t0 = Instant::now();
    let mut p = Programs::default();
    answer(&mut p, status(2, false, 0, 0, 0), t0);
    p.apply(ProgramsIntent::Ask(ProgramAction::Run, 2), &ready(), t0);
    let estop = ProgramsCx {
        motion: Err("emergency stop is active".into()),
        ..ready()
    };
    let (_, text) = p.apply(ProgramsIntent::Confirm, &estop, t0).unwrap();
    assert!(text.contains("emergency stop"), "{text}");
    assert!(sent(&mut p).is_empty());
    p.apply(ProgramsIntent::Ask(ProgramAction::Run, 2), &ready(), t0);
    p.stopped();
    assert!(p.proposal.is_none(), "STOP forgets the question");
    assert_eq!(p.apply(ProgramsIntent::Confirm, &ready(), t0), None);
    assert!(sent(&mut p).is_empty());
}

#[test]
fn stepping_asks_once_then_each_step_is_said_with_its_number() {
    let t0 = Instant::now();
    let mut p = Programs::default();
    answer(&mut p, status(1, false, 0, 0, 0), t0);
    p.apply(ProgramsIntent::Ask(ProgramAction::Step, 1), &ready(), t0);
    assert!(
        p.proposal
            .as_ref()
            .unwrap()
            .text
            .contains("one step of program 1")
    );
    p.apply(ProgramsIntent::Confirm, &ready(), t0);
    assert_eq!(sent(&mut p), [call(ProgramAction::Step, 1)]);
    let said = answer(&mut p, status(1, true, 1, 0, 0), t0);
    assert_eq!(p.row(1).state(), ProgramState::Paused);
    assert!(
        said.iter().any(|(_, t)| t == "program 1 started at step 1"),
        "{said:?}"
    );
    // The next steps go without a question.
    for step in 2..=4 {
        let said = p.apply(ProgramsIntent::Ask(ProgramAction::Step, 1), &ready(), t0);
        assert!(p.proposal.is_none());
        assert_eq!(said.unwrap().1, "program 1: one step sent");
        assert_eq!(sent(&mut p), [call(ProgramAction::Step, 1)]);
        let said = answer(&mut p, status(1, true, step, 0, 0), t0);
        assert_eq!(
            said,
            [(Level::Info, format!("program 1 paused at step {step}"))]
        );
        assert_eq!(p.row(1).step(), Some(step));
    }
    p.apply(ProgramsIntent::Ask(ProgramAction::Resume, 1), &ready(), t0);
    assert_eq!(sent(&mut p), [call(ProgramAction::Resume, 1)]);
    assert_eq!(p.row(1).state(), ProgramState::Running);
    // STOP takes the confirmation back: the next step asks again.
    p.stopped();
    p.apply(ProgramsIntent::Ask(ProgramAction::Pause, 1), &ready(), t0);
    sent(&mut p);
    p.apply(ProgramsIntent::Ask(ProgramAction::Step, 1), &ready(), t0);
    assert!(p.proposal.is_some());
}

#[test]
fn an_error_an_end_and_a_refusal_are_said() {
    let t0 = Instant::now();
    let mut p = Programs::default();
    answer(&mut p, status(1, true, 5, 0, 0), t0);
    let said = answer(&mut p, status(1, false, 0, 0xB0A, 7), t0);
    assert_eq!(said.len(), 1, "{said:?}");
    assert_eq!(said[0].0, Level::Error);
    assert!(
        said[0]
            .1
            .contains("program 1 stopped with error B0A at step 7"),
        "{said:?}"
    );
    assert!(
        said[0].1.contains("position number holds no data"),
        "{said:?}"
    );
    assert_eq!(
        p.row(1).state(),
        ProgramState::Error {
            code: ErrorCode(0xB0A),
            step: 7
        }
    );
    answer(&mut p, status(3, true, 2, 0, 0), t0);
    let said = answer(&mut p, status(3, false, 0, 0, 0), t0);
    assert_eq!(said, [(Level::Info, "program 3 ended".to_owned())]);
    let said = p.handle_event(
        &LinkEvent::ErrorReply {
            id: RequestId(2),
            origin: Origin::User,
            command: call(ProgramAction::Run, 3),
            code: ErrorCode(0xB03),
        },
        t0,
    );
    assert_eq!(said[0].0, Level::Error);
    assert!(
        said[0]
            .1
            .starts_with("program 3: run: the controller refused it: error B03")
    );
}

#[test]
fn reads_go_while_watched_or_while_a_program_started_here_runs() {
    let t0 = Instant::now();
    let mut p = Programs::default();
    p.tick(t0, true);
    assert!(p.take_commands().is_empty(), "nothing watched");
    p.apply(ProgramsIntent::Watch(true), &ready(), t0);
    p.apply(ProgramsIntent::Select(9), &ready(), t0);
    p.tick(t0, false);
    assert!(p.take_commands().is_empty(), "the line is down");
    p.tick(t0, true);
    let reads: Vec<u8> = p
        .take_commands()
        .into_iter()
        .map(|(c, user)| {
            assert!(!user, "reads are spare");
            match c {
                Command::ProgramStatus(q) => q.program,
                other => panic!("{other:?}"),
            }
        })
        .collect();
    assert_eq!(
        reads,
        [1, 2, 3, 4, 9],
        "the sweep's first 4 and the selected one"
    );
    p.tick(t0 + MIN_ROUND, true);
    assert!(p.take_commands().is_empty(), "the round is not answered");
    for n in [1, 2, 3, 4, 9] {
        answer(&mut p, status(n, false, 0, 0, 0), t0);
    }
    p.tick(t0 + MIN_ROUND / 2, true);
    assert!(p.take_commands().is_empty(), "not before the status cycle");
    p.tick(t0 + MIN_ROUND, true);
    let next: Vec<_> = p.take_commands();
    assert_eq!(next.len(), 5, "{next:?}");
    // The whole range comes round.
    let mut seen = std::collections::BTreeSet::new();
    let mut now = t0 + MIN_ROUND;
    for _ in 0..20 {
        for n in Programs::numbers() {
            answer(&mut p, status(n, false, 0, 0, 0), now);
        }
        now += MIN_ROUND;
        p.tick(now, true);
        for (c, _) in p.take_commands() {
            if let Command::ProgramStatus(q) = c {
                seen.insert(q.program);
            }
        }
    }
    assert_eq!(seen.len(), 64);
    // The view closed: only a program started here is read on.
    p.apply(ProgramsIntent::Watch(false), &ready(), now);
    answer(&mut p, status(5, false, 0, 0, 0), now);
    p.apply(ProgramsIntent::Ask(ProgramAction::Run, 5), &ready(), now);
    p.apply(ProgramsIntent::Confirm, &ready(), now);
    for n in Programs::numbers() {
        answer(&mut p, status(n, n == 5, 1, 0, 0), now);
    }
    now += MIN_ROUND;
    p.tick(now, true);
    let reads: Vec<Command> = p.take_commands().into_iter().map(|(c, _)| c).collect();
    assert!(reads.contains(&Command::ProgramStatus(ProgramStatusQuery { program: 5 })));
    assert!(!reads.contains(&Command::ProgramStatus(ProgramStatusQuery { program: 1 })));
}

#[test]
fn a_lost_line_says_what_becomes_of_a_program_started_here() {
    let t0 = Instant::now();
    let mut p = Programs::default();
    answer(&mut p, status(1, false, 0, 0, 0), t0);
    p.apply(ProgramsIntent::Ask(ProgramAction::Run, 1), &ready(), t0);
    p.apply(ProgramsIntent::Confirm, &ready(), t0);
    answer(&mut p, status(1, true, 4, 0, 0), t0);
    let text = p.line_gone().expect("said");
    assert!(text.contains("program 1"), "{text}");
    assert!(text.contains("pauses every program"), "{text}");
    assert_eq!(p.row(1).state(), ProgramState::Unknown);
}

#[test]
fn through_the_pendant_a_jog_that_ended_lets_the_demo_run_pause_step_and_end() {
    use crate::pendant::sim_bench::{Bench, Fault};
    use crate::sim::programs::TaskState;
    let mut b = Bench::new(crate::sim::SimSetup::default());
    let sim_state = |b: &Bench| b.sim.programs().state(1).map(|(s, step, _)| (s, step));
    // A jog step runs to its end first: then Run is no longer refused for it.
    let now = b.now();
    b.p.jog_step(
        crate::pendant::JogAxis::X,
        crate::protocol::Direction::Negative,
        now,
    );
    b.pump(|_| Fault::Pass);
    // The view open: program 1's status read.
    b.apply(ProgramsIntent::Watch(true));
    let now = b.now();
    b.p.tick(now);
    b.pump(|_| Fault::Pass);
    assert!(b.p.programs.row(1).status.is_some());
    b.apply(ProgramsIntent::Ask(ProgramAction::Run, 1));
    assert!(
        b.p.programs.proposal.is_none(),
        "refused while the step moves"
    );
    let said = &b.p.programs.feedback.as_ref().unwrap().1;
    assert!(said.contains("a jog or move of this window runs"), "{said}");
    b.settle();
    b.apply(ProgramsIntent::Ask(ProgramAction::Run, 1));
    assert!(
        b.p.programs.proposal.is_some(),
        "{:?}",
        b.p.programs.feedback
    );
    b.apply(ProgramsIntent::Confirm);
    b.pump(|_| Fault::Pass);
    assert_eq!(sim_state(&b).map(|s| s.0), Some(TaskState::Running));
    // A status round: the view reads the program running.
    b.t += MIN_ROUND;
    let now = b.now();
    b.p.tick(now);
    b.pump(|_| Fault::Pass);
    assert_eq!(b.p.programs.row(1).state(), ProgramState::Running);
    b.apply(ProgramsIntent::Ask(ProgramAction::Pause, 1));
    b.pump(|_| Fault::Pass);
    assert!(
        b.sent
            .last()
            .is_some_and(|c| *c == call(ProgramAction::Pause, 1)),
        "{:?}",
        b.p.programs.feedback
    );
    for _ in 0..400 {
        b.t += Duration::from_millis(20);
        b.sim.advance(b.t);
        if sim_state(&b).is_some_and(|s| s.0 == TaskState::Paused) {
            break;
        }
    }
    let (state, at) = sim_state(&b).unwrap();
    assert_eq!(state, TaskState::Paused);
    // One step asks once, then runs exactly one step.
    b.apply(ProgramsIntent::Ask(ProgramAction::Step, 1));
    b.apply(ProgramsIntent::Confirm);
    b.pump(|_| Fault::Pass);
    for _ in 0..400 {
        b.t += Duration::from_millis(20);
        b.sim.advance(b.t);
        if sim_state(&b).is_some_and(|s| s.0 == TaskState::Paused && s.1 != at) {
            break;
        }
    }
    let (state, next) = sim_state(&b).unwrap();
    assert_eq!(state, TaskState::Paused);
    assert!(next == at + 1 || (at == 14 && next == 5), "{at} -> {next}");
    // STOP: the pendant's own STOP request; the program is ended by End all.
    b.apply(ProgramsIntent::EndAll);
    b.pump(|_| Fault::Pass);
    assert_eq!(sim_state(&b).map(|s| s.0), Some(TaskState::NotStarted));
}
