//! The Delta RMC151's axes beside the arm (DESIGN.md "Devices"): the connection, each
//! axis's last status, the commands sent and what became of them, and steps and
//! hold-to-run on an axis with the arm's hold machine and STOP latch. Sans-IO: link
//! events and the time come in, calls for the RMC link go out.

#[cfg(test)]
mod lamp_tests;
pub mod lamps;
pub mod settings;
#[cfg(test)]
mod tests;

use std::collections::VecDeque;
use std::time::Instant;

use super::connection::LineState;
use super::jog::JogMode;
use super::jog::hold::{HoldAction, HoldMachine, JogInput, Press, StopCause};
use super::{Level, Message};
use crate::link::RequestId;
use crate::protocol::Direction;
use crate::rmc::{
    AxisId, AxisStatus, Command, ControllerStatus, HoldJog, MoveRelative, RmcEvent, TgPhase,
};
use crate::robot::RelativeTo;
pub use settings::{RmcJogSettings, RmcSettings};

/// Commands kept in the axis panel's log.
const KEEP_LOG: usize = 200;

/// What the pendant says of a command whose ACK never came: it may have arrived.
pub const UNACKNOWLEDGED: &str = "sent, not acknowledged: check the axis before sending again";

/// One of an axis's jog buttons: the axis and a direction.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct AxisJog {
    pub axis: AxisId,
    pub direction: Direction,
}

impl AxisJog {
    fn sign(self) -> f32 {
        match self.direction {
            Direction::Positive => 1.0,
            Direction::Negative => -1.0,
        }
    }

    /// "Axis 1+".
    pub fn label(self) -> String {
        let sign = if self.sign() > 0.0 { "+" } else { "-" };
        format!("{}{sign}", self.axis)
    }
}

/// What the axis panel asks for.
#[derive(Clone, Debug, PartialEq)]
pub enum AxisIntent {
    /// A jog input on an axis's − or + (reported every frame while down, once when up).
    Jog(JogInput, Press<AxisJog>),
    /// Enable/Disable Axis (97).
    Enable(AxisId, bool),
    /// Clear Faults (4).
    ClearFaults(AxisId),
    /// Stop (Closed Loop) (6) for one axis, at STOP's deceleration.
    Stop(AxisId),
    /// The panel's new jog choices.
    Settings(RmcJogSettings),
    /// The RMC's connection settings (applied on Connect).
    Connection(RmcSettings),
    /// Open the RMC's connection (closing the current one).
    Connect,
    /// Close it.
    Disconnect,
}

/// What the pendant asks of the RMC link.
#[derive(Clone, Debug, PartialEq)]
pub enum AxisCall {
    Send(AxisId, Command),
    Hold(AxisId, HoldJog),
    Release(AxisId),
    RenewLease,
    Connect,
    Disconnect,
}

/// An axis as last polled.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct AxisView {
    /// The last status whose ACK matched REQ (its In Position and TG bits are valid).
    pub status: Option<AxisStatus>,
    /// The last status read at all (positions are valid even while ACK is awaited).
    pub latest: Option<AxisStatus>,
    pub at: Option<Instant>,
    /// A command sent whose ACK is awaited.
    pub awaiting: bool,
    /// The move acknowledged and followed until the target generator is done.
    pub following: Option<Command>,
    /// The target generator's phases seen (trusted statuses, each change once) since the
    /// last move was acknowledged: the lamps' history of that move.
    pub phases: Vec<TgPhase>,
    /// The command last written to the axis (the link's own too), as it went on the line.
    pub sent: Option<Command>,
    /// The last command the RMC took (its ACK seen): what the lamps' words follow.
    pub taken: Option<Command>,
}

impl AxisView {
    pub fn enabled(&self) -> bool {
        self.status.is_some_and(|s| s.bits.enabled())
    }

    pub fn phase(&self) -> TgPhase {
        self.status.map_or(TgPhase::Complete, |s| s.bits.phase())
    }
}

/// One line of the command log: what was sent and what became of it.
#[derive(Clone, Debug, PartialEq)]
pub struct LogLine {
    pub at: Instant,
    pub axis: Option<AxisId>,
    pub text: String,
}

