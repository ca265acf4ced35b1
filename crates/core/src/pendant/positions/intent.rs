//! What the Positions view asks of the pendant, and how the position table answers it
//! (teach here, read, edit, preview, write; Go to No. N is a move, the jog state's).

use std::time::Instant;

use super::{Column, Positions, record_of_pose};
use crate::pendant::controller::ControllerState;
use crate::pendant::{Level, Request};
use crate::protocol::{ArmSystem, PositionRecord, RecordArm};

/// One thing the operator asked of the position table.
#[derive(Clone, Debug, PartialEq)]
pub enum PositionsIntent {
    /// Read the controller's positions `from..=to`.
    Read {
        from: u16,
        to: u16,
    },
    /// Stop the read in progress.
    CancelRead,
    /// Store the current pose (selected work and tool frame, current arm system) into the
    /// draft at `number`, with an optional name.
    TeachHere {
        number: u16,
        name: String,
    },
    /// A typed cell, checked when it ends.
    SetCell {
        number: u16,
        column: Column,
        text: String,
    },
    /// The pendant's name beside a number (empty: none).
    SetName {
        number: u16,
        name: String,
    },
    /// A row of the draft back to the controller's.
    Revert(u16),
    Undo,
    Redo,
    /// Show what a write would change, with the checks of a step per row.
    PreviewWrite,
    /// Write what the preview shows (`take_the_risk`: the operator confirmed writing
    /// while a program runs).
    ConfirmWrite {
        take_the_risk: bool,
    },
    CancelPreview,
    /// 2D6H to the controller's position `number`.
    Go(u16),
    /// A file's records (or why it could not be read) into the draft.
    Import {
        path: String,
        read: Result<Vec<(PositionRecord, Option<String>)>, String>,
    },
}

/// What the position table's intents need to know of the rest of the model.
pub struct PositionsCx<'a> {
    pub line_up: bool,
    /// 215H says a program runs (or nothing is known: counted as running, to be safe).
    pub program_running: bool,
    /// The polled pose, for "teach here".
    pub controller: &'a ControllerState,
    /// Whether the arm could go to a record now (the checks of a step), for the preview.
    pub check: &'a dyn Fn(&PositionRecord) -> Result<(), String>,
}

/// An intent's word for the operator: news, or why it was refused.
pub type Answer = Result<Option<String>, String>;

impl Positions {
    /// Applies one Positions intent but Go (a move: the pendant's, through the jog
    /// state); the answer is kept beside the table and returned, to be said.
    pub fn apply(
        &mut self,
        intent: PositionsIntent,
        cx: &PositionsCx,
        now: Instant,
    ) -> Option<(Level, String)> {
        let answer = self.answer(intent, cx, now);
        let said = match answer {
            Ok(Some(text)) => (Level::Info, text),
            Ok(None) => return None,
            Err(text) => (Level::Warning, text),
        };
        self.feedback = Some(said.clone());
        Some(said)
    }

    fn answer(&mut self, intent: PositionsIntent, cx: &PositionsCx, now: Instant) -> Answer {
        match intent {
            PositionsIntent::Read { from, to } => {
                if !cx.line_up {
                    Err("not connected".into())
                } else {
                    self.start_read(from..=to)
                        .map(|()| Some(format!("reading positions {from}-{to}")))
                }
            }
            PositionsIntent::CancelRead => Ok(self.cancel_read()),
            PositionsIntent::TeachHere { number, name } => {
                self.teach_here(cx.controller, number, name, now)
            }
            PositionsIntent::SetCell {
                number,
                column,
                text,
            } => self.set_cell(number, column, &text).map(|()| None),
            PositionsIntent::SetName { number, name } => {
                let name = name.trim().to_owned();
                if name.chars().count() > crate::pendant::teach::MAX_NAME_CHARS
                    || name.chars().any(char::is_control)
                {
                    Err(format!(
                        "a name is at most {} characters, without control characters",
                        crate::pendant::teach::MAX_NAME_CHARS
                    ))
                } else {
                    self.set_name(number, Some(name).filter(|n| !n.is_empty()));
                    Ok(None)
                }
            }
            PositionsIntent::Revert(n) => {
                self.revert(n);
                Ok(None)
            }
            PositionsIntent::Undo => Ok((!self.undo()).then(|| "nothing to undo".into())),
            PositionsIntent::Redo => Ok((!self.redo()).then(|| "nothing to redo".into())),
            PositionsIntent::PreviewWrite => {
                self.preview(cx.program_running, cx.check).map(|()| None)
            }
            PositionsIntent::ConfirmWrite { take_the_risk } => {
                self.write_confirmed(cx, take_the_risk)
            }
            PositionsIntent::CancelPreview => {
                self.cancel_preview();
                Ok(None)
            }
            // A move: the pendant sends it through the jog state.
            PositionsIntent::Go(_) => Ok(None),
            PositionsIntent::Import { path, read } => read
                .and_then(|records| self.import(records))
                .map(|n| {
                    Some(format!(
                        "{path}: {n} rows into the draft (Undo takes them out)"
                    ))
                })
                .map_err(|e| format!("{path}: nothing imported: {e}")),
        }
    }

    /// The table's commands as requests, in order (reads in the background, writes at
    /// the user's priority, behind any STOP already asked for).
    pub fn take_requests(&mut self) -> impl Iterator<Item = Request> + use<> {
        self.take_commands().into_iter().map(|(command, user)| {
            if user {
                Request::Submit(command)
            } else {
                Request::Background(command)
            }
        })
    }

    fn teach_here(
        &mut self,
        controller: &ControllerState,
        number: u16,
        name: String,
        now: Instant,
    ) -> Answer {
        let status = controller
            .work
            .as_ref()
            .map(|s| s.value)
            .ok_or("not taught: no position read yet")?;
        if controller.is_stale(now) {
            return Err("not taught: the position is out of date".into());
        }
        let pose = controller
            .work_position()
            .ok_or("not taught: no position read yet")?;
        let arm = match status.common.arm {
            ArmSystem::Right => RecordArm::Right,
            ArmSystem::Left => RecordArm::Left,
            ArmSystem::Undetermined => RecordArm::Unspecified,
        };
        let mut rec = record_of_pose(number, pose.to_wire(), arm);
        // Rates the row had stay: teaching moves the place, not how it is reached.
        if let Some(old) = self.shown(number) {
            rec.speed = old.speed;
            rec.accel = old.accel;
            rec.decel = old.decel;
        }
        self.put(rec)?;
        if !name.trim().is_empty() {
            self.set_name(number, Some(name.trim().to_owned()));
        }
        Ok(Some(format!(
            "taught No. {number}: X {:.3} Y {:.3} Z {:.3} R {:.3} (work {}, tool {}) into the draft: Write to store it in the controller",
            pose.x, pose.y, pose.z, pose.r, status.work, status.tool
        )))
    }

    fn write_confirmed(&mut self, cx: &PositionsCx, take_the_risk: bool) -> Answer {
        if !cx.line_up {
            return Err("not written: not connected".into());
        }
        let running = cx.program_running;
        let n = self.confirm_write(running, take_the_risk)?;
        Ok(Some(format!(
            "writing {n} positions{}",
            if running && take_the_risk {
                " while a program runs (confirmed)"
            } else {
                ""
            }
        )))
    }
}
