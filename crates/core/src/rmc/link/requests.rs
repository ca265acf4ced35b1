//! The application's requests to the RMC link core: a command checked and queued, a
//! held jog started or released, STOP, reconnect.

use std::time::Instant;

use super::axis::Chain;
use super::{HoldJog, Line, RmcCore, RmcRequest};
use crate::link::RequestId;
use crate::rmc::{AxisId, Command, MoveRelative};
use crate::robot::RelativeTo;

/// What a refused [`RmcRequest::Hold`] is called in its [`super::RmcEvent::NotSent`].
pub const HELD_JOG: &str = "Held jog";

impl RmcCore {
    pub(super) fn handle_app(&mut self, now: Instant, request: RmcRequest) {
        match request {
            RmcRequest::Send { id, axis, command } => self.submit(id, axis, command),
            RmcRequest::Hold { id, axis, jog } => self.hold(now, id, axis, jog),
            RmcRequest::Release { axis } => {
                if let Some(a) = self.axis(axis)
                    && a.chain.take().is_some()
                {
                    a.stop_owed = true;
                }
            }
            RmcRequest::StopAll => {
                self.drop_queued_motion("STOP");
                for a in &mut self.axes {
                    a.chain = None;
                    if a.stoppable() {
                        a.stop_owed = true;
                    }
                }
            }
            RmcRequest::StopsInOrder { axis } => self.stops_in_order(axis),
            RmcRequest::Reconnect => {
                if matches!(self.line, Line::Up) {
                    self.lose_line(now, "closed to reconnect on request".into());
                    self.drop_line = true;
                }
                self.line = Line::Down { retry_at: now };
            }
            RmcRequest::SetPollInterval(d) => self.config.poll_interval = d,
        }
    }

    /// Why motion cannot be queued for `axis` now, if it cannot.
    pub(super) fn motion_refusal(&self, axis: AxisId) -> Option<String> {
        let Some(a) = self.axes.get(axis.index()) else {
            return Some(format!(
                "{axis} is not one of the {} axes polled",
                self.axes.len()
            ));
        };
        if self.closing.is_some() {
            return Some("the link is closing".into());
        }
        if !matches!(self.line, Line::Up) {
            return Some("the RMC is not connected".into());
        }
        if a.last.is_some_and(|s| !s.bits.enabled()) {
            return Some(format!("{axis} is not enabled: enable it first"));
        }
        if a.chain.is_some() {
            return Some(format!("a jog runs on {axis}"));
        }
        None
    }

    pub(super) fn submit(&mut self, id: RequestId, axis: AxisId, command: Command) {
        if let Err(e) = command.check() {
            return self.not_sent(id, axis, command.name(), e.to_string());
        }
        let refusal = if command.moves() {
            self.motion_refusal(axis)
        } else if axis.index() >= self.axes.len() {
            Some(format!(
                "{axis} is not one of the {} axes polled",
                self.axes.len()
            ))
        } else if self.closing.is_some() {
            Some("the link is closing".into())
        } else {
            None
        };
        match refusal {
            Some(why) => self.not_sent(id, axis, command.name(), why),
            None => self.queue.push_back((id, axis, command)),
        }
    }

    /// A Release (of `axis`) or STOP (`None`) again, in order: a jog it overtook on its
    /// way ends (not sent if none of its moves went out, else Stop (6) owed); queued
    /// motion is dropped after a STOP. An axis with no jog is left alone (its Stop (6)
    /// was owed by the first copy).
    fn stops_in_order(&mut self, axis: Option<AxisId>) {
        if axis.is_none() {
            self.drop_queued_motion("STOP came first");
        }
        let why = match axis {
            Some(_) => "released before it went out",
            None => "STOP came first",
        };
        let mut refused = Vec::new();
        for a in &mut self.axes {
            if axis.is_some_and(|x| x != a.id) {
                continue;
            }
            let Some(chain) = a.chain.take() else {
                continue;
            };
            if chain.started || a.may_move {
                a.stop_owed = true;
            } else {
                refused.push((chain.id, a.id));
            }
        }
        for (id, axis) in refused {
            self.not_sent(id, axis, HELD_JOG, why);
        }
    }

    pub(super) fn hold(&mut self, now: Instant, id: RequestId, axis: AxisId, jog: HoldJog) {
        let probe = Command::MoveRelative(MoveRelative {
            distance: jog.direction,
            speed: jog.speed,
            accel: jog.accel,
            decel: jog.decel,
            relative_to: RelativeTo::Target,
        });
        if let Err(e) = probe.check() {
            return self.not_sent(id, axis, HELD_JOG, e.to_string());
        }
        if let Some(why) = self.motion_refusal(axis) {
            return self.not_sent(id, axis, HELD_JOG, why);
        }
        // The request itself renews the lease (as submitting a jog does on Format B).
        self.lease_renewed = Some(now);
        let lease = self.lease_secs();
        if let Some(a) = self.axis(axis) {
            a.chain = Some(Chain::new(id, jog, lease));
        }
    }
}
