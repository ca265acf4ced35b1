//! The simple interference-check zones on the wire: 2A2H range queries (PROTOCOL.md 3.46).
//!
//! Decisions where PROTOCOL.md leaves gaps, all `[inferred]`:
//! - The controller has the zones [`ZONE_NUMBERS`] (1-10); a query answers every number
//!   of `first..first+count-1`, cut to what fits the reply buffer (as 2A0H/2A4H are).
//! - A zone the file does not define is answered as a record of all zeros (corners equal:
//!   no volume), as an unset zone parameter would read.
//! - Records end after coordinate 2 (PROTOCOL.md 3.46: "records that end after coordinate
//!   2"; the real tail is unknown) and carry X, Y, Z (pattern 07, as the page's example).
//! - Number 0, a number above the last zone, count 0, or a range past the last zone: A03,
//!   as the position-table range queries answer.

use crate::protocol::{
    Axis, Milli, PerAxis, Reply, ZONE_NUMBERS, ZoneQuery, ZoneRecord, ZoneTable,
};
use crate::sim::controller::Controller;
use crate::sim::errors::SimError;

/// The zone the file leaves out: both corners at the origin.
fn unset() -> ZoneRecord {
    let zero = PerAxis::from_pairs([Axis::A1, Axis::A2, Axis::A3].map(|a| (a, Milli(0))));
    ZoneRecord::new(zero, zero)
}

impl Controller {
    /// 2A2H simple interference-check zone definitions.
    pub(crate) fn msg_zones(&mut self, q: ZoneQuery) -> Result<Reply, SimError> {
        let last = u16::from(q.first) + u16::from(q.count.max(1)) - 1;
        if q.count == 0 || !ZONE_NUMBERS.contains(&q.first) || last > u16::from(*ZONE_NUMBERS.end())
        {
            return Err(SimError::BadValue);
        }
        let fit = ZoneTable::records_fitting(3, self.cfg.reply_buffer).max(1);
        let records = (q.first..=last as u8)
            .take(fit)
            .map(|n| self.zones.get(&n).cloned().unwrap_or_else(unset))
            .collect();
        Ok(Reply::ZoneTable(ZoneTable {
            first: q.first,
            records,
        }))
    }

    /// The zones as the file gave them.
    pub fn zones(&self) -> &crate::files::coords_file::Zones {
        &self.zones
    }
}

#[cfg(test)]
mod tests {
    use std::time::Duration;

    use crate::protocol::{Command, ErrorCode, Frame, ScMode, Station};
    use crate::sim::{Controller, SimSetup};

    use super::*;

    fn ask(c: &mut Controller, q: ZoneQuery) -> Reply {
        let bytes = Command::ZoneQuery(q)
            .to_bytes(Station::DEFAULT, ScMode::Computed)
            .unwrap();
        let out = c.handle(&bytes, Duration::ZERO).expect("a reply");
        Reply::decode(&Frame::parse(&out).unwrap()).unwrap()
    }

    #[test]
    fn the_built_in_zones_are_answered_and_unset_ones_read_as_zeros() {
        let mut c = Controller::new(SimSetup::default());
        let Reply::ZoneTable(t) = ask(
            &mut c,
            ZoneQuery {
                first: 1,
                count: 10,
            },
        ) else {
            panic!("not a zone table")
        };
        assert_eq!(t.first, 1);
        assert_eq!(t.records.len(), 10);
        assert_eq!(Some(&t.records[0]), c.zones().get(&1));
        assert_eq!(Some(&t.records[1]), c.zones().get(&2));
        assert_eq!(t.records[9], unset());
        assert!(
            t.records
                .iter()
                .all(|r| r.surplus.is_empty() && r.corner1.pattern().0 == 7)
        );
    }

    #[test]
    fn bad_numbers_and_counts_are_refused_as_the_range_queries_do() {
        let mut c = Controller::new(SimSetup::default());
        for (first, count) in [(0, 1), (11, 1), (1, 0), (10, 2), (5, 255)] {
            assert_eq!(
                ask(&mut c, ZoneQuery { first, count }),
                Reply::Error(ErrorCode(0xA03)),
                "{first} {count}"
            );
        }
    }

    #[test]
    fn a_small_reply_buffer_cuts_the_answer() {
        let mut setup = SimSetup::default();
        setup.config.reply_buffer = 200;
        let mut c = Controller::new(setup);
        let Reply::ZoneTable(t) = ask(
            &mut c,
            ZoneQuery {
                first: 1,
                count: 10,
            },
        ) else {
            panic!("not a zone table")
        };
        assert_eq!(t.records.len(), ZoneTable::records_fitting(3, 200));
        assert!(t.records.len() < 10);
    }
}
