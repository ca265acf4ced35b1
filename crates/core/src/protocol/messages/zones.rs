//! 2A2H: the simple interference-check zones, range query (PROTOCOL.md 3.46), each record
//! sized from the reply's length with any surplus after coordinate 2 kept raw.

use std::ops::RangeInclusive;

use crate::protocol::axis::{Axis, PerAxis};
use crate::protocol::error::{EncodeError, MessageError};
use crate::protocol::fields::{Name, Reader, Show, printable};
use crate::protocol::units::{AxisUnit, Milli};
use crate::protocol::writer::Writer;

/// The zone numbers a controller has. `[inferred]` The pages give only "from 1"
/// (PROTOCOL.md 3.46); 10 is the count of the X-SEL SCARA zone parameters as remembered
/// from vendor manuals, unverified. The one place the simulator's table and the pendant's
/// read take it from.
pub const ZONE_NUMBERS: RangeInclusive<u8> = 1..=10;

/// Characters a record may carry after coordinate 2 that the reply-length bound allows
/// for. `[inferred]` The tail was not readable (PROTOCOL.md 3.46); it is believed to hold an
/// output or flag number and an error type: 64 characters is a generous guess, used only
/// to size the time-out.
pub const ZONE_TAIL_ALLOWANCE: usize = 64;

/// Characters before the records of a reply (`#`, station, ID, zone number, count) and
/// SC CR LF after them.
const REPLY_HEAD: usize = 10;
const REPLY_TAIL: usize = 4;

/// 2A2H command: `count` zone definitions from number `first`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct ZoneQuery {
    /// First zone definition number, from 1.
    pub first: u8,
    /// Number of records (limited by the reply buffer).
    pub count: u8,
}

impl Default for ZoneQuery {
    fn default() -> Self {
        ZoneQuery { first: 1, count: 1 }
    }
}

impl ZoneQuery {
    pub(crate) fn read(r: &mut Reader<'_, '_>) -> Result<Self, MessageError> {
        let first = r.u8(Name::new("zone definition number"), 2, Show::Number)?;
        let count = r.u8(Name::new("number of records"), 2, Show::Number)?;
        Ok(ZoneQuery { first, count })
    }

    pub(crate) fn write(&self, w: &mut Writer<'_>) -> Result<(), EncodeError> {
        w.hex_fit(u32::from(self.first), 2);
        w.hex_fit(u32::from(self.count), 2);
        Ok(())
    }

    /// The longest reply that can answer it: the readable part of each record at 4 axes
    /// plus [`ZONE_TAIL_ALLOWANCE`], within the 2048-byte reply buffer.
    pub fn max_reply_len(&self) -> usize {
        let per = 2 + 16 * 4 + ZONE_TAIL_ALLOWANCE;
        (REPLY_HEAD + REPLY_TAIL + per * usize::from(self.count)).min(super::super::REPLY_BUFFER)
    }
}

/// One zone definition: a rectangular solid by two opposite corners in the base
/// coordinate system, on the axes of its own pattern (X, Y, Z in 0.001 mm, R in 0.001
/// deg), and whatever the record carried after coordinate 2, raw.
#[derive(Clone, Debug, Default, PartialEq, Eq, Hash)]
pub struct ZoneRecord {
    /// Corner 1; its axes are the record's coordinate effective axis pattern.
    pub corner1: PerAxis<Milli>,
    /// The opposite corner, on the same axes.
    pub corner2: PerAxis<Milli>,
    /// Characters after coordinate 2 (not readable on the pages: kept as they came).
    pub surplus: Vec<u8>,
}

impl ZoneRecord {
    /// A record on the axes `corner1` names (`corner2` must name the same).
    pub fn new(corner1: PerAxis<Milli>, corner2: PerAxis<Milli>) -> Self {
        ZoneRecord {
            corner1,
            corner2,
            surplus: Vec::new(),
        }
    }

    /// Characters of the readable part: pattern and both corners.
    pub fn readable_len(&self) -> usize {
        2 + 16 * self.corner1.len()
    }

    /// The surplus as text (it came as printable ASCII).
    pub fn surplus_text(&self) -> String {
        self.surplus.escape_ascii().to_string()
    }
}

/// 2A2H reply: `records.len()` zone definitions from number `first`.
#[derive(Clone, Debug, Default, PartialEq, Eq, Hash)]
pub struct ZoneTable {
    /// First zone definition number (echo).
    pub first: u8,
    /// The records (at most 255), all of one length on the wire.
    pub records: Vec<ZoneRecord>,
}

/// Unit of a zone coordinate: R axes in deg, others in mm.
fn unit(a: Axis) -> AxisUnit {
    if a.is_scara_r() {
        AxisUnit::Deg
    } else {
        AxisUnit::Mm
    }
}

