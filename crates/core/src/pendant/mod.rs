//! The application model: connection, controller state, readiness, jog planning and the
//! operator's messages. No egui, no threads, no clock: time comes in as an argument, link
//! events come in through [`Pendant::handle_event`], and what must go to the link comes
//! out of [`Pendant::take_requests`].

pub mod alarms;
pub mod axes;
pub mod bundle;
pub mod connection;
pub mod controller;
pub mod coords;
pub mod frame_log;
mod intent;
pub mod jog;
mod out;
pub mod positions;
pub mod programs;
pub mod samples;
pub mod script;
pub mod signals;
pub mod snapshot;
pub mod teach;
pub mod zones;

use std::collections::VecDeque;
use std::time::{Duration, Instant};

use serde::{Deserialize, Serialize};

/// How often a held jog's lease is renewed (the link's fact).
pub use crate::link::RENEW_EVERY;
use crate::link::health::LinkHealth;
/// The link's events and their vocabulary, as the pendant takes them in.
pub use crate::link::{LineDownReason, LinkEvent, Origin, RequestId};
use crate::protocol::{AxisPattern, Command, CoordKind, Home, MmPerSec, Reply, Servo};
use crate::robot::{RobotModel, Scara};
pub use connection::{ConnectionSettings, LineKind, LineState};
pub use controller::ControllerState;
pub use controller::readiness::NotReady;
use controller::{readiness, transitions};
pub use intent::Intent;
use intent::UI_SCALES;
pub use jog::hold::{HeldJog, JogInput, JogTarget, Press, StopCause};
pub use jog::{
    Interpolation, JogAxis, JogCx, JogMode, JogSettings, PhysicalJog, PlannedStep, Refusal,
};
pub use out::{Level, Message, Out, Request};

/// Jogging's view of the rest of the model, from the pendant's own fields (so the jog
/// state itself may be borrowed mutably beside it).
macro_rules! jog_cx {
    ($p:expr) => {
        jog::JogCx {
            model: &$p.model,
            kin: &$p.kin,
            controller: &$p.controller,
            settings: &$p.settings.jog,
            line_up: $p.line.is_up(),
            zones: $p.zones.boxes(),
        }
    };
}

/// The pendant's requests and messages, for a sub-model to write into.
macro_rules! out {
    ($p:expr) => {
        Out {
            requests: &mut $p.requests,
            messages: &mut $p.messages,
        }
    };
}

/// How long a "press again to confirm" for an arm flip stays armed.
pub(crate) const CONFIRM_FOR: Duration = Duration::from_secs(5);
/// The span of the link-health fault counts.
const MINUTE: Duration = Duration::from_secs(60);

/// Everything persisted between runs (eframe storage).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Settings {
    pub connection: ConnectionSettings,
    pub jog: JogSettings,
    /// Taught points as earlier versions kept them with the settings: read once, to be
    /// taken into the teach list's own file, and never written here again.
    #[serde(rename = "teach", skip_serializing)]
    pub legacy_teach: teach::TeachList,
    /// Light theme (the default is dark).
    pub light_theme: bool,
    /// Rows the frame log keeps (None: [`frame_log::DEFAULT_CAP`]).
    pub frame_log_cap: Option<usize>,
    /// MB of memory the frame log's rows may take (None: the default budget).
    pub frame_log_budget_mb: Option<usize>,
    /// The size of everything in the window (Ctrl + / Ctrl - / Ctrl 0; None: 100%).
    pub ui_scale: Option<f32>,
    /// The folder of the last file read or written: a name typed without a folder goes
    /// there (None: the user's documents).
    pub last_folder: Option<std::path::PathBuf>,
    /// The Delta RMC151 beside the robot.
    pub rmc: axes::RmcSettings,
    /// What the plots capture when a move starts.
    pub captures: samples::capture::CaptureSettings,
}

/// The motion phase the lamps show.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MotionPhase {
    Idle,
    Accelerating,
    Constant,
    Decelerating,
    Done,
    Jogging,
    Stopped,
}

/// The command an event answers, for the events that answer one.
fn event_command(event: &LinkEvent) -> Option<&Command> {
    match event {
        LinkEvent::Reply { command, .. }
        | LinkEvent::ErrorReply { command, .. }
        | LinkEvent::Timeout { command, .. }
        | LinkEvent::Interrupted { command, .. }
        | LinkEvent::NotSent { command, .. } => Some(command),
        _ => None,
    }
}

/// The pendant's model of the world.
pub struct Pendant {
    pub settings: Settings,
    pub model: RobotModel,
    kin: Scara,
    pub line: LineState,
    /// The kind of line asked for at the last Connect (the settings may have been edited
    /// since): who owns the open line follows from it.
    pub line_kind: Option<LineKind>,
    pub controller: ControllerState,
    pub health: Option<LinkHealth>,
    /// Time-out and error counts of the health reports of the last minute.
    health_window: VecDeque<(Instant, u64, u64)>,
    pub messages: VecDeque<Message>,
    /// Every frame on the line (a capped ring), for the frame log pane.
    pub frame_log: frame_log::FrameLog,
    /// The last raw frame typed in the frame log: its message ID as sent, or why not.
    pub raw_sent: Option<Result<String, String>>,
    /// Jogging's own state: hold-to-run, the move followed, the speed cap, the last word.
    pub jog: jog::JogState,
    requests: Vec<Request>,
    /// The coordinate-table editor: drafts, reads, "over the arm".
    pub coords: coords::CoordEditor,
    /// The teach list, a load waiting for "Replace", and what Undo load brings back.
    pub teach: teach::book::TeachBook,
    /// The RMC151's axes.
    pub axes: axes::RmcAxes,
    /// The controller's position table: as read, the draft, the write going on.
    pub positions: positions::Positions,
    /// Every polled position and status with its time, for the plots.
    pub samples: samples::polled::Polled,
    /// The watched inputs, outputs, flags and variables.
    pub signals: signals::Signals,
    /// The controller's programs: their state, the operation asked about.
    pub programs: programs::Programs,
    /// The controller's alarm history and the alarms seen arriving.
    pub alarms: alarms::Alarms,
    /// Controller snapshots: the one being taken, the latest two, a comparison.
    pub snapshots: snapshot::Snapshots,
    /// The controller's interference zones (2A2H).
    pub zones: zones::Zones,
}

impl Pendant {
    pub fn new(mut settings: Settings, model: RobotModel) -> Self {
        let log_cap = settings.frame_log_cap.unwrap_or(frame_log::DEFAULT_CAP);
        let log_budget = settings
            .frame_log_budget_mb
            .map_or(frame_log::DEFAULT_BUDGET_BYTES, |mb| {
                mb.saturating_mul(1024 * 1024)
            });
        let teach = teach::book::TeachBook::new(std::mem::take(&mut settings.legacy_teach));
        Self {
            axes: axes::RmcAxes::new(settings.rmc.axis_count()),
            samples: {
                let mut p = samples::polled::Polled::new(settings.rmc.axis_count());
                p.captures.settings = settings.captures;
                p
            },
            teach,
            positions: positions::Positions::new(),
            signals: signals::Signals::default(),
            programs: programs::Programs::default(),
            alarms: alarms::Alarms::default(),
            snapshots: snapshot::Snapshots::default(),
            zones: zones::Zones::default(),
            coords: coords::CoordEditor::new(model.work_table_size, model.tool_table_size),
            kin: Scara::new(&model),
            model,
            settings,
            line: LineState::Closed,
            line_kind: None,
            controller: ControllerState::default(),
            health: None,
            health_window: VecDeque::new(),
            messages: VecDeque::new(),
            frame_log: {
                let mut log = frame_log::FrameLog::new(log_cap);
                log.set_budget(log_budget);
                log
            },
            jog: jog::JogState::default(),
            raw_sent: None,
            requests: Vec::new(),
        }
    }

