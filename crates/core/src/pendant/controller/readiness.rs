//! Whether the controller may be asked to move now, and if not, the reason an operator reads.

use std::fmt;

use crate::protocol::{HomeState, ScaraStatus, SystemMode, SystemStatus};

/// Why motion controls are disabled. The first reason that applies is shown.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum NotReady {
    /// The line is down or not open yet.
    LineDown,
    /// No status has been read since the line opened.
    NoStatus,
    /// The last status is too old to trust (polls are failing).
    StatusStale,
    /// The mode switch is on MANUAL: the teach pendant of the controller has control.
    Manual,
    /// A mode other than AUTO or MANUAL (update modes, undetermined).
    OtherMode(SystemMode),
    EmergencyStop,
    DriveCutOff,
    /// An alarm is pending; 252H resets it.
    Alarm,
    /// The controller does not report "system ready".
    ControllerNotReady,
    ServoOff,
    NotHomed,
    /// A homing or servo switch is in progress.
    Busy,
}

impl fmt::Display for NotReady {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            NotReady::LineDown => f.write_str("the line is down"),
            NotReady::NoStatus => f.write_str("no status read from the controller yet"),
            NotReady::StatusStale => f.write_str("the controller's status is out of date"),
            NotReady::Manual => f.write_str("the controller is in MANUAL mode"),
            NotReady::OtherMode(m) => write!(
                f,
                "the controller is in {} mode",
                m.name().unwrap_or("an unknown")
            ),
            NotReady::EmergencyStop => f.write_str("emergency stop is active"),
            NotReady::DriveCutOff => f.write_str("the drive source is cut off"),
            NotReady::Alarm => f.write_str("an alarm is pending: reset it first"),
            NotReady::ControllerNotReady => f.write_str("the controller is not ready"),
            NotReady::ServoOff => f.write_str("servo is off: switch it on first"),
            NotReady::NotHomed => f.write_str("the arm is not homed: home it first"),
            NotReady::Busy => f.write_str("homing or servo switching in progress"),
        }
    }
}

/// Checks that hold for every command that acts (servo, home, alarm reset excepted
/// where noted): the line, the status, the mode and the safety circuit.
pub fn controller_gate(
    line_up: bool,
    system: Option<&SystemStatus>,
    stale: bool,
) -> Result<(), NotReady> {
    if !line_up {
        return Err(NotReady::LineDown);
    }
    let Some(s) = system else {
        return Err(NotReady::NoStatus);
    };
    if stale {
        return Err(NotReady::StatusStale);
    }
    match s.mode {
        SystemMode::AUTO => {}
        SystemMode::MANUAL => return Err(NotReady::Manual),
        other => return Err(NotReady::OtherMode(other)),
    }
    if s.status1.emergency_stop() {
        return Err(NotReady::EmergencyStop);
    }
    if s.status3.drive_cut_off() {
        return Err(NotReady::DriveCutOff);
    }
    Ok(())
}

/// Whether a pending alarm blocks motion: a critical error is set.
pub fn alarm_pending(s: &SystemStatus) -> bool {
    s.critical_error.0 != 0
}

/// Everything a move needs: the controller gate, no alarm, ready, and every SCARA axis
/// servo on, homed and not busy homing.
pub fn motion_gate(
    line_up: bool,
    system: Option<&SystemStatus>,
    scara: Option<&ScaraStatus>,
    stale: bool,
) -> Result<(), NotReady> {
    controller_gate(line_up, system, stale)?;
    let s = system.ok_or(NotReady::NoStatus)?;
    if alarm_pending(s) {
        return Err(NotReady::Alarm);
    }
    if !s.status3.ready() {
        return Err(NotReady::ControllerNotReady);
    }
    let scara = scara.ok_or(NotReady::NoStatus)?;
    let axes = || scara.axes.iter().map(|(_, a)| a.status);
    if axes().any(|st| st.home_state() == HomeState::Homing) {
        return Err(NotReady::Busy);
    }
    if axes().any(|st| !st.servo_on()) {
        return Err(NotReady::ServoOff);
    }
    if axes().any(|st| st.home_state() != HomeState::Done) {
        return Err(NotReady::NotHomed);
    }
    Ok(())
}
