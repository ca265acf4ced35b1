//! `Controller`: the simulated X-SEL controller, sans-IO. A frame and the time in, the
//! reply bytes (or silence) out; `advance(now)` moves the world.

use std::time::Duration;

use super::errors::SimError;
use super::framing::{Silence, max_command};
use super::motion::{Motion, MotionKind};
use super::programs::Programs;
use super::signals::Signals;
use super::state::{Alarm, AxisKind, AxisState, Counters, HomeProgress, Mode, SimConfig};
use crate::files::coords_file::{self, PositionTable, Zones};
use crate::protocol::{
    Command, ErrorCode, Frame, FrameErrorKind, Header, MessageId, RealEncoding, Reply, Sc, Station,
};
use crate::robot::{ArmSystem, CoordSystem, CoordTables, Joints, Pose, RobotModel, Scara};

/// Motion commands, counted as received, started and refused (233H-236H, 26BH,
/// 2D4H-2D6H).
fn is_motion_id(id: MessageId) -> bool {
    matches!(
        id,
        MessageId::HOME
            | MessageId::MOVE_ABSOLUTE
            | MessageId::MOVE_RELATIVE
            | MessageId::JOG
            | MessageId::POSITION_MOVE
            | MessageId::SCARA_MOVE_ABSOLUTE
            | MessageId::SCARA_MOVE_RELATIVE
            | MessageId::SCARA_MOVE_POSITION
    )
}

/// Everything a controller starts from (no file IO: the caller loads files).
#[derive(Debug, Clone)]
pub struct SimSetup {
    pub config: SimConfig,
    pub model: RobotModel,
    pub coords: CoordTables,
    /// The position table (209H-291H, 26BH, 2D6H); numbers above the model's maximum
    /// (`config.position_digits`) are kept but never reached.
    pub positions: PositionTable,
    /// The simple interference-check zones (2A2H), by number.
    pub zones: Zones,
    /// SEL programs (213H, 253H-257H); by default the demo ([`crate::sel::DEMO`]).
    pub programs: Vec<crate::sel::Program>,
}

impl Default for SimSetup {
    fn default() -> Self {
        Self::for_model(RobotModel::default_model())
    }
}

impl SimSetup {
    /// A model with the shipped example coordinate tables and positions.
    pub fn for_model(model: RobotModel) -> Self {
        let defaults = coords_file::defaults(&model);
        Self {
            config: SimConfig::default(),
            model,
            coords: defaults.tables,
            positions: defaults.positions,
            zones: defaults.zones,
            programs: crate::sel::parse(crate::sel::DEMO)
                .runnable()
                .cloned()
                .collect(),
        }
    }
}

/// How many alarms 216H type 3 can list (newest first).
pub const ALARM_HISTORY: usize = 64;

/// A picture of the controller for tests and the control API.
#[derive(Debug, Clone, PartialEq)]
pub struct Snapshot {
    pub joints: Joints,
    /// Linear axes 5 and 6 (mm).
    pub linear: [f64; 2],
    pub axes: [AxisState; 8],
    /// Axis pattern of the axes in use (moving, homing, switching servo).
    pub in_use: u8,
    pub mode: Mode,
    pub emergency_stop: bool,
    pub drive_cut_off: bool,
    pub alarm: Option<Alarm>,
    pub work: usize,
    pub tool: usize,
    /// Tool tip in the base frame.
    pub tip_base: Pose,
    pub arm: ArmSystem,
}

