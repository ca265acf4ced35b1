//! The position table on the wire: 209H/21FH/22DH queries, 244H/245H/26DH/290H/291H writes
//! and 26BH move to a position number (PROTOCOL.md 3.24-3.33), on 3- or 4-digit models.
//!
//! Decisions where PROTOCOL.md leaves gaps, all `[inferred]`:
//! - A query looks at the numbers `first..first+count-1` and answers the effective
//!   (stored) ones in ascending order (PROTOCOL.md 3.25's first reading). A reply is cut
//!   to what fits the reply buffer, header to LF (as 2A0H/2A4H are): it then holds the
//!   lowest-numbered effective records, and a host goes on from the last number it got
//!   plus one. The count field says how many came.
//! - Number 0, a number above the model's maximum (3000 on 3-digit models, 20000 on
//!   4-digit ones: the spec's arithmetic, PROTOCOL.md 3.24), count 0, or a range that
//!   runs past the maximum: A03. A record naming an axis the controller does not have:
//!   A04; an arm system for SCARA 2 (this controller has one SCARA): A04; an arm system
//!   on a record without a SCARA axis: A03.
//! - A write is checked whole before anything is stored: a refused write changes
//!   nothing. Records are stored in order (a number named twice keeps the last).
//! - 244H/245H/26DH carry no arm system: a record they write has none ("no
//!   specification"), replacing any the position had.
//! - A record written with axis pattern 00 clears that position (no axis, no data).
//! - 3-digit models answer A01 (unknown message) to the 4-digit messages 21FH, 22DH,
//!   26DH, 290H and 291H; 4-digit models answer every one.
//! - A command longer than the receive buffer (2051 or 1023 bytes) is never read as a
//!   frame: silence, as for every message (PROTOCOL.md 1.6, `sim/framing.rs`).
//! - 26BH has no PTP/CP choice: the SCARA goes PTP to the record's X, Y, Z, R (selected
//!   work and tool frames, as 2D6H), on the record's arm system where it names one, else
//!   on the current arm without switching. Its speed (mm/s) and accelerations (0.01 G)
//!   become PTP percentages of the model's CP maxima; linear axes take them as they are.
//!   An empty AND of the patterns, or a number with no data: B0A.

use crate::files::coords_file::PositionTable;
use crate::protocol::{
    PositionData, PositionMove, PositionQuery, PositionQueryKind, PositionRecord, PositionWrite,
    PositionWriteKind, PositionsWritten, RecordArm, Reply,
};
use crate::robot::{ArmPolicy, G_MM_S2};
use crate::sim::controller::Controller;
use crate::sim::errors::SimError;

use super::axis::SCARA;

/// Highest position number of a 3-digit model (PROTOCOL.md 3.24: "max 3000 records").
pub const MAX_POSITIONS_3_DIGIT: u16 = 3000;
/// Highest position number of a 4-digit model (PROTOCOL.md 3.24 and erratum E1: 20000).
pub const MAX_POSITIONS_4_DIGIT: u16 = 20_000;

/// Whether a query kind uses 4-digit numbers (not answered by 3-digit models).
fn query_is_4_digit(kind: PositionQueryKind) -> bool {
    !matches!(kind, PositionQueryKind::Query)
}

/// Whether a write kind uses 4-digit numbers (not answered by 3-digit models).
fn write_is_4_digit(kind: PositionWriteKind) -> bool {
    !matches!(kind, PositionWriteKind::Range | PositionWriteKind::Change)
}

/// A rate of 26BH (mm/s, or 0.01 G as mm/s^2) as a PTP percentage of `max` (0 stays 0:
/// the parameter's value), rounded up, 1 to 100.
fn percent_of(v: f64, max: f64) -> u16 {
    if v <= 0.0 {
        0
    } else {
        (v / max * 100.0).ceil().clamp(1.0, 100.0) as u16
    }
}

impl Controller {
    /// The highest position number of this model (3000 or 20000).
    pub fn max_position(&self) -> u16 {
        if self.cfg.position_digits == 3 {
            MAX_POSITIONS_3_DIGIT
        } else {
            MAX_POSITIONS_4_DIGIT
        }
    }

    /// The position table.
    pub fn positions(&self) -> &PositionTable {
        &self.positions
    }

