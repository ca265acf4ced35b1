//! The SEL interpreter: steps run in simulated time inside the controller's advance;
//! program start, end, pause and one step as the 253H-257H handlers ask.

use std::time::Duration;

use super::{MAX_STEPS_PER_ADVANCE, STEP_TIME, TaskState, Wait, number, slot};
use crate::protocol::messages::signals::{GLOBAL_FLAGS, INPUTS, OUTPUTS};
use crate::protocol::{AxisPattern, BitSpace, CentiG, MmPerSec, PositionMove, VarKind};
use crate::sel::{Command, Join, Row, Value};
use crate::sim::controller::Controller;
use crate::sim::errors::SimError;

/// The SCARA's axes, which a program with moves holds while started.
const ARM: u8 = 0x0F;

/// What one step did.
enum Outcome {
    Next,
    Jump(usize),
    End,
}

impl Controller {
    /// Runs every running program up to `now` (called by `advance`, after the motions).
    pub(crate) fn run_programs(&mut self, now: Duration) {
        if !self.programs.any_running() {
            return;
        }
        for i in 0..self.programs.tasks.len() {
            if self.programs.tasks[i].state == TaskState::Running {
                self.acting = Some(i);
                self.run_task(i, now);
                self.acting = None;
            }
        }
    }

    fn run_task(&mut self, i: usize, now: Duration) {
        let mut budget = MAX_STEPS_PER_ADVANCE;
        loop {
            if self.programs.tasks[i].state != TaskState::Running || !self.wait_over(i, now) {
                return;
            }
            let t = &mut self.programs.tasks[i];
            // A step boundary: where a pause or the end of a one step takes hold.
            if t.pause_asked || t.steps_left == Some(0) {
                t.state = TaskState::Paused;
                t.pause_asked = false;
                t.steps_left = None;
                return;
            }
            if t.clock > now {
                return;
            }
            if budget == 0 {
                t.clock = now;
                return;
            }
            budget -= 1;
            if let Some(k) = t.steps_left.as_mut() {
                *k -= 1;
            }
            let pc = t.pc;
            t.current = pc;
            t.clock += STEP_TIME;
            let step = u16::try_from(pc + 1).unwrap_or(u16::MAX);
            let outcome = match self.programs.row(i, pc) {
                None => Ok(Outcome::End),
                // A line with an error never loads; kept here as a refusal all the same.
                Some(None) => Err(SimError::BadValue),
                Some(Some(row)) => self.step(i, &row),
            };
            match outcome {
                Ok(Outcome::Next) => self.programs.tasks[i].pc = pc + 1,
                Ok(Outcome::Jump(to)) => self.programs.tasks[i].pc = to,
                Ok(Outcome::End) => {
                    self.end_program(i, (0, 0));
                    return;
                }
                Err(e) => {
                    self.program_error(i, e, step);
                    return;
                }
            }
        }
    }

    /// Whether task `i` waits for nothing any more (its wait is cleared then).
    fn wait_over(&mut self, i: usize, now: Duration) -> bool {
        let program = number(i);
        let t = &self.programs.tasks[i];
        let (over, output, clock) = match t.wait {
            Wait::Nothing => return true,
            Wait::Motion { axes, output } => {
                let moving = self.motions.iter().any(|m| m.axes & axes != 0);
                // A move stopped short (238H) does not turn its output on; the program
                // goes on with the next step `[inferred: the simulator's choice]`.
                let completed = (0..8)
                    .filter(|k| axes & (1 << k) != 0)
                    .all(|k| self.axes[k].completed);
                (!moving, output.filter(|_| completed), now)
            }
            Wait::Until { at, output } => (now >= at, output, at),
            Wait::Signal {
                number,
                on,
                deadline,
                output,
            } => {
                if self.signal(number, program) == on {
                    (true, None, now)
                } else if deadline.is_some_and(|d| now >= d) {
                    (true, output, deadline.unwrap_or(now))
                } else {
                    (false, None, now)
                }
            }
        };
        if over {
            if let Some(n) = output {
                // Outputs and flags were checked when the file was read.
                let _ = self.signals.set_by_program(n, program, true);
            }
            let t = &mut self.programs.tasks[i];
            t.wait = Wait::Nothing;
            t.clock = t.clock.max(clock);
        }
        over
    }

