//! Previews for the arm view's ghost (a jog button's next step, the "step here" target,
//! the move in progress) and the "step here" target itself: filled in from the view,
//! edited in the jog panel, moved to only when the operator presses "Go to target", after
//! the same checks as every move.

use std::time::{Duration, Instant};

use super::plan::{self as jog, JogAxis, PlannedStep, Refusal};
use super::{JogCx, JogState};
use crate::pendant::controller::ControllerState;
use crate::pendant::teach::TeachPoint;
use crate::pendant::{Level, MotionPhase, Out};
use crate::protocol::Direction;
use crate::robot::{Joints, Pose, jog_delta_to_work, tip_in_work};

/// How long a "press again to confirm" for an arm flip stays armed.
const CONFIRM_FOR: Duration = super::CONFIRM_FOR;

/// A target in the work frame selected when it was set.
#[derive(Clone, Debug, PartialEq)]
pub struct StepTarget {
    /// Tool tip, work frame: X, Y, Z mm, R deg.
    pub pose: Pose,
    /// The work and tool frames it was set in.
    pub work: u8,
    pub tool: u8,
    /// An arm flip asked to be confirmed at this time.
    confirm: Option<Instant>,
}

/// What a step would do, for the ghost: where its tool tip aims (base frame), the joints
/// of the end pose when known, and the planner's answer.
#[derive(Clone, Debug)]
pub struct StepPreview {
    pub label: String,
    /// The move was sent and runs (its checks were passed, its second press given).
    pub in_progress: bool,
    pub tip_base: Pose,
    pub joints: Option<Joints>,
    pub plan: Result<PlannedStep, Refusal>,
}

impl JogState {
    /// The target set from the arm view, if any.
    pub fn step_target(&self) -> Option<&StepTarget> {
        self.step_target.as_ref()
    }

    /// Sets the target to the tool tip at `pose` in the selected work frame. Refused
    /// (with a message) until the frames are known.
    pub fn set_step_target(
        &mut self,
        controller: &ControllerState,
        out: &mut Out,
        pose: Pose,
        now: Instant,
    ) {
        let Some((work, tool)) = controller.frame_numbers() else {
            return self.says(
                out,
                Level::Warning,
                "no target: the frames are not known yet",
                now,
            );
        };
        self.step_target = Some(StepTarget {
            pose,
            work,
            tool,
            confirm: None,
        });
        self.says(
            out,
            Level::Info,
            format!(
                "target X {:.3} Y {:.3} (work {work}): press \"Go to target\" to move",
                pose.x, pose.y
            ),
            now,
        );
    }

    /// Edits the target's pose (the jog panel's fields); a pending confirmation lapses.
    pub fn edit_step_target(&mut self, pose: Pose) {
        if let Some(t) = self.step_target.as_mut()
            && t.pose != pose
        {
            t.pose = pose;
            t.confirm = None;
        }
    }

    /// A pending "Go to target" confirmation lapses (the target stays).
    pub(super) fn lapse_target_confirm(&mut self) {
        if let Some(t) = self.step_target.as_mut() {
            t.confirm = None;
        }
    }

    pub fn clear_step_target(&mut self) {
        self.step_target = None;
    }

    /// What "Go to target" would do now.
    pub fn preview_target(&self, cx: &JogCx, now: Instant) -> Option<StepPreview> {
        let t = self.step_target.as_ref()?;
        let arm = self.arm_now(cx, now).ok();
        let tip_base = arm.map_or(t.pose, |a| a.work.work_to_base(&t.pose));
        let plan = match (frames_changed(cx.controller, t), arm) {
            (Some(why), _) => Err(Refusal::FramesChanged(why)),
            (None, None) => Err(Refusal::NoPosition),
            (None, Some(a)) => jog::plan_to(cx.model, cx.kin, &self.sent(cx), &t.pose, &a),
        };
        Some(StepPreview {
            label: "target".into(),
            in_progress: false,
            tip_base,
            joints: plan.as_ref().ok().map(|p| p.end),
            plan,
        })
    }

    /// What "Go" on a taught point would do now, for its ghost.
    pub fn preview_go(&self, cx: &JogCx, point: &TeachPoint, now: Instant) -> StepPreview {
        let pose = Pose::from_wire(point.pose);
        let arm = self.arm_now(cx, now).ok();
        let tip_base = arm.map_or(pose, |a| a.work.work_to_base(&pose));
        let frames = cx.controller.frame_numbers().and_then(|(work, tool)| {
            crate::pendant::teach::check_go(point, work, tool)
                .err()
                .map(|e| e.to_string())
        });
        let plan = match (frames, arm) {
            (Some(why), _) => Err(Refusal::FramesChanged(why)),
            (None, None) => Err(Refusal::NoPosition),
            (None, Some(a)) => jog::plan_go(cx.model, cx.kin, &self.sent(cx), point, &a),
        };
        StepPreview {
            label: point.name.clone(),
            in_progress: false,
            tip_base,
            joints: plan.as_ref().ok().map(|p| p.end),
            plan,
        }
    }