    /// Another robot model for the checks (a new connection may name one).
    pub fn set_model(&mut self, model: RobotModel) {
        self.kin = Scara::new(&model);
        let sizes = |m: &RobotModel| (m.work_table_size, m.tool_table_size);
        if sizes(&model) != sizes(&self.model) {
            // Tables of another size: drafts start again at the new sizes.
            self.coords = coords::CoordEditor::new(model.work_table_size, model.tool_table_size);
            self.controller.work_table = None;
            self.controller.tool_table = None;
        }
        self.model = model;
    }

    pub fn kinematics(&self) -> &Scara {
        &self.kin
    }

    /// The axis and sign a physical jog sends on this robot (PgUp raises the tool).
    pub fn physical_jog(&self, jog: PhysicalJog) -> JogTarget {
        jog.target(&self.model)
    }

    /// The requests collected since the last call, in the order they must reach their
    /// line: the window forwards them as they are, never reordering (a STOP already
    /// took out the motion asked for before it, and a release its own start).
    pub fn take_requests(&mut self) -> Vec<Request> {
        let mut requests = std::mem::take(&mut self.requests);
        requests.extend(self.axes.take_calls().into_iter().map(Request::Axes));
        requests
    }

    /// Applies one event from the RMC151's link.
    pub fn handle_axes_event(&mut self, now: Instant, event: crate::rmc::RmcEvent) {
        use crate::rmc::RmcEvent;
        self.frame_log.record_rmc_event(&event);
        match &event {
            RmcEvent::Status {
                axis, status, at, ..
            } => {
                self.samples.rmc_status(*at, *axis, status);
                // Positions are valid while an ACK is awaited (only the bits are not).
                if let Some((level, text)) =
                    self.axes
                        .keep_limits(*axis, status, &self.settings.rmc, now)
                {
                    self.say(level, text, now);
                }
            }
            RmcEvent::Sent {
                axis, command, at, ..
            } if command.moves() => self.samples.rmc_moved(*at, *axis, command),
            _ => {}
        }
        if let Some((level, text)) = self.axes.handle_event(now, event) {
            self.say(level, text, now);
        }
    }

    /// Adds a message for the operator (the window reports its file work through it).
    pub fn say(&mut self, level: Level, text: impl Into<String>, now: Instant) {
        out::say(&mut self.messages, level, text, now);
    }

    /// A sub-model's words for the operator, in order.
    fn tell(&mut self, said: impl IntoIterator<Item = (Level, String)>, now: Instant) {
        for (level, text) in said {
            self.say(level, text, now);
        }
    }

    /// A word for the operator from outside the model (the window's own actions).
    pub fn note(&mut self, text: impl Into<String>, now: Instant) {
        self.say(Level::Info, text, now);
    }

    /// The last word beside the pad, also said in Messages.
    fn jog_says(&mut self, level: Level, text: impl Into<String>, now: Instant) {
        self.jog.says(&mut out!(self), level, text, now);
    }

    // ---- the line ----

    /// Opens the line in the settings (closing the current one).
    pub fn connect(&mut self, now: Instant) {
        self.line = LineState::Opening;
        self.line_kind = Some(self.settings.connection.kind);
        self.line_gone(now);
        self.requests.push(Request::Connect);
    }

    /// Closes the line; a jog or move still running is stopped on the way out.
    pub fn disconnect(&mut self, now: Instant) {
        self.requests.push(Request::Disconnect);
        self.line = LineState::Closed;
        self.line_kind = None;
        self.line_gone(now);
    }

    /// The records a whole-table read ([`Request::ReadTable`]) asks for: the model's
    /// table, as far as 2A4H can number it.
    pub fn table_records(&self, kind: CoordKind) -> std::ops::Range<u16> {
        let size = match kind {
            CoordKind::Work => self.model.work_table_size,
            CoordKind::Tool => self.model.tool_table_size,
        };
        0..size.min(usize::from(crate::protocol::COORD_RECORDS)) as u16
    }

    /// The RMC151's connection could not be started: its line is down, and why.
    pub fn rmc_connect_failed(&mut self, reason: String, now: Instant) {
        self.say(Level::Error, format!("RMC: {reason}"), now);
        self.axes.line = LineState::Down { reason, since: now };
    }

    /// The window started at `now` (`wall` on the clock): the frame log's times count
    /// from here.
    pub fn window_started(&mut self, now: Instant, wall: std::time::SystemTime) {
        self.frame_log.set_origin(Some(now), wall);
    }

    /// A frame log of `rows` synthetic rows (the benches' memory of a full log).
    pub fn fill_log_synthetic(&mut self, rows: u64) {
        self.frame_log.fill_synthetic(rows);
    }

    /// The link could not be started at all (the port could not be opened, a bad file).
    pub fn connect_failed(&mut self, reason: String, now: Instant) {
        self.say(Level::Error, format!("cannot connect: {reason}"), now);
        self.line = LineState::Down { reason, since: now };
    }

    fn line_gone(&mut self, _now: Instant) {
        self.controller.line_lost();
        self.coords.line_gone();
        self.positions.line_gone();
        if let Some(text) = self.signals.line_gone() {
            self.say(Level::Warning, text, _now);
        }
        if let Some(text) = self.programs.line_gone() {
            self.say(Level::Warning, text, _now);
        }
        self.alarms.line_gone();
        self.zones.line_gone();
        if let Some((level, text)) = self.snapshots.line_gone() {
            self.say(level, text, _now);
        }
        if self.jog.line_lost() {
            self.say(Level::Error, "the line went down during a jog", _now);
        }
    }

    // ---- events ----