/// The RMC151 as the pendant knows it.
pub struct RmcAxes {
    pub line: LineState,
    /// CPU Module ID (17 on an RMC151E).
    pub module: Option<u32>,
    pub controller: Option<ControllerStatus>,
    pub axes: Vec<AxisView>,
    pub log: VecDeque<LogLine>,
    pub hold: HoldMachine<AxisJog>,
    /// The last word beside the axis buttons.
    pub feedback: Option<Message>,
    /// Requests sent and not yet answered, with what they were.
    pending: Vec<(RequestId, AxisId, Command)>,
    calls: Vec<AxisCall>,
}

impl RmcAxes {
    pub fn new(axes: usize) -> Self {
        Self {
            line: LineState::Closed,
            module: None,
            controller: None,
            axes: vec![AxisView::default(); axes],
            log: VecDeque::new(),
            hold: HoldMachine::default(),
            feedback: None,
            pending: Vec::new(),
            calls: Vec::new(),
        }
    }

    pub fn take_calls(&mut self) -> Vec<AxisCall> {
        std::mem::take(&mut self.calls)
    }

    pub fn view(&self, axis: AxisId) -> Option<&AxisView> {
        self.axes.get(axis.index())
    }

    fn log(&mut self, now: Instant, axis: Option<AxisId>, text: String) {
        if self.log.len() >= KEEP_LOG {
            self.log.pop_front();
        }
        self.log.push_back(LogLine {
            at: now,
            axis,
            text,
        });
    }

    fn says(&mut self, level: Level, text: String, now: Instant) -> (Level, String) {
        self.feedback = Some(Message {
            level,
            text: text.clone(),
            at: now,
            detail: None,
        });
        (level, text)
    }

    /// The id of a call sent: the link numbers its requests in the order they came.
    /// (The link's `Sent` event records what really went out under that id, so a held
    /// jog needs no entry here.)
    pub fn sent(&mut self, id: RequestId, axis: AxisId, command: Command) {
        self.record(id, axis, command);
    }

    /// Keeps what request `id` is (replacing what was kept for it).
    fn record(&mut self, id: RequestId, axis: AxisId, command: Command) {
        match self.pending.iter_mut().find(|(p, ..)| *p == id) {
            Some(entry) => *entry = (id, axis, command),
            None => self.pending.push((id, axis, command)),
        }
    }

    /// Applies one intent; what the operator should read comes back.
    pub fn apply(
        &mut self,
        intent: AxisIntent,
        settings: &mut RmcSettings,
        now: Instant,
    ) -> Option<(Level, String)> {
        match intent {
            AxisIntent::Jog(input, press) => self.jog_input(input, press, settings, now),
            AxisIntent::Enable(axis, on) => self.send(axis, Command::Enable(on), now),
            AxisIntent::ClearFaults(axis) => self.send(axis, Command::ClearFaults, now),
            AxisIntent::Stop(axis) => {
                let decel = settings.stop_decel();
                if self.hold.jog().is_some_and(|j| j.target.axis == axis) {
                    self.stop(StopCause::Button);
                }
                self.send(axis, Command::Stop { decel }, now)
            }
            AxisIntent::Settings(jog) => {
                settings.jog = jog;
                None
            }
            AxisIntent::Connection(s) => {
                *settings = s;
                None
            }
            AxisIntent::Connect => {
                self.line = LineState::Opening;
                self.axes = vec![AxisView::default(); settings.axis_count()];
                self.calls.push(AxisCall::Connect);
                None
            }
            AxisIntent::Disconnect => {
                self.stop(StopCause::LineLost);
                self.line = LineState::Closed;
                self.calls.push(AxisCall::Disconnect);
                None
            }
        }
    }

    fn send(&mut self, axis: AxisId, command: Command, now: Instant) -> Option<(Level, String)> {
        if !self.line.is_up() {
            return Some(self.says(
                Level::Warning,
                format!(
                    "{} not sent to {axis}: the RMC is not connected",
                    command.name()
                ),
                now,
            ));
        }
        self.calls.push(AxisCall::Send(axis, command));
        None
    }