    /// What a move to position record `rec` would do now, for its ghost: Go to No. N
    /// hovered (the controller's record) or a row of the write preview (the draft's).
    pub fn preview_position(
        &self,
        cx: &JogCx,
        rec: &crate::protocol::PositionRecord,
        now: Instant,
    ) -> Option<StepPreview> {
        let arm = self.arm_now(cx, now).ok();
        let plan = match &arm {
            None => Err(Refusal::NoPosition),
            Some(a) => jog::plan_position_go(cx.model, cx.kin, &self.sent(cx), rec, a),
        };
        let tip_base = match (&plan, &arm) {
            (Ok(p), Some(a)) => a.work.work_to_base(&p.end_work),
            (Err(_), Some(a)) => {
                // The record's place as far as it says (axes it lacks stay where they are).
                let here = crate::robot::tip_in_work(cx.kin, &a.joints, &a.work, &a.tool);
                let mut w = here.to_wire();
                for (i, axis) in [
                    crate::protocol::Axis::A1,
                    crate::protocol::Axis::A2,
                    crate::protocol::Axis::A3,
                    crate::protocol::Axis::A4,
                ]
                .into_iter()
                .enumerate()
                {
                    if let Some(v) = rec.coords.get(axis) {
                        w[i] = v.0;
                    }
                }
                a.work.work_to_base(&Pose::from_wire(w))
            }
            _ => return None,
        };
        Some(StepPreview {
            label: format!("No. {}", rec.number),
            in_progress: false,
            tip_base,
            joints: plan.as_ref().ok().map(|p| p.end),
            plan,
        })
    }

    /// "Go to target": 2D4H after the readiness, frame and move checks; an arm flip
    /// asks for a second press. The target stays set (a refused one can be edited).
    pub fn go_to_target(&mut self, cx: &JogCx, out: &mut Out, now: Instant) {
        let Some(t) = self.step_target.clone() else {
            return;
        };
        if !self.may_send_move(cx, out, "move", now) {
            return;
        }
        if let Some(why) = frames_changed(cx.controller, &t) {
            return self.says(out, Level::Warning, format!("refused: {why}"), now);
        }
        let plan = self
            .arm_now(cx, now)
            .and_then(|a| jog::plan_to(cx.model, cx.kin, &self.sent(cx), &t.pose, &a));
        let plan = match plan {
            Ok(p) => p,
            Err(why) => return self.refused(out, &why, now),
        };
        let confirmed = t
            .confirm
            .is_some_and(|at| now.duration_since(at) < CONFIRM_FOR);
        if !confirmed && let Some(text) = plan.confirm_text("the target", "\"Go to target\" again")
        {
            if let Some(st) = self.step_target.as_mut() {
                st.confirm = Some(now);
            }
            return self.says(out, Level::Warning, text, now);
        }
        // Sent: the ghost now shows the move in progress.
        self.step_target = None;
        self.send(out, plan);
        self.says(
            out,
            Level::Info,
            format!("go to target X {:.3} Y {:.3}: sent", t.pose.x, t.pose.y),
            now,
        );
    }

    /// What a click on a jog button would do now: the planner's answer, and where the
    /// step aims even when it is refused (a joint step's end joints; a Cartesian step's
    /// tool tip from the actual position).
    pub fn preview_jog(
        &self,
        cx: &JogCx,
        axis: JogAxis,
        dir: Direction,
        now: Instant,
    ) -> Option<StepPreview> {
        let arm = self.arm_now(cx, now).ok()?;
        let plan = self.preview_step(cx, axis, dir, now);
        let settings = cx.settings;
        let step = if dir == Direction::Positive {
            settings.step
        } else {
            -settings.step
        };
        let kin = cx.kin;
        let (tip_base, joints) = match &plan {
            Ok(p) => (arm.tool.flange_to_tip(&kin.forward(&p.end)), Some(p.end)),
            Err(_) if axis.is_joint() => {
                let mut end = arm.joints.to_array();
                end[axis.index()] += step;
                let end = Joints::from_array(end);
                (arm.tool.flange_to_tip(&kin.forward(&end)), Some(end))
            }
            Err(_) => {
                let mut delta = [0.0; 4];
                delta[axis.index()] = step;
                let flange_r = kin.forward(&arm.joints).r;
                let d = jog_delta_to_work(
                    &Pose::from_array(delta),
                    settings.frame,
                    &arm.work,
                    &arm.tool,
                    flange_r,
                );
                let now_work = tip_in_work(kin, &arm.joints, &arm.work, &arm.tool);
                let end = Pose::new(
                    now_work.x + d.x,
                    now_work.y + d.y,
                    now_work.z + d.z,
                    now_work.r + d.r,
                );
                (arm.work.work_to_base(&end), None)
            }
        };
        let sign = if dir == Direction::Positive { "+" } else { "-" };
        Some(StepPreview {
            in_progress: false,
            label: format!(
                "{}{sign} {} {}",
                axis.name(),
                settings.step,
                axis.unit().trim()
            ),
            tip_base,
            joints,
            plan,
        })
    }