    /// Applies one event from the link.
    pub fn handle_event(&mut self, now: Instant, event: LinkEvent) {
        self.frame_log.record_event(&event);
        self.link_stop(now, &event);
        if event_command(&event).is_some_and(|c| self.snapshots.owns(c)) {
            if let Some((level, text)) = self.snapshots.handle_event(&event) {
                self.say(level, text, now);
            }
            return self.snapshot_out();
        }
        if event_command(&event).is_some_and(positions::Positions::owns) {
            for (level, text) in self.positions.handle_event(&event) {
                self.say(level, text, now);
            }
            let requests = self.positions.take_requests();
            return self.requests.extend(requests);
        }
        if event_command(&event).is_some_and(alarms::Alarms::owns) {
            if let Some((level, text)) = self.alarms.handle_event(&event) {
                self.say(level, text, now);
            }
            return self.alarms_out();
        }
        if event_command(&event).is_some_and(zones::Zones::owns) {
            let before = self.zones.revision();
            if let Some((level, text)) = self.zones.handle_event(&event) {
                self.say(level, text, now);
            }
            if self.zones.revision() != before {
                // A press confirmed against the old zones is asked again.
                self.jog.confirmations_lapse();
                self.positions.go_confirm = None;
                self.teach.go_confirm = None;
            }
            return self.zones_out();
        }
        if event_command(&event).is_some_and(programs::Programs::owns) {
            for (level, text) in self.programs.handle_event(&event, now) {
                self.say(level, text, now);
            }
            return self.programs_out();
        }
        if event_command(&event).is_some_and(signals::Signals::owns) {
            let cx = self.signals_cx(now);
            for (level, text) in self.signals.handle_event(&event, cx, now) {
                self.say(level, text, now);
            }
            return self.signals_out();
        }
        match event {
            LinkEvent::Connected { line } | LinkEvent::Reconnected { line } => {
                self.say(Level::Info, format!("connected: {line}"), now);
                self.line = LineState::Up { line, since: now };
                self.health_window.clear();
                self.requests
                    .push(Request::Submit(controller::version_query()));
                self.requests.push(Request::ReadTable(CoordKind::Work));
                self.alarms.connected();
                self.alarms_out();
                self.zones.start(true);
                self.zones_out();
            }
            LinkEvent::Disconnected { reason } => {
                let reason = match connection::open_hint(&reason) {
                    Some(hint) => format!("{reason}. {hint}"),
                    None => reason.to_string(),
                };
                self.say(Level::Error, format!("line down: {reason}"), now);
                self.line = LineState::Down { reason, since: now };
                self.line_gone(now);
            }
            LinkEvent::Reply { command, reply, .. } => self.reply(now, command, reply),
            LinkEvent::ErrorReply { command, code, .. } => {
                let text = format!(
                    "{} ({}) refused: error {code}",
                    command.id(),
                    name(&command)
                );
                if command.moves_arm() {
                    self.jog.motion_refused();
                    self.jog_says(Level::Error, text, now);
                } else {
                    self.say(Level::Error, text, now);
                }
            }
            LinkEvent::Timeout {
                command,
                origin: crate::link::Origin::User,
                ..
            } => {
                let text = format!("no reply to {} ({})", command.id(), name(&command));
                if command.moves_arm() {
                    self.jog.motion_unanswered();
                    self.jog_says(Level::Error, text, now);
                } else {
                    self.say(Level::Warning, text, now);
                }
            }
            LinkEvent::NotSent {
                command, reason, ..
            } => {
                let text = format!("{} ({}) not sent: {reason}", command.id(), name(&command));
                if reason == crate::link::NotSentReason::StopCameFirst {
                    // Ended by the STOP the operator (or the link) gave: no refusal, and
                    // the latch keeps that STOP's cause.
                    self.jog.ended_by_stop(&command);
                    self.say(Level::Info, text, now);
                } else if command.moves_arm() {
                    self.jog.motion_refused();
                    self.jog_says(Level::Error, text, now);
                } else {
                    self.say(Level::Warning, text, now);
                }
            }
            LinkEvent::TableProgress {
                kind,
                received,
                total,
            } => self.coords.table_progress(kind, received, total),
            LinkEvent::TableDone {
                kind,
                axes,
                first,
                records,
                missing,
            } => {
                let done = coords::TableDone {
                    kind,
                    axes,
                    first,
                    records: &records,
                    missing: &missing,
                };
                self.coords
                    .table_done(&mut self.controller, &mut out!(self), done, now);
                if kind == CoordKind::Work && self.controller.tool_table.is_none() {
                    self.requests.push(Request::ReadTable(CoordKind::Tool));
                }
            }
            LinkEvent::Interrupted { command, .. } if command.moves_arm() => {
                self.jog.motion_unanswered();
                self.jog_says(
                    Level::Error,
                    format!(
                        "the line was lost while {} ({}) waited for its reply: the arm may \
                         have moved",
                        command.id(),
                        name(&command)
                    ),
                    now,
                );
            }
            LinkEvent::ShutDown(report) if !report.is_clean() => {
                self.say(Level::Error, format!("link closed: {report}"), now);
            }
            LinkEvent::GuardianStopped(why) => self.guardian_stopped(&why, now),
            LinkEvent::Health(h) => {
                let errors = h.bad_frames + h.error_replies;
                self.health_window.push_back((now, h.timeouts, errors));
                // The newest report a minute old or more stays as the baseline.
                let minute_old = |at: &Instant| now.saturating_duration_since(*at) >= MINUTE;
                while self
                    .health_window
                    .get(1)
                    .is_some_and(|(at, ..)| minute_old(at))
                {
                    self.health_window.pop_front();
                }
                self.health = Some(h);
            }
            _ => {}
        }
    }

    fn reply(&mut self, now: Instant, command: Command, reply: Reply) {
        if matches!(reply, Reply::Ack(_)) && command.moves_arm() {
            let channel = self.moved_channel(&command);
            let label = format!("{} ({})", command.id(), name(&command));
            self.samples.xsel_moved(now, label, channel);
        }
        match reply {
            Reply::SystemStatus(s) => {
                let old = self.controller.system.as_ref().map(|o| &o.value);
                let previous = old.map(|o| o.critical_error);
                for (level, text) in transitions::system(old, &s) {
                    self.say(level, text, now);
                }
                let code = s.critical_error;
                if code != crate::protocol::ErrorCode::NONE && previous.is_some_and(|c| c != code) {
                    // The reply that brought it is the frame log's last row.
                    let row = self.frame_log.end().saturating_sub(1);
                    let wall = self
                        .frame_log
                        .row(row)
                        .map_or(self.frame_log.origin_wall(), |r| self.frame_log.wall(&r));
                    self.alarms.alarm_arrived(code, now, wall, row);
                    self.alarms_out();
                }
                self.controller.system = Some(controller::Stamped { value: s, at: now });
            }
            Reply::ScaraStatus(s) => {
                let mut values = [0i32; 4];
                for (i, slot) in values.iter_mut().enumerate() {
                    let axis = crate::protocol::Axis::from_index(i as u8);
                    if let Some(a) = axis.and_then(|axis| s.axes.get(axis)) {
                        *slot = a.position.0;
                    }
                }
                let system = s.common.system;
                if system == crate::protocol::PositionSystem::Joint {
                    self.samples.xsel_joints(now, values);
                }
                if system == crate::protocol::PositionSystem::Work {
                    let old = self.controller.work.as_ref().map(|o| &o.value.axes);
                    for (level, text) in transitions::axes(old, &s.axes) {
                        self.say(level, text, now);
                    }
                }
                self.controller.scara_status(s, now);
                if system == crate::protocol::PositionSystem::Work {
                    // In position and the phase as the pendant reads them with this poll in.
                    let in_position = self.in_position().unwrap_or(false);
                    let phase = samples::polled::phase_level(self.motion_phase(now));
                    self.samples.xsel_work(now, values, in_position, phase);
                }
            }
            Reply::Version(v) => self.controller.version = Some(v),
            Reply::Ack(_) => self.jog.acknowledged(&command, now),
            _ => {}
        }
    }