    fn jog_input(
        &mut self,
        input: JogInput,
        press: Press<AxisJog>,
        settings: &RmcSettings,
        now: Instant,
    ) -> Option<(Level, String)> {
        let before = self.hold.jog();
        match self.hold.report(input, press) {
            HoldAction::None => None,
            HoldAction::Renew => {
                self.calls.push(AxisCall::RenewLease);
                None
            }
            HoldAction::Release => {
                let j = before?;
                let axis = j.target.axis;
                // Pressed and released within one frame: the hold has not gone out, and
                // never will (a Release would overtake it on the link's STOP channel
                // and find no jog to stop).
                let queued = self
                    .calls
                    .iter()
                    .position(|c| matches!(c, AxisCall::Hold(a, _) if *a == axis));
                let text = match queued {
                    Some(at) => {
                        self.calls.remove(at);
                        format!(
                            "{} released before it started: nothing sent",
                            j.target.label()
                        )
                    }
                    None => {
                        self.calls.push(AxisCall::Release(axis));
                        format!("{} released: Stop (6) sent", j.target.label())
                    }
                };
                self.says(Level::Info, text, now);
                None
            }
            HoldAction::Latched(target) => Some(self.says(
                Level::Warning,
                format!(
                    "{} not started: {}",
                    target.label(),
                    self.hold.latch_text().unwrap_or_default()
                ),
                now,
            )),
            HoldAction::Press(target) => self.press(input, target, settings, now),
        }
    }

    fn press(
        &mut self,
        input: JogInput,
        target: AxisJog,
        settings: &RmcSettings,
        now: Instant,
    ) -> Option<(Level, String)> {
        let jog = settings.jog;
        let units = settings.units(target.axis);
        let refuse = |why: String| format!("{} refused: {why}", target.label());
        if let Err(why) = jog.check() {
            return Some(self.says(Level::Warning, refuse(why), now));
        }
        let limits = settings.limits(target.axis);
        if let Err(why) = limits.check() {
            return Some(self.says(Level::Warning, refuse(why), now));
        }
        if !self.line.is_up() {
            return Some(self.says(
                Level::Warning,
                refuse("the RMC is not connected".into()),
                now,
            ));
        }
        if let Some(why) = self.not_ready(target.axis) {
            return Some(self.says(Level::Warning, refuse(why), now));
        }
        let status = self
            .view(target.axis)
            .and_then(|v| v.status)
            .unwrap_or_default();
        match jog.mode {
            JogMode::Step => {
                let base = match jog.relative_to {
                    RelativeTo::Command => status.command_position,
                    RelativeTo::Actual => status.actual_position,
                    RelativeTo::Target => status.target_position,
                };
                if let Err(why) = limits.check_end(base + target.sign() * jog.step, units) {
                    return Some(self.says(Level::Warning, refuse(why), now));
                }
                let command = Command::MoveRelative(MoveRelative {
                    distance: target.sign() * jog.step,
                    speed: jog.speed,
                    accel: jog.accel,
                    decel: jog.decel,
                    relative_to: jog.relative_to,
                });
                self.calls.push(AxisCall::Send(target.axis, command));
                Some(self.says(
                    Level::Info,
                    format!(
                        "{}: Move Relative {} relative to {}",
                        target.label(),
                        target.sign() * jog.step,
                        jog.relative_to.name()
                    ),
                    now,
                ))
            }
            JogMode::Continuous => {
                if let Some(limit) = limits.ahead(target.sign())
                    && (limit - status.target_position) * target.sign() <= 0.0
                {
                    return Some(self.says(
                        Level::Warning,
                        refuse(format!("it is at its soft limit {limit:.3} {units}")),
                        now,
                    ));
                }
                let hold = HoldJog {
                    direction: target.sign(),
                    speed: jog.speed,
                    accel: jog.accel,
                    decel: jog.decel,
                };
                self.calls.push(AxisCall::Hold(target.axis, hold));
                self.hold.started(input, target, now);
                // Said in Messages; beside the buttons it shows while the jog runs
                // (`jog_line`), never after.
                Some((Level::Info, format!("jogging {}", target.label())))
            }
        }
    }
}

