//! Coordinate-system definition queries: 2A0H and 2A4H, limited to the reply buffer.

use crate::protocol::{
    Axis, AxisPattern, CoordKind, CoordQuery, CoordQuery2, CoordTable, CoordTable2, Milli, PerAxis,
    Reply, XyzR,
};
use crate::robot::CoordSystem;
use crate::sim::controller::Controller;
use crate::sim::errors::SimError;

impl Controller {
    /// The records `first..first+count` of a table that exist and, `fit` at most, fit
    /// the reply buffer.
    fn table_slice(
        &self,
        kind: CoordKind,
        first: u8,
        count: u8,
        fit: usize,
    ) -> Result<&[CoordSystem], SimError> {
        let table = match kind {
            CoordKind::Work => &self.coords.work,
            CoordKind::Tool => &self.coords.tool,
        };
        let first = usize::from(first);
        if first >= table.len() {
            return Err(SimError::BadValue);
        }
        let n = usize::from(count).min(table.len() - first).min(fit);
        Ok(&table.entries()[first..first + n])
    }

    /// 2A0H coordinate system definition data (PROTOCOL.md 3.15).
    pub(crate) fn msg_coords(&mut self, q: CoordQuery) -> Result<Reply, SimError> {
        let fit = CoordTable::records_fitting(self.cfg.reply_buffer);
        let records = self.table_slice(q.kind, q.first, q.count, fit)?;
        let records = records
            .iter()
            .map(|cs| {
                let [x, y, z, r] = cs.to_wire().map(Milli);
                XyzR { x, y, z, r }
            })
            .collect();
        Ok(Reply::CoordTable(CoordTable {
            kind: q.kind,
            first: q.first,
            records,
        }))
    }

    /// 2A4H coordinate system definition data 2 (PROTOCOL.md 3.16, corrected counts):
    /// pattern `0F`, `F0` or `FF` (the decoder refuses others); this single-SCARA
    /// controller answers `0F` for `FF` and refuses `F0` (no second SCARA) `[inferred]`.
    pub(crate) fn msg_coords2(&mut self, q: CoordQuery2) -> Result<Reply, SimError> {
        if q.axes == AxisPattern::SCARA_2 {
            return Err(SimError::BadAxis);
        }
        // This controller answers pattern 0F whatever was asked.
        let fit = CoordTable2::records_fitting(AxisPattern::SCARA_1, self.cfg.reply_buffer);
        let records = self.table_slice(q.kind, q.first, q.count, fit)?;
        let records = records
            .iter()
            .map(|cs| {
                let [x, y, z, r] = cs.to_wire().map(Milli);
                PerAxis::from_pairs([(Axis::A1, x), (Axis::A2, y), (Axis::A3, z), (Axis::A4, r)])
            })
            .collect();
        Ok(Reply::CoordTable2(CoordTable2 {
            axes: AxisPattern::SCARA_1,
            kind: q.kind,
            first: q.first,
            records,
        }))
    }
}