    /// Time-outs and errors (bad frames and refusals) counted over the last minute of
    /// health reports (less while the line has been up for less than a minute).
    pub fn faults_last_minute(&self) -> Option<(u64, u64)> {
        let (_, t0, e0) = self.health_window.front()?;
        let (_, t1, e1) = self.health_window.back()?;
        Some((t1.saturating_sub(*t0), e1.saturating_sub(*e0)))
    }

    // ---- readiness ----

    /// Whether the controller may be asked to move now.
    pub fn motion_ready(&self, now: Instant) -> Result<(), NotReady> {
        jog_cx!(self).motion_ready(now)
    }

    /// Whether servo and homing commands may be sent (no servo or homing condition).
    pub fn controller_ready(&self, now: Instant) -> Result<(), NotReady> {
        readiness::controller_gate(
            self.line.is_up(),
            self.controller.system.as_ref().map(|s| &s.value),
            self.controller.is_stale(now),
        )
    }

    // ---- servo, home, alarm ----

    pub fn servo(&mut self, on: bool, now: Instant) {
        if let Err(why) = self.controller_ready(now) {
            return self.say(Level::Warning, format!("servo not switched: {why}"), now);
        }
        self.requests.push(Request::Submit(Command::Servo(Servo {
            axes: AxisPattern::SCARA_1,
            on,
        })));
    }

    pub fn home(&mut self, now: Instant) {
        if let Err(why) = self.controller_ready(now) {
            return self.say(Level::Warning, format!("not homed: {why}"), now);
        }
        // 0 = the controller's parameter speeds for the search and creep.
        self.requests.push(Request::Submit(Command::Home(Home {
            axes: AxisPattern::SCARA_1,
            search: MmPerSec(0),
            creep: MmPerSec(0),
        })));
    }

    pub fn reset_alarm(&mut self, now: Instant) {
        if !self.line.is_up() {
            return self.say(Level::Warning, "alarm not reset: the line is down", now);
        }
        self.requests.push(Request::Submit(Command::AlarmReset));
    }

    // ---- STOP ----

    /// STOP from the STOP button: 238H at the head of the queue. Always allowed.
    pub fn stop(&mut self, now: Instant) {
        self.stop_by(StopCause::Button, now);
    }

    /// STOP, saying who sent it: 238H at the head of the queue, whatever the state; the
    /// latch holds while any jog control is still down.
    pub fn stop_by(&mut self, cause: StopCause, now: Instant) {
        // Motion asked for earlier this frame has not gone out: it never will.
        self.requests
            .retain(|r| !matches!(r, Request::Submit(c) if c.moves_arm() || c.is_program_start()));
        // So has a signal's change confirmed this frame: STOP comes first.
        let change = |r: &Request| {
            matches!(
                r,
                Request::Submit(Command::BitChange(_) | Command::VarWrite(_))
            )
        };
        let change_dropped = self.requests.iter().any(change);
        self.requests.retain(|r| !change(r));
        if let Some(text) = self.signals.stopped(change_dropped) {
            self.say(Level::Warning, text, now);
        }
        self.requests.push(Request::Stop);
        self.jog.stop(cause, now);
        self.axes.stop(cause);
        self.positions.go_confirm = None;
        self.teach.go_confirm = None;
        self.programs.stopped();
        // The operator's own STOP is news of the expected kind; any other is a warning.
        let level = match cause {
            StopCause::Button | StopCause::Esc | StopCause::Exit => Level::Info,
            _ => Level::Warning,
        };
        self.jog_says(level, format!("STOP sent ({})", cause.name()), now);
    }

    /// A held continuous jog about to enter `zones`: STOP (latched), then the next press
    /// of the same control, once released, may jog into them.
    fn stop_before_zones(&mut self, target: jog::hold::JogTarget, zones: &[u8], now: Instant) {
        self.stop_by(StopCause::Zone(zones[0]), now);
        self.jog.arm_zone_pass(target, zones, now);
        let label = target.label();
        self.jog_says(
            Level::Warning,
            format!(
                "{label} stopped before {} ({}): release it, then press {label} again \
                 within {} s to jog into it",
                jog::zones_text(zones),
                zones::ZONE_ACTION,
                CONFIRM_FOR.as_secs()
            ),
            now,
        );
    }

    /// The link's own STOPs (lapsed lease, stalled line) reach Messages and latch.
    fn link_stop(&mut self, now: Instant, event: &LinkEvent) {
        let origin = match event {
            LinkEvent::Reply {
                origin, command, ..
            }
            | LinkEvent::ErrorReply {
                origin, command, ..
            } if command.is_stop() => *origin,
            _ => return,
        };
        let cause = match origin {
            crate::link::Origin::LeaseLapsed => StopCause::LeaseLapsed,
            crate::link::Origin::SafetyStop => StopCause::LinkSafety,
            _ => return,
        };
        self.jog.stopped_outside(cause, now);
        self.jog_says(
            Level::Warning,
            format!("STOP sent by the link: {}", cause.name()),
            now,
        );
    }

    /// The guardian stopped the arm by itself: a jog still held is latched as for any
    /// STOP the operator did not give.
    fn guardian_stopped(&mut self, why: &str, now: Instant) {
        self.jog.stopped_outside(StopCause::Guardian, now);
        self.jog_says(
            Level::Warning,
            format!("STOP sent by the guardian process: {why}"),
            now,
        );
    }

    /// The work coordinate (0-3: X, Y, Z, R) a move changes most: a relative move's
    /// largest distance, an absolute move's farthest target from the polled pose.
    fn moved_channel(&self, command: &Command) -> usize {
        let now = |axis: crate::protocol::Axis| {
            self.controller
                .work
                .as_ref()
                .and_then(|w| w.value.axes.get(axis))
                .map_or(0, |a| a.position.0)
        };
        let distances: Vec<(usize, i64)> = match command {
            Command::ScaraMoveRelative(m) => m
                .targets
                .iter()
                .map(|(a, d)| (a.index(), i64::from(d.0).abs()))
                .collect(),
            Command::ScaraMoveAbsolute(m) => m
                .targets
                .iter()
                .map(|(a, t)| (a.index(), (i64::from(t.0) - i64::from(now(a))).abs()))
                .collect(),
            Command::Jog(j) => j.axes.iter().map(|a| (a.index(), 1)).collect(),
            _ => Vec::new(),
        };
        distances
            .into_iter()
            .max_by_key(|(_, d)| *d)
            .map_or(0, |(i, _)| i)
    }

    /// Once a frame: captures whose samples are in are taken; a jog held while the
    /// controller leaves the state that allows motion is stopped (and latched).
    pub fn tick(&mut self, now: Instant) {
        self.samples.poll_captures(now);
        self.signals.tick(now, self.line.is_up());
        self.signals_out();
        self.programs.tick(now, self.line.is_up());
        self.programs_out();
        self.snapshot_work(now);
        self.samples.signal_samples(self.signals.take_samples());
        if self.jog.hold.jog().is_none() {
            return;
        }
        if let Err(why) = self.motion_ready(now) {
            return self.stop_by(StopCause::NotReady(why), now);
        }
        if let Some((target, zones)) = self.jog.zone_ahead(&jog_cx!(self), now) {
            return self.stop_before_zones(target, &zones, now);
        }
        if let Some(label) = self.jog.ended_by_controller(&self.controller) {
            self.jog_says(
                Level::Warning,
                format!(
                    "{label} stopped by the controller (a limit or the edge of reach): \
                     release it"
                ),
                now,
            );
        }
    }
}