impl RmcAxes {
    /// STOP, whoever sent it: a held axis jog ends and latches while its input is down.
    /// (The window sends Stop (6) to every axis through the link.)
    pub fn stop(&mut self, cause: StopCause) {
        // Motion asked for earlier this frame has not gone out: it never will.
        self.calls.retain(|c| match c {
            AxisCall::Send(_, command) => !command.moves(),
            AxisCall::Hold(..) => false,
            _ => true,
        });
        if let Some(j) = self.hold.stop(cause) {
            self.calls.push(AxisCall::Release(j.target.axis));
        }
    }

    /// A held jog on `axis` stops once it comes within stopping distance of the soft
    /// limit ahead of it: the distance Stop (6) needs at STOP's deceleration, and one poll
    /// more of travel, since the pendant sees the axis only when it polls [I: the link's
    /// 20 ms poll, doubled for a late one].
    pub fn keep_limits(
        &mut self,
        axis: AxisId,
        status: &AxisStatus,
        settings: &RmcSettings,
        now: Instant,
    ) -> Option<(Level, String)> {
        const POLL_MARGIN_S: f32 = 0.04;
        let jog = self.hold.jog().filter(|j| j.target.axis == axis)?;
        let limit = settings.limits(axis).ahead(jog.target.sign())?;
        let speed = status.target_velocity.abs();
        let braking = speed * speed / (2.0 * settings.stop_decel()) + speed * POLL_MARGIN_S;
        let left = (limit - status.target_position) * jog.target.sign();
        if left > braking {
            return None;
        }
        self.stop(StopCause::SoftLimit);
        let units = settings.units(axis);
        Some(self.says(
            Level::Warning,
            format!(
                "{} stopped short of its soft limit {limit:.3} {units} (at {:.3})",
                jog.target.label(),
                status.target_position
            ),
            now,
        ))
    }

    /// The window lost focus: it will see no release, so a held jog stops (its Release
    /// goes out), and the stop is said (beside the buttons once they are released, and
    /// back for Messages): a STOP the operator did not give is never silent.
    pub fn focus_lost_at(&mut self, now: Instant) -> Option<(Level, String)> {
        let j = self.hold.focus_lost()?;
        self.calls.push(AxisCall::Release(j.target.axis));
        Some(self.says(
            Level::Warning,
            format!(
                "{}: Stop (6) sent: {}",
                j.target.label(),
                StopCause::FocusLost.name()
            ),
            now,
        ))
    }

    fn command_of(&mut self, id: Option<RequestId>, remove: bool) -> Option<(AxisId, Command)> {
        let id = id?;
        let at = self.pending.iter().position(|(p, ..)| *p == id)?;
        let (_, axis, command) = if remove {
            self.pending.remove(at)
        } else {
            *self.pending.get(at)?
        };
        Some((axis, command))
    }