/// The simulated controller.
pub struct Controller {
    pub(crate) cfg: SimConfig,
    pub(crate) model: RobotModel,
    pub(crate) kin: Scara,
    pub(crate) coords: CoordTables,
    pub(crate) positions: PositionTable,
    pub(crate) zones: Zones,
    pub(crate) work_no: usize,
    pub(crate) tool_no: usize,
    pub(crate) axes: [AxisState; 8],
    /// Axis values in axis order: J1 deg, J2 deg, Z mm, J4 deg, axis 5 mm, axis 6 mm.
    pub(crate) values: [f64; 8],
    pub(crate) motions: Vec<Motion>,
    pub(crate) mode: Mode,
    pub(crate) estop: bool,
    pub(crate) drive_cut: bool,
    pub(crate) alarm: Option<Alarm>,
    pub(crate) history: Vec<Alarm>,
    pub(crate) latest_error: u16,
    /// The last refusal (`&` reply) or alarm, newest wins: what 216H reports.
    pub(crate) last_error: Option<Alarm>,
    pub(crate) rebooting_until: Option<Duration>,
    pub(crate) now: Duration,
    pub(crate) counters: Counters,
    /// Inputs, outputs, flags, variables and the I/O interlock (boxed: some 100 kB).
    pub(crate) signals: Box<Signals>,
    /// The SEL programs and their tasks.
    pub(crate) programs: Box<Programs>,
    /// The program slot whose step runs now: its own moves pass the check that the
    /// axes another program holds are taken.
    pub(crate) acting: Option<usize>,
}

impl Controller {
    pub fn new(setup: SimSetup) -> Self {
        let kin = Scara::new(&setup.model);
        let home = setup.model.home;
        let mut values = [0.0; 8];
        values[..4].copy_from_slice(&home.to_array());
        let mut c = Controller {
            cfg: setup.config,
            kin,
            model: setup.model,
            coords: setup.coords,
            positions: setup.positions,
            zones: setup.zones,
            work_no: 0,
            tool_no: 0,
            axes: [AxisState::default(); 8],
            values,
            motions: Vec::new(),
            mode: Mode::Auto,
            estop: false,
            drive_cut: false,
            alarm: None,
            history: Vec::new(),
            latest_error: 0,
            last_error: None,
            rebooting_until: None,
            now: Duration::ZERO,
            counters: Counters::default(),
            signals: Box::default(),
            programs: Box::new(Programs::new(setup.programs)),
            acting: None,
        };
        c.cfg.linear_axes = c.cfg.linear_axes.min(2);
        if c.cfg.start_ready {
            for i in 0..c.axis_count() {
                c.axes[i].servo = true;
                c.axes[i].home = HomeProgress::Done;
            }
        }
        c
    }

    /// Axis pattern of the axes this controller has (SCARA 1-4, linear 5-6).
    pub fn present(&self) -> u8 {
        (1u16 << self.axis_count()).wrapping_sub(1) as u8
    }

    pub(crate) fn axis_count(&self) -> usize {
        4 + usize::from(self.cfg.linear_axes)
    }

    /// Rotary (0.001 deg) or linear (0.001 mm) each-axis unit of axis index `i`.
    pub fn axis_kind(i: usize) -> AxisKind {
        if i == 0 || i == 1 || i == 3 {
            AxisKind::Rotary
        } else {
            AxisKind::Linear
        }
    }

    pub fn config(&self) -> &SimConfig {
        &self.cfg
    }

    pub fn model(&self) -> &RobotModel {
        &self.model
    }

    pub fn station(&self) -> u8 {
        self.cfg.station
    }

    /// Minimum time between a command's last byte and the reply's first byte.
    pub fn reply_delay(&self) -> Duration {
        self.cfg.reply_delay
    }

    pub fn set_reply_delay(&mut self, delay: Duration) {
        self.cfg.reply_delay = delay;
    }

    pub fn counters(&self) -> &Counters {
        &self.counters
    }

    /// Inputs, outputs, flags, variables and the I/O interlock.
    pub fn signals(&self) -> &Signals {
        &self.signals
    }

    /// The signals, to set from outside the protocol (console, front panel, tests).
    pub fn signals_mut(&mut self) -> &mut Signals {
        &mut self.signals
    }

    /// How real variables travel (20FH, 24DH).
    pub fn set_real_encoding(&mut self, encoding: RealEncoding) {
        self.cfg.real_encoding = encoding;
    }

    /// Answers one frame (bytes up to and including LF) received at `now`. Returns the
    /// reply, or `None` when the controller stays silent.
    pub fn handle(&mut self, frame: &[u8], now: Duration) -> Option<Vec<u8>> {
        let mut out = Vec::with_capacity(64);
        self.handle_into(frame, now, &mut out).then_some(out)
    }