impl Pendant {
    /// Sends a frame typed as its body: station, message ID and data, e.g. `99215`
    /// (no header, SC or CR LF: the link adds them, with the checksum or `@@` as the
    /// connection settings say). Returns what was sent, or why not.
    pub fn send_raw(&mut self, body: &str, now: Instant) -> Result<Command, String> {
        let cx = frame_log::raw_send::RawCx {
            station: crate::protocol::Station(self.settings.connection.station),
            line_up: self.line.is_up(),
            motion: self.motion_ready(now),
        };
        let (result, (level, text)) = frame_log::raw_send::raw_command(body, &cx);
        if let Ok(command) = &result {
            self.requests.push(Request::Submit(command.clone()));
        }
        self.say(level, text, now);
        result
    }

    // ---- intents ----

    /// Applies one intent.
    pub fn apply(&mut self, intent: Intent, now: Instant) {
        match intent {
            Intent::Jog(input, press) => self.jog_input(input, press, now),
            Intent::FocusLost => self.focus_lost(now),
            Intent::Stop(cause) => self.stop_by(cause, now),
            Intent::JogSettings(settings) => self.set_jog_settings(settings),
            Intent::Servo(on) => self.servo(on, now),
            Intent::Home => self.home(now),
            Intent::ResetAlarm => self.reset_alarm(now),
            Intent::GoToTarget => self.go_to_target(now),
            Intent::EditTarget(pose) => self.jog.edit_step_target(pose),
            Intent::ClearTarget => self.jog.clear_step_target(),
            Intent::TeachGo(index) => self.teach_go(index, now),
            Intent::TeachRecord(name) => self.teach_record(&name, now),
            Intent::TeachList(list) => self.teach.set(list),
            Intent::Positions(p) => self.apply_positions(p, now),
            Intent::Signals(s) => self.apply_signals(s, now),
            Intent::Programs(p) => self.apply_programs(p, now),
            Intent::Alarms(a) => self.apply_alarms(a, now),
            Intent::ReadZones => self.read_zones(now),
            Intent::Snapshot(s) => self.apply_snapshot(s, now),
            Intent::TeachLoaded { path, read } => {
                let said = self.teach.loaded(&path, read);
                self.tell(said, now);
            }
            Intent::TeachConfirmLoad => {
                let said = self.teach.confirm_load();
                self.tell(said, now);
            }
            Intent::TeachCancelLoad => self.teach.cancel_load(),
            Intent::TeachUndoLoad => {
                let said = self.teach.undo_load();
                self.tell(said, now);
            }
            Intent::SetTarget(pose) => self.set_step_target(pose, now),
            Intent::ConnectionSettings(c) => self.settings.connection = c,
            Intent::Connect => self.connect(now),
            Intent::Disconnect => self.disconnect(now),
            Intent::RaiseSpeedCap(mm_s) => self.jog.raise_speed_cap(&mut out!(self), mm_s, now),
            Intent::ResetSpeedCap => self.jog.reset_speed_cap(&mut out!(self), now),
            Intent::LightTheme(light) => self.settings.light_theme = light,
            Intent::Coords(c) => self.apply_coords(c, now),
            Intent::FrameLogCap(cap) => {
                self.frame_log.set_cap(cap);
                self.settings.frame_log_cap = Some(cap);
            }
            Intent::FrameLogBudget(mb) => {
                self.frame_log.set_budget(mb.saturating_mul(1024 * 1024));
                self.settings.frame_log_budget_mb = Some(mb);
            }
            Intent::ClearFrameLog => self.frame_log.clear(),
            Intent::CaptureSettings(c) => {
                self.settings.captures = c;
                self.samples.captures.settings = c;
            }
            Intent::ClearCaptures => self.samples.captures.list.clear(),
            Intent::UiScale(scale) => {
                self.settings.ui_scale = (scale.is_finite() && (scale - 1.0).abs() > 1e-3)
                    .then(|| scale.clamp(UI_SCALES.0, UI_SCALES.1));
            }
            Intent::FileUsed(path) => {
                self.settings.last_folder = path.parent().map(std::path::Path::to_path_buf);
            }
            Intent::Axes(intent) => {
                if let Some((level, text)) = self.axes.apply(intent, &mut self.settings.rmc, now) {
                    self.say(level, text, now);
                }
            }
            Intent::SendRaw(body) => {
                // The outcome is kept for the frame log pane and said in Messages.
                self.raw_sent = Some(self.send_raw(&body, now).map(|c| c.id().to_string()));
            }
        }
    }

    /// Applies a frame's intents: the jog inputs' states first (so a STOP latches every
    /// input down this frame), then STOPs, then the rest in order.
    pub fn apply_all(&mut self, intents: impl IntoIterator<Item = Intent>, now: Instant) {
        let rank = |i: &Intent| match i {
            Intent::Jog(..) | Intent::FocusLost | Intent::Axes(axes::AxisIntent::Jog(..)) => 0,
            Intent::Stop(_) => 1,
            _ => 2,
        };
        let mut intents: Vec<Intent> = intents.into_iter().collect();
        intents.sort_by_key(rank);
        for intent in intents {
            self.apply(intent, now);
        }
    }

    /// Applies one Positions intent: the table decides, Go to No. N moves through the
    /// jog state; the words go to Messages.
    pub fn apply_positions(&mut self, intent: positions::PositionsIntent, now: Instant) {
        if let positions::PositionsIntent::Go(n) = intent {
            self.position_go(n, now);
        } else {
            self.apply_to_table(intent, now);
        }
        let requests = self.positions.take_requests();
        self.requests.extend(requests);
    }

