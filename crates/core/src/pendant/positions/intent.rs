//! What the Positions view asks of the pendant, and how the pendant answers it (teach
//! here, read, edit, preview, write, Go to No. N).

use std::time::Instant;

use super::{Column, Row, record_of_pose};
use crate::pendant::{Level, Pendant, Request};
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

impl Pendant {
    /// Applies one Positions intent.
    pub fn apply_positions(&mut self, intent: PositionsIntent, now: Instant) {
        let result: Result<Option<String>, String> = match intent {
            PositionsIntent::Read { from, to } => {
                if !self.line.is_up() {
                    Err("not connected".into())
                } else {
                    self.positions
                        .start_read(from..=to)
                        .map(|()| Some(format!("reading positions {from}-{to}")))
                }
            }
            PositionsIntent::CancelRead => Ok(self.positions.cancel_read()),
            PositionsIntent::TeachHere { number, name } => self.teach_here(number, name, now),
            PositionsIntent::SetCell {
                number,
                column,
                text,
            } => self
                .positions
                .set_cell(number, column, &text)
                .map(|()| None),
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
                    self.positions
                        .set_name(number, Some(name).filter(|n| !n.is_empty()));
                    Ok(None)
                }
            }
            PositionsIntent::Revert(n) => {
                self.positions.revert(n);
                Ok(None)
            }
            PositionsIntent::Undo => Ok((!self.positions.undo()).then(|| "nothing to undo".into())),
            PositionsIntent::Redo => Ok((!self.positions.redo()).then(|| "nothing to redo".into())),
            PositionsIntent::PreviewWrite => self.preview_positions(now),
            PositionsIntent::ConfirmWrite { take_the_risk } => {
                self.write_positions(take_the_risk, now)
            }
            PositionsIntent::CancelPreview => {
                self.positions.cancel_preview();
                Ok(None)
            }
            PositionsIntent::Go(n) => {
                self.position_go(n, now);
                Ok(None)
            }
            PositionsIntent::Import { path, read } => read
                .and_then(|records| self.positions.import(records))
                .map(|n| {
                    Some(format!(
                        "{path}: {n} rows into the draft (Undo takes them out)"
                    ))
                })
                .map_err(|e| format!("{path}: nothing imported: {e}")),
        };
        match result {
            Ok(Some(text)) => {
                self.positions.feedback = Some((Level::Info, text.clone()));
                self.say(Level::Info, text, now);
            }
            Ok(None) => {}
            Err(text) => {
                self.positions.feedback = Some((Level::Warning, text.clone()));
                self.say(Level::Warning, text, now);
            }
        }
        self.positions_out();
    }

    /// Moves the position table's commands to the requests, in order (reads in the
    /// background, writes at the user's priority, behind any STOP already asked for).
    pub(crate) fn positions_out(&mut self) {
        for (command, user) in self.positions.take_commands() {
            self.requests.push(if user {
                Request::Submit(command)
            } else {
                Request::Background(command)
            });
        }
    }

    fn teach_here(
        &mut self,
        number: u16,
        name: String,
        now: Instant,
    ) -> Result<Option<String>, String> {
        let status = self
            .controller
            .work
            .as_ref()
            .map(|s| s.value)
            .ok_or("not taught: no position read yet")?;
        if self.controller.is_stale(now) {
            return Err("not taught: the position is out of date".into());
        }
        let pose = self
            .controller
            .work_position()
            .ok_or("not taught: no position read yet")?;
        let arm = match status.common.arm {
            ArmSystem::Right => RecordArm::Right,
            ArmSystem::Left => RecordArm::Left,
            ArmSystem::Undetermined => RecordArm::Unspecified,
        };
        let mut rec = record_of_pose(number, pose.to_wire(), arm);
        // Rates the row had stay: teaching moves the place, not how it is reached.
        if let Some(old) = self.positions.shown(number) {
            rec.speed = old.speed;
            rec.accel = old.accel;
            rec.decel = old.decel;
        }
        self.positions.put(rec)?;
        if !name.trim().is_empty() {
            self.positions
                .set_name(number, Some(name.trim().to_owned()));
        }
        Ok(Some(format!(
            "taught No. {number}: X {:.3} Y {:.3} Z {:.3} R {:.3} (work {}, tool {}) into the draft: Write to store it in the controller",
            pose.x, pose.y, pose.z, pose.r, status.work, status.tool
        )))
    }

    fn preview_positions(&mut self, now: Instant) -> Result<Option<String>, String> {
        let running = self.program_running();
        let arm = self.arm_now(now);
        let (model, kin, settings) = (&self.model, &self.kin, self.jog_sent());
        self.positions.preview(running, |rec| match &arm {
            Ok(arm) => crate::pendant::jog::plan_position_go(model, kin, &settings, rec, arm)
                .map(|_| ())
                .map_err(|why| why.to_string()),
            Err(why) => Err(format!("not checked: {why}")),
        })?;
        Ok(None)
    }

    fn write_positions(
        &mut self,
        take_the_risk: bool,
        now: Instant,
    ) -> Result<Option<String>, String> {
        if !self.line.is_up() {
            return Err("not written: not connected".into());
        }
        let running = self.program_running();
        let n = self.positions.confirm_write(running, take_the_risk)?;
        let _ = now;
        Ok(Some(format!(
            "writing {n} positions{}",
            if running && take_the_risk {
                " while a program runs (confirmed)"
            } else {
                ""
            }
        )))
    }

    /// 215H says a program runs (or nothing is known: counted as running, to be safe).
    pub fn program_running(&self) -> bool {
        self.controller
            .system
            .as_ref()
            .is_none_or(|s| s.value.status2.program_running())
    }

    /// Go to No. `n`: 2D6H to what the controller holds there, after the checks of a
    /// step; an arm flip asks for a second press.
    pub fn position_go(&mut self, n: u16, now: Instant) {
        let rec = match self.positions.row(n) {
            Row::Held(r) => *r,
            Row::Empty => {
                return self.jog_says(
                    Level::Warning,
                    format!("refused: No. {n} holds no data"),
                    now,
                );
            }
            _ => {
                return self.jog_says(
                    Level::Warning,
                    format!("refused: No. {n} has not been read: read it first (Go checks the controller's own record)"),
                    now,
                );
            }
        };
        if !self.may_send_move("move", now) {
            return;
        }
        let plan = self.arm_now(now).and_then(|arm| {
            crate::pendant::jog::plan_position_go(
                &self.model,
                &self.kin,
                &self.jog_sent(),
                &rec,
                &arm,
            )
        });
        let plan = match plan {
            Ok(plan) => plan,
            Err(why) => return self.jog_refused(&why, now),
        };
        let confirmed =
            self.positions.go_confirm.take().is_some_and(|(m, at)| {
                m == n && now.duration_since(at) < crate::pendant::CONFIRM_FOR
            });
        if plan.flips_arm && !confirmed {
            self.positions.go_confirm = Some((n, now));
            return self.jog_says(
                Level::Warning,
                format!(
                    "Go to No. {n} flips the arm system: press again within {} s to confirm",
                    crate::pendant::CONFIRM_FOR.as_secs()
                ),
                now,
            );
        }
        let differs = if self.positions.differs(n) {
            " (the controller's record: the draft's row differs and is not written)"
        } else {
            ""
        };
        self.requests.push(Request::Submit(plan.command.clone()));
        self.jog_says(Level::Info, format!("go to No. {n}: sent{differs}"), now);
        self.jog.followed = Some(crate::pendant::Followed {
            plan,
            accepted: None,
            stopped: None,
        });
    }
}
