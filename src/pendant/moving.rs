//! The pendant's motion intents: jog steps (planned and checked), continuous jogs on a
//! lease, moves to taught points, and the motion phase the lamps show.

use std::time::Instant;

use super::jog::{self, JogAxis, PlannedStep, Refusal};
use super::{CONFIRM_FOR, Followed, HeldJog, HoldSource, Level, MotionPhase, Pendant, Request};
use crate::protocol::Direction;
use crate::robot::{Move, in_position};

impl Pendant {
    // ---- jog ----

    /// What the planner needs of the arm now: polled joints, the command and target
    /// positions of the move being followed, and the selected work and tool frames.
    pub(super) fn arm_now(&self, now: Instant) -> Result<jog::ArmNow, Refusal> {
        let c = &self.controller;
        let joints = c.joint_position().ok_or(Refusal::NoPosition)?;
        let work = c.work_frame().ok_or(Refusal::NoTable("work"))?;
        let tool = c.tool_frame().ok_or(Refusal::NoTable("tool"))?;
        let target = self.followed.as_ref().and_then(|f| {
            let t = now.saturating_duration_since(f.accepted?).as_secs_f64();
            Some(f.plan.profile.sample(t).joints)
        });
        Ok(jog::ArmNow {
            joints,
            command: self.command_position,
            target,
            work,
            tool,
        })
    }

    /// What a step of `axis` in `dir` would do now, without sending it.
    pub fn preview_step(
        &self,
        axis: JogAxis,
        dir: Direction,
        now: Instant,
    ) -> Result<PlannedStep, Refusal> {
        let arm = self.arm_now(now)?;
        jog::plan_step(&self.model, &self.kin, &self.settings.jog, axis, dir, &arm)
    }

    /// Whether a move may go out now: the controller ready for motion and no earlier move
    /// still waiting for its reply (one outstanding). If not, says why beside the jog
    /// controls, naming the earlier `what` ("step", "move").
    pub(super) fn may_send_move(&mut self, what: &str, now: Instant) -> bool {
        if let Err(why) = self.motion_ready(now) {
            self.jog_says(Level::Warning, format!("not sent: {why}"), now);
            return false;
        }
        if self.followed.as_ref().is_some_and(|f| f.accepted.is_none()) {
            self.jog_says(
                Level::Warning,
                format!("not sent: the previous {what} is still waiting for its reply"),
                now,
            );
            return false;
        }
        true
    }

    /// "Go" on a taught point: 2D4H after the frame check and the same checks as a step.
    pub fn teach_go(&mut self, index: usize, now: Instant) {
        let Some(point) = self.settings.teach.get(index).cloned() else {
            return;
        };
        if !self.may_send_move("move", now) {
            return;
        }
        if let Some((work, tool)) = self.controller.frame_numbers()
            && let Err(why) = super::teach::check_go(&point, work, tool)
        {
            return self.jog_says(Level::Warning, format!("refused: {why}"), now);
        }
        let plan = self
            .arm_now(now)
            .and_then(|arm| jog::plan_go(&self.model, &self.kin, &self.settings.jog, &point, &arm));
        match plan {
            Ok(plan) => {
                self.requests.push(Request::Submit(plan.command));
                self.jog_says(Level::Info, format!("go to \"{}\": sent", point.name), now);
                self.followed = Some(Followed {
                    plan,
                    accepted: None,
                    stopped: false,
                });
            }
            Err(why) => self.jog_says(Level::Warning, format!("refused: {why}"), now),
        }
    }

    /// "Record": the current pose, arm system and frame numbers under `name` (a free
    /// name is made up when it is empty).
    pub fn teach_record(&mut self, name: &str, now: Instant) {
        let Some(status) = self.controller.work.as_ref().map(|s| s.value) else {
            return self.say(Level::Warning, "not recorded: no position read yet", now);
        };
        if self.controller.is_stale(now) {
            return self.say(
                Level::Warning,
                "not recorded: the position is out of date",
                now,
            );
        }
        let Some(pose) = self.controller.work_position() else {
            return self.say(Level::Warning, "not recorded: no position read yet", now);
        };
        let name = if name.trim().is_empty() {
            self.settings.teach.unique_name("P")
        } else {
            name.trim().to_owned()
        };
        let at = super::teach::TaughtPose {
            pose: pose.to_wire(),
            arm: status.common.arm,
            work: status.work,
            tool: status.tool,
        };
        match self.settings.teach.record(&name, at) {
            Ok(_) => self.say(Level::Info, format!("recorded \"{name}\""), now),
            Err(e) => self.say(Level::Warning, format!("not recorded: {e}"), now),
        }
    }

