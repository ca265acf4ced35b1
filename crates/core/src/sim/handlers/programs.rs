//! Programs: 213H program status, 253H-257H run, end, pause, one step and resume
//! (PROTOCOL.md 3.44-3.45), on the interpreter in `sim::programs`.

use crate::protocol::{
    ErrorCode, ProgramAction, ProgramCall, ProgramFlags, ProgramStatus, ProgramStatusQuery, Reply,
};
use crate::sim::controller::Controller;
use crate::sim::errors::SimError;
use crate::sim::programs::{TaskState, slot};

impl Controller {
    /// 213H: a program's state. A number 1-64 with no program loaded answers "not
    /// started", as a controller with an empty slot would `[inferred]`; 00 or a number
    /// above 64 is refused (A03).
    pub(crate) fn msg_program_status(&mut self, q: ProgramStatusQuery) -> Result<Reply, SimError> {
        slot(q.program).ok_or(SimError::BadValue)?;
        let (state, step, (code, error_step)) =
            self.programs
                .state(q.program)
                .unwrap_or((TaskState::NotStarted, 0, (0, 0)));
        Ok(Reply::ProgramStatus(ProgramStatus {
            program: q.program,
            flags: ProgramFlags::default().with_started(state != TaskState::NotStarted),
            step,
            error: ErrorCode(code),
            error_step,
        }))
    }

    /// 253H-257H. `00` names every started program for end, pause and resume; run and
    /// one step need a number (A03 for 00).
    pub(crate) fn msg_program(&mut self, c: &ProgramCall) -> Result<(), SimError> {
        if c.is_all() {
            return self.all_programs(c.action);
        }
        match c.action {
            ProgramAction::Run => self.start_program(c.program, false),
            ProgramAction::Step => self.one_step_program(c.program),
            ProgramAction::Pause => self.pause_program(c.program),
            ProgramAction::Resume => self.resume_program(c.program),
            ProgramAction::End => {
                let i = slot(c.program).ok_or(SimError::BadValue)?;
                self.programs
                    .program(c.program)
                    .ok_or(SimError::NoProgram)?;
                // Ending a program not started is no error `[inferred]`.
                self.end_program(i, (0, 0));
                Ok(())
            }
        }
    }

    fn all_programs(&mut self, action: ProgramAction) -> Result<(), SimError> {
        let started: Vec<u8> = self
            .programs
            .numbers()
            .filter(|&n| {
                self.programs
                    .state(n)
                    .is_some_and(|(s, ..)| s != TaskState::NotStarted)
            })
            .collect();
        match action {
            ProgramAction::Run | ProgramAction::Step => Err(SimError::BadValue),
            ProgramAction::End => {
                self.end_all_programs(0);
                Ok(())
            }
            ProgramAction::Pause => {
                for n in started {
                    self.pause_program(n)?;
                }
                Ok(())
            }
            ProgramAction::Resume => {
                for n in started {
                    self.resume_program(n)?;
                }
                Ok(())
            }
        }
    }
}
