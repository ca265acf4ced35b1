//! The controller's control API (not on the wire: E-stop, mode, selections, alarms, as
//! a test or the `xsel-sim` operator would set them), its reboot and servo timing, and
//! the state checks the soak tests run.

use super::controller::{ALARM_HISTORY, Controller, Snapshot};
use super::errors::SimError;
use super::state::{Alarm, HomeProgress, Mode, ServoSwitch};
use crate::files::coords_file::PositionTable;
use crate::robot::CoordTables;

impl Controller {
    /// Emergency stop: servos drop at once, moves end where they are (cancelled).
    pub fn set_emergency_stop(&mut self, on: bool) {
        self.estop = on;
        if on {
            self.halt_all(SimError::EmergencyStop.code());
        }
    }

    /// Drive source cut-off: like an emergency stop for the motors.
    pub fn set_drive_cut_off(&mut self, on: bool) {
        self.drive_cut = on;
        if on {
            self.halt_all(SimError::DriveCutOff.code());
        }
    }

    /// AUTO or MANUAL. Protocol commands that act are refused in MANUAL.
    pub fn set_mode(&mut self, mode: Mode) {
        self.mode = mode;
    }

    pub fn mode(&self) -> Mode {
        self.mode
    }

    /// Selects the work coordinate system; `false` if the table has no such number.
    pub fn select_work(&mut self, number: usize) -> bool {
        let ok = number < self.coords.work.len();
        if ok {
            self.work_no = number;
        }
        ok
    }

    /// Selects the tool coordinate system; `false` if the table has no such number.
    pub fn select_tool(&mut self, number: usize) -> bool {
        let ok = number < self.coords.tool.len();
        if ok {
            self.tool_no = number;
        }
        ok
    }

    pub fn coords(&self) -> &CoordTables {
        &self.coords
    }

    /// Replaces the coordinate tables (sizes as given); selections beyond them go to 0.
    pub fn set_coords(&mut self, coords: CoordTables) {
        self.coords = coords;
        if self.work_no >= self.coords.work.len() {
            self.work_no = 0;
        }
        if self.tool_no >= self.coords.tool.len() {
            self.tool_no = 0;
        }
    }

    /// The position table, to edit from outside the protocol (tests, the console).
    pub fn positions_mut(&mut self) -> &mut PositionTable {
        &mut self.positions
    }

    /// Clears the positions numbered `from..=to`; how many held data.
    pub fn clear_positions(&mut self, from: u16, to: u16) -> usize {
        if from > to {
            return 0;
        }
        let gone: Vec<u16> = self.positions.range(from..=to).map(|(&n, _)| n).collect();
        for n in &gone {
            self.positions.remove(n);
        }
        gone.len()
    }

    /// Raises an alarm: servos off, moves halted (cancelled), acting commands refused
    /// until 252H.
    pub fn raise_alarm(&mut self, code: u16, axis: Option<u8>, message: &str) {
        let code = code & 0xFFF;
        let alarm = Alarm {
            code,
            axis: axis.filter(|a| (1..=8).contains(a)),
            message: printable(message),
            ..Alarm::default()
        };
        if let Some(a) = alarm.axis {
            self.axes[usize::from(a - 1)].error = code;
        }
        self.record_alarm(alarm);
        self.halt_all(code);
    }

    /// A program's step failed: the alarm names the program and step; every program ends
    /// and the moves brake to a stop, servos stay on `[inferred: an operation-cancellation
    /// level error; the spec pages name no program errors]`.
    pub(crate) fn raise_program_alarm(&mut self, code: u16, program: u8, step: u16, message: &str) {
        self.record_alarm(Alarm {
            code: code & 0xFFF,
            axis: None,
            program,
            step,
            message: printable(message),
        });
        self.end_all_programs(code & 0xFFF);
        let now = self.now;
        for m in self.motions.iter_mut() {
            if !m.cancelled() {
                m.stop(now);
            }
        }
    }

    /// The alarm pending, latest and first in the history.
    fn record_alarm(&mut self, alarm: Alarm) {
        self.latest_error = alarm.code;
        self.last_error = Some(alarm.clone());
        self.history.insert(0, alarm.clone());
        self.history.truncate(ALARM_HISTORY);
        self.alarm = Some(alarm);
    }

    /// Clears the pending alarm and the axes' error codes, as 252H does.
    pub fn reset_alarm(&mut self) {
        self.alarm = None;
        self.last_error = None;
        for a in self.axes.iter_mut() {
            a.error = 0;
        }
    }

    /// Stops everything at once (E-stop, cut-off, alarm): positions freeze, servos off,
    /// every program ends with `code` (0: without an error, as a reset ends them).
    fn halt_all(&mut self, code: u16) {
        let now = self.now;
        self.advance(now);
        self.end_all_programs(code);
        for m in std::mem::take(&mut self.motions) {
            self.end_motion(&m, true);
        }
        for a in self.axes.iter_mut() {
            a.servo = false;
            a.switching = None;
            if let HomeProgress::Homing { .. } = a.home {
                a.home = HomeProgress::NotDone;
            }
        }
    }