    /// Input, output or flag `n` as program `program` sees it (900-999: its own flags).
    fn signal(&self, n: u16, program: u8) -> bool {
        let (space, owner) = if INPUTS.holds(n) {
            (BitSpace::Input, 0)
        } else if OUTPUTS.holds(n) {
            (BitSpace::Output, 0)
        } else if GLOBAL_FLAGS.holds(n) {
            (BitSpace::Flag, 0)
        } else {
            (BitSpace::Flag, program)
        };
        self.signals.bit(space, owner, n).unwrap_or(false)
    }

    /// An operand's value: a literal, or `*n`, integer variable n.
    fn value(&self, v: Value, program: u8) -> Result<f64, SimError> {
        match v {
            Value::Literal(x) => Ok(x),
            Value::Variable(n) => Ok(f64::from(self.int(n, program)?)),
        }
    }

    /// Integer variable `n` (1-99 the program's own, 200-299 global).
    fn int(&self, n: u16, program: u8) -> Result<i32, SimError> {
        self.signals
            .int(n, var_owner(n, program))
            .map_err(|_| SimError::BadValue)
    }

    fn set_int(&mut self, n: u16, program: u8, v: i64) -> Result<(), SimError> {
        let v = i32::try_from(v).map_err(|_| SimError::BadValue)?;
        self.signals
            .set_int(n, var_owner(n, program), v)
            .map_err(|_| SimError::BadValue)
    }

    /// Runs one row of program slot `i`.
    fn step(&mut self, i: usize, row: &Row) -> Result<Outcome, SimError> {
        let program = number(i);
        if let Some(c) = row.condition {
            let v = self.signal(c.number, program) != c.negated;
            let t = &mut self.programs.tasks[i];
            t.condition = Some(match (c.join, t.condition) {
                (Join::And, Some(before)) => before && v,
                (Join::Or, Some(before)) => before || v,
                _ => v,
            });
        }
        let Some(command) = &row.command else {
            return Ok(Outcome::Next);
        };
        // "If the input condition is not satisfied, the program proceeds to the next step"
        // (IAI's SEL manual, "SEL language structure").
        if !self.programs.tasks[i].condition.take().unwrap_or(true) {
            return Ok(Outcome::Next);
        }
        let output = row.output;
        let set_output = |c: &mut Controller, on: bool| -> Result<(), SimError> {
            match output {
                Some(n) => c.signals.set_by_program(n, program, on),
                None => Ok(()),
            }
        };
        let clock = self.programs.tasks[i].clock;
        match *command {
            Command::MoveP(v) | Command::MoveL(v) => {
                let position = self.value(v, program)?;
                let position = u16::try_from(position as i64).map_err(|_| SimError::BadValue)?;
                let linear = matches!(command, Command::MoveL(_));
                self.program_move(i, position, linear)?;
                // The output turns off as an actuator command starts and on as it ends.
                set_output(self, false)?;
                let axes = self.motions.last().map_or(0, |m| m.axes);
                self.programs.tasks[i].wait = Wait::Motion { axes, output };
            }
            Command::Vel(v) | Command::Acc(v) | Command::Dcl(v) => {
                let x = self.value(v, program)?;
                if !(x > 0.0 && x.is_finite()) {
                    return Err(SimError::BadValue);
                }
                let r = &mut self.programs.tasks[i].rates;
                match command {
                    Command::Vel(_) => r.vel_mm_s = x,
                    Command::Acc(_) => r.acc_g = x,
                    _ => r.dcl_g = x,
                }
            }
            Command::Bits { on, from, to } => {
                for n in from..=to {
                    self.signals.set_by_program(n, program, on)?;
                }
            }
            Command::WaitBit {
                on,
                number,
                timeout,
            } => {
                let deadline = match timeout {
                    Some(v) => Some(clock + seconds(self.value(v, program)?)?),
                    None => None,
                };
                set_output(self, false)?;
                self.programs.tasks[i].wait = Wait::Signal {
                    number,
                    on,
                    deadline,
                    output,
                };
            }
            Command::Wait(v) => {
                let at = clock + seconds(self.value(v, program)?)?;
                set_output(self, false)?;
                self.programs.tasks[i].wait = Wait::Until { at, output };
            }
            Command::Tag(_) => {}
            Command::Goto(tag) => {
                let to = self.programs.tag(i, tag).ok_or(SimError::BadValue)?;
                return Ok(Outcome::Jump(to));
            }
            Command::Let { var, value }
            | Command::Add { var, value }
            | Command::Sub { var, value } => {
                let x = self.value(value, program)? as i64;
                let before = i64::from(self.int(var, program)?);
                let result = match command {
                    Command::Let { .. } => x,
                    Command::Add { .. } => before + x,
                    _ => before - x,
                };
                self.set_int(var, program, result)?;
                // Arithmetic turns its output on when the result is zero `[inferred]`.
                set_output(self, result == 0)?;
            }
            Command::Compare { op, var, value } => {
                let a = i64::from(self.int(var, program)?);
                let b = self.value(value, program)? as i64;
                set_output(self, op.holds(a, b))?;
            }
            Command::Exit => return Ok(Outcome::End),
        }
        Ok(Outcome::Next)
    }