    /// A position number this model has (1 to its maximum), else A03.
    pub(crate) fn check_position_number(&self, number: u16) -> Result<(), SimError> {
        if number == 0 || number > self.max_position() {
            return Err(SimError::BadValue);
        }
        Ok(())
    }

    /// `count` numbers from `first`, all this model has, at least one: else A03.
    fn check_position_range(&self, first: u16, count: u16) -> Result<(), SimError> {
        if count == 0 {
            return Err(SimError::BadValue);
        }
        self.check_position_number(first)?;
        let last = u32::from(first) + u32::from(count) - 1;
        if last > u32::from(self.max_position()) {
            return Err(SimError::BadValue);
        }
        Ok(())
    }

    /// A move's target from a stored position: the command's pattern ANDed with the
    /// record's (empty, or no record: B0A), the coordinates in wire units per axis, and
    /// the record.
    pub(crate) fn position_target(
        &self,
        pattern: u8,
        number: u16,
    ) -> Result<(u8, [i32; 8], PositionRecord), SimError> {
        let record = *self.positions.get(&number).ok_or(SimError::NoPosition)?;
        let pattern = pattern & record.coords.pattern().0;
        if pattern == 0 {
            return Err(SimError::NoPosition);
        }
        let mut values = [0i32; 8];
        for (axis, v) in record.coords.iter() {
            values[axis.index()] = v.0;
        }
        Ok((pattern, values, record))
    }

    /// 209H / 21FH / 22DH effective position data query (PROTOCOL.md 3.25-3.27).
    pub(crate) fn msg_position_query(&mut self, q: PositionQuery) -> Result<Reply, SimError> {
        if self.cfg.position_digits == 3 && query_is_4_digit(q.kind) {
            return Err(SimError::UnknownMessage);
        }
        self.check_position_range(q.first, q.count)?;
        let last = q.first + (q.count - 1);
        let mut len = q.kind.reply_len([]);
        let mut records = Vec::new();
        for record in self.positions.range(q.first..=last).map(|(_, r)| r) {
            len += q.kind.record_len(record);
            if len > self.cfg.reply_buffer {
                break;
            }
            let mut record = *record;
            if q.kind != PositionQueryKind::Query3 {
                record.arms = Default::default();
            }
            records.push(record);
        }
        Ok(Reply::Positions(PositionData {
            kind: q.kind,
            records,
        }))
    }

    /// 244H / 245H / 26DH / 290H / 291H position data writes (PROTOCOL.md 3.28-3.32):
    /// every record checked, then all stored.
    pub(crate) fn msg_position_write(&mut self, w: &PositionWrite) -> Result<Reply, SimError> {
        if self.cfg.position_digits == 3 && write_is_4_digit(w.kind) {
            return Err(SimError::UnknownMessage);
        }
        let count = u16::try_from(w.records.len()).map_err(|_| SimError::BadValue)?;
        let first = w.records.first().map_or(0, |r| r.number);
        if w.kind.is_range() {
            self.check_position_range(first, count)?;
        } else if count == 0 {
            return Err(SimError::BadValue);
        }
        for r in &w.records {
            self.check_position_number(r.number)?;
            let pattern = r.coords.pattern().0;
            if pattern & !self.present() != 0 || r.arms.scara2 != RecordArm::Unspecified {
                return Err(SimError::BadAxis);
            }
            if r.arms.scara1 != RecordArm::Unspecified && pattern & SCARA == 0 {
                return Err(SimError::BadValue);
            }
        }
        for r in &w.records {
            if r.coords.is_empty() {
                self.positions.remove(&r.number);
            } else {
                self.positions.insert(r.number, *r);
            }
        }
        Ok(Reply::PositionsWritten(PositionsWritten {
            kind: w.kind,
            first: if w.kind.is_range() { first } else { 0 },
            count,
        }))
    }