    /// Software reset (25BH): silent for the reboot time, then servos off, moves gone,
    /// alarm cleared; home state and positions kept (absolute encoders) `[inferred,
    /// PROTOCOL.md 3.13]`.
    pub(crate) fn reboot(&mut self) {
        self.halt_all(0);
        self.alarm = None;
        for a in self.axes.iter_mut() {
            a.error = 0;
            a.completed = false;
        }
        self.counters.resets += 1;
        self.rebooting_until = Some(self.now + self.cfg.reboot_time);
    }

    pub fn is_rebooting(&self) -> bool {
        self.rebooting_until.is_some()
    }

    pub(crate) fn start_servo_switch(&mut self, pattern: u8, on: bool) {
        let until = self.now + self.cfg.servo_switch_time;
        for i in 0..8 {
            if pattern & (1 << i) != 0 {
                let a = &mut self.axes[i];
                a.completed = false;
                if a.servo == on {
                    a.completed = true;
                } else {
                    a.switching = Some(ServoSwitch { on, until });
                }
            }
        }
    }

    /// The state in one picture.
    pub fn snapshot(&self) -> Snapshot {
        Snapshot {
            joints: self.joints(),
            linear: [self.values[4], self.values[5]],
            axes: self.axes,
            in_use: self.in_use(),
            mode: self.mode,
            emergency_stop: self.estop,
            drive_cut_off: self.drive_cut,
            alarm: self.alarm.clone(),
            work: self.work_no,
            tool: self.tool_no,
            tip_base: self.tip_base(),
            arm: self.kin.arm_system(&self.joints()),
        }
    }

    /// Checks that the state is coherent: positions inside their ranges and finite,
    /// status bits consistent. `Err` names the first problem.
    pub fn check_invariants(&self) -> Result<(), String> {
        for i in 0..self.axis_count() {
            let (lo, hi) = self.axis_range(i);
            let v = self.values[i];
            if !v.is_finite() || v < lo - 1e-9 || v > hi + 1e-9 {
                return Err(format!("axis {} at {v} outside {lo}..{hi}", i + 1));
            }
        }
        let in_use = self.in_use();
        for (i, a) in self.axes.iter().enumerate() {
            let bit = 1u8 << i;
            if i >= self.axis_count() && (a.servo || in_use & bit != 0) {
                return Err(format!("absent axis {} has state", i + 1));
            }
            if matches!(a.home, HomeProgress::Homing { .. }) && in_use & bit == 0 {
                return Err(format!("axis {} homing but not in use", i + 1));
            }
            if (self.estop || self.drive_cut) && (a.servo || a.switching.is_some()) {
                return Err(format!("axis {} servo on during E-stop/cut-off", i + 1));
            }
        }
        for m in &self.motions {
            if m.axes & !self.present() != 0 {
                return Err("motion on an absent axis".into());
            }
            for i in 0..8 {
                if m.axes & (1 << i) != 0 && !self.axes[i].servo {
                    return Err(format!("axis {} moving with servo off", i + 1));
                }
            }
        }
        let mut seen = 0u8;
        for m in &self.motions {
            if seen & m.axes != 0 {
                return Err("two motions own one axis".into());
            }
            seen |= m.axes;
        }
        Ok(())
    }
}

/// Printable ASCII only, 255 characters at most (216H's message field).
fn printable(message: &str) -> String {
    message
        .chars()
        .filter(|c| c.is_ascii_graphic() || *c == ' ')
        .take(255)
        .collect()
}

#[cfg(test)]
mod tests {
    use std::time::Duration;

    use super::*;
    use crate::sim::SimSetup;

    #[test]
    fn silence_rules_are_counted_by_reason() {
        let mut c = Controller::new(SimSetup::default());
        let t = Duration::ZERO;
        let first = |r: Option<Vec<u8>>| r.map(|r| r[0]);
        assert_eq!(first(c.handle(b"!992120189\r\n", t)), Some(b'#'));
        assert_eq!(first(c.handle(b"!9921201@@\r\n", t)), Some(b'#'));
        for (bytes, _) in [
            (&b"!992120188\r\n"[..], "checksum"),
            (b"!982120188\r\n", "station"),
            (b"#992120189\r\n", "header"),
            (b"!992120189\n", "terminator"),
            (b"!99\r\n", "short"),
        ] {
            assert_eq!(c.handle(bytes, t), None);
        }
        let n = *c.counters();
        assert_eq!(n.at_at, 1);
        assert_eq!(
            (n.silent_checksum, n.silent_station, n.silent_header),
            (1, 1, 1)
        );
        assert_eq!((n.silent_terminator, n.silent_other), (1, 1));
        assert_eq!(
            first(c.handle(b"!992a10f01d\r\n", t)),
            Some(b'#'),
            "lower case"
        );
    }
}
