//! 2A0H and 2A4H: work/tool coordinate system definition tables (range queries).

use crate::protocol::axis::{Axis, AxisPattern, PerAxis};
use crate::protocol::error::{EncodeError, MessageError};
use crate::protocol::fields::{Name, Reader, Show};
use crate::protocol::hex::parse_hex8;
use crate::protocol::units::{AxisUnit, Milli};
use crate::protocol::writer::Writer;

/// Which table a coordinate query reads.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum CoordKind {
    /// 0: work coordinate system definitions.
    #[default]
    Work,
    /// 1: tool coordinate system definitions.
    Tool,
}

const KIND_CODES: &[(u32, &str)] = &[
    (0, "work coordinate systems"),
    (1, "tool coordinate systems"),
];

fn read_kind(r: &mut Reader<'_, '_>) -> Result<CoordKind, MessageError> {
    match r.u8(Name::new("type"), 1, Show::Code(KIND_CODES))? {
        0 => Ok(CoordKind::Work),
        1 => Ok(CoordKind::Tool),
        _ => Err(r.invalid("0 (work) or 1 (tool)")),
    }
}

/// The record count of a table reply: two hex digits hold at most 255.
fn record_count(w: &Writer<'_>, n: usize) -> Result<u32, EncodeError> {
    u32::try_from(n).ok().filter(|&n| n <= 255).ok_or_else(|| {
        w.error(
            "number of records",
            format!("= {n}: at most 255 records fit"),
        )
    })
}

/// Type, first definition number and record count: the head 2A0H and 2A4H replies share.
fn write_table_head(w: &mut Writer<'_>, kind: CoordKind, first: u8, count: u32) {
    w.hex_fit(kind_code(kind), 1);
    w.hex_fit(u32::from(first), 2);
    w.hex_fit(count, 2);
}

fn kind_code(k: CoordKind) -> u32 {
    match k {
        CoordKind::Work => 0,
        CoordKind::Tool => 1,
    }
}

/// 2A0H command: read `count` definitions of `kind` from number `first` (4 axes each).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct CoordQuery {
    /// Work or tool table.
    pub kind: CoordKind,
    /// First definition number, from 0.
    pub first: u8,
    /// Number of records (limited by the reply buffer, PROTOCOL.md 1.7).
    pub count: u8,
}

impl CoordQuery {
    pub(crate) fn read(r: &mut Reader<'_, '_>) -> Result<Self, MessageError> {
        let kind = read_kind(r)?;
        let first = r.u8(Name::new("first definition number"), 2, Show::Number)?;
        let count = r.u8(Name::new("number of records"), 2, Show::Number)?;
        Ok(CoordQuery { kind, first, count })
    }

    pub(crate) fn write(&self, w: &mut Writer<'_>) -> Result<(), EncodeError> {
        w.hex_fit(kind_code(self.kind), 1);
        w.hex_fit(u32::from(self.first), 2);
        w.hex_fit(u32::from(self.count), 2);
        Ok(())
    }
}

/// One 2A0H record: the offsets of a SCARA coordinate system definition.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct XyzR {
    /// X offset, 0.001 mm.
    pub x: Milli,
    /// Y offset, 0.001 mm.
    pub y: Milli,
    /// Z offset, 0.001 mm.
    pub z: Milli,
    /// R offset, 0.001 deg.
    pub r: Milli,
}

/// 2A0H reply: `records.len()` definitions from number `first`.
#[derive(Clone, Debug, Default, PartialEq, Eq, Hash)]
pub struct CoordTable {
    /// Work or tool table (echo).
    pub kind: CoordKind,
    /// First definition number.
    pub first: u8,
    /// The records (at most 255).
    pub records: Vec<XyzR>,
}

/// SC CR LF, after a reply's records.
const REPLY_TAIL: usize = 4;

