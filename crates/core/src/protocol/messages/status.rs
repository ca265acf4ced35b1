//! 212H axis status and 215H system status: the per-axis block and the status bytes.

use crate::protocol::axis::{Axis, AxisPattern, PerAxis};
use crate::protocol::error::{EncodeError, MessageError};
use crate::protocol::fields::{BitDef, Name, Reader, Show};
use crate::protocol::ids::ErrorCode;
use crate::protocol::units::{AxisUnit, Milli};
use crate::protocol::writer::Writer;

/// Home state, bits 1-2 of the axis status (PROTOCOL.md 3.3).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum HomeState {
    /// 0: home return not done.
    NotDone,
    /// 1: homing in progress.
    Homing,
    /// 2: home return done.
    Done,
    /// 3: not defined by the spec.
    Undefined,
}

flags! {
    /// Axis status byte of 212H / 2A1H / 2A3H (PROTOCOL.md 3.3). Bits 6-7 reserved and kept
    /// as received.
    AxisStatus {
        /// Bit 0: a task owns the axis (moving, switching servo, paused).
        in_use / with_in_use = 0, "servo axis in use";
        /// Bit 3: servo on.
        servo_on / with_servo_on = 3, "servo on";
        /// Bit 4: the last operation command completed normally.
        completed_normally / with_completed_normally = 4, "operation completed normally";
        /// Bit 5: push error detected.
        push_error / with_push_error = 5, "push error";
    }
    groups [BitDef {
        lo: 1,
        width: 2,
        name: "home state",
        values: &[(0, "not done"), (1, "homing"), (2, "done")],
    }]
}

impl AxisStatus {
    /// Bits 1-2.
    pub const fn home_state(self) -> HomeState {
        match (self.0 >> 1) & 3 {
            0 => HomeState::NotDone,
            1 => HomeState::Homing,
            2 => HomeState::Done,
            _ => HomeState::Undefined,
        }
    }

    /// This value with bits 1-2 set to `state`.
    pub const fn with_home_state(self, state: HomeState) -> Self {
        let code = match state {
            HomeState::NotDone => 0,
            HomeState::Homing => 1,
            HomeState::Done => 2,
            HomeState::Undefined => 3,
        };
        AxisStatus((self.0 & !0b110) | (code << 1))
    }
}

flags! {
    /// Axis sensor input status, 1 hex digit (PROTOCOL.md 3.3). Each: 1 = ON.
    SensorInput {
        /// Bit 0: creep sensor.
        creep / with_creep = 0, "creep sensor";
        /// Bit 1: overrun sensor.
        overrun / with_overrun = 1, "overrun sensor";
        /// Bit 2: home sensor.
        home / with_home = 2, "home sensor";
    }
}

flags! {
    /// Encoder status (at reset) (PROTOCOL.md 3.3).
    EncoderStatus {
        /// Bit 0: OS overspeed.
        overspeed / with_overspeed = 0, "OS overspeed";
        /// Bit 1: FS full-absolute status.
        full_absolute / with_full_absolute = 1, "FS full-absolute status";
        /// Bit 2: CE count error.
        count_error / with_count_error = 2, "CE count error";
        /// Bit 3: OF counter overflow.
        counter_overflow / with_counter_overflow = 3, "OF counter overflow";
        /// Bit 5: ME multi-rotation error.
        multi_rotation_error / with_multi_rotation_error = 5, "ME multi-rotation error";
        /// Bit 6: BE battery error.
        battery_error / with_battery_error = 6, "BE battery error";
        /// Bit 7: BA battery alarm.
        battery_alarm / with_battery_alarm = 7, "BA battery alarm";
    }
}

/// The 16-character per-axis block of 212H, 2A1H and 2A3H replies.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct AxisState {
    /// Axis status bits.
    pub status: AxisStatus,
    /// Sensor inputs (1 hex digit).
    pub sensor: SensorInput,
    /// Axis error number, `000` = none.
    pub error: ErrorCode,
    /// Encoder status bits.
    pub encoder: EncoderStatus,
    /// Current position (0.001 mm, or 0.001 deg for rotary axes).
    pub position: Milli,
}