    /// Applies one event from the RMC link; what the operator should read comes back.
    pub fn handle_event(&mut self, now: Instant, event: RmcEvent) -> Option<(Level, String)> {
        match event {
            RmcEvent::LineUp { name, .. } => {
                self.line = LineState::Up {
                    line: name.clone(),
                    since: now,
                };
                Some((Level::Info, format!("RMC connected: {name}")))
            }
            RmcEvent::LineDown { reason, .. } => {
                self.stop(StopCause::LineLost);
                self.pending.clear();
                for v in &mut self.axes {
                    v.awaiting = false;
                    v.following = None;
                }
                self.line = LineState::Down {
                    reason: reason.clone(),
                    since: now,
                };
                Some(self.says(Level::Error, format!("RMC line down: {reason}"), now))
            }
            RmcEvent::Module { cpu_id } => {
                self.module = Some(cpu_id);
                match cpu_id {
                    crate::rmc::registers::RMC151E_ID | 16 => None,
                    other => Some((
                        Level::Warning,
                        format!(
                            "the RMC reports CPU Module ID {other}, not an RMC150E/151E (16/17)"
                        ),
                    )),
                }
            }
            RmcEvent::Controller { status, .. } => {
                self.controller = Some(status);
                None
            }
            RmcEvent::Status {
                axis,
                status,
                trusted,
                at,
            } => {
                let done = self.axes.get_mut(axis.index()).and_then(|v| {
                    v.latest = Some(status);
                    v.at = Some(at);
                    v.awaiting = !trusted;
                    if !trusted {
                        return None;
                    }
                    v.status = Some(status);
                    let phase = status.bits.phase();
                    if v.phases.last() != Some(&phase) {
                        v.phases.push(phase);
                    }
                    let finished = status.bits.tg_done() && status.target_velocity == 0.0;
                    v.following.take_if(|_| finished)
                });
                if let Some(command) = done {
                    let s = status;
                    let in_pos = if s.bits.in_position() {
                        "in position"
                    } else {
                        "not in position"
                    };
                    self.log(
                        now,
                        Some(axis),
                        format!(
                            "{} done: command {:.3}, actual {:.3}, {in_pos}",
                            command.name(),
                            s.command_position,
                            s.actual_position
                        ),
                    );
                }
                None
            }
            RmcEvent::Sent {
                id,
                axis,
                command,
                req,
                ..
            } => {
                let who = if id.is_some() {
                    ""
                } else {
                    " (the link's own)"
                };
                self.log(
                    now,
                    Some(axis),
                    format!("sent {command}, REQ {}{who}", u8::from(req)),
                );
                // What went out under a request's id is what it is (a held jog's first
                // move, not the request that asked for it).
                if let Some(id) = id {
                    self.record(id, axis, command);
                }
                if let Some(v) = self.axes.get_mut(axis.index()) {
                    v.awaiting = true;
                    v.following = None;
                    v.sent = Some(command);
                }
                None
            }
            RmcEvent::Acknowledged { id, axis, .. } => {
                let command = self.command_of(id, true).map(|(_, c)| c);
                let name = command.map_or("the link's command", |c| c.name());
                self.log(now, Some(axis), format!("ACK = REQ: {name} received"));
                if let Some(v) = self.axes.get_mut(axis.index()) {
                    v.taken = v.sent.take().or(command);
                    v.following = command.filter(Command::moves);
                    if v.following.is_some() {
                        v.phases.clear();
                    }
                }
                None
            }
            RmcEvent::NotSent {
                id,
                axis,
                what,
                reason,
            } => {
                self.command_of(Some(id), true);
                self.stop_jog_of(Some(axis), StopCause::Refused);
                Some(self.says(Level::Warning, format!("{what} not sent: {reason}"), now))
            }
            RmcEvent::Unconfirmed { id, axis, answered } => {
                let name = self
                    .command_of(id, true)
                    .map_or("a command", |(_, c)| c.name());
                if let Some(v) = self.axes.get_mut(axis.index()) {
                    v.sent = None;
                }
                self.stop_jog_of(Some(axis), StopCause::Refused);
                let how = if answered {
                    "the RMC answered the write, and ACK never came to equal REQ"
                } else {
                    "no reply to the write, and ACK did not change"
                };
                Some(self.says(
                    Level::Error,
                    format!("{axis}: {name} {UNACKNOWLEDGED} ({how}; it is not sent again)"),
                    now,
                ))
            }
            RmcEvent::Exception { id, function, code } => {
                let what = self.command_of(id, true);
                self.stop_jog_of(what.map(|(a, _)| a), StopCause::Refused);
                let name = what.map_or("a request".to_string(), |(a, c)| {
                    format!("{} to {a}", c.name())
                });
                Some(self.says(
                    Level::Error,
                    format!(
                        "the RMC refused {name}: Modbus exception {:02} ({}) to function {function}",
                        code.0,
                        code.name()
                    ),
                    now,
                ))
            }
            RmcEvent::SafetyStop { why, axes } => {
                match why {
                    crate::rmc::link::SafetyStop::LeaseLapsed => self.stop(StopCause::LeaseLapsed),
                    crate::rmc::link::SafetyStop::Guardian => self.stop(StopCause::Guardian),
                    _ => {}
                }
                let names: Vec<String> = axes.iter().map(|a| a.to_string()).collect();
                Some(self.says(
                    Level::Warning,
                    format!(
                        "Stop (6) sent by the link to {}: {}",
                        names.join(", "),
                        why.text()
                    ),
                    now,
                ))
            }
            RmcEvent::JogEnded { axis, why } => {
                self.stop_jog_of(Some(axis), StopCause::Refused);
                Some(self.says(Level::Warning, format!("jog ended: {why}"), now))
            }
            RmcEvent::Ignored { why } => {
                self.log(now, None, format!("ignored: {why}"));
                None
            }
            RmcEvent::Dropped(_)
            | RmcEvent::FrameSent { .. }
            | RmcEvent::FrameReceived { .. }
            | RmcEvent::Garbage { .. }
            | RmcEvent::Timeout { .. } => None,
            RmcEvent::Closed => {
                self.line = LineState::Closed;
                None
            }
        }
    }

