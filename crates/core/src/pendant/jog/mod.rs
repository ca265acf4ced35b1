//! Jogging: the planner ([`plan`]), hold-to-run and the STOP latch ([`hold`]), the step
//! target ([`target`]), the jog speed cap ([`speed_cap`]), and here the pendant's motion
//! intents: jog steps (planned and checked), continuous jogs on a lease, moves to taught
//! points, and the motion phase the lamps show.

pub mod hold;
pub mod plan;
pub mod speed_cap;
pub mod target;

use std::time::Instant;

pub use plan::*;

use self::hold::{HeldJog, HoldAction, HoldMachine, JogInput, JogTarget, Press, StopCause};
use crate::pendant::Message;
use crate::robot::Joints;

/// Jogging's own state: the jog inputs down and the STOP latch, the move the pendant
/// follows, the command position, an arm flip waiting for its second press, the step
/// target, the speed cap, and the last word beside the pad.
#[derive(Debug)]
pub struct JogState {
    /// The last word on a jog button: the refusal or the controller's answer.
    pub feedback: Option<Message>,
    /// Hold-to-run: the jog inputs down, the jog they drive, the STOP latch.
    pub(super) hold: HoldMachine,
    /// The jog speed cap at the tool, mm/s (not saved: a restart brings back the
    /// reduced speed).
    pub(super) speed_cap_mm_s: f64,
    pub(super) followed: Option<Followed>,
    /// End of the last accepted move (joints): the "command position".
    pub(super) command_position: Option<Joints>,
    /// When the held continuous jog's 236H was accepted: a poll answered after it that
    /// finds no axis in use means the controller ended the jog itself (a limit, the edge
    /// of reach) while the operator still holds it.
    pub(super) jog_accepted: Option<Instant>,
    /// The operator was told the controller ended the held jog.
    pub(super) jog_end_said: bool,
    /// A step that flips the arm, waiting for a second press until then.
    pub(super) confirm: Option<(JogAxis, crate::protocol::Direction, Instant)>,
    /// The target filled in from the arm view ("step here"), moved to only on "Go".
    pub(super) step_target: Option<target::StepTarget>,
}