/// Reads the per-axis blocks for every axis of `pattern`; `unit` gives each axis's unit.
pub(crate) fn read_axis_blocks(
    r: &mut Reader<'_, '_>,
    pattern: AxisPattern,
    unit: impl Fn(Axis) -> AxisUnit,
) -> Result<PerAxis<AxisState>, MessageError> {
    let mut out = PerAxis::new();
    for a in pattern {
        let status = AxisStatus(r.u8(Name::axis("status", a), 2, Show::Bits(AxisStatus::BITS))?);
        let sensor = SensorInput(r.u8(
            Name::axis("sensor input", a),
            1,
            Show::Bits(SensorInput::BITS),
        )?);
        let error = r.error_code(Name::axis("error code", a))?;
        let encoder = EncoderStatus(r.u8(
            Name::axis("encoder status", a),
            2,
            Show::Bits(EncoderStatus::BITS),
        )?);
        let position = r.coord(Name::axis("position", a), unit(a))?;
        out.set(
            a,
            AxisState {
                status,
                sensor,
                error,
                encoder,
                position,
            },
        );
    }
    Ok(out)
}

/// Writes the axis pattern and one block per axis.
pub(crate) fn write_axis_blocks(
    w: &mut Writer<'_>,
    axes: &PerAxis<AxisState>,
) -> Result<(), EncodeError> {
    w.hex_fit(u32::from(axes.pattern().0), 2);
    for (a, s) in axes.iter() {
        w.hex_fit(u32::from(s.status.0), 2);
        if s.sensor.0 > 0xF {
            return Err(w.error(Name::axis("sensor input", a), "does not fit 1 hex digit"));
        }
        w.hex_fit(u32::from(s.sensor.0), 1);
        w.hex(
            &Name::axis("error code", a).to_string(),
            u32::from(s.error.0),
            3,
        )?;
        w.hex_fit(u32::from(s.encoder.0), 2);
        w.coord(s.position);
    }
    Ok(())
}

/// System mode, 1 hex digit of 215H (PROTOCOL.md 3.4).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct SystemMode(pub u8);

impl SystemMode {
    /// 0: undetermined.
    pub const UNDETERMINED: SystemMode = SystemMode(0);
    /// 1: AUTO.
    pub const AUTO: SystemMode = SystemMode(1);
    /// 2: MANUAL.
    pub const MANUAL: SystemMode = SystemMode(2);
    /// 3: slave-update mode.
    pub const SLAVE_UPDATE: SystemMode = SystemMode(3);
    /// 4: core-update mode.
    pub const CORE_UPDATE: SystemMode = SystemMode(4);

    /// The mode's name, `None` for a code the spec does not define.
    pub const fn name(self) -> Option<&'static str> {
        match self.0 {
            0 => Some("undetermined"),
            1 => Some("AUTO"),
            2 => Some("MANUAL"),
            3 => Some("slave-update mode"),
            4 => Some("core-update mode"),
            _ => None,
        }
    }
}

const MODE_CODES: &[(u32, &str)] = &[
    (0, "undetermined"),
    (1, "AUTO"),
    (2, "MANUAL"),
    (3, "slave-update mode"),
    (4, "core-update mode"),
];

flags! {
    /// 215H system status byte 1.
    SystemStatus1 {
        /// Bit 0: mode switch in MANUAL (0 = AUTO).
        manual_switch / with_manual_switch = 0, "mode switch MANUAL";
        /// Bit 1: TP enable switch OFF.
        tp_enable_off / with_tp_enable_off = 1, "TP enable switch OFF";
        /// Bit 2: safety gate open (enable switch on some controllers).
        safety_gate_open / with_safety_gate_open = 2, "safety gate open";
        /// Bit 3: emergency stop active.
        emergency_stop / with_emergency_stop = 3, "emergency stop";
        /// Bit 4: power error.
        power_error / with_power_error = 4, "power error";
        /// Bit 5: battery low warning.
        battery_low / with_battery_low = 5, "battery low warning";
        /// Bit 6: battery voltage error.
        battery_error / with_battery_error = 6, "battery voltage error";
    }
}

flags! {
    /// 215H system status byte 2.
    SystemStatus2 {
        /// Bit 0: application data flash-ROM write/erase in progress.
        flash_writing / with_flash_writing = 0, "flash-ROM write in progress";
        /// Bit 1: slave parameter write in progress.
        slave_parameter_writing / with_slave_parameter_writing = 1, "slave parameter write in progress";
        /// Bit 2: servo interlock.
        servo_interlock / with_servo_interlock = 2, "servo interlock";
        /// Bit 3: I/O interlock.
        io_interlock / with_io_interlock = 3, "I/O interlock";
        /// Bit 4: waiting for restart.
        waiting_for_restart / with_waiting_for_restart = 4, "waiting for restart";
        /// Bit 5: program running.
        program_running / with_program_running = 5, "program running";
    }
}