impl CoordTable {
    /// How many records of a 2A0H reply fit a reply buffer of `reply_buffer` bytes: 11
    /// characters before the records, 32 for each, SC CR LF (PROTOCOL.md 1.7, 3.15).
    pub fn records_fitting(reply_buffer: usize) -> usize {
        reply_buffer.saturating_sub(11 + REPLY_TAIL) / 32
    }

    pub(crate) fn read(r: &mut Reader<'_, '_>) -> Result<Self, MessageError> {
        let kind = read_kind(r)?;
        let first = r.u8(Name::new("first definition number"), 2, Show::Number)?;
        let count = usize::from(r.u8(Name::new("number of records"), 2, Show::Number)?);
        let mut records = Vec::with_capacity(count);
        for i in 0..count {
            let first_no = usize::from(first) + i;
            let x = r.coord(Name::record("X offset", first_no, None), AxisUnit::Mm)?;
            let y = r.coord(Name::record("Y offset", first_no, None), AxisUnit::Mm)?;
            let z = r.coord(Name::record("Z offset", first_no, None), AxisUnit::Mm)?;
            let rr = r.coord(Name::record("R offset", first_no, None), AxisUnit::Deg)?;
            records.push(XyzR { x, y, z, r: rr });
        }
        Ok(CoordTable {
            kind,
            first,
            records,
        })
    }

    pub(crate) fn write(&self, w: &mut Writer<'_>) -> Result<(), EncodeError> {
        let n = record_count(w, self.records.len())?;
        write_table_head(w, self.kind, self.first, n);
        for rec in &self.records {
            w.coord(rec.x);
            w.coord(rec.y);
            w.coord(rec.z);
            w.coord(rec.r);
        }
        Ok(())
    }
}

/// How many definitions of one table 2A4H can name: the first number is one byte (0-255).
pub const COORD_RECORDS: u16 = 256;

/// 2A4H command: read definitions for the axes of `axes` (`0F`, `F0` or `FF`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct CoordQuery2 {
    /// Query axis pattern: `0F`, `F0` or `FF` only.
    pub axes: AxisPattern,
    /// Work or tool table.
    pub kind: CoordKind,
    /// First definition number, from 0.
    pub first: u8,
    /// Number of records.
    pub count: u8,
}

impl Default for CoordQuery2 {
    fn default() -> Self {
        CoordQuery2 {
            axes: AxisPattern::SCARA_1,
            kind: CoordKind::Work,
            first: 0,
            count: 1,
        }
    }
}

fn query_pattern_ok(p: AxisPattern) -> bool {
    matches!(p.0, 0x0F | 0xF0 | 0xFF)
}

impl CoordQuery2 {
    pub(crate) fn read(r: &mut Reader<'_, '_>) -> Result<Self, MessageError> {
        let axes = r.pattern("query axis pattern")?;
        if !query_pattern_ok(axes) {
            return Err(r.invalid("0F, F0 or FF"));
        }
        let kind = read_kind(r)?;
        let first = r.u8(Name::new("first definition number"), 2, Show::Number)?;
        let count = r.u8(Name::new("number of records"), 2, Show::Number)?;
        Ok(CoordQuery2 {
            axes,
            kind,
            first,
            count,
        })
    }

    pub(crate) fn write(&self, w: &mut Writer<'_>) -> Result<(), EncodeError> {
        if !query_pattern_ok(self.axes) {
            return Err(w.error(
                "query axis pattern",
                format!("= {:02X}: only 0F, F0 or FF are allowed", self.axes.0),
            ));
        }
        w.hex_fit(u32::from(self.axes.0), 2);
        w.hex_fit(kind_code(self.kind), 1);
        w.hex_fit(u32::from(self.first), 2);
        w.hex_fit(u32::from(self.count), 2);
        Ok(())
    }
}

/// 2A4H reply: definitions for the axes of the response pattern (record size = 8 × set
/// bits, PROTOCOL.md 3.16 with corrected columns).
#[derive(Clone, Debug, Default, PartialEq, Eq, Hash)]
pub struct CoordTable2 {
    /// Response axis pattern: the queried axes that exist on this model.
    pub axes: AxisPattern,
    /// Work or tool table (echo).
    pub kind: CoordKind,
    /// First definition number.
    pub first: u8,
    /// The records (at most 255); each has exactly the axes of `axes`.
    pub records: Vec<PerAxis<Milli>>,
}

