//! The simulated controller's state: system flags, per-axis servo/home/status, alarms,
//! counters and the configuration it was started with.

use std::time::Duration;

/// System mode reported by 215H (PROTOCOL.md 3.4).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Mode {
    #[default]
    Auto,
    Manual,
}

impl Mode {
    /// 215H system mode digit: 1 AUTO, 2 MANUAL.
    pub fn code(self) -> u8 {
        match self {
            Mode::Auto => 1,
            Mode::Manual => 2,
        }
    }
}

/// The simulated axis's homing, with its timing; reported as the protocol's
/// [`crate::protocol::HomeState`] (212H status bits 1-2, PROTOCOL.md 3.3).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum HomeProgress {
    #[default]
    NotDone,
    /// Homing, started at `since`, ends at `until`.
    Homing {
        since: Duration,
        until: Duration,
    },
    Done,
}

impl HomeProgress {
    /// What 212H reports of it.
    pub fn state(self) -> crate::protocol::HomeState {
        use crate::protocol::HomeState;
        match self {
            HomeProgress::NotDone => HomeState::NotDone,
            HomeProgress::Homing { .. } => HomeState::Homing,
            HomeProgress::Done => HomeState::Done,
        }
    }
}

/// A servo switch in progress: the servo reaches `on` at `until`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ServoSwitch {
    pub on: bool,
    pub until: Duration,
}

/// What a simulated axis is (axes 1-4 are the SCARA, 5-6 optional linear axes).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AxisKind {
    /// SCARA J1, J2 or R: positions in 0.001 deg in the each-axis system.
    Rotary,
    /// SCARA Z or a linear axis: 0.001 mm.
    Linear,
}

/// Servo, home and completion state of one axis.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct AxisState {
    pub servo: bool,
    pub switching: Option<ServoSwitch>,
    pub home: HomeProgress,
    /// 212H bit 4: the last operation command on this axis completed normally.
    pub completed: bool,
    /// Axis error code shown by 212H (0 = none).
    pub error: u16,
}

impl AxisState {
    pub fn is_homed(&self) -> bool {
        self.home == HomeProgress::Done
    }
}

/// A pending alarm (raised by the control API or by the simulation).
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Alarm {
    pub code: u16,
    /// Axis number 1-8 the alarm belongs to, if any (216H detail 3, 212H error code).
    pub axis: Option<u8>,
    /// The program and step (1-based) that raised it; 0 for none (216H details 1-2).
    pub program: u8,
    pub step: u16,
    /// Free text for 216H's message field (at most 255 ASCII characters are sent).
    pub message: String,
}

/// What the controller received and did: read by tests and soak runs through the
/// control API (never sent on the wire).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Counters {
    /// Frames handed to the controller (after line splitting), valid or not, and runs the
    /// line splitter dropped (no `!` header, cut by a new `!`, too long).
    pub frames: u64,
    /// Frames ignored under the silence rules, by reason.
    pub silent_header: u64,
    pub silent_station: u64,
    pub silent_checksum: u64,
    pub silent_terminator: u64,
    pub silent_other: u64,
    /// Frames ignored because the controller was rebooting after 25BH.
    pub silent_rebooting: u64,
    /// 25BH carried out without a reply (`reset_replies` off).
    pub silent_reset: u64,
    /// Frames that passed the silence rules and carried `@@` as SC.
    pub at_at: u64,
    /// Normal (`#`) and error (`&`) replies produced (sent). Every frame is a reply, an
    /// error or a silence: `frames == replies + errors + silent()`.
    pub replies: u64,
    pub errors: u64,
    /// Motion commands (233H, 234H, 235H, 236H, 26BH, 2D4H, 2D5H, 2D6H) received, started
    /// (answered `#`) and refused (answered `&`).
    pub motion_received: u64,
    pub motion_started: u64,
    pub motion_refused: u64,
    /// Motions that ended normally (bit 4 set) or were cancelled (stop, E-stop, limit).
    pub motion_completed: u64,
    pub motion_cancelled: u64,
    /// 238H received.
    pub stops: u64,
    /// Servo switch commands accepted.
    pub servo_commands: u64,
    /// 25BH software resets performed.
    pub resets: u64,
    /// Replies produced but not delivered because the line failed while sending them.
    pub lost_replies: u64,
    /// Input bytes read but never served because the line failed before their turn.
    pub input_lost_bytes: u64,
}

impl Counters {
    pub fn silent(&self) -> u64 {
        self.silent_header
            + self.silent_station
            + self.silent_checksum
            + self.silent_terminator
            + self.silent_other
            + self.silent_rebooting
            + self.silent_reset
    }
}

/// Default servo switch time, ms.
pub const DEFAULT_SERVO_SWITCH_MS: u64 = 50;

/// Everything the controller needs at start (no file IO: loading is done by the caller).
#[derive(Debug, Clone)]
pub struct SimConfig {
    /// Station number (PROTOCOL.md 1.3, default 99h).
    pub station: u8,
    /// Minimum reply delay, the I/O parameter 97 analogue (PROTOCOL.md 1.5).
    pub reply_delay: Duration,
    /// Reply buffer in bytes: 2048, or 1024 for a J/K/TT model setting (PROTOCOL.md 1.7).
    pub reply_buffer: usize,
    /// Time a servo takes to switch on or off (`xsel-sim --servo-on-ms`). Published hosts
    /// wait 100 ms after the 232H reply before moving, or move at once and poll 212H
    /// `[observed]`: the default of 50 ms serves both.
    pub servo_switch_time: Duration,
    /// Time a home return takes.
    pub homing_time: Duration,
    /// 25BH: answer `#` before rebooting (the spec does not say; PROTOCOL.md 3.13).
    pub reset_replies: bool,
    /// 25BH: how long the controller stays silent while rebooting.
    pub reboot_time: Duration,
    /// Number of linear axes after the SCARA (0, 1 or 2: axes 5 and 6).
    pub linear_axes: u8,
    /// Stroke of the linear axes in mm (0..=stroke).
    pub linear_stroke_mm: f64,
    /// Maximum speed of the linear axes in mm/s.
    pub linear_max_speed: f64,
    /// All axes homed and servo on at start (handy for demos; off = like a cold start).
    pub start_ready: bool,
    /// Position numbering of the model: 4 digits (positions 1-20000, every position
    /// message) or 3 (1-3000; 21FH, 22DH, 26DH, 290H, 291H answer A01) `[inferred:
    /// PROTOCOL.md 3.24's arithmetic]`. Anything but 3 counts as 4.
    pub position_digits: u8,
    /// How real variables travel in 20FH and 24DH: PROTOCOL.md 3.40's two encodings, which
    /// a host cannot read from the controller (console `real-encoding plain|swapped`).
    pub real_encoding: crate::protocol::RealEncoding,
}

impl Default for SimConfig {
    fn default() -> Self {
        Self {
            station: 0x99,
            reply_delay: Duration::from_millis(2),
            reply_buffer: crate::protocol::REPLY_BUFFER,
            servo_switch_time: Duration::from_millis(DEFAULT_SERVO_SWITCH_MS),
            homing_time: Duration::from_millis(800),
            reset_replies: true,
            reboot_time: Duration::from_millis(1500),
            linear_axes: 0,
            linear_stroke_mm: 600.0,
            linear_max_speed: 800.0,
            start_ready: false,
            position_digits: 4,
            real_encoding: crate::protocol::RealEncoding::default(),
        }
    }
}