impl ZoneTable {
    /// How many records of `axes_count` axes and no surplus fit a reply buffer of
    /// `reply_buffer` bytes (PROTOCOL.md 3.46: 30 four-axis records in 2048).
    pub fn records_fitting(axes_count: usize, reply_buffer: usize) -> usize {
        reply_buffer.saturating_sub(REPLY_HEAD + REPLY_TAIL) / (2 + 16 * axes_count)
    }

    /// Reads the records by the reply's length: (characters left) / count each, compared
    /// with 2 + 16 x (set bits) of each record's own pattern; what is left of a record
    /// after coordinate 2 is its surplus (PROTOCOL.md 3.46, DESIGN.md's gap table).
    pub(crate) fn read(r: &mut Reader<'_, '_>) -> Result<Self, MessageError> {
        let first = r.u8(Name::new("zone definition number"), 2, Show::Number)?;
        let count = usize::from(r.u8(Name::new("number of records"), 2, Show::Number)?);
        let left = r.remaining();
        if count == 0 {
            return Ok(ZoneTable {
                first,
                records: Vec::new(),
            });
        }
        if !left.is_multiple_of(count) {
            return Err(r.invalid(format!(
                "a count that divides the {left} characters of records evenly"
            )));
        }
        let size = left / count;
        let mut records = Vec::with_capacity(count);
        for i in 0..count {
            let no = usize::from(first) + i;
            let axes = r.pattern("coordinate effective axis pattern")?;
            let readable = 2 + 16 * axes.count();
            if readable > size {
                return Err(r.invalid(format!(
                    "at most {} axes: each record has {size} characters by the reply's length",
                    size.saturating_sub(2) / 16
                )));
            }
            let mut corner1 = PerAxis::new();
            for a in axes {
                corner1.set(a, r.coord(Name::record("corner 1", no, Some(a)), unit(a))?);
            }
            let mut corner2 = PerAxis::new();
            for a in axes {
                corner2.set(a, r.coord(Name::record("corner 2", no, Some(a)), unit(a))?);
            }
            let surplus = match size - readable {
                0 => Vec::new(),
                n => r
                    .text(
                        Name::record("unread tail (raw)", no, None),
                        n,
                        printable,
                        "printable characters",
                    )?
                    .to_vec(),
            };
            records.push(ZoneRecord {
                corner1,
                corner2,
                surplus,
            });
        }
        Ok(ZoneTable { first, records })
    }