    /// A Positions intent the table answers itself (all but Go), given what it checks.
    fn apply_to_table(&mut self, intent: positions::PositionsIntent, now: Instant) {
        let jog_cx = jog_cx!(self);
        let arm = self.jog.arm_now(&jog_cx, now);
        let settings = self.jog.sent(&jog_cx);
        let check = |rec: &crate::protocol::PositionRecord| match &arm {
            Ok(arm) => jog::plan_position_go(&self.model, &self.kin, &settings, rec, arm)
                .map(|_| ())
                .map_err(|why| why.to_string()),
            Err(why) => Err(format!("not checked: {why}")),
        };
        let cx = positions::PositionsCx {
            line_up: self.line.is_up(),
            program_running: self.program_running(),
            controller: &self.controller,
            check: &check,
        };
        let said = self.positions.apply(intent, &cx, now);
        self.tell(said, now);
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
    fn position_go(&mut self, n: u16, now: Instant) {
        let cx = jog_cx!(self);
        let mut out = out!(self);
        let rec = match self.positions.row(n) {
            positions::Row::Held(r) => *r,
            positions::Row::Empty => {
                let text = format!("refused: No. {n} holds no data");
                return self.jog.says(&mut out, Level::Warning, text, now);
            }
            _ => {
                let text = format!(
                    "refused: No. {n} has not been read: read it first (Go checks the controller's own record)"
                );
                return self.jog.says(&mut out, Level::Warning, text, now);
            }
        };
        if !self.jog.may_send_move(&cx, &mut out, "move", now) {
            return;
        }
        let plan = self.jog.arm_now(&cx, now).and_then(|arm| {
            jog::plan_position_go(cx.model, cx.kin, &self.jog.sent(&cx), &rec, &arm)
        });
        let plan = match plan {
            Ok(plan) => plan,
            Err(why) => return self.jog.refused(&mut out, &why, now),
        };
        let confirmed = self
            .positions
            .go_confirm
            .take()
            .is_some_and(|(m, at)| m == n && now.duration_since(at) < CONFIRM_FOR);
        if !confirmed && let Some(text) = plan.confirm_text(&format!("Go to No. {n}"), "again") {
            self.positions.go_confirm = Some((n, now));
            return self.jog.says(&mut out, Level::Warning, text, now);
        }
        let differs = if self.positions.differs(n) {
            " (the controller's record: the draft's row differs and is not written)"
        } else {
            ""
        };
        self.jog.send(&mut out, plan);
        let text = format!("go to No. {n}: sent{differs}");
        self.jog.says(&mut out, Level::Info, text, now);
    }

    /// Applies one Signals intent: the sub-model decides; its words go to Messages.
    pub fn apply_signals(&mut self, intent: signals::SignalsIntent, now: Instant) {
        let cx = self.signals_cx(now);
        if let Some((level, text)) = self.signals.apply(intent, cx, now) {
            self.say(level, text, now);
        }
        self.signals_out();
    }

    /// What the signals' checks need to know of the line and the controller.
    fn signals_cx(&self, now: Instant) -> signals::SignalsCx {
        let system = self.controller.system.as_ref().map(|s| s.value);
        signals::SignalsCx {
            ready: self.controller_ready(now).map_err(|why| why.to_string()),
            program_running: system.map(|s| s.status2.program_running()),
            io_interlock: system.is_some_and(|s| s.status2.io_interlock()),
        }
    }

    /// Applies one Alarms intent: the sub-model decides; its words go to Messages.
    pub fn apply_alarms(&mut self, intent: alarms::AlarmsIntent, now: Instant) {
        if let Some((level, text)) = self.alarms.apply(intent, self.line.is_up()) {
            self.say(level, text, now);
        }
        self.alarms_out();
    }

    /// Reads the controller's zones again (2A2H): the boxes the checks use are replaced.
    pub fn read_zones(&mut self, now: Instant) {
        if let Some((level, text)) = self.zones.start(self.line.is_up()) {
            self.say(level, text, now);
        }
        self.zones_out();
    }

    /// Moves the zone reads to the requests, in the line time the polls leave.
    fn zones_out(&mut self) {
        for command in self.zones.take_commands() {
            self.requests.push(Request::Spare(command));
        }
    }

    /// Moves the alarm history's reads to the requests, in the line time the polls leave.
    fn alarms_out(&mut self) {
        for command in self.alarms.take_commands() {
            self.requests.push(Request::Spare(command));
        }
    }

    /// Applies one snapshot intent: the sub-model decides; its words go to Messages.
    pub fn apply_snapshot(&mut self, intent: snapshot::SnapshotIntent, now: Instant) {
        if let snapshot::SnapshotIntent::RestorePositions = intent {
            let (level, text) = self.restore_positions();
            self.snapshots.feedback = Some((level, text.clone()));
            return self.say(level, text, now);
        }
        let line = match &self.line {
            LineState::Up { line, .. } => Some(line.as_str()),
            _ => None,
        };
        let said = self
            .snapshots
            .apply(intent, line, std::time::SystemTime::now());
        if let Some((level, text)) = said {
            self.say(level, text, now);
        }
        self.snapshot_out();
    }

    /// A snapshot's positions into the Positions draft (one undo step); the write is the
    /// operator's, through the view's preview.
    fn restore_positions(&mut self) -> (Level, String) {
        let Some(source) = self.snapshots.restore_source() else {
            return (Level::Warning, "take or open a snapshot first".into());
        };
        if self.positions.busy() {
            return (
                Level::Warning,
                "the position table is being read or written: restore when it is done".into(),
            );
        }
        let records: Result<Vec<_>, String> = source
            .positions
            .iter()
            .map(|p| p.to_record().map(|r| (r, None)))
            .collect();
        let taken = source.taken.clone();
        match records.and_then(|r| self.positions.import(r)) {
            Ok(0) => (
                Level::Warning,
                format!("the snapshot of {taken} holds no position: nothing restored"),
            ),
            Ok(n) => (
                Level::Info,
                format!(
                    "{n} position(s) of the snapshot of {taken} put into the Positions draft \
                     (Undo takes them back): nothing is sent until Write there, with its \
                     preview; numbers the snapshot does not hold are left as they are"
                ),
            ),
            Err(e) => (
                Level::Warning,
                format!("not restored: {e} (the draft is unchanged)"),
            ),
        }
    }

    /// Moves the snapshot's own reads to the requests, in the line time the polls leave.
    fn snapshot_out(&mut self) {
        for command in self.snapshots.take_commands() {
            self.requests.push(Request::Spare(command));
        }
    }

    /// The parts of a snapshot other sub-models read: the position table (its view's
    /// read of every number), the alarm history, the coordinate tables read at connect
    /// and the zones (read again). Handed over once, taken in when they end.
    fn snapshot_work(&mut self, now: Instant) {
        use snapshot::{Part, Snapshots};
        let handed = self.snapshots.handed();
        let said = match self.snapshots.part() {
            Some(Part::Positions) if !handed => {
                match self.positions.start_read(1..=self.positions.capacity()) {
                    Ok(()) => {
                        self.snapshots.handed_over();
                        let requests = self.positions.take_requests();
                        self.requests.extend(requests);
                        None
                    }
                    Err(why) => self.snapshots.part_read(|s| {
                        s.missing.push(format!("position table: {why}"));
                    }),
                }
            }
            Some(Part::Positions) if self.positions.read.is_none() => {
                let mut held = Vec::new();
                let mut unknown = 0;
                for n in 1..=self.positions.capacity() {
                    match self.positions.row(n) {
                        positions::Row::Held(r) => held.push(*r),
                        positions::Row::Empty => {}
                        _ => unknown += 1,
                    }
                }
                self.snapshots.part_read(|s| {
                    Snapshots::positions_read(&held)(s);
                    if unknown > 0 {
                        s.missing
                            .push(format!("position table: {unknown} number(s) not read"));
                    }
                })
            }
            Some(Part::Alarms) if !handed => {
                let said = self
                    .alarms
                    .apply(alarms::AlarmsIntent::Read, self.line.is_up());
                self.snapshots.handed_over();
                self.alarms_out();
                said
            }
            Some(Part::Alarms) if self.alarms.reading().is_none() => {
                let records: Vec<snapshot::AlarmEntry> = self
                    .alarms
                    .records()
                    .iter()
                    .filter_map(|r| r.detail.as_ref().ok().map(|d| (r.record, d).into()))
                    .collect();
                let failed = self.alarms.records().len() - records.len();
                self.snapshots.part_read(|s| {
                    s.alarms = records;
                    if failed > 0 {
                        s.missing
                            .push(format!("alarm history: {failed} record(s) not read"));
                    }
                })
            }
            Some(Part::Tables) => {
                let table =
                    |t: &Option<controller::ReadTable>| t.as_ref().map(|t| t.records.clone());
                let (work, tool) = (
                    table(&self.controller.work_table),
                    table(&self.controller.tool_table),
                );
                self.snapshots
                    .part_read(Snapshots::tables(work.as_deref(), tool.as_deref()))
            }
            Some(Part::Zones) if !handed => {
                let said = self.zones.start(self.line.is_up());
                self.snapshots.handed_over();
                self.zones_out();
                said
            }
            Some(Part::Zones) if !self.zones.reading() => {
                let defined: Vec<(u8, crate::protocol::ZoneRecord)> = self
                    .zones
                    .read()
                    .iter()
                    .filter(|z| self.zones.boxes().iter().any(|b| b.number == z.number))
                    .map(|z| (z.number, z.record.clone()))
                    .collect();
                let failed = self.zones.failed().then(|| {
                    self.zones
                        .outcome
                        .as_ref()
                        .map_or(String::new(), |o| o.1.clone())
                });
                self.snapshots
                    .part_read(Snapshots::zones_read(&defined, failed))
            }
            _ => None,
        };
        if let Some((level, text)) = said {
            self.say(level, text, now);
        }
        self.snapshot_out();
    }

    /// Applies one Programs intent: the sub-model decides; its words go to Messages.
    pub fn apply_programs(&mut self, intent: programs::ProgramsIntent, now: Instant) {
        let cx = self.programs_cx(now);
        if let Some((level, text)) = self.programs.apply(intent, &cx, now) {
            self.say(level, text, now);
        }
        self.programs_out();
    }

    /// What the programs' checks need to know of the line, the controller and the jog.
    fn programs_cx(&self, now: Instant) -> programs::ProgramsCx {
        let jogging = if let Some(cause) = self.jog.hold.latch() {
            Some(format!(
                "the STOP latch holds ({}): release the jog controls first",
                cause.name()
            ))
        } else if self.jog.hold.jog().is_some() || self.own_move_runs(now) {
            Some("a jog or move of this window runs: let it end or STOP first".to_owned())
        } else {
            None
        };
        programs::ProgramsCx {
            ready: self.controller_ready(now).map_err(|why| why.to_string()),
            motion: self.motion_ready(now).map_err(|why| why.to_string()),
            jogging,
        }
    }

    /// Whether a move this window sent is on its way or running: sent and not answered
    /// yet, or its profile not ended (a move that ended stays followed for the arm view).
    fn own_move_runs(&self, now: Instant) -> bool {
        let pending = self
            .jog
            .followed
            .as_ref()
            .is_some_and(|f| f.accepted.is_none() && f.stopped.is_none());
        pending
            || matches!(
                self.motion_phase(now),
                MotionPhase::Accelerating | MotionPhase::Constant | MotionPhase::Decelerating
            )
    }

    /// Moves the programs' commands to the requests: status reads in the line time the
    /// polls leave, operations at the user's priority (behind any STOP).
    fn programs_out(&mut self) {
        for (command, user) in self.programs.take_commands() {
            self.requests.push(if user {
                Request::Submit(command)
            } else {
                Request::Spare(command)
            });
        }
    }

    /// Moves the signals' commands to the requests: reads in the line time the polls
    /// leave, changes and read-backs at the user's priority (behind any STOP).
    fn signals_out(&mut self) {
        for (command, user) in self.signals.take_commands() {
            self.requests.push(if user {
                Request::Submit(command)
            } else {
                Request::Spare(command)
            });
        }
    }
}

impl Pendant {
    // ---- jogging: the jog state decides; the pendant lends it the rest ----