    /// MOVP (PTP, the record's arm system, as 26BH) or MOVL (a CP line) to a position, at
    /// the program's VEL, ACC and DCL.
    fn program_move(&mut self, i: usize, position: u16, linear: bool) -> Result<(), SimError> {
        let r = self.programs.tasks[i].rates;
        let centi_g = |g: f64| (g * 100.0).round().clamp(0.0, f64::from(u16::MAX)) as u16;
        let speed = r.vel_mm_s.round().clamp(0.0, f64::from(u16::MAX)) as u16;
        let (accel, decel) = (centi_g(r.acc_g), centi_g(r.dcl_g));
        if !linear {
            return self.msg_position_move(&PositionMove {
                axes: AxisPattern(self.present()),
                accel: CentiG(accel),
                decel: CentiG(decel),
                speed: MmPerSec(speed),
                position,
            });
        }
        self.check_position_number(position)?;
        let (pattern, values, record) = self.position_target(self.present(), position)?;
        let pick = |mine: u16, rec: u16| if mine != 0 { mine } else { rec };
        let rates = [
            pick(speed, record.speed.0),
            pick(accel, record.accel.0),
            pick(decel, record.decel.0),
        ];
        self.scara_or_linear_move(pattern, &values, false, None, rates)
    }

    /// Starts program `n` (253H, or 256H on a program not started): refused while the
    /// controller cannot act, for a program not loaded or already started, and when it
    /// moves the arm while the arm is taken (another program, or a move in progress).
    pub(crate) fn start_program(&mut self, n: u8, one_step: bool) -> Result<(), SimError> {
        let i = slot(n).ok_or(SimError::BadValue)?;
        self.check_can_act()?;
        let program = self.programs.program(n).ok_or(SimError::NoProgram)?;
        let holds = if program.moves() { ARM } else { 0 };
        if self.programs.tasks[i].started() {
            return Err(SimError::ProgramState);
        }
        if holds & (self.programs.held_by_others(Some(i)) | self.busy_axes()) != 0 {
            return Err(SimError::AxisBusy);
        }
        let t = &mut self.programs.tasks[i];
        *t = super::Task {
            state: TaskState::Running,
            holds,
            clock: self.now,
            steps_left: one_step.then_some(1),
            ..super::Task::default()
        };
        Ok(())
    }