flags! {
    /// 215H system status byte 3.
    SystemStatus3 {
        /// Bit 0: drive source cut off.
        drive_cut_off / with_drive_cut_off = 0, "drive source cut off";
        /// Bit 1: operating in AUTO mode.
        auto_operation / with_auto_operation = 1, "operating in AUTO mode";
        /// Bit 2: system ready.
        ready / with_ready = 2, "system ready";
        /// Bit 4: operation mode positioner (0 = program).
        positioner_mode / with_positioner_mode = 4, "operation mode positioner";
    }
}

/// 215H reply: system status (PROTOCOL.md 3.4).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct SystemStatus {
    /// System mode (1 hex digit).
    pub mode: SystemMode,
    /// Critical-level system error number.
    pub critical_error: ErrorCode,
    /// Latest system error number.
    pub latest_error: ErrorCode,
    /// Status byte 1 (switches, E-stop, power, battery).
    pub status1: SystemStatus1,
    /// Status byte 2 (interlocks, program running).
    pub status2: SystemStatus2,
    /// Status byte 3 (drive cut-off, AUTO operation, ready).
    pub status3: SystemStatus3,
    /// Status byte 4 (reserved).
    pub status4: u8,
}

impl SystemStatus {
    /// Whether a motion command may be sent: AUTO, ready, drive source on, no E-stop.
    /// [inferred] PROTOCOL.md 3.4 (suggested gate).
    pub const fn motion_allowed(&self) -> bool {
        self.mode.0 == SystemMode::AUTO.0
            && self.status3.ready()
            && !self.status3.drive_cut_off()
            && !self.status1.emergency_stop()
    }

    pub(crate) fn read(r: &mut Reader<'_, '_>) -> Result<Self, MessageError> {
        let mode = SystemMode(r.u8(Name::new("system mode"), 1, Show::Code(MODE_CODES))?);
        let critical_error = r.error_code(Name::new("critical-level system error"))?;
        let latest_error = r.error_code(Name::new("latest system error"))?;
        let status1 = SystemStatus1(r.u8(
            Name::new("system status byte 1"),
            2,
            Show::Bits(SystemStatus1::BITS),
        )?);
        let status2 = SystemStatus2(r.u8(
            Name::new("system status byte 2"),
            2,
            Show::Bits(SystemStatus2::BITS),
        )?);
        let status3 = SystemStatus3(r.u8(
            Name::new("system status byte 3"),
            2,
            Show::Bits(SystemStatus3::BITS),
        )?);
        let status4 = r.u8(Name::new("system status byte 4 (reserved)"), 2, Show::Hex)?;
        Ok(SystemStatus {
            mode,
            critical_error,
            latest_error,
            status1,
            status2,
            status3,
            status4,
        })
    }

    pub(crate) fn write(&self, w: &mut Writer<'_>) -> Result<(), EncodeError> {
        w.hex("system mode", u32::from(self.mode.0), 1)?;
        w.hex(
            "critical-level system error",
            u32::from(self.critical_error.0),
            3,
        )?;
        w.hex("latest system error", u32::from(self.latest_error.0), 3)?;
        w.hex_fit(u32::from(self.status1.0), 2);
        w.hex_fit(u32::from(self.status2.0), 2);
        w.hex_fit(u32::from(self.status3.0), 2);
        w.hex_fit(u32::from(self.status4), 2);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn axis_status_bits() {
        let s = AxisStatus(0x1C);
        assert!(s.servo_on());
        assert!(s.completed_normally());
        assert!(!s.in_use());
        assert_eq!(s.home_state(), HomeState::Done);
        let built = AxisStatus::default()
            .with_servo_on(true)
            .with_completed_normally(true)
            .with_home_state(HomeState::Done);
        assert_eq!(built, s);
        assert_eq!(AxisStatus(0x0D).home_state(), HomeState::Done);
        assert!(AxisStatus(0x0D).in_use());
    }

    #[test]
    fn motion_gate() {
        let ok = SystemStatus {
            mode: SystemMode::AUTO,
            status3: SystemStatus3(0x06),
            ..Default::default()
        };
        assert!(ok.motion_allowed());
        let estop = SystemStatus {
            status1: SystemStatus1::default().with_emergency_stop(true),
            ..ok
        };
        assert!(!estop.motion_allowed());
    }
}