    /// As [`Controller::handle`], writing the reply into `out` (cleared first); `true` when
    /// there is a reply to send.
    pub fn handle_into(&mut self, frame: &[u8], now: Duration, out: &mut Vec<u8>) -> bool {
        self.answer(frame, now, out).is_ok()
    }

    /// As [`Controller::handle_into`]; `Err` says why the controller stays silent.
    /// Every frame counts once: a reply (`#`), an error (`&`) or a silence by reason.
    pub fn answer(
        &mut self,
        frame: &[u8],
        now: Duration,
        out: &mut Vec<u8>,
    ) -> Result<(), Silence> {
        out.clear();
        self.advance(now);
        self.counters.frames += 1;
        let result = self.answer_counted(frame, out);
        if let Err(silence) = result {
            self.count_silence(silence);
        }
        result
    }

    /// A run the line assembler dropped before it could be a frame (no `!` header, cut by
    /// a new `!`, too long): counted like a frame that got no reply.
    pub fn note_dropped(&mut self, reason: Silence, now: Duration) {
        self.advance(now);
        self.counters.frames += 1;
        self.count_silence(reason);
    }

    /// Replies the line could not deliver and input bytes read but never served, when
    /// the line failed in the middle (counted, never silently dropped).
    pub fn note_lost(&mut self, replies: u64, input_bytes: u64) {
        self.counters.lost_replies += replies;
        self.counters.input_lost_bytes += input_bytes;
    }

    fn count_silence(&mut self, silence: Silence) {
        let c = &mut self.counters;
        match silence {
            Silence::Header => c.silent_header += 1,
            Silence::Station => c.silent_station += 1,
            Silence::Checksum => c.silent_checksum += 1,
            Silence::Terminator => c.silent_terminator += 1,
            Silence::Rebooting => c.silent_rebooting += 1,
            Silence::Reset => c.silent_reset += 1,
            Silence::TooShort | Silence::MessageId | Silence::Overflow | Silence::Unencodable => {
                c.silent_other += 1
            }
        }
    }

    /// The body of [`Controller::answer`]: counts replies and errors actually produced;
    /// the caller counts silences.
    fn answer_counted(&mut self, frame: &[u8], out: &mut Vec<u8>) -> Result<(), Silence> {
        if self.rebooting_until.is_some() {
            return Err(Silence::Rebooting);
        }
        let frame = self.accept(frame)?;
        if frame.sc() == Sc::AtAt {
            self.counters.at_at += 1;
        }
        let motion = frame.id().is_some_and(is_motion_id);
        if motion {
            self.counters.motion_received += 1;
        }
        let result = Command::decode(&frame)
            .map_err(|e| SimError::from_message_error(&e))
            .and_then(|cmd| self.dispatch(&cmd));
        let station = Station(self.cfg.station);
        match result {
            Ok(reply) => {
                if motion {
                    self.counters.motion_started += 1;
                }
                // 25BH without a reply carries out the reset but answers nothing.
                let reply = reply.ok_or(Silence::Reset)?;
                // Typed replies are built within their fields' ranges.
                reply
                    .encode_into(station, out)
                    .map_err(|_| Silence::Unencodable)?;
                self.counters.replies += 1;
            }
            Err(e) => {
                if motion {
                    self.counters.motion_refused += 1;
                }
                self.last_error = Some(Alarm {
                    code: e.code(),
                    message: e.text().to_owned(),
                    ..Alarm::default()
                });
                Reply::Error(ErrorCode(e.code()))
                    .encode_into(station, out)
                    .map_err(|_| Silence::Unencodable)?;
                self.counters.errors += 1;
            }
        }
        Ok(())
    }