    /// Ends program slot `i` with `error` (code, step; 0 = none): its move stops.
    pub(crate) fn end_program(&mut self, i: usize, error: (u16, u16)) {
        let t = &mut self.programs.tasks[i];
        if !t.started() {
            return;
        }
        let moving = match t.wait {
            Wait::Motion { axes, .. } => axes,
            _ => 0,
        };
        *t = super::Task {
            error,
            ..super::Task::default()
        };
        let now = self.now;
        for m in self.motions.iter_mut() {
            if m.axes & moving != 0 && !m.cancelled() {
                m.stop(now);
            }
        }
    }

    /// Ends every started program (an alarm, E-stop, cut-off or reset): each records
    /// `code` at its own step (0: ended without an error).
    pub(crate) fn end_all_programs(&mut self, code: u16) {
        for i in 0..self.programs.tasks.len() {
            let step = self.programs.tasks[i].step();
            let error = if code == 0 { (0, 0) } else { (code, step) };
            self.end_program(i, error);
        }
    }

    /// A step failed: the program ends with the code and step, and the controller raises
    /// the alarm (every program ends, moves stop, acting commands are refused until 252H;
    /// servos stay on `[inferred: an operation-cancellation level error]`).
    fn program_error(&mut self, i: usize, e: SimError, step: u16) {
        let n = number(i);
        self.end_program(i, (e.code(), step));
        self.raise_program_alarm(
            e.code(),
            n,
            step,
            &format!("program {n} step {step}: {}", e.text()),
        );
    }

    /// 255H: pause program `n` at its next step boundary (started programs only).
    pub(crate) fn pause_program(&mut self, n: u8) -> Result<(), SimError> {
        let t = self.task_mut(n)?;
        match t.state {
            TaskState::NotStarted => Err(SimError::ProgramState),
            TaskState::Paused => Ok(()),
            TaskState::Running => {
                t.pause_asked = true;
                Ok(())
            }
        }
    }

    /// 257H: a paused program runs on (a running one is left as it is).
    pub(crate) fn resume_program(&mut self, n: u8) -> Result<(), SimError> {
        self.check_can_act()?;
        let now = self.now;
        let t = self.task_mut(n)?;
        match t.state {
            TaskState::NotStarted => Err(SimError::ProgramState),
            TaskState::Running => {
                t.pause_asked = false;
                t.steps_left = None;
                Ok(())
            }
            TaskState::Paused => {
                t.state = TaskState::Running;
                t.steps_left = None;
                t.clock = t.clock.max(now);
                Ok(())
            }
        }
    }

    /// 256H: one step of a paused program, or the first step of one not started; refused
    /// for a program running freely.
    pub(crate) fn one_step_program(&mut self, n: u8) -> Result<(), SimError> {
        self.check_can_act()?;
        let now = self.now;
        let t = self.task_mut(n)?;
        match t.state {
            TaskState::NotStarted => self.start_program(n, true),
            TaskState::Running => Err(SimError::ProgramState),
            TaskState::Paused => {
                t.state = TaskState::Running;
                t.steps_left = Some(1);
                t.clock = t.clock.max(now);
                Ok(())
            }
        }
    }

    fn task_mut(&mut self, n: u8) -> Result<&mut super::Task, SimError> {
        let i = slot(n).ok_or(SimError::BadValue)?;
        if self.programs.program(n).is_none() {
            return Err(SimError::NoProgram);
        }
        Ok(&mut self.programs.tasks[i])
    }
}

/// Whose integer variable `n` is: global (0) or the program's own.
fn var_owner(n: u16, program: u8) -> u8 {
    if VarKind::Integer.numbers(true).contains(&n) {
        0
    } else {
        program
    }
}

/// A time operand in seconds, as a duration (0.001 s resolution).
fn seconds(s: f64) -> Result<Duration, SimError> {
    if !(0.0..=9_999.0).contains(&s) {
        return Err(SimError::BadValue);
    }
    Ok(Duration::from_millis((s * 1000.0).round() as u64))
}