    /// What a step of `axis` in `dir` would do now, without sending it.
    pub fn preview_step(
        &self,
        axis: JogAxis,
        dir: crate::protocol::Direction,
        now: Instant,
    ) -> Result<PlannedStep, Refusal> {
        self.jog.preview_step(&jog_cx!(self), axis, dir, now)
    }

    /// A click on a jog button in step mode: plan, check, send (or refuse, or ask to
    /// confirm an arm flip).
    pub fn jog_step(&mut self, axis: JogAxis, dir: crate::protocol::Direction, now: Instant) {
        let cx = jog_cx!(self);
        self.jog.step(&cx, &mut out!(self), axis, dir, now);
    }

    /// One jog input's state this frame (the hold-to-run machine decides what it means).
    fn jog_input(&mut self, input: JogInput, press: Press, now: Instant) {
        let cx = jog_cx!(self);
        self.jog.input(&cx, &mut out!(self), input, press, now);
    }

    /// The window lost focus: it cannot see a key or button come up, so every jog stops.
    fn focus_lost(&mut self, now: Instant) {
        if let Some((level, text)) = self.axes.focus_lost_at(now) {
            self.say(level, text, now);
        }
        self.jog.focus_lost(&mut out!(self), now);
    }

    /// The continuous jog running on a held input.
    pub fn held_jog(&self) -> Option<HeldJog> {
        self.jog.held_jog()
    }

    /// The control `input` is held on now, if any (the pad lights it).
    pub fn held_on(&self, input: JogInput) -> Option<JogTarget> {
        self.jog.held_on(input)
    }

    /// The STOP latch beside the pad: "STOP (Esc): release the jog controls".
    pub fn stop_latch(&self) -> Option<String> {
        self.jog.stop_latch()
    }

    /// New jog choices; a refusal or an armed confirmation made under the old ones goes.
    fn set_jog_settings(&mut self, settings: JogSettings) {
        if settings != self.settings.jog {
            self.settings.jog = settings;
            self.jog.settings_changed();
        }
    }

    /// The jog settings as they go on the line: speeds within the cap.
    pub fn jog_sent(&self) -> JogSettings {
        self.jog.sent(&jog_cx!(self))
    }

    /// The jog speed cap at the tool, mm/s.
    pub fn speed_cap(&self) -> f64 {
        self.jog.speed_cap()
    }

    /// The motion phase of the move being followed.
    pub fn motion_phase(&self, now: Instant) -> MotionPhase {
        self.jog.motion_phase(&self.controller, now)
    }

    /// Whether the controller ended the held jog by itself (see
    /// [`jog::JogState::held_jog_ended`]).
    pub fn held_jog_ended(&self) -> bool {
        self.jog.held_jog_ended(&self.controller)
    }

    /// The polled joints within the model's positioning band of the command position.
    pub fn in_position(&self) -> Option<bool> {
        self.jog.in_position(&self.controller, &self.model)
    }

    /// The planned move being followed, for the arm view's ghost.
    pub fn followed_move(&self) -> Option<&crate::robot::Move> {
        self.jog.followed_move()
    }

    /// The target set from the arm view, if any.
    pub fn step_target(&self) -> Option<&jog::target::StepTarget> {
        self.jog.step_target()
    }

