//! System messages: 201H version, 215H system status, 216H error detail, 252H alarm
//! reset, 25BH software reset. (200H test call is echoed by the dispatcher.)

use crate::protocol::{
    ErrorCode, ErrorDetail, ErrorDetailQuery, Reply, SystemMode, SystemStatus, SystemStatus1,
    SystemStatus2, SystemStatus3, UnitType, VersionInfo, VersionQuery,
};
use crate::sim::controller::Controller;
use crate::sim::errors::SimError;
use crate::sim::state::Mode;

/// 201H answers: model code, unit code, version, build date (PROTOCOL.md 3.2; values are
/// the simulator's own).
const VERSIONS: [(u8, u8, u16); 4] = [
    (0x15, 0x00, 0x0107), // main CPU application
    (0x15, 0x01, 0x0102), // main CPU core
    (0x15, 0x02, 0x0031), // driver CPU
    (0x15, 0x03, 0x0010), // SIO board
];

impl Controller {
    /// 201H version code query (PROTOCOL.md 3.2).
    pub(crate) fn msg_version(&mut self, q: VersionQuery) -> Result<Reply, SimError> {
        let UnitType(unit) = q.unit;
        let &(model, unit_code, version) =
            VERSIONS.get(usize::from(unit)).ok_or(SimError::BadValue)?;
        if q.device != 0 {
            return Err(SimError::BadValue);
        }
        Ok(Reply::Version(VersionInfo {
            unit: q.unit,
            device: q.device,
            model,
            unit_code,
            version,
            year: 2024,
            month: 3,
            day: 15,
            hour: 10,
            minute: 20,
            second: 30,
        }))
    }

    /// 215H system status (PROTOCOL.md 3.4).
    pub(crate) fn msg_system_status(&mut self) -> Reply {
        let manual = self.mode == Mode::Manual;
        let ready = !self.estop && !self.drive_cut && self.alarm.is_none();
        Reply::SystemStatus(SystemStatus {
            mode: SystemMode(self.mode.code()),
            critical_error: ErrorCode(self.alarm.as_ref().map_or(0, |a| a.code)),
            latest_error: ErrorCode(self.latest_error),
            status1: SystemStatus1::default()
                .with_manual_switch(manual)
                .with_emergency_stop(self.estop),
            status2: SystemStatus2::default()
                .with_io_interlock(self.signals.interlock())
                .with_program_running(self.programs.any_started()),
            status3: SystemStatus3::default()
                .with_drive_cut_off(self.drive_cut)
                .with_auto_operation(!manual)
                .with_ready(ready),
            status4: 0,
        })
    }

    /// 216H error detail (PROTOCOL.md 3.5): the pending alarm or the last refusal or
    /// alarm, an axis's error,
    /// or a record of the alarm history (newest = record 1).
    pub(crate) fn msg_error_detail(&mut self, q: ErrorDetailQuery) -> Result<Reply, SimError> {
        let nth = |record: usize| record.checked_sub(1).and_then(|i| self.history.get(i));
        let alarm = match q {
            // The pending alarm, else the last refusal or alarm; "latest" the last
            // refusal (`&` reply) or alarm, so a host asking after a refusal learns why
            // `[inferred: the spec names the types, not which errors they cover]`.
            ErrorDetailQuery::System { latest: false } => {
                self.alarm.as_ref().or(self.last_error.as_ref())
            }
            ErrorDetailQuery::System { latest: true } => self.last_error.as_ref(),
            ErrorDetailQuery::Axis { axis } => {
                if axis == 0 || usize::from(axis) > self.axis_count() {
                    return Err(SimError::BadAxis);
                }
                let code = self.axes[usize::from(axis) - 1].error;
                self.history
                    .iter()
                    .find(|a| a.code == code && a.axis == Some(axis))
                    .filter(|_| code != 0)
            }
            // The newest alarm a program raised `[inferred: type 2 names a program]`.
            ErrorDetailQuery::Program { program } => self
                .history
                .iter()
                .find(|a| a.program == program && program != 0),
            ErrorDetailQuery::ListRecord { record } if record >= 1 => nth(usize::from(record)),
            ErrorDetailQuery::ExtendedListRecord { record } if record >= 1 => {
                nth(usize::from(record))
            }
            _ => return Err(SimError::BadValue),
        };
        let mut detail = ErrorDetail::default();
        if let Some(a) = alarm {
            detail.error = ErrorCode(a.code);
            // Details 1-8: program, step, axis, point, 5-8 unused.
            detail.details[0] = u32::from(a.program);
            detail.details[1] = u32::from(a.step);
            detail.details[2] = u32::from(a.axis.unwrap_or(0));
            let text = a.message.as_bytes();
            detail.message = text[..text.len().min(255)].to_vec();
        }
        Ok(Reply::ErrorDetail(detail))
    }

    /// 252H alarm reset: clears the pending alarm and axis error codes.
    pub(crate) fn msg_alarm_reset(&mut self) -> Result<(), SimError> {
        self.reset_alarm();
        Ok(())
    }

    /// 25BH software reset: then silent for the reboot time (acknowledged first when
    /// `reset_replies` is on).
    pub(crate) fn msg_reset(&mut self) -> Result<(), SimError> {
        if self.mode == Mode::Manual {
            return Err(SimError::ManualMode);
        }
        self.reboot();
        Ok(())
    }
}