    /// 26BH move to a position number (PROTOCOL.md 3.33): the AND rule, rates 0 = the
    /// record's, then the parameter's.
    pub(crate) fn msg_position_move(&mut self, m: &PositionMove) -> Result<(), SimError> {
        self.check_pattern(m.axes.0)?;
        self.check_position_number(m.position)?;
        let (pattern, values, record) = self.position_target(m.axes.0, m.position)?;
        let pick = |cmd: u16, rec: u16| if cmd != 0 { cmd } else { rec };
        let speed = pick(m.speed.0, record.speed.0);
        let accel = pick(m.accel.0, record.accel.0);
        let decel = pick(m.decel.0, record.decel.0);
        let rates = if pattern & SCARA != 0 {
            let (v, a) = (self.model.cp_max_speed_mm_s, self.model.cp_max_accel_mm_s2);
            let cg = |c: u16| f64::from(c) * G_MM_S2 / 100.0;
            [
                percent_of(f64::from(speed), v),
                percent_of(cg(accel), a),
                percent_of(cg(decel), a),
            ]
        } else {
            [speed, accel, decel]
        };
        let policy = match record.arms.scara1 {
            RecordArm::Right => ArmPolicy::Right,
            RecordArm::Left => ArmPolicy::Left,
            RecordArm::Unspecified => ArmPolicy::CurrentNoSwitch,
        };
        self.scara_or_linear_move(pattern, &values, false, Some(policy), rates)
    }
}

#[cfg(test)]
mod tests {
    use std::time::Duration;

    use super::*;
    use crate::protocol::{
        Axis, CentiG, Command, Frame, Milli, MmPerSec, PerAxis, RecordArms, ScMode, Station,
    };
    use crate::sim::SimSetup;

    fn sim(digits: u8) -> Controller {
        let mut s = SimSetup::default();
        s.config.position_digits = digits;
        s.config.start_ready = true;
        s.config.linear_axes = 1;
        s.positions.clear();
        Controller::new(s)
    }

    /// Sends a command built by the protocol encoder; the reply decoded.
    fn ask(c: &mut Controller, cmd: &Command) -> Reply {
        let bytes = cmd.to_bytes(Station::DEFAULT, ScMode::Computed).unwrap();
        let out = c.handle(&bytes, Duration::ZERO).expect("a reply");
        Reply::decode(&Frame::parse(&out).unwrap()).unwrap()
    }

    /// Sends a frame body (SC computed); the reply text without CR LF.
    fn raw(c: &mut Controller, body: &str) -> String {
        let sc = crate::protocol::checksum(body.as_bytes());
        let bytes = format!("{body}{sc:02X}\r\n").into_bytes();
        let out = c.handle(&bytes, Duration::ZERO).expect("a reply");
        String::from_utf8(out).unwrap().trim_end().to_owned()
    }

    fn rec(number: u16, coords: &[(Axis, i32)]) -> PositionRecord {
        PositionRecord {
            number,
            coords: PerAxis::from_pairs(coords.iter().map(|&(a, v)| (a, Milli(v)))),
            ..PositionRecord::default()
        }
    }

    fn query(kind: PositionQueryKind, first: u16, count: u16) -> Command {
        Command::PositionQuery(PositionQuery { kind, first, count })
    }

    fn write(kind: PositionWriteKind, records: Vec<PositionRecord>) -> Command {
        Command::PositionWrite(PositionWrite { kind, records })
    }

    fn records(r: Reply) -> Vec<PositionRecord> {
        match r {
            Reply::Positions(d) => d.records,
            other => panic!("not position data: {other:?}"),
        }
    }

    fn refused(r: Reply) -> u16 {
        match r {
            Reply::Error(e) => e.0,
            other => panic!("not refused: {other:?}"),
        }
    }

    const XYZR: [Axis; 4] = [Axis::A1, Axis::A2, Axis::A3, Axis::A4];

    #[test]
    fn writes_then_reads_back_equal_in_every_variant() {
        let mut c = sim(4);
        let mut scara = rec(5, &[(Axis::A1, 300_000), (Axis::A2, -150_000)]);
        scara.arms.scara1 = RecordArm::Left;
        scara.speed = MmPerSec(100);
        scara.accel = CentiG(30);
        let w = ask(&mut c, &write(PositionWriteKind::Change3, vec![scara]));
        assert_eq!(
            w,
            Reply::PositionsWritten(PositionsWritten {
                kind: PositionWriteKind::Change3,
                first: 0,
                count: 1
            })
        );
        assert_eq!(
            records(ask(&mut c, &query(PositionQueryKind::Query3, 1, 10))),
            vec![scara]
        );
        // 21FH and 209H carry no arm system.
        let plain = PositionRecord {
            arms: RecordArms::default(),
            ..scara
        };
        for kind in [PositionQueryKind::Query2, PositionQueryKind::Query] {
            assert_eq!(records(ask(&mut c, &query(kind, 5, 1))), vec![plain]);
        }
        // 245H writes no arm system: the stored record has none.
        ask(&mut c, &write(PositionWriteKind::Change, vec![plain]));
        assert_eq!(
            records(ask(&mut c, &query(PositionQueryKind::Query3, 5, 1))),
            vec![plain]
        );
        // Signed coordinates, axis 5, the 4-digit range's top.
        let far = rec(20_000, &[(Axis::A3, -1), (Axis::A5, 123_456)]);
        ask(&mut c, &write(PositionWriteKind::Change2, vec![far]));
        assert_eq!(
            records(ask(&mut c, &query(PositionQueryKind::Query2, 19_990, 11))),
            vec![far]
        );
        assert_eq!(c.positions()[&20_000], far);
    }

