//! The simulator's programs: the SEL programs loaded and each one's task (not started,
//! running or paused, its step pointer, waits, rates and error), as 213H reports them.
//!
//! The interpreter itself (`run.rs`) runs inside [`Controller::advance`]: each step
//! takes [`STEP_TIME`] of simulated time, waits (moves, timers, signals) end with the
//! world they wait on, and one advance runs at most [`MAX_STEPS_PER_ADVANCE`] steps of a
//! program, so a program that never ends costs bounded work and time.
//!
//! [`Controller::advance`]: super::Controller::advance

mod run;
#[cfg(test)]
mod tests;

use std::time::Duration;

use crate::protocol::messages::signals::PROGRAMS;
use crate::sel::{Program, Row};

/// Simulated time one step takes. Not on any page read: X-SEL executes a step in well
/// under a millisecond `[inferred]`; 1 ms keeps a loop without waits at 1000 steps a
/// second of simulated time.
pub const STEP_TIME: Duration = Duration::from_millis(1);

/// The most steps one program runs in one advance of the world; beyond it, the program's
/// clock jumps to the present (a program that never waits cannot hold the simulator).
pub const MAX_STEPS_PER_ADVANCE: u32 = 2000;

/// Slots: programs 1-64.
const SLOTS: usize = (PROGRAMS.end - PROGRAMS.start) as usize;

/// Where a program is.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum TaskState {
    #[default]
    NotStarted,
    Running,
    /// Started and held between steps (255H, or after a one step).
    Paused,
}

/// What a step waits for before the next one.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) enum Wait {
    #[default]
    Nothing,
    /// The move on `axes` to end; `output` turns on when it completes normally.
    Motion { axes: u8, output: Option<u16> },
    /// The time `at`; `output` on then.
    Until { at: Duration, output: Option<u16> },
    /// Signal `number` to be `on`, or the `deadline`; `output` on at the deadline.
    Signal {
        number: u16,
        on: bool,
        deadline: Option<Duration>,
        output: Option<u16>,
    },
}

/// The rates VEL, ACC and DCL set for the moves that follow (0: the position record's,
/// else the model's default).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct Rates {
    pub vel_mm_s: f64,
    pub acc_g: f64,
    pub dcl_g: f64,
}

/// One program's run.
#[derive(Clone, Debug, Default)]
pub(crate) struct Task {
    pub state: TaskState,
    /// Index of the next step to run.
    pub pc: usize,
    /// Index of the step being run (while it waits).
    pub current: usize,
    pub wait: Wait,
    /// Steps left before pausing (256H one step), `None` running freely.
    pub steps_left: Option<u32>,
    /// 255H: pause at the next step boundary.
    pub pause_asked: bool,
    pub rates: Rates,
    /// The conditions of the rows so far that had a condition and no command.
    pub condition: Option<bool>,
    /// Axes the program holds while started (the arm, when it has moves).
    pub holds: u8,
    /// When the next step may run.
    pub clock: Duration,
    /// The last error: code and 1-based step (000 = none).
    pub error: (u16, u16),
}

impl Task {
    pub fn started(&self) -> bool {
        self.state != TaskState::NotStarted
    }

    /// 213H's executing step (1-based): the step waiting, else the next one; 0 when not
    /// started `[inferred: the page says only "executing step"]`.
    pub fn step(&self) -> u16 {
        if !self.started() {
            return 0;
        }
        let index = if self.wait == Wait::Nothing {
            self.pc
        } else {
            self.current
        };
        u16::try_from(index + 1).unwrap_or(u16::MAX)
    }
}

/// The loaded programs and their tasks.
#[derive(Clone, Debug)]
pub struct Programs {
    loaded: Vec<Option<Program>>,
    pub(crate) tasks: Vec<Task>,
}

impl Default for Programs {
    fn default() -> Self {
        Programs {
            loaded: vec![None; SLOTS],
            tasks: vec![Task::default(); SLOTS],
        }
    }
}

/// Slot of program `n` (1-64).
pub(crate) fn slot(n: u8) -> Option<usize> {
    PROGRAMS
        .contains(&n)
        .then(|| usize::from(n - PROGRAMS.start))
}

/// Program number of slot `i`.
pub(crate) fn number(i: usize) -> u8 {
    PROGRAMS.start + i as u8
}

impl Programs {
    /// Programs to load; a number outside 1-64 or seen twice keeps the first.
    pub fn new(programs: impl IntoIterator<Item = Program>) -> Self {
        let mut p = Programs::default();
        for program in programs {
            if let Some(i) = slot(program.number)
                && p.loaded[i].is_none()
            {
                p.loaded[i] = Some(program);
            }
        }
        p
    }

    /// Program `n`, if loaded.
    pub fn program(&self, n: u8) -> Option<&Program> {
        self.loaded.get(slot(n)?)?.as_ref()
    }

    /// The numbers of the loaded programs.
    pub fn numbers(&self) -> impl Iterator<Item = u8> + '_ {
        (0..SLOTS).filter(|&i| self.loaded[i].is_some()).map(number)
    }

    /// Program `n`'s state, step (213H's) and error (code, step).
    pub fn state(&self, n: u8) -> Option<(TaskState, u16, (u16, u16))> {
        let t = self.tasks.get(slot(n)?)?;
        Some((t.state, t.step(), t.error))
    }

    /// Program `n` in words: "program 1 (pick and place): running at step 6".
    pub fn describe(&self, n: u8) -> Option<String> {
        let p = self.program(n)?;
        let (state, step, (code, at)) = self.state(n)?;
        let name = if p.name.is_empty() {
            format!("program {n}")
        } else {
            format!("program {n} ({})", p.name)
        };
        let state = match state {
            TaskState::Running => format!("running at step {step}"),
            TaskState::Paused => format!("paused before step {step}"),
            TaskState::NotStarted if code != 0 => format!("ended by error {code:03X} at step {at}"),
            TaskState::NotStarted => "not started".to_owned(),
        };
        Some(format!("{name}: {state}"))
    }

    /// The row at step index `pc` of program slot `i`, if there is one.
    pub(crate) fn row(&self, i: usize, pc: usize) -> Option<Option<Row>> {
        let steps = &self.loaded.get(i)?.as_ref()?.steps;
        steps.get(pc).map(|s| s.row.clone())
    }

    pub(crate) fn tag(&self, i: usize, tag: u16) -> Option<usize> {
        self.loaded.get(i)?.as_ref()?.tag(tag)
    }

    /// Whether any program is started (215H status byte 2 bit 5, "program running").
    pub fn any_started(&self) -> bool {
        self.tasks.iter().any(Task::started)
    }

    /// Whether the world changes with time because of a program.
    pub fn any_running(&self) -> bool {
        self.tasks.iter().any(|t| t.state == TaskState::Running)
    }

    /// Axes held by started programs other than `except`.
    pub(crate) fn held_by_others(&self, except: Option<usize>) -> u8 {
        self.tasks
            .iter()
            .enumerate()
            .filter(|&(i, t)| Some(i) != except && t.started())
            .fold(0, |held, (_, t)| held | t.holds)
    }
}
