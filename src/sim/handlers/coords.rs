//! Coordinate-system definition queries: 2A0H and 2A4H, limited to the reply buffer.

use super::{Fields, expect_len};
use crate::robot::CoordSystem;
use crate::sim::controller::Controller;
use crate::sim::errors::SimError;
use crate::sim::framing::{begin_reply, finish, push_hex, push_i32};

impl Controller {
    /// The table (0 work, 1 tool) and the records `first..first+count` that exist and fit
    /// a reply of `header` characters plus `record` characters each plus SC CR LF in the
    /// reply buffer (PROTOCOL.md 1.7; the count includes header to LF `[inferred]`).
    fn table_slice(
        &self,
        typ: u8,
        first: usize,
        count: usize,
        header: usize,
        record: usize,
    ) -> Result<Vec<CoordSystem>, SimError> {
        let table = match typ {
            0 => &self.coords.work,
            1 => &self.coords.tool,
            _ => return Err(SimError::BadValue),
        };
        if first >= table.len() {
            return Err(SimError::BadValue);
        }
        let fit = (self.cfg.reply_buffer.saturating_sub(header + 4)) / record.max(1);
        let n = count.min(table.len() - first).min(fit);
        Ok(table.entries()[first..first + n].to_vec())
    }

    /// 2A0H coordinate system definition data (PROTOCOL.md 3.15).
    pub(crate) fn msg_coords(
        &mut self,
        id: [u8; 3],
        data: &[u8],
        out: &mut Vec<u8>,
    ) -> Result<(), SimError> {
        expect_len(data, 5)?;
        let mut f = Fields::new(data);
        let typ = f.u8(1)?;
        let first = f.u8(2)?;
        let count = f.u8(2)?;
        let records = self.table_slice(typ, first.into(), count.into(), 11, 32)?;
        begin_reply(out, self.cfg.station, id);
        push_hex(out, u32::from(typ), 1);
        push_hex(out, u32::from(first), 2);
        push_hex(out, records.len() as u32, 2);
        for cs in &records {
            for v in cs.to_wire() {
                push_i32(out, v);
            }
        }
        finish(out);
        Ok(())
    }

    /// 2A4H coordinate system definition data 2 (PROTOCOL.md 3.16, corrected counts):
    /// pattern `0F`, `F0` or `FF`; this single-SCARA controller answers `0F` for `FF` and
    /// refuses `F0` (no second SCARA) `[inferred]`.
    pub(crate) fn msg_coords2(
        &mut self,
        id: [u8; 3],
        data: &[u8],
        out: &mut Vec<u8>,
    ) -> Result<(), SimError> {
        expect_len(data, 7)?;
        let mut f = Fields::new(data);
        let pattern = f.u8(2)?;
        let typ = f.u8(1)?;
        let first = f.u8(2)?;
        let count = f.u8(2)?;
        let reply_pattern = match pattern {
            0x0F | 0xFF => 0x0Fu8,
            _ => return Err(SimError::BadAxis),
        };
        let records = self.table_slice(typ, first.into(), count.into(), 13, 32)?;
        begin_reply(out, self.cfg.station, id);
        push_hex(out, u32::from(reply_pattern), 2);
        push_hex(out, u32::from(typ), 1);
        push_hex(out, u32::from(first), 2);
        push_hex(out, records.len() as u32, 2);
        for cs in &records {
            for v in cs.to_wire() {
                push_i32(out, v);
            }
        }
        finish(out);
        Ok(())
    }
}