    #[test]
    fn range_writes_number_records_from_the_start() {
        let mut c = sim(4);
        let body = |n| rec(n, &[(Axis::A1, i32::from(n) * 1000)]);
        for (kind, start) in [
            (PositionWriteKind::Range, 10),
            (PositionWriteKind::Range3, 300),
        ] {
            let r = ask(&mut c, &write(kind, (start..start + 3).map(body).collect()));
            assert_eq!(
                r,
                Reply::PositionsWritten(PositionsWritten {
                    kind,
                    first: start,
                    count: 3
                })
            );
            let got = records(ask(&mut c, &query(PositionQueryKind::Query2, start, 3)));
            assert_eq!(got, (start..start + 3).map(body).collect::<Vec<_>>());
        }
        // On the wire: 244H records carry no number; they land at 10 and 11.
        let mut c = sim(4);
        assert_eq!(
            raw(
                &mut c,
                "!9924400A002010000000000640000C35001000000000064000124F8"
            ),
            "#9924400A00262"
        );
        assert_eq!(c.positions()[&10].coords.get(Axis::A1), Some(Milli(50_000)));
        assert_eq!(c.positions()[&11].coords.get(Axis::A1), Some(Milli(75_000)));
        assert_eq!(c.positions().len(), 2);
    }

    #[test]
    fn queries_walk_effective_records_and_fit_the_reply_buffer() {
        let mut c = sim(4);
        let four = |n| rec(n, &XYZR.map(|a| (a, i32::from(n))));
        let all: Vec<_> = (1..=100).map(four).collect();
        for chunk in all.chunks(30) {
            ask(&mut c, &write(PositionWriteKind::Change3, chunk.to_vec()));
        }
        // Gaps are skipped; numbers ascend.
        ask(
            &mut c,
            &write(PositionWriteKind::Change2, vec![rec(3, &[]), rec(4, &[])]),
        );
        let got = records(ask(&mut c, &query(PositionQueryKind::Query2, 1, 6)));
        let numbers: Vec<u16> = got.iter().map(|r| r.number).collect();
        assert_eq!(numbers, [1, 2, 5, 6]);
        // Asked for 100 records of 4 axes: as many as fit 2048 bytes, from the lowest.
        for (kind, fit) in [
            (PositionQueryKind::Query, 41),
            (PositionQueryKind::Query2, 40),
            (PositionQueryKind::Query3, 39),
        ] {
            assert_eq!(kind.records_fitting(4, 2048), fit);
            let cmd = query(kind, 5, 100);
            let bytes = cmd.to_bytes(Station::DEFAULT, ScMode::Computed).unwrap();
            let out = c.handle(&bytes, Duration::ZERO).unwrap();
            assert!(out.len() <= 2048, "{kind:?}: {}", out.len());
            let got = records(Reply::decode(&Frame::parse(&out).unwrap()).unwrap());
            assert_eq!(got.len(), fit, "{kind:?}");
            assert_eq!(got[0].number, 5);
            // One more would not have fitted.
            assert!(out.len() + kind.record_len(&got[0]) > 2048);
        }
        // The small buffer halves it.
        let mut s = SimSetup::default();
        s.config.reply_buffer = 1024;
        s.positions = all.iter().map(|r| (r.number, *r)).collect();
        let mut small = Controller::new(s);
        let got = records(ask(&mut small, &query(PositionQueryKind::Query3, 1, 100)));
        assert_eq!(got.len(), 19);
        // Nothing effective is a valid answer.
        assert_eq!(
            records(ask(&mut c, &query(PositionQueryKind::Query3, 500, 10))),
            vec![]
        );
    }