    /// The silence rules (PROTOCOL.md 1.6): a command frame for this station, whole, with a
    /// right SC or `@@`, no longer than the receive buffer (PROTOCOL.md 1.7: 1023 or 2051
    /// bytes by the reply-buffer setting); anything else gets no reply.
    fn accept<'a>(&self, bytes: &'a [u8]) -> Result<Frame<'a>, Silence> {
        if bytes.len() > max_command(self.cfg.reply_buffer) {
            return Err(Silence::Overflow);
        }
        if bytes.first() != Some(&Header::Command.byte()) {
            return Err(Silence::Header);
        }
        let frame = Frame::parse(bytes).map_err(|e| match e.kind {
            FrameErrorKind::BadHeader { .. } => Silence::Header,
            FrameErrorKind::BadStation => Silence::Station,
            FrameErrorKind::MissingCr { .. }
            | FrameErrorKind::MissingLf { .. }
            | FrameErrorKind::MissingLineEnd { .. } => Silence::Terminator,
            FrameErrorKind::BadSc { .. } | FrameErrorKind::Checksum { .. } => Silence::Checksum,
            FrameErrorKind::TooShort { .. } => Silence::TooShort,
            FrameErrorKind::TooLong { .. } => Silence::Overflow,
            FrameErrorKind::BadMessageId => Silence::MessageId,
        })?;
        if frame.station() != Station(self.cfg.station) {
            return Err(Silence::Station);
        }
        Ok(frame)
    }

    /// Runs one decoded command: the reply to send (`None`: none, as after 25BH when
    /// `reset_replies` is off), or the refusal.
    fn dispatch(&mut self, cmd: &Command) -> Result<Option<Reply>, SimError> {
        let reply = match *cmd {
            Command::TestCall(data) => Reply::TestCall(data),
            Command::Version(q) => self.msg_version(q)?,
            Command::AxisStatus { axes } => self.msg_axis_status(axes),
            Command::SystemStatus => self.msg_system_status(),
            Command::ErrorDetail(q) => self.msg_error_detail(q)?,
            Command::CoordQuery(q) => self.msg_coords(q)?,
            Command::CoordQuery2(q) => self.msg_coords2(q)?,
            Command::ZoneQuery(q) => self.msg_zones(q)?,
            Command::ScaraStatus(q) => self.msg_scara_status(q.axes, q.system),
            Command::ScaraStatus2(q) => self.msg_scara_status2(q.axes, q.system_1_4),
            Command::PositionQuery(q) => self.msg_position_query(q)?,
            Command::PositionWrite(ref w) => self.msg_position_write(w)?,
            Command::BitQuery(ref q) => self.msg_bit_query(q)?,
            Command::VarQuery(ref q) => self.msg_var_query(q)?,
            Command::VarWrite(ref d) => self.msg_var_write(d)?,
            Command::ProgramStatus(q) => self.msg_program_status(q)?,
            Command::SoftwareReset => {
                self.msg_reset()?;
                return Ok(self.cfg.reset_replies.then_some(Reply::Ack(cmd.id())));
            }
            _ => {
                self.act(cmd)?;
                Reply::Ack(cmd.id())
            }
        };
        Ok(Some(reply))
    }

    /// Commands answered with the plain acknowledge.
    fn act(&mut self, cmd: &Command) -> Result<(), SimError> {
        match cmd {
            Command::Servo(s) => self.msg_servo(s),
            Command::Home(h) => self.msg_home(h),
            Command::MoveAbsolute(m) => self.msg_linear_move(m, false),
            Command::MoveRelative(m) => self.msg_linear_move(m, true),
            Command::Jog(j) => self.msg_jog(j),
            Command::Stop(s) => self.msg_stop(s),
            Command::AlarmReset => self.msg_alarm_reset(),
            Command::SpeedChange(s) => self.msg_speed_change(s),
            Command::ScaraMoveAbsolute(m) => self.msg_scara_move(m, false),
            Command::ScaraMoveRelative(m) => self.msg_scara_move(m, true),
            Command::ScaraMovePosition(m) => self.msg_scara_position(m),
            Command::PositionMove(m) => self.msg_position_move(m),
            Command::BitChange(c) => self.msg_bit_change(c),
            Command::Program(c) => self.msg_program(c),
            _ => Err(SimError::UnknownMessage),
        }
    }

    /// Moves the world to `now`: servo switches, homing, motions, reboot.
    pub fn advance(&mut self, now: Duration) {
        if now < self.now {
            return;
        }
        self.now = now;
        if let Some(until) = self.rebooting_until
            && now >= until
        {
            self.rebooting_until = None;
        }
        for a in self.axes.iter_mut() {
            if let Some(sw) = a.switching
                && now >= sw.until
            {
                a.servo = sw.on;
                a.switching = None;
                a.completed = true;
            }
        }
        let mut i = 0;
        while i < self.motions.len() {
            let m = &self.motions[i];
            let v = m.values_at(now, &self.values);
            let finished = m.finished(now);
            self.set_values(v);
            if finished {
                let m = self.motions.swap_remove(i);
                self.end_motion(&m, m.cancelled());
            } else {
                i += 1;
            }
        }
        self.run_programs(now);
    }

    /// Takes a motion's axis values (it leaves the axes it does not own unchanged).
    fn set_values(&mut self, v: [f64; 8]) {
        for (i, new) in v.into_iter().enumerate() {
            self.values[i] = self.clamp_axis(i, new);
        }
    }

    /// Keeps a value inside its axis range (guards against rounding at the limits).
    pub(crate) fn clamp_axis(&self, i: usize, v: f64) -> f64 {
        let (lo, hi) = self.axis_range(i);
        if v.is_finite() {
            v.clamp(lo, hi)
        } else {
            lo.max(0.0).min(hi)
        }
    }

    /// Soft limits of an axis in its each-axis unit.
    pub(crate) fn axis_range(&self, i: usize) -> (f64, f64) {
        let m = &self.model;
        match i {
            0 => (m.j1.min, m.j1.max),
            1 => (m.j2.min, m.j2.max),
            2 => (m.z.min, m.z.max),
            3 => (m.r.min, m.r.max),
            _ => (0.0, self.cfg.linear_stroke_mm),
        }
    }

    pub(crate) fn end_motion(&mut self, m: &Motion, cancelled: bool) {
        for i in 0..8 {
            if m.axes & (1 << i) == 0 {
                continue;
            }
            let a = &mut self.axes[i];
            a.completed = !cancelled;
            if m.kind == MotionKind::Home {
                a.home = if cancelled {
                    HomeProgress::NotDone
                } else {
                    HomeProgress::Done
                };
            }
        }
        if cancelled {
            self.counters.motion_cancelled += 1;
        } else {
            self.counters.motion_completed += 1;
        }
    }

    /// Whether nothing changes with time: no axis in use and no reboot under way (the
    /// world then only changes by a command).
    pub fn at_rest(&self) -> bool {
        self.in_use() == 0 && self.rebooting_until.is_none() && !self.programs.any_running()
    }

    /// The SEL programs loaded and where each one is.
    pub fn programs(&self) -> &Programs {
        &self.programs
    }

    /// Replaces the programs (all of them end first, without an error).
    pub fn load_programs(&mut self, programs: impl IntoIterator<Item = crate::sel::Program>) {
        self.end_all_programs(0);
        *self.programs = Programs::new(programs);
    }

    /// Axis pattern of the axes in use: moving, homing or switching servo.
    pub fn in_use(&self) -> u8 {
        let moving = self.motions.iter().fold(0, |p, m| p | m.axes);
        let switching = self
            .axes
            .iter()
            .enumerate()
            .filter(|(_, a)| a.switching.is_some())
            .fold(0, |p, (i, _)| p | (1 << i));
        moving | switching
    }

    /// Current SCARA joints.
    pub fn joints(&self) -> Joints {
        Joints::new(
            self.values[0],
            self.values[1],
            self.values[2],
            self.values[3],
        )
    }

    pub(crate) fn work(&self) -> CoordSystem {
        self.coords
            .work
            .get(self.work_no)
            .copied()
            .unwrap_or(CoordSystem::ZERO)
    }

    pub(crate) fn tool(&self) -> CoordSystem {
        self.coords
            .tool
            .get(self.tool_no)
            .copied()
            .unwrap_or(CoordSystem::ZERO)
    }

    /// Tool tip of the selected tool, base frame.
    pub fn tip_base(&self) -> Pose {
        self.tool().flange_to_tip(&self.kin.forward(&self.joints()))
    }

    /// Tool tip of the selected tool, selected work frame.
    pub fn tip_work(&self) -> Pose {
        self.work().base_to_work(&self.tip_base())
    }
}