    /// A click on a jog button in step mode: plan, check, send (or refuse, or ask to
    /// confirm an arm flip).
    pub fn jog_step(&mut self, axis: JogAxis, dir: Direction, now: Instant) {
        if !self.may_send_move("step", now) {
            return;
        }
        let plan = match self.preview_step(axis, dir, now) {
            Ok(plan) => plan,
            Err(why) => return self.jog_says(Level::Warning, format!("refused: {why}"), now),
        };
        let confirmed = self.confirm.take().is_some_and(|(a, d, at)| {
            a == axis && d == dir && now.duration_since(at) < CONFIRM_FOR
        });
        if plan.flips_arm && !confirmed {
            self.confirm = Some((axis, dir, now));
            return self.jog_says(
                Level::Warning,
                format!(
                    "{}{} flips the arm system: press again within {} s to confirm",
                    axis.name(),
                    if dir == Direction::Positive { "+" } else { "-" },
                    CONFIRM_FOR.as_secs()
                ),
                now,
            );
        }
        self.requests.push(Request::Submit(plan.command));
        self.jog_says(
            Level::Info,
            format!(
                "{}{} {} {}: sent",
                axis.name(),
                if dir == Direction::Positive { "+" } else { "-" },
                self.settings.jog.step,
                axis.unit()
            ),
            now,
        );
        self.followed = Some(Followed {
            plan,
            accepted: None,
            stopped: false,
        });
    }

    /// A jog button pressed in continuous mode: 236H until released.
    pub fn jog_press(&mut self, axis: JogAxis, dir: Direction, source: HoldSource, now: Instant) {
        if let Err(why) = self.motion_ready(now) {
            return self.jog_says(Level::Warning, format!("not sent: {why}"), now);
        }
        self.requests.push(Request::Submit(jog::continuous_jog(
            &self.settings.jog,
            axis,
            dir,
        )));
        self.held = Some(HeldJog {
            axis,
            direction: dir,
            source,
            since: now,
        });
        self.followed = None;
        self.command_position = None;
        self.jog_says(Level::Info, format!("jogging {}", axis.name()), now);
    }

    /// Called every frame while the button or key is still held: renews the lease.
    pub fn jog_held(&mut self) {
        if self.held.is_some() {
            self.requests.push(Request::RenewJogLease);
        }
    }

    /// The button or key was released, or the window lost focus: 238H.
    pub fn jog_release(&mut self, now: Instant) {
        if self.held.take().is_some() {
            self.requests.push(Request::Stop);
            self.jog_says(Level::Info, "jog released: STOP sent", now);
        }
    }

    pub fn held_jog(&self) -> Option<HeldJog> {
        self.held
    }

    /// The motion phase of the move being followed.
    pub fn motion_phase(&self, now: Instant) -> MotionPhase {
        if self.held.is_some() {
            return MotionPhase::Jogging;
        }
        let Some(f) = &self.followed else {
            return MotionPhase::Idle;
        };
        if f.stopped {
            return MotionPhase::Stopped;
        }
        let Some(at) = f.accepted else {
            return MotionPhase::Idle;
        };
        let t = now.saturating_duration_since(at).as_secs_f64();
        match f.plan.profile.sample(t).phase {
            crate::robot::Phase::Accel => MotionPhase::Accelerating,
            crate::robot::Phase::ConstantVelocity => MotionPhase::Constant,
            crate::robot::Phase::Decel => MotionPhase::Decelerating,
            crate::robot::Phase::Complete => MotionPhase::Done,
        }
    }

    /// The polled joints within the model's positioning band of the command position.
    pub fn in_position(&self) -> Option<bool> {
        let actual = self.controller.joint_position()?;
        let command = self.command_position.unwrap_or(actual);
        Some(in_position(&actual, &command, &self.model.in_position))
    }

    /// The planned move being followed, for the arm view's ghost.
    pub fn followed_move(&self) -> Option<&Move> {
        self.followed.as_ref().map(|f| &f.plan.profile)
    }
}