    /// Sets the target to the tool tip at `pose` in the selected work frame.
    pub fn set_step_target(&mut self, pose: crate::robot::Pose, now: Instant) {
        self.jog
            .set_step_target(&self.controller, &mut out!(self), pose, now);
    }

    /// What "Go to target" would do now.
    pub fn preview_target(&self, now: Instant) -> Option<jog::target::StepPreview> {
        self.jog.preview_target(&jog_cx!(self), now)
    }

    /// What "Go" on taught point `index` would do now, for its ghost.
    pub fn preview_go(&self, index: usize, now: Instant) -> Option<jog::target::StepPreview> {
        let point = self.teach.list().get(index)?;
        Some(self.jog.preview_go(&jog_cx!(self), point, now))
    }

    /// What a move to position record `rec` would do now, for its ghost.
    pub fn preview_position(
        &self,
        rec: &crate::protocol::PositionRecord,
        now: Instant,
    ) -> Option<jog::target::StepPreview> {
        self.jog.preview_position(&jog_cx!(self), rec, now)
    }

    /// "Go to target": 2D4H after the readiness, frame and move checks.
    pub fn go_to_target(&mut self, now: Instant) {
        let cx = jog_cx!(self);
        self.jog.go_to_target(&cx, &mut out!(self), now);
    }

    /// What a click on a jog button would do now, for the ghost.
    pub fn preview_jog(
        &self,
        axis: JogAxis,
        dir: crate::protocol::Direction,
        now: Instant,
    ) -> Option<jog::target::StepPreview> {
        self.jog.preview_jog(&jog_cx!(self), axis, dir, now)
    }

    /// The move in progress (sent and not yet ended), as a preview of its end.
    pub fn preview_followed(&self, now: Instant) -> Option<jog::target::StepPreview> {
        self.jog.preview_followed(&jog_cx!(self), now)
    }

    /// "Go" on a taught point: 2D4H after the frame check and the same checks as a step;
    /// an arm flip or a path into a zone asks for a second press; the RMC axes it names
    /// move with it.
    pub fn teach_go(&mut self, index: usize, now: Instant) {
        let Some(point) = self.teach.list().get(index).cloned() else {
            return;
        };
        let cx = jog_cx!(self);
        let mut out = out!(self);
        if !self.jog.may_send_move(&cx, &mut out, "move", now) {
            return;
        }
        let refused = |jog: &mut jog::JogState, out: &mut Out, why: String| {
            jog.says(out, Level::Warning, format!("refused: {why}"), now);
        };
        if let Some((work, tool)) = cx.controller.frame_numbers()
            && let Err(why) = teach::check_go(&point, work, tool)
        {
            return refused(&mut self.jog, &mut out, why.to_string());
        }
        // The RMC axes the point names are checked first: nothing moves unless all may.
        let axis_moves = if point.axes.is_empty() {
            Vec::new()
        } else {
            match self.axes.go_moves(&point.axes, &self.settings.rmc) {
                Ok(moves) => moves,
                Err(why) => return refused(&mut self.jog, &mut out, why.to_string()),
            }
        };
        let plan = self
            .jog
            .arm_now(&cx, now)
            .and_then(|arm| jog::plan_go(cx.model, cx.kin, &self.jog.sent(&cx), &point, &arm));
        let confirmed = self.teach.go_confirm.take().is_some_and(|(go, at)| {
            go == (index, self.teach.revision()) && now.duration_since(at) < CONFIRM_FOR
        });
        match plan {
            Ok(plan)
                if !confirmed
                    && let Some(text) =
                        plan.confirm_text(&format!("Go to \"{}\"", point.name), "Go again") =>
            {
                self.teach.go_confirm = Some(((index, self.teach.revision()), now));
                self.jog.says(&mut out, Level::Warning, text, now);
            }
            Ok(plan) => {
                self.jog.send(&mut out, plan);
                self.axes.queue(axis_moves);
                let text = format!("go to \"{}\": sent", point.name);
                self.jog.says(&mut out, Level::Info, text, now);
            }
            Err(why) => self.jog.refused(&mut out, &why, now),
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
        let at = teach::TaughtPose {
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
}

impl Pendant {
    // ---- the coordinate tables: the editor decides; the pendant lends it the rest ----

    /// Applies one of the coordinate pane's intents.
    pub fn apply_coords(&mut self, intent: coords::CoordsIntent, now: Instant) {
        let cx = coords::CoordsCx {
            line_up: self.line.is_up(),
            controller: &self.controller,
            model: &self.model,
        };
        self.coords.apply(intent, &cx, &mut out!(self), now);
    }

    /// The controller's table as read, if it was.
    pub fn read_table(&self, kind: crate::robot::FrameKind) -> Option<&controller::ReadTable> {
        coords::read_table(&self.controller, kind)
    }

    /// Reads a whole table from the controller again (the draft keeps its edits).
    pub fn reload_table(&mut self, kind: CoordKind, now: Instant) {
        let line_up = self.line.is_up();
        self.coords.reload(line_up, &mut out!(self), kind, now);
    }

    /// Stops the read in progress; what was read so far is kept, the rest shown unread.
    pub fn cancel_table_read(&mut self) {
        self.coords.cancel_read(&mut out!(self));
    }

    /// The record ranges of a table not read (empty when all were, or none was read).
    pub fn unread_ranges(&self, kind: crate::robot::FrameKind) -> Vec<std::ops::Range<u16>> {
        coords::unread_ranges(&self.controller, kind)
    }

    /// Reads again only the records a read missed, range by range.
    pub fn retry_unread(&mut self, kind: CoordKind, now: Instant) {
        let cx = coords::CoordsCx {
            line_up: self.line.is_up(),
            controller: &self.controller,
            model: &self.model,
        };
        self.coords.retry_unread(&cx, &mut out!(self), kind, now);
    }

    /// The draft becomes the controller's table (one undo step).
    pub fn draft_from_controller(&mut self, kind: crate::robot::FrameKind) {
        self.coords.draft_from_controller(&self.controller, kind);
    }

    /// Frames to draw over the arm (see [`coords::CoordEditor::frames_over_arm`]).
    pub fn frames_over_arm(&self) -> Vec<(crate::robot::FrameKind, u8, crate::robot::CoordSystem)> {
        self.coords.frames_over_arm(&self.controller)
    }

    /// Both drafts in a file format.
    pub fn export_tables(&self, format: coords::file::TableFormat) -> String {
        self.coords.export(format)
    }

    /// Reads a file into the drafts (see [`coords::CoordEditor::import`]).
    pub fn import_tables(
        &mut self,
        bytes: &[u8],
        format: coords::file::TableFormat,
    ) -> Result<usize, teach::file::FileError> {
        self.coords.import(bytes, format, &self.model)
    }

    /// Asks the window to give the drafts to the built-in simulator as its tables.
    pub fn give_draft_to_simulator(&mut self, _now: Instant) {
        self.coords.give_to_simulator(&mut out!(self));
    }
}

/// The message's name for the operator: "SCARA relative move".
fn name(command: &Command) -> &'static str {
    command.id().name().unwrap_or("command")
}

#[cfg(test)]
mod hold_tests;
#[cfg(test)]
mod order_props;
#[cfg(test)]
pub(crate) mod sim_bench;
#[cfg(test)]
mod tests;
