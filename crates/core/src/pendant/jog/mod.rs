//! Jogging: the planner ([`plan`]), hold-to-run and the STOP latch ([`hold`]), the step
//! target ([`target`]), the jog speed cap ([`speed_cap`]), and here jogging's own state
//! and intents: jog steps (planned and checked), continuous jogs on a lease, the move
//! followed, and the motion phase the lamps show.

mod events;
pub mod hold;
pub mod plan;
pub mod speed_cap;
pub mod target;
pub mod zone_watch;

use std::time::Instant;

pub use plan::*;

use self::hold::{HeldJog, HoldAction, HoldMachine, JogInput, JogTarget, Press, StopCause};
use self::plan as jog;
use super::controller::ControllerState;
use super::controller::readiness::{self, NotReady};
use super::{CONFIRM_FOR, Level, Message, MotionPhase, Out, Request};
use crate::protocol::Direction;
use crate::robot::{Joints, Move, RobotModel, Scara, in_position};

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
    /// A continuous jog into interference zones, waiting for a second press until then.
    pub(super) zone_pass: Option<zone_watch::ZonePass>,
    /// The zones the held continuous jog was confirmed into (it may enter these).
    pub(super) zones_let: Vec<u8>,
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
            zone_pass: None,
            zones_let: Vec::new(),
        }
    }
}

/// A move the pendant sent and follows.
#[derive(Clone, Debug)]
pub(super) struct Followed {
    pub(super) plan: PlannedStep,
    /// When the controller accepted it; `None` while the reply is awaited.
    pub(super) accepted: Option<Instant>,
    /// When a STOP went out while it was followed.
    pub(super) stopped: Option<Instant>,
}

/// What jogging needs to know of the rest of the model: the robot, the polled
/// controller, the operator's jog choices and whether the line is up.
pub struct JogCx<'a> {
    pub model: &'a RobotModel,
    pub kin: &'a Scara,
    pub controller: &'a ControllerState,
    pub settings: &'a JogSettings,
    pub line_up: bool,
    /// The controller's interference zones as read (2A2H): every move's path is checked
    /// against them.
    pub zones: &'a [crate::robot::ZoneBox],
}

impl JogCx<'_> {
    /// Whether the controller may be asked to move now.
    pub fn motion_ready(&self, now: Instant) -> Result<(), NotReady> {
        let c = self.controller;
        readiness::motion_gate(
            self.line_up,
            c.system.as_ref().map(|s| &s.value),
            c.work.as_ref().map(|s| &s.value),
            c.is_stale(now),
        )
    }
}