impl Default for JogState {
    fn default() -> Self {
        Self {
            feedback: None,
            hold: HoldMachine::default(),
            speed_cap_mm_s: speed_cap::REDUCED_SPEED_MM_S,
            followed: None,
            command_position: None,
            jog_accepted: None,
            jog_end_said: false,
            confirm: None,
            step_target: None,
        }
    }
}
use self::plan as jog;
use super::{CONFIRM_FOR, Followed, Level, MotionPhase, Pendant, Request};
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
        let target = self.jog.followed.as_ref().and_then(|f| {
            let t = now.saturating_duration_since(f.accepted?).as_secs_f64();
            Some(f.plan.profile.sample(t).joints)
        });
        Ok(jog::ArmNow {
            joints,
            command: self.jog.command_position,
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
        jog::plan_step(&self.model, &self.kin, &self.jog_sent(), axis, dir, &arm)
    }

    /// Whether a move may go out now: the controller ready for motion and no earlier move
    /// still waiting for its reply (one outstanding). If not, says why beside the jog
    /// controls, naming the earlier `what` ("step", "move").
    pub(super) fn may_send_move(&mut self, what: &str, now: Instant) -> bool {
        if let Err(why) = self.motion_ready(now) {
            self.jog_says(Level::Warning, format!("not sent: {why}"), now);
            return false;
        }
        if self
            .jog
            .followed
            .as_ref()
            .is_some_and(|f| f.accepted.is_none())
        {
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
        let Some(point) = self.teach.list().get(index).cloned() else {
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
        // The RMC axes the point names are checked first: nothing moves unless all may.
        let axis_moves = if point.axes.is_empty() {
            Vec::new()
        } else {
            match self.axes.go_moves(&point.axes, &self.settings.rmc) {
                Ok(moves) => moves,
                Err(why) => return self.jog_says(Level::Warning, format!("refused: {why}"), now),
            }
        };
        let plan = self
            .arm_now(now)
            .and_then(|arm| jog::plan_go(&self.model, &self.kin, &self.jog_sent(), &point, &arm));
        match plan {
            Ok(plan) => {
                self.requests.push(Request::Submit(plan.command.clone()));
                self.axes.queue(axis_moves);
                self.jog_says(Level::Info, format!("go to \"{}\": sent", point.name), now);
                self.jog.followed = Some(Followed {
                    plan,
                    accepted: None,
                    stopped: None,
                });
            }
            Err(why) => self.jog_refused(&why, now),
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
            self.teach.list().unique_name("P")
        } else {
            name.trim().to_owned()
        };
        let at = super::teach::TaughtPose {
            pose: pose.to_wire(),
            arm: status.common.arm,
            work: status.work,
            tool: status.tool,
        };
        let axes = if self.settings.rmc.teach_axes {
            match self.axes.taught_positions() {
                Ok(axes) => axes,
                Err(why) => return self.say(Level::Warning, format!("not recorded: {why}"), now),
            }
        } else {
            Vec::new()
        };
        match self.teach.edit(|l| l.record_with_axes(&name, at, axes)) {
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
            Err(why) => return self.jog_refused(&why, now),
        };
        let confirmed = self.jog.confirm.take().is_some_and(|(a, d, at)| {
            a == axis && d == dir && now.duration_since(at) < CONFIRM_FOR
        });
        if plan.flips_arm && !confirmed {
            self.jog.confirm = Some((axis, dir, now));
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
        self.requests.push(Request::Submit(plan.command.clone()));
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
        self.jog.followed = Some(Followed {
            plan,
            accepted: None,
            stopped: None,
        });
    }

    /// One jog input's state this frame (the hold-to-run machine decides what it means).
    pub(super) fn jog_input(&mut self, input: JogInput, press: Press, now: Instant) {
        let held = self.jog.hold.jog();
        match self.jog.hold.report(input, press) {
            HoldAction::None => {}
            HoldAction::Press(target) => match self.settings.jog.mode {
                JogMode::Step => self.jog_step(target.axis, target.direction, now),
                JogMode::Continuous => self.jog_press(input, target, now),
            },
            HoldAction::Renew => self.requests.push(Request::RenewJogLease),
            HoldAction::Release => {
                let label = held.map(|j| j.target.label()).unwrap_or_default();
                // A press and its release in one frame (a tap, a slow frame): the start
                // has not gone out, and never will. The STOP still goes (harmless).
                let before = self.requests.len();
                self.requests
                    .retain(|r| !matches!(r, Request::Submit(c) if c.is_continuous_jog()));
                self.requests.push(Request::Stop);
                if self.requests.len() <= before {
                    // Its "jogging" was never true: the tap's own words replace it.
                    let jogging = format!("jogging {label}");
                    if self
                        .messages
                        .back()
                        .is_some_and(|m| m.at == now && m.text == jogging)
                    {
                        self.messages.pop_back();
                    }
                    self.jog_says(
                        Level::Info,
                        format!(
                            "{label} pressed and released in one frame: no jog sent, only STOP"
                        ),
                        now,
                    );
                } else {
                    self.jog_says(Level::Info, format!("{label} released: STOP sent"), now);
                }
            }
            HoldAction::Latched(target) => self.jog_says(
                Level::Warning,
                format!(
                    "{} not sent: STOP is latched until every jog control is released",
                    target.label()
                ),
                now,
            ),
        }
    }

    /// A fresh press in continuous mode: one 236H, held until released.
    fn jog_press(&mut self, input: JogInput, target: JogTarget, now: Instant) {
        if let Err(why) = self.motion_ready(now) {
            return self.jog_says(
                Level::Warning,
                format!("{} not sent: {why}", target.label()),
                now,
            );
        }
        let command = jog::continuous_jog(&self.jog_sent(), target.axis, target.direction);
        self.requests.push(Request::Submit(command));
        self.jog.hold.started(input, target, now);
        self.jog.jog_accepted = None;
        self.jog.jog_end_said = false;
        self.jog.followed = None;
        self.jog.command_position = None;
        self.jog_says(Level::Info, format!("jogging {}", target.label()), now);
    }

    /// The window lost focus: it cannot see a key or button come up, so the jog stops.
    pub(super) fn focus_lost(&mut self, now: Instant) {
        if let Some((level, text)) = self.axes.focus_lost_at(now) {
            self.say(level, text, now);
        }
        if self.jog.hold.focus_lost().is_some() {
            self.requests.push(Request::Stop);
            self.jog_says(
                Level::Info,
                format!("STOP sent ({})", StopCause::FocusLost.name()),
                now,
            );
        }
    }

    /// The continuous jog running on a held input.
    pub fn held_jog(&self) -> Option<HeldJog> {
        self.jog.hold.jog()
    }

    /// The control `input` is held on now, if any (the pad lights it).
    pub fn held_on(&self, input: JogInput) -> Option<JogTarget> {
        self.jog.hold.on(input)
    }

    /// The STOP latch beside the pad: "STOP (Esc): release the jog controls".
    pub fn stop_latch(&self) -> Option<String> {
        self.jog.hold.latch_text()
    }

    /// New jog choices; a refusal or an armed confirmation made under the old ones goes.
    pub(super) fn set_jog_settings(&mut self, settings: JogSettings) {
        if settings == self.settings.jog {
            return;
        }
        self.settings.jog = settings;
        self.jog.confirm = None;
        if self
            .jog
            .feedback
            .as_ref()
            .is_some_and(|m| m.level != Level::Info)
        {
            self.jog.feedback = None;
        }
    }

    /// The jog settings as they go on the line: speeds within the cap.
    pub fn jog_sent(&self) -> JogSettings {
        speed_cap::apply(&self.settings.jog, &self.model, self.jog.speed_cap_mm_s)
    }

    /// The jog speed cap at the tool, mm/s.
    pub fn speed_cap(&self) -> f64 {
        self.jog.speed_cap_mm_s
    }

    /// Raises (or lowers) the cap until the window closes; a raise is said in Messages.
    pub(super) fn raise_speed_cap(&mut self, mm_s: f64, now: Instant) {
        if !mm_s.is_finite() || mm_s <= 0.0 {
            return;
        }
        let mm_s = mm_s.min(speed_cap::MAX_CAP_MM_S);
        self.jog.speed_cap_mm_s = mm_s;
        self.say(
            Level::Warning,
            format!("jog speed cap set to {mm_s:.0} mm/s at the tool until the window closes"),
            now,
        );
    }

    /// Back to the reduced jog speed.
    pub(super) fn reset_speed_cap(&mut self, now: Instant) {
        self.jog.speed_cap_mm_s = speed_cap::REDUCED_SPEED_MM_S;
        self.say(
            Level::Info,
            format!(
                "jog speed cap back to the reduced speed, {:.0} mm/s",
                speed_cap::REDUCED_SPEED_MM_S
            ),
            now,
        );
    }

    /// The motion phase of the move being followed.
    pub fn motion_phase(&self, now: Instant) -> MotionPhase {
        if self.jog.hold.jog().is_some() {
            return if self.held_jog_ended() {
                MotionPhase::Stopped
            } else {
                MotionPhase::Jogging
            };
        }
        let Some(f) = &self.jog.followed else {
            return MotionPhase::Idle;
        };
        let Some(at) = f.accepted else {
            return if f.stopped.is_some() {
                MotionPhase::Stopped
            } else {
                MotionPhase::Idle
            };
        };
        // A STOP after the profile had ended stopped nothing: the move is done, as the
        // controller's "completed" says. One before its end cut it short.
        if let Some(stop) = f.stopped {
            let t = stop.saturating_duration_since(at).as_secs_f64();
            if f.plan.profile.sample(t).phase != crate::robot::Phase::Complete {
                return MotionPhase::Stopped;
            }
        }
        let t = now.saturating_duration_since(at).as_secs_f64();
        match f.plan.profile.sample(t).phase {
            crate::robot::Phase::Accel => MotionPhase::Accelerating,
            crate::robot::Phase::ConstantVelocity => MotionPhase::Constant,
            crate::robot::Phase::Decel => MotionPhase::Decelerating,
            crate::robot::Phase::Complete => MotionPhase::Done,
        }
    }

    /// Whether the controller ended the held jog by itself: a poll answered after its
    /// 236H was accepted (so sent after it: one command outstanding) finds no axis in use.
    /// [inferred] the controller clears "in use" when a jog stops at a limit or the edge
    /// of reach, as the simulator does.
    pub fn held_jog_ended(&self) -> bool {
        let Some(accepted) = self.jog.jog_accepted else {
            return false;
        };
        self.controller.work.as_ref().is_some_and(|w| {
            w.at > accepted && w.value.axes.iter().all(|(_, a)| !a.status.in_use())
        })
    }

    /// The polled joints within the model's positioning band of the command position.
    /// Off while a jog runs or a followed move's profile has not ended, whatever the
    /// polled joints say.
    pub fn in_position(&self) -> Option<bool> {
        let actual = self.controller.joint_position()?;
        if self.jog.hold.jog().is_some() {
            return Some(false);
        }
        let now_moving = self
            .jog
            .followed
            .as_ref()
            .is_some_and(|f| f.stopped.is_none() && f.accepted.is_none());
        if now_moving {
            return Some(false);
        }
        let command = self.jog.command_position.unwrap_or(actual);
        Some(in_position(&actual, &command, &self.model.in_position))
    }

    /// The planned move being followed, for the arm view's ghost.
    pub fn followed_move(&self) -> Option<&Move> {
        self.jog.followed.as_ref().map(|f| &f.plan.profile)
    }
}