/// All records at once when every character is a hex digit (the common case); `None`
/// sends the caller down the field-by-field path, which names any bad field.
fn fast_records(
    r: &mut Reader<'_, '_>,
    axes: AxisPattern,
    count: usize,
) -> Option<Vec<PerAxis<Milli>>> {
    let per = axes.count();
    let len = count * per * 8;
    let block = r.peek_block(len)?;
    let mut slots = [0usize; 8];
    for (slot, a) in slots.iter_mut().zip(axes) {
        *slot = a.index();
    }
    let slots = slots.get(..per)?;
    let mut records = Vec::with_capacity(count);
    let mut bad = false;
    if per > 0 {
        for rec in block.chunks_exact(per * 8) {
            let mut vals = [Milli(0); 8];
            for (field, &slot) in rec.chunks_exact(8).zip(slots) {
                let v = <&[u8; 8]>::try_from(field).ok().and_then(parse_hex8);
                bad |= v.is_none();
                if let Some(dst) = vals.get_mut(slot) {
                    *dst = Milli::from_wire(v.unwrap_or(0));
                }
            }
            records.push(PerAxis::from_slots(axes, vals));
        }
    } else {
        records.resize(count, PerAxis::new());
    }
    if bad {
        return None;
    }
    r.skip(len);
    Some(records)
}

/// Unit of a 2A4H offset: R axes (4, 8) in deg, others in mm.
fn offset_unit(a: Axis) -> AxisUnit {
    if a.is_scara_r() {
        AxisUnit::Deg
    } else {
        AxisUnit::Mm
    }
}

impl CoordTable2 {
    /// How many records of `axes` a 2A4H reply fits in a reply buffer of `reply_buffer`
    /// bytes: 13 characters before the records (`#`, station, ID, pattern, type, first,
    /// count), 8 per axis of each record, SC CR LF (PROTOCOL.md 1.7, 3.16).
    pub fn records_fitting(axes: AxisPattern, reply_buffer: usize) -> usize {
        reply_buffer.saturating_sub(13 + REPLY_TAIL) / (8 * axes.count().max(1))
    }

    pub(crate) fn read(r: &mut Reader<'_, '_>) -> Result<Self, MessageError> {
        let axes = r.pattern("response axis pattern")?;
        let kind = read_kind(r)?;
        let first = r.u8(Name::new("first definition number"), 2, Show::Number)?;
        let count = usize::from(r.u8(Name::new("number of records"), 2, Show::Number)?);
        if let Some(records) = fast_records(r, axes, count) {
            return Ok(CoordTable2 {
                axes,
                kind,
                first,
                records,
            });
        }
        let mut records = Vec::with_capacity(count);
        for i in 0..count {
            let no = usize::from(first) + i;
            let mut rec = PerAxis::new();
            for a in axes {
                rec.set(
                    a,
                    r.coord(Name::record("offset", no, Some(a)), offset_unit(a))?,
                );
            }
            records.push(rec);
        }
        Ok(CoordTable2 {
            axes,
            kind,
            first,
            records,
        })
    }

    pub(crate) fn write(&self, w: &mut Writer<'_>) -> Result<(), EncodeError> {
        let n = record_count(w, self.records.len())?;
        w.hex_fit(u32::from(self.axes.0), 2);
        write_table_head(w, self.kind, self.first, n);
        for (i, rec) in self.records.iter().enumerate() {
            if rec.pattern() != self.axes {
                return Err(w.error(
                    format!("record {i}"),
                    format!(
                        "has axes {}, but the response axis pattern is {}",
                        rec.pattern(),
                        self.axes
                    ),
                ));
            }
            for (_, v) in rec.iter() {
                w.coord(v);
            }
        }
        Ok(())
    }
}