    /// Why `axis` takes no motion from the pendant now, if it does not: disabled, halted,
    /// the controller in PROGRAM mode or disabled.
    pub fn not_ready(&self, axis: AxisId) -> Option<String> {
        let Some(status) = self.view(axis).and_then(|v| v.status) else {
            return Some(format!("no status from {axis} yet"));
        };
        if let Some(c) = self.controller {
            if !c.run_mode() {
                return Some("the RMC is in PROGRAM mode".into());
            }
            if !c.enabled() {
                return Some("the RMC controller is disabled".into());
            }
        }
        if !status.bits.enabled() {
            return Some(format!("{axis} is not enabled: enable it first"));
        }
        if status.bits.halted() {
            return Some(format!("{axis} is halted: clear its faults first"));
        }
        None
    }

    /// The axes' Command Positions to record with a taught point, in 0.001 pu, or why
    /// not (Command Position: where each axis is sent, not where it happens to be) [I].
    pub fn taught_positions(&self) -> Result<Vec<i32>, String> {
        if !self.line.is_up() {
            return Err(
                "the RMC is not connected (untick \"with RMC axes\" to record the arm alone)"
                    .into(),
            );
        }
        AxisId::first(self.axes.len())
            .map(|axis| {
                let status = self
                    .view(axis)
                    .and_then(|v| v.status)
                    .ok_or_else(|| format!("no status from {axis} yet"))?;
                let milli = (f64::from(status.command_position) * 1000.0).round();
                if milli.is_finite() && milli.abs() <= f64::from(i32::MAX) {
                    Ok(milli as i32)
                } else {
                    Err(format!(
                        "{axis}'s position {} cannot be kept",
                        status.command_position
                    ))
                }
            })
            .collect()
    }

    /// The Move Absolute (20) of each axis a taught point names, or why not (all are
    /// checked before any goes out).
    pub fn go_moves(&self, axes: &[i32], settings: &RmcSettings) -> Result<Vec<AxisCall>, String> {
        let jog = settings.jog;
        if !self.line.is_up() {
            return Err("the point has RMC axes and the RMC is not connected".into());
        }
        if axes.len() > self.axes.len() {
            return Err(format!(
                "the point has {} RMC axes, {} are polled",
                axes.len(),
                self.axes.len()
            ));
        }
        jog.check()?;
        AxisId::first(axes.len())
            .zip(axes)
            .map(|(axis, milli)| {
                if let Some(why) = self.not_ready(axis) {
                    return Err(why);
                }
                let position = (f64::from(*milli) / 1000.0) as f32;
                let limits = settings.limits(axis);
                limits.check()?;
                limits
                    .check_end(position, settings.units(axis))
                    .map_err(|why| format!("{axis}'s move refused: {why}"))?;
                let command = Command::MoveAbsolute(crate::rmc::MoveAbsolute {
                    position,
                    speed: jog.speed,
                    accel: jog.accel,
                    decel: jog.decel,
                });
                Ok(AxisCall::Send(axis, command))
            })
            .collect()
    }

    /// Calls the pendant decided on (a Go's axis moves), in order.
    pub fn queue(&mut self, calls: Vec<AxisCall>) {
        self.calls.extend(calls);
    }

    /// A held jog on `axis` ends and latches (its move was refused).
    fn stop_jog_of(&mut self, axis: Option<AxisId>, cause: StopCause) {
        if self.hold.jog().is_some_and(|j| Some(j.target.axis) == axis) {
            self.stop(cause);
        }
    }
}