    /// The move in progress (sent and not yet ended), as a preview of its end.
    pub fn preview_followed(&self, cx: &JogCx, now: Instant) -> Option<StepPreview> {
        let f = self.followed.as_ref().filter(|f| f.stopped.is_none())?;
        if f.accepted.is_some() && self.motion_phase(cx.controller, now) == MotionPhase::Done {
            return None;
        }
        let tool = cx.controller.tool_frame()?;
        Some(StepPreview {
            label: "moving to".into(),
            in_progress: true,
            tip_base: tool.flange_to_tip(&cx.kin.forward(&f.plan.end)),
            joints: Some(f.plan.end),
            plan: Ok(f.plan.clone()),
        })
    }
}

/// The target's frames differ from the selected ones: the same numbers would mean
/// another place.
fn frames_changed(controller: &ControllerState, t: &StepTarget) -> Option<String> {
    let (work, tool) = controller.frame_numbers()?;
    (work != t.work || tool != t.tool).then(|| {
        format!(
            "the target was set in work {} / tool {}, work {work} / tool {tool} is selected now",
            t.work, t.tool
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pendant::tests::submitted;
    use crate::pendant::{Pendant, Settings};
    use crate::protocol::Command;
    use crate::robot::{RobotModel, Scara};

    fn ready_at(joints: Joints, now: Instant) -> Pendant {
        let mut p = Pendant::new(Settings::default(), RobotModel::default_model());
        let kin = Scara::new(&p.model);
        for event in crate::pendant::script::ready_controller(&kin, joints) {
            p.handle_event(now, event);
        }
        p.take_requests();
        p
    }

    #[test]
    fn step_here_only_fills_the_target_and_go_sends_one_checked_2d4h() {
        let now = Instant::now();
        let mut p = ready_at(Joints::new(30.0, 60.0, 50.0, 0.0), now);
        p.set_step_target(Pose::new(300.0, 100.0, 50.0, 90.0), now);
        assert!(
            submitted(&mut p).is_empty(),
            "setting a target moves nothing"
        );
        let preview = p.preview_target(now).map(|t| t.plan.is_ok());
        assert_eq!(preview, Some(true));
        p.go_to_target(now);
        let sent = submitted(&mut p);
        assert!(
            matches!(sent.as_slice(), [Command::ScaraMoveAbsolute(m)] if m.targets.get(crate::protocol::Axis::A1).map(|t| t.0) == Some(300_000)),
            "{sent:?}"
        );
        assert!(p.step_target().is_none(), "a sent target is done");
        assert!(
            p.preview_followed(now).is_some(),
            "the move in progress is the ghost"
        );
    }

    #[test]
    fn an_unreachable_target_is_refused_with_its_reason_and_nothing_is_sent() {
        let now = Instant::now();
        let mut p = ready_at(Joints::new(30.0, 60.0, 50.0, 0.0), now);
        p.set_step_target(Pose::new(520.0, 0.0, 50.0, 90.0), now);
        let refusal = p
            .preview_target(now)
            .and_then(|t| t.plan.err())
            .map(|e| e.to_string());
        assert!(
            refusal
                .as_deref()
                .is_some_and(|r| r.contains("out of reach")),
            "{refusal:?}"
        );
        p.go_to_target(now);
        assert!(submitted(&mut p).is_empty());
        let said = p
            .jog
            .feedback
            .as_ref()
            .map(|m| m.text.clone())
            .unwrap_or_default();
        assert_eq!(said, "refused: target out of reach", "one short sentence");
        let detail = p.jog.feedback.as_ref().and_then(|m| m.detail.clone());
        assert!(
            detail.is_some_and(|d| d.starts_with("refused: out of reach") && d.contains(" mm")),
            "the details are kept for the hover"
        );
        assert!(
            p.step_target().is_some(),
            "a refused target stays to be edited"
        );
    }

    #[test]
    fn a_refused_cartesian_jog_still_shows_where_it_aims() {
        let now = Instant::now();
        let p = ready_at(Joints::new(0.0, 20.0, 50.0, 0.0), now);
        let mut p = p;
        p.settings.jog.step = 50.0;
        let preview = p.preview_jog(JogAxis::X, Direction::Positive, now);
        let Some(preview) = preview else {
            panic!("no preview")
        };
        assert!(preview.plan.is_err());
        let start = p.kinematics().forward(&Joints::new(0.0, 20.0, 50.0, 0.0));
        assert!(
            (preview.tip_base.x - start.x - 50.0).abs() < 1e-6,
            "{preview:?}"
        );
        assert_eq!(preview.label, "X+ 50 mm");
    }
}