    #[test]
    fn bad_numbers_ranges_and_fields_are_refused_and_change_nothing() {
        let mut c = sim(4);
        let ok = rec(1, &[(Axis::A1, 1)]);
        ask(&mut c, &write(PositionWriteKind::Change3, vec![ok]));
        let before = c.positions().clone();
        use PositionQueryKind as Q;
        use PositionWriteKind as W;
        for (cmd, code) in [
            (query(Q::Query3, 0, 1), 0xA03),
            (query(Q::Query3, 1, 0), 0xA03),
            (query(Q::Query3, 20_001, 1), 0xA03),
            (query(Q::Query3, 19_999, 3), 0xA03),
            (write(W::Change3, vec![ok, rec(0, &[(Axis::A1, 1)])]), 0xA03),
            (
                write(W::Change2, vec![rec(20_001, &[(Axis::A1, 1)])]),
                0xA03,
            ),
            (
                write(
                    W::Range3,
                    (19_999..=20_001)
                        .map(|n| rec(n, &[(Axis::A1, 1)]))
                        .collect(),
                ),
                0xA03,
            ),
            (write(W::Change3, vec![]), 0xA03),
            // Axis 7: this controller has axes 1-5.
            (write(W::Change2, vec![ok, rec(2, &[(Axis::A7, 1)])]), 0xA04),
            // An arm system for SCARA 2, and one on a linear-only record.
            (
                write(
                    W::Change3,
                    vec![PositionRecord {
                        arms: RecordArms {
                            scara1: RecordArm::Unspecified,
                            scara2: RecordArm::Left,
                        },
                        ..rec(2, &[(Axis::A1, 1)])
                    }],
                ),
                0xA04,
            ),
            (
                write(
                    W::Range3,
                    vec![PositionRecord {
                        arms: RecordArms {
                            scara1: RecordArm::Right,
                            scara2: RecordArm::Unspecified,
                        },
                        ..rec(2, &[(Axis::A5, 1)])
                    }],
                ),
                0xA03,
            ),
        ] {
            assert_eq!(refused(ask(&mut c, &cmd)), code, "{cmd:?}");
            assert_eq!(c.positions(), &before, "{cmd:?} changed the table");
        }
        // A count the records cannot hold: the decoder refuses the field (A03).
        let short = ["!9926D", "0002", "0001", "01", "000000000000", "00000001"].concat();
        assert!(raw(&mut c, &short).starts_with("&99A03"));
        assert_eq!(c.positions(), &before);
    }

    #[test]
    fn three_digit_models_refuse_the_four_digit_messages() {
        let mut c3 = sim(3);
        let mut c4 = sim(4);
        let r = rec(7, &[(Axis::A1, 1)]);
        use PositionQueryKind as Q;
        use PositionWriteKind as W;
        for cmd in [
            query(Q::Query2, 1, 1),
            query(Q::Query3, 1, 1),
            write(W::Change2, vec![r]),
            write(W::Range3, vec![r]),
            write(W::Change3, vec![r]),
        ] {
            assert_eq!(refused(ask(&mut c3, &cmd)), 0xA01, "{cmd:?}");
            assert!(!matches!(ask(&mut c4, &cmd), Reply::Error(_)), "{cmd:?}");
        }
        for cmd in [
            query(Q::Query, 1, 1),
            write(W::Change, vec![r]),
            write(W::Range, vec![r]),
        ] {
            assert!(!matches!(ask(&mut c3, &cmd), Reply::Error(_)), "{cmd:?}");
        }
        // 3000 is the 3-digit models' top.
        assert_eq!(refused(ask(&mut c3, &query(Q::Query, 3000, 2))), 0xA03);
        assert!(!matches!(
            ask(&mut c3, &query(Q::Query, 3000, 1)),
            Reply::Error(_)
        ));
        assert_eq!(
            refused(ask(
                &mut c3,
                &write(W::Change, vec![rec(3001, &[(Axis::A1, 1)])])
            )),
            0xA03
        );
        assert_eq!(c3.positions().len(), 1);
        // 26BH and 2D6H stay.
        assert!(!raw(&mut c3, "!9926B010000000000000007").starts_with("&99A01"));
        assert!(!raw(&mut c3, "!992D601000000000000000007").starts_with("&99A01"));
    }

