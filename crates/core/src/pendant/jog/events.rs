//! What the link's answers and the STOPs do to jogging's own state: a move accepted or
//! refused, a STOP from anywhere, the line lost, and the controller ending a held jog.

use std::time::Instant;

use super::JogState;
use super::hold::StopCause;
use crate::pendant::controller::ControllerState;
use crate::protocol::Command;

impl JogState {
    /// The controller accepted `command`: the move followed starts, a held jog runs, a
    /// STOP ended what moved.
    pub fn acknowledged(&mut self, command: &Command, now: Instant) {
        match command {
            Command::ScaraMoveRelative(_)
            | Command::ScaraMoveAbsolute(_)
            | Command::ScaraMovePosition(_) => self.accepted(command, now),
            Command::Jog(j) if j.is_continuous() && self.hold.jog().is_some() => {
                self.jog_accepted = Some(now);
            }
            Command::Jog(j) if j.distance.0 != 0 => self.accepted(command, now),
            Command::Stop(_) => {
                if let Some(f) = self.followed.as_mut() {
                    f.stopped.get_or_insert(now);
                }
                // The arm stopped short: the command position is where it is.
                self.command_position = None;
            }
            _ => {}
        }
    }

    /// The move followed, if it is `command`, was accepted: its end is the command
    /// position.
    fn accepted(&mut self, command: &Command, now: Instant) {
        if let Some(f) = self
            .followed
            .as_mut()
            .filter(|f| f.plan.command == *command)
        {
            f.accepted = Some(now);
            self.command_position = Some(f.plan.end);
        }
    }

    /// A move or jog the controller (or the link) refused: the jog ends, latched.
    pub fn motion_refused(&mut self) {
        self.followed = None;
        self.hold.stop(StopCause::Refused);
    }

    /// A move got no answer (timed out, or the line was lost while it waited): it is
    /// followed no more.
    pub fn motion_unanswered(&mut self) {
        self.followed = None;
    }

    /// `command` never went out because a STOP came first: if it is the move followed
    /// (not yet accepted), it is followed no more; the latch keeps that STOP's cause.
    pub fn ended_by_stop(&mut self, command: &Command) {
        if self
            .followed
            .as_ref()
            .is_some_and(|f| f.plan.command == *command && f.accepted.is_none())
        {
            self.followed = None;
        }
    }

    /// The pendant's STOP (`cause`): the latch holds, an armed confirmation goes, the
    /// move followed is stopped.
    pub fn stop(&mut self, cause: StopCause, now: Instant) {
        self.hold.stop(cause);
        self.confirm = None;
        self.zone_pass = None;
        if let Some(f) = self.followed.as_mut() {
            f.stopped.get_or_insert(now);
        }
    }

    /// A STOP the operator did not give (the link's, the guardian's): the latch holds,
    /// the move followed is stopped short.
    pub fn stopped_outside(&mut self, cause: StopCause, now: Instant) {
        self.hold.stop(cause);
        self.zone_pass = None;
        if let Some(f) = self.followed.as_mut() {
            f.stopped.get_or_insert(now);
        }
        self.command_position = None;
    }

    /// The line went down: nothing is followed; true when a jog was held (latched).
    pub fn line_lost(&mut self) -> bool {
        let jogging = self.hold.stop(StopCause::LineLost).is_some();
        self.zone_pass = None;
        self.followed = None;
        self.command_position = None;
        jogging
    }

    /// The held jog's label, the first time the controller is seen to have ended it by
    /// itself (a limit, the edge of reach) while the operator still holds it.
    pub fn ended_by_controller(&mut self, controller: &ControllerState) -> Option<String> {
        if !self.held_jog_ended(controller) || std::mem::replace(&mut self.jog_end_said, true) {
            return None;
        }
        Some(
            self.hold
                .jog()
                .map(|j| j.target.label())
                .unwrap_or_default(),
        )
    }
}