    pub(crate) fn write(&self, w: &mut Writer<'_>) -> Result<(), EncodeError> {
        let n = u32::try_from(self.records.len())
            .ok()
            .filter(|&n| n <= 255)
            .ok_or_else(|| {
                w.error(
                    "number of records",
                    format!("= {}: at most 255 records fit", self.records.len()),
                )
            })?;
        let size = self
            .records
            .first()
            .map_or(0, |r| r.readable_len() + r.surplus.len());
        for (i, rec) in self.records.iter().enumerate() {
            if rec.corner1.pattern() != rec.corner2.pattern() {
                return Err(w.error(
                    format!("record {i}"),
                    "corner 2 must name the axes corner 1 names",
                ));
            }
            if rec.readable_len() + rec.surplus.len() != size {
                return Err(w.error(
                    format!("record {i}"),
                    "every record must have the same length: a reader sizes them by the reply's length",
                ));
            }
            if !rec.surplus.iter().all(|&c| printable(c)) {
                return Err(w.error(format!("record {i}"), "the surplus must be printable"));
            }
        }
        w.hex_fit(u32::from(self.first), 2);
        w.hex_fit(n, 2);
        for rec in &self.records {
            w.hex_fit(u32::from(rec.corner1.pattern().0), 2);
            for (_, v) in rec.corner1.iter() {
                w.coord(v);
            }
            for (_, v) in rec.corner2.iter() {
                w.coord(v);
            }
            w.bytes(&rec.surplus);
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::protocol::{Command, Frame, Reply, ScMode, Station, describe};

    fn framed(s: &str) -> Vec<u8> {
        let mut b = s.as_bytes().to_vec();
        b.extend_from_slice(b"\r\n");
        b
    }

    fn reply(s: &str) -> Result<Reply, MessageError> {
        let b = framed(s);
        Reply::decode(&Frame::parse(&b).unwrap())
    }

    fn answered(r: &Reply) -> String {
        String::from_utf8(r.to_bytes(Station::DEFAULT).unwrap())
            .unwrap()
            .trim_end()
            .to_string()
    }

    fn xyz(x: i32, y: i32, z: i32) -> PerAxis<Milli> {
        PerAxis::from_pairs([
            (Axis::A1, Milli(x)),
            (Axis::A2, Milli(y)),
            (Axis::A3, Milli(z)),
        ])
    }

    /// Reframes `data` (after the ID) as a 2A2H reply with a computed SC.
    fn with_sc(data: &str) -> String {
        let body = format!("#992A2{data}");
        let sc = crate::protocol::checksum(body.as_bytes());
        format!("{body}{sc:02X}")
    }

    /// PROTOCOL.md 3.50's two 2A2H frames, byte for byte, both ways.
    #[test]
    fn the_checked_examples_of_section_3_50_decode_and_encode_back() {
        let q = Command::ZoneQuery(ZoneQuery { first: 1, count: 1 });
        let b = framed("!992A20101FA");
        assert_eq!(Command::decode(&Frame::parse(&b).unwrap()).unwrap(), q);
        let sent = q.to_bytes(Station::DEFAULT, ScMode::Computed).unwrap();
        assert_eq!(sent, b);

        let text = "#992A2010107000186A0FFFE79600000000000030D40000186A00000C35046";
        let table = Reply::ZoneTable(ZoneTable {
            first: 1,
            records: vec![ZoneRecord::new(
                xyz(100_000, -100_000, 0),
                xyz(200_000, 100_000, 50_000),
            )],
        });
        assert_eq!(reply(text).unwrap(), table);
        assert_eq!(answered(&table), text);
        assert_eq!(text.len() + 2, 64, "PROTOCOL.md 3.50 gives 64 with CR LF");
    }

    #[test]
    fn a_longer_record_keeps_its_tail_raw_and_sizes_come_from_the_reply_length() {
        // Two records of pattern 07 with 6 unknown characters each.
        let rec = "07000186A0FFFE79600000000000030D40000186A00000C350";
        let data = format!("0102{rec}012C01{rec}000000");
        let Reply::ZoneTable(t) = reply(&with_sc(&data)).unwrap() else {
            panic!("not a zone table")
        };
        assert_eq!(t.records.len(), 2);
        assert_eq!(t.records[0].surplus, b"012C01");
        assert_eq!(t.records[1].surplus_text(), "000000");
        assert_eq!(t.records[1].corner2, xyz(200_000, 100_000, 50_000));
        // And back, byte for byte.
        assert_eq!(answered(&Reply::ZoneTable(t)), with_sc(&data));
    }

    #[test]
    fn records_that_do_not_divide_the_reply_are_refused_with_the_reason() {
        let rec = "07000186A0FFFE79600000000000030D40000186A00000C350";
        let e = reply(&with_sc(&format!("0102{rec}{rec}0"))).unwrap_err();
        assert!(e.to_string().contains("divides the 101 characters"), "{e}");
        // A pattern wider than the record's share.
        let e = reply(&with_sc(&format!("01010F{}", &rec[2..]))).unwrap_err();
        assert!(e.to_string().contains("at most 3 axes"), "{e}");
        // No records.
        assert_eq!(
            reply(&with_sc("0100")).unwrap(),
            Reply::ZoneTable(ZoneTable {
                first: 1,
                records: vec![]
            })
        );
    }

    #[test]
    fn the_frame_log_names_every_field_and_the_raw_tail() {
        let rec = "07000186A0FFFE79600000000000030D40000186A00000C350";
        let b = framed(&with_sc(&format!("0101{rec}AB")));
        let d = format!("{:?}", describe(&b));
        for needle in [
            "zone definition number",
            "number of records",
            "coordinate effective axis pattern",
            "record 1 axis 2 corner 1",
            "-100.000",
            "record 1 axis 3 corner 2",
            "unread tail (raw)",
            "AB",
        ] {
            assert!(d.contains(needle), "{needle} missing from {d}");
        }
    }

    #[test]
    fn records_of_another_length_are_not_encoded() {
        let mut long = ZoneRecord::new(xyz(0, 0, 0), xyz(1, 1, 1));
        long.surplus = b"00".to_vec();
        let t = Reply::ZoneTable(ZoneTable {
            first: 1,
            records: vec![ZoneRecord::new(xyz(0, 0, 0), xyz(1, 1, 1)), long],
        });
        let e = t.to_bytes(Station::DEFAULT).unwrap_err();
        assert!(e.to_string().contains("same length"), "{e}");
        assert_eq!(ZoneTable::records_fitting(4, 2048), 30);
        assert_eq!(ZoneTable::records_fitting(4, 1024), 15);
        assert!(!Command::ZoneQuery(ZoneQuery::default()).is_motion());
        assert_eq!(
            Command::ZoneQuery(ZoneQuery {
                first: 1,
                count: 10
            })
            .max_reply_len(),
            14 + 10 * (66 + ZONE_TAIL_ALLOWANCE)
        );
    }
}