impl JogState {
    /// What the planner needs of the arm now: polled joints, the command and target
    /// positions of the move being followed, and the selected work and tool frames.
    pub fn arm_now<'a>(&self, cx: &JogCx<'a>, now: Instant) -> Result<jog::ArmNow<'a>, Refusal> {
        let c = cx.controller;
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
            zones: cx.zones,
        })
    }

    /// The jog settings as they go on the line: speeds within the cap.
    pub fn sent(&self, cx: &JogCx) -> JogSettings {
        speed_cap::apply(cx.settings, cx.model, self.speed_cap_mm_s)
    }

    /// What a step of `axis` in `dir` would do now, without sending it.
    pub fn preview_step(
        &self,
        cx: &JogCx,
        axis: JogAxis,
        dir: Direction,
        now: Instant,
    ) -> Result<PlannedStep, Refusal> {
        let arm = self.arm_now(cx, now)?;
        jog::plan_step(cx.model, cx.kin, &self.sent(cx), axis, dir, &arm)
    }

    /// The last word beside the pad, also said in Messages.
    pub fn says(&mut self, out: &mut Out, level: Level, text: impl Into<String>, now: Instant) {
        let text = text.into();
        self.feedback = Some(Message {
            level,
            text: text.clone(),
            at: now,
            detail: None,
        });
        out.say(level, text, now);
    }

    /// A refusal beside the pad in one short sentence, the whole of it in Messages and
    /// on hover.
    pub fn refused(&mut self, out: &mut Out, why: &Refusal, now: Instant) {
        let full = format!("refused: {why}");
        self.feedback = Some(Message {
            level: Level::Warning,
            text: format!("refused: {}", why.short()),
            at: now,
            detail: Some(full.clone()),
        });
        out.say(Level::Warning, full, now);
    }

    /// Whether a move may go out now: the controller ready for motion and no earlier move
    /// still waiting for its reply (one outstanding). If not, says why beside the jog
    /// controls, naming the earlier `what` ("step", "move").
    pub fn may_send_move(&mut self, cx: &JogCx, out: &mut Out, what: &str, now: Instant) -> bool {
        if let Err(why) = cx.motion_ready(now) {
            self.says(out, Level::Warning, format!("not sent: {why}"), now);
            return false;
        }
        if self.followed.as_ref().is_some_and(|f| f.accepted.is_none()) {
            self.says(
                out,
                Level::Warning,
                format!("not sent: the previous {what} is still waiting for its reply"),
                now,
            );
            return false;
        }
        true
    }

    /// A planned move goes out (after any request asked for before it) and is followed.
    pub fn send(&mut self, out: &mut Out, plan: PlannedStep) {
        out.push(Request::Submit(plan.command.clone()));
        self.followed = Some(Followed {
            plan,
            accepted: None,
            stopped: None,
        });
    }

    /// A click on a jog button in step mode: plan, check, send (or refuse, or ask to
    /// confirm an arm flip).
    pub fn step(&mut self, cx: &JogCx, out: &mut Out, axis: JogAxis, dir: Direction, now: Instant) {
        if !self.may_send_move(cx, out, "step", now) {
            return;
        }
        let plan = match self.preview_step(cx, axis, dir, now) {
            Ok(plan) => plan,
            Err(why) => return self.refused(out, &why, now),
        };
        let confirmed = self.confirm.take().is_some_and(|(a, d, at)| {
            a == axis && d == dir && now.duration_since(at) < CONFIRM_FOR
        });
        let sign = if dir == Direction::Positive { "+" } else { "-" };
        if !confirmed
            && let Some(text) = plan.confirm_text(&format!("{}{sign}", axis.name()), "again")
        {
            self.confirm = Some((axis, dir, now));
            return self.says(out, Level::Warning, text, now);
        }
        out.push(Request::Submit(plan.command.clone()));
        self.says(
            out,
            Level::Info,
            format!(
                "{}{sign} {} {}: sent",
                axis.name(),
                cx.settings.step,
                axis.unit()
            ),
            now,
        );
        self.followed = Some(Followed {
            plan,
            accepted: None,
            stopped: None,
        });
    }

    /// One jog input's state this frame (the hold-to-run machine decides what it means).
    pub fn input(
        &mut self,
        cx: &JogCx,
        out: &mut Out,
        input: JogInput,
        press: Press,
        now: Instant,
    ) {
        let held = self.hold.jog();
        match self.hold.report(input, press) {
            HoldAction::None => {}
            HoldAction::Press(target) => match cx.settings.mode {
                JogMode::Step => self.step(cx, out, target.axis, target.direction, now),
                JogMode::Continuous => self.press(cx, out, input, target, now),
            },
            HoldAction::Renew => out.push(Request::RenewJogLease),
            HoldAction::Release => {
                let label = held.map(|j| j.target.label()).unwrap_or_default();
                // A press and its release in one frame (a tap, a slow frame): the start
                // has not gone out, and never will. The STOP still goes (harmless).
                let before = out.requests.len();
                out.requests
                    .retain(|r| !matches!(r, Request::Submit(c) if c.is_continuous_jog()));
                out.push(Request::Stop);
                if out.requests.len() <= before {
                    // Its "jogging" was never true: the tap's own words replace it.
                    let jogging = format!("jogging {label}");
                    if out
                        .messages
                        .back()
                        .is_some_and(|m| m.at == now && m.text == jogging)
                    {
                        out.messages.pop_back();
                    }
                    self.says(
                        out,
                        Level::Info,
                        format!(
                            "{label} pressed and released in one frame: no jog sent, only STOP"
                        ),
                        now,
                    );
                } else {
                    self.says(
                        out,
                        Level::Info,
                        format!("{label} released: STOP sent"),
                        now,
                    );
                }
            }
            HoldAction::Latched(target) => self.says(
                out,
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
    fn press(
        &mut self,
        cx: &JogCx,
        out: &mut Out,
        input: JogInput,
        target: JogTarget,
        now: Instant,
    ) {
        if let Err(why) = cx.motion_ready(now) {
            return self.says(
                out,
                Level::Warning,
                format!("{} not sent: {why}", target.label()),
                now,
            );
        }
        let zones_let = match self.zones_ahead(cx, target, now) {
            Ok(entered) if entered.is_empty() => Vec::new(),
            Ok(entered) => {
                let Some(pass) = self
                    .zone_pass
                    .take()
                    .filter(|p| p.lets(target, &entered, now))
                else {
                    return self.ask_zone_pass(out, target, entered, now);
                };
                pass.zones
            }
            Err(why) => {
                let text = format!(
                    "{} not sent: the zones cannot be checked: {why}",
                    target.label()
                );
                return self.says(out, Level::Warning, text, now);
            }
        };
        self.zone_pass = None;
        self.zones_let = zones_let;
        let command = jog::continuous_jog(&self.sent(cx), target.axis, target.direction);
        out.push(Request::Submit(command));
        self.hold.started(input, target, now);
        self.jog_accepted = None;
        self.jog_end_said = false;
        self.followed = None;
        self.command_position = None;
        self.says(out, Level::Info, format!("jogging {}", target.label()), now);
    }

    /// The zones a continuous jog of `target` would enter before a STOP could hold it,
    /// from where the arm is (none where no zone is read).
    fn zones_ahead(&self, cx: &JogCx, target: JogTarget, now: Instant) -> Result<Vec<u8>, Refusal> {
        if !cx.zones.iter().any(crate::robot::ZoneBox::is_defined) {
            return Ok(Vec::new());
        }
        let arm = self.arm_now(cx, now)?;
        Ok(
            zone_watch::way_ahead(cx.model, cx.kin, &self.sent(cx), target, &arm)
                .map(|way| zone_watch::zones_entered(&way, &arm))
                .unwrap_or_default(),
        )
    }

    /// A continuous jog toward zones: not sent, a second press of the same control asked
    /// for.
    fn ask_zone_pass(&mut self, out: &mut Out, target: JogTarget, zones: Vec<u8>, now: Instant) {
        let label = target.label();
        let text = format!(
            "{label} would enter {} within its stopping distance ({}): press {label} \
             again within {} s to jog into it",
            plan::zones_text(&zones),
            super::zones::ZONE_ACTION,
            CONFIRM_FOR.as_secs()
        );
        self.zone_pass = Some(zone_watch::ZonePass {
            target,
            zones,
            at: now,
        });
        self.says(out, Level::Warning, text, now);
    }

    /// The held continuous jog, if the way it may still go enters a zone it was not
    /// confirmed into: its label and those zones (the caller STOPs it, then arms the
    /// second press with [`JogState::arm_zone_pass`]).
    pub fn zone_ahead(&self, cx: &JogCx, now: Instant) -> Option<(JogTarget, Vec<u8>)> {
        let jog = self.hold.jog()?;
        let mut entered = self.zones_ahead(cx, jog.target, now).ok()?;
        entered.retain(|z| !self.zones_let.contains(z));
        (!entered.is_empty()).then_some((jog.target, entered))
    }

    /// After a jog stopped before `zones`: the next press of `target` (once released)
    /// within the confirmation time may jog into them and those it was let into.
    pub fn arm_zone_pass(&mut self, target: JogTarget, zones: &[u8], now: Instant) {
        let mut all = std::mem::take(&mut self.zones_let);
        for z in zones {
            if !all.contains(z) {
                all.push(*z);
            }
        }
        self.zone_pass = Some(zone_watch::ZonePass {
            target,
            zones: all,
            at: now,
        });
    }

    /// The window lost focus: it cannot see a key or button come up, so the jog stops.
    pub fn focus_lost(&mut self, out: &mut Out, now: Instant) {
        if self.hold.focus_lost().is_some() {
            out.push(Request::Stop);
            self.says(
                out,
                Level::Info,
                format!("STOP sent ({})", StopCause::FocusLost.name()),
                now,
            );
        }
    }

    /// The continuous jog running on a held input.
    pub fn held_jog(&self) -> Option<HeldJog> {
        self.hold.jog()
    }

    /// The control `input` is held on now, if any (the pad lights it).
    pub fn held_on(&self, input: JogInput) -> Option<JogTarget> {
        self.hold.on(input)
    }

    /// The STOP latch beside the pad: "STOP (Esc): release the jog controls".
    pub fn stop_latch(&self) -> Option<String> {
        self.hold.latch_text()
    }

    /// The jog choices changed: a refusal or an armed confirmation made under the old
    /// ones goes.
    /// What the checks see changed (the zones read again): every armed second press is
    /// taken back, the step's and the target's.
    pub fn confirmations_lapse(&mut self) {
        self.confirm = None;
        self.zone_pass = None;
        self.lapse_target_confirm();
    }

    pub fn settings_changed(&mut self) {
        self.confirm = None;
        self.zone_pass = None;
        if self
            .feedback
            .as_ref()
            .is_some_and(|m| m.level != Level::Info)
        {
            self.feedback = None;
        }
    }

    /// The jog speed cap at the tool, mm/s.
    pub fn speed_cap(&self) -> f64 {
        self.speed_cap_mm_s
    }

    /// Raises (or lowers) the cap until the window closes; a raise is said in Messages.
    pub fn raise_speed_cap(&mut self, out: &mut Out, mm_s: f64, now: Instant) {
        if !mm_s.is_finite() || mm_s <= 0.0 {
            return;
        }
        let mm_s = mm_s.min(speed_cap::MAX_CAP_MM_S);
        self.speed_cap_mm_s = mm_s;
        out.say(
            Level::Warning,
            format!("jog speed cap set to {mm_s:.0} mm/s at the tool until the window closes"),
            now,
        );
    }

    /// Back to the reduced jog speed.
    pub fn reset_speed_cap(&mut self, out: &mut Out, now: Instant) {
        self.speed_cap_mm_s = speed_cap::REDUCED_SPEED_MM_S;
        out.say(
            Level::Info,
            format!(
                "jog speed cap back to the reduced speed, {:.0} mm/s",
                speed_cap::REDUCED_SPEED_MM_S
            ),
            now,
        );
    }

    /// The motion phase of the move being followed.
    pub fn motion_phase(&self, controller: &ControllerState, now: Instant) -> MotionPhase {
        if self.hold.jog().is_some() {
            return if self.held_jog_ended(controller) {
                MotionPhase::Stopped
            } else {
                MotionPhase::Jogging
            };
        }
        let Some(f) = &self.followed else {
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
    pub fn held_jog_ended(&self, controller: &ControllerState) -> bool {
        let Some(accepted) = self.jog_accepted else {
            return false;
        };
        controller.work.as_ref().is_some_and(|w| {
            w.at > accepted && w.value.axes.iter().all(|(_, a)| !a.status.in_use())
        })
    }

    /// The polled joints within the model's positioning band of the command position.
    /// Off while a jog runs or a followed move's profile has not ended, whatever the
    /// polled joints say.
    pub fn in_position(&self, controller: &ControllerState, model: &RobotModel) -> Option<bool> {
        let actual = controller.joint_position()?;
        if self.hold.jog().is_some() {
            return Some(false);
        }
        let now_moving = self
            .followed
            .as_ref()
            .is_some_and(|f| f.stopped.is_none() && f.accepted.is_none());
        if now_moving {
            return Some(false);
        }
        let command = self.command_position.unwrap_or(actual);
        Some(in_position(&actual, &command, &model.in_position))
    }

    /// The planned move being followed, for the arm view's ghost.
    pub fn followed_move(&self) -> Option<&Move> {
        self.followed.as_ref().map(|f| &f.plan.profile)
    }
}