    #[test]
    fn position_move_follows_the_and_rule_and_the_record() {
        let mut c = sim(4);
        let target = rec(
            7,
            &[(Axis::A1, 350_000), (Axis::A2, 20_000), (Axis::A3, 30_000)],
        );
        let lin = rec(8, &[(Axis::A5, 100_000)]);
        ask(
            &mut c,
            &write(PositionWriteKind::Change3, vec![target, lin]),
        );
        let mv = |axes: u8, position: u16| {
            Command::PositionMove(PositionMove {
                axes: crate::protocol::AxisPattern(axes),
                position,
                ..PositionMove::default()
            })
        };
        // Empty AND, no data, bad number, axis the controller lacks.
        assert_eq!(refused(ask(&mut c, &mv(0x08, 7))), 0xB0A);
        assert_eq!(refused(ask(&mut c, &mv(0x0F, 9))), 0xB0A);
        assert_eq!(refused(ask(&mut c, &mv(0x0F, 0))), 0xA03);
        assert_eq!(refused(ask(&mut c, &mv(0x40, 7))), 0xA04);
        // Pattern 0F AND 07: X, Y, Z move; R stays.
        let r_before = c.tip_work().r;
        assert_eq!(
            ask(&mut c, &mv(0x0F, 7)),
            Reply::Ack(crate::protocol::MessageId::POSITION_MOVE)
        );
        let mut t = Duration::ZERO;
        while !c.at_rest() {
            t += Duration::from_millis(10);
            c.advance(t);
            assert!(t < Duration::from_secs(60), "move never ends");
        }
        let tip = c.tip_work();
        assert!((tip.x - 350.0).abs() < 1e-3, "{tip:?}");
        assert!((tip.y - 20.0).abs() < 1e-3, "{tip:?}");
        assert!((tip.z - 30.0).abs() < 1e-3, "{tip:?}");
        assert!((tip.r - r_before).abs() < 1e-3, "{tip:?}");
        // The linear axis alone.
        assert!(!matches!(ask(&mut c, &mv(0x10, 8)), Reply::Error(_)));
        while !c.at_rest() {
            t += Duration::from_millis(10);
            c.advance(t);
        }
        assert!((c.snapshot().linear[0] - 100.0).abs() < 1e-3);
        assert_eq!(c.counters().motion_started, 2);
    }

    #[test]
    fn position_move_takes_the_records_arm_system() {
        use crate::robot::ArmSystem;
        for (arm, want) in [
            (RecordArm::Left, ArmSystem::Left),
            (RecordArm::Right, ArmSystem::Right),
        ] {
            let mut c = sim(4);
            let mut r = rec(1, &XYZR.map(|a| (a, 0)));
            r.coords =
                PerAxis::from_pairs([(Axis::A1, Milli(300_000)), (Axis::A2, Milli(100_000))]);
            r.arms.scara1 = arm;
            ask(&mut c, &write(PositionWriteKind::Range3, vec![r]));
            let cmd = Command::PositionMove(PositionMove {
                axes: crate::protocol::AxisPattern(0x0F),
                position: 1,
                ..PositionMove::default()
            });
            assert_eq!(
                ask(&mut c, &cmd),
                Reply::Ack(crate::protocol::MessageId::POSITION_MOVE),
                "{arm:?}"
            );
            let mut t = Duration::ZERO;
            while !c.at_rest() {
                t += Duration::from_millis(10);
                c.advance(t);
                assert!(t < Duration::from_secs(60), "move never ends");
            }
            assert_eq!(c.snapshot().arm, want);
            let tip = c.tip_work();
            assert!(
                (tip.x - 300.0).abs() < 1e-3 && (tip.y - 100.0).abs() < 1e-3,
                "{tip:?}"
            );
        }
    }

    #[test]
    fn rates_become_percentages_of_the_cp_maxima() {
        assert_eq!(percent_of(0.0, 2000.0), 0);
        assert_eq!(percent_of(1.0, 2000.0), 1);
        assert_eq!(percent_of(1000.0, 2000.0), 50);
        assert_eq!(percent_of(5000.0, 2000.0), 100);
    }
}
