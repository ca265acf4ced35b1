//! System messages: 200H test call, 201H version, 215H system status, 216H error detail,
//! 252H alarm reset, 25BH software reset.

use super::{Fields, expect_len};
use crate::sim::controller::Controller;
use crate::sim::errors::SimError;
use crate::sim::framing::{begin_reply, finish, push_hex};
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
    /// 200H: echoes 0-10 data characters `[inferred, PROTOCOL.md 3.1]`.
    pub(crate) fn msg_test_call(
        &mut self,
        id: [u8; 3],
        data: &[u8],
        out: &mut Vec<u8>,
    ) -> Result<(), SimError> {
        if data.len() > 10 {
            return Err(SimError::WrongLength);
        }
        if !data.iter().all(|b| b.is_ascii_graphic() || *b == b' ') {
            return Err(SimError::BadValue);
        }
        begin_reply(out, self.cfg.station, id);
        out.extend_from_slice(data);
        finish(out);
        Ok(())
    }

    /// 201H version code query (PROTOCOL.md 3.2).
    pub(crate) fn msg_version(
        &mut self,
        id: [u8; 3],
        data: &[u8],
        out: &mut Vec<u8>,
    ) -> Result<(), SimError> {
        expect_len(data, 3)?;
        let mut f = Fields::new(data);
        let unit = f.u8(2)?;
        let device = f.u8(1)?;
        let &(model, unit_code, version) =
            VERSIONS.get(usize::from(unit)).ok_or(SimError::BadValue)?;
        if device != 0 {
            return Err(SimError::BadValue);
        }
        begin_reply(out, self.cfg.station, id);
        push_hex(out, u32::from(unit), 2);
        push_hex(out, u32::from(device), 1);
        push_hex(out, u32::from(model), 2);
        push_hex(out, u32::from(unit_code), 2);
        push_hex(out, u32::from(version), 4);
        for (v, w) in [(2024u32, 4), (3, 2), (15, 2), (10, 2), (20, 2), (30, 2)] {
            push_hex(out, v, w);
        }
        finish(out);
        Ok(())
    }

    /// 215H system status (PROTOCOL.md 3.4).
    pub(crate) fn msg_system_status(
        &mut self,
        id: [u8; 3],
        data: &[u8],
        out: &mut Vec<u8>,
    ) -> Result<(), SimError> {
        expect_len(data, 0)?;
        let critical = self.alarm.as_ref().map_or(0, |a| a.code);
        let manual = self.mode == Mode::Manual;
        let byte1 = u32::from(manual) | (u32::from(self.estop) << 3);
        let byte2 = 0u32;
        let ready = !self.estop && !self.drive_cut && self.alarm.is_none();
        let byte3 = u32::from(self.drive_cut) | (u32::from(!manual) << 1) | (u32::from(ready) << 2);
        begin_reply(out, self.cfg.station, id);
        push_hex(out, u32::from(self.mode.code()), 1);
        push_hex(out, u32::from(critical), 3);
        push_hex(out, u32::from(self.latest_error), 3);
        for b in [byte1, byte2, byte3, 0] {
            push_hex(out, b, 2);
        }
        finish(out);
        Ok(())
    }

    /// 216H error detail (PROTOCOL.md 3.5): the pending or latest alarm, an axis's error,
    /// or a record of the alarm history (newest = record 1).
    pub(crate) fn msg_error_detail(
        &mut self,
        id: [u8; 3],
        data: &[u8],
        out: &mut Vec<u8>,
    ) -> Result<(), SimError> {
        expect_len(data, 6)?;
        let mut f = Fields::new(data);
        let type1 = f.u8(1)?;
        let type2 = f.u16(2)?;
        let record = f.u16(3)?;
        let alarm = match type1 {
            0 if type2 == 0 => self.alarm.clone(),
            0 if type2 == 1 => self.history.first().cloned(),
            1 => {
                let axis = usize::from(type2);
                if axis == 0 || axis > self.axis_count() {
                    return Err(SimError::BadAxis);
                }
                let code = self.axes[axis - 1].error;
                self.history
                    .iter()
                    .find(|a| a.code == code && a.axis == Some(axis as u8))
                    .cloned()
                    .filter(|_| code != 0)
            }
            2 => None,
            3 if type2 >= 1 => self.history.get(usize::from(type2) - 1).cloned(),
            5 if record >= 1 => self.history.get(usize::from(record) - 1).cloned(),
            _ => return Err(SimError::BadValue),
        };
        begin_reply(out, self.cfg.station, id);
        let (code, axis, text) = alarm.as_ref().map_or((0, 0, ""), |a| {
            (a.code, a.axis.unwrap_or(0), a.message.as_str())
        });
        push_hex(out, u32::from(code), 3);
        // Details 1-8: program, step, axis, point, 5-8 unused.
        for d in [0, 0, u32::from(axis), 0, 0, 0, 0, 0] {
            push_hex(out, d, 8);
        }
        out.extend_from_slice(b"000000000000000"); // reserved, decimal digits 2,2,2,1,2,2,4
        let text = &text.as_bytes()[..text.len().min(255)];
        push_hex(out, text.len() as u32, 2);
        out.extend_from_slice(text);
        finish(out);
        Ok(())
    }

    /// 252H alarm reset: clears the pending alarm and axis error codes.
    pub(crate) fn msg_alarm_reset(
        &mut self,
        id: [u8; 3],
        data: &[u8],
        out: &mut Vec<u8>,
    ) -> Result<(), SimError> {
        expect_len(data, 0)?;
        self.alarm = None;
        for a in self.axes.iter_mut() {
            a.error = 0;
        }
        self.ack(id, out);
        Ok(())
    }

    /// 25BH software reset: optionally acknowledged, then silent for the reboot time.
    pub(crate) fn msg_reset(
        &mut self,
        id: [u8; 3],
        data: &[u8],
        out: &mut Vec<u8>,
    ) -> Result<(), SimError> {
        expect_len(data, 0)?;
        if self.mode == Mode::Manual {
            return Err(SimError::ManualMode);
        }
        self.reboot();
        if self.cfg.reset_replies {
            self.ack(id, out);
        } else {
            out.clear();
        }
        Ok(())
    }
}
