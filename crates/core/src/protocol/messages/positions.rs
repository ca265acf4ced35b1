//! Position data (PROTOCOL.md 3.24-3.33): 209H/21FH/22DH queries, 244H/245H/26DH/290H/291H
//! writes and 26BH move to a position number, sharing one variable-length record.

use crate::protocol::axis::{Axis, AxisPattern, PerAxis};
use crate::protocol::error::{EncodeError, MessageError};
use crate::protocol::fields::{Name, Reader, Show};
use crate::protocol::ids::MessageId;
use crate::protocol::units::{AxisUnit, CentiG, Milli, MmPerSec};
use crate::protocol::writer::Writer;

/// Width of position numbers and counts: 3 digits (209H, 244H, 245H) or 4 (21FH, 22DH,
/// 26DH, 290H, 291H) `[spec p.19, p.35, p.36, p.44, p.45, p.60, p.63, p.64]`.
const fn digits(four: bool) -> usize {
    if four { 4 } else { 3 }
}

/// The highest number a field of `d` hex digits holds.
const fn max_of(d: usize) -> u32 {
    (1 << (4 * d)) - 1
}

/// Position numbers of a controller with 3-digit position messages (209H, 244H, 245H):
/// the pages' arithmetic uses 3,000 records `[spec p.19, p.44, p.45]`.
pub const MAX_POSITIONS_3_DIGIT: u16 = 3_000;
/// Position numbers of a controller with 4-digit messages (21FH, 22DH, 26DH, 290H, 291H):
/// the arithmetic uses 20,000 `[spec p.35, p.36, p.60, p.63, p.64; PROTOCOL.md 3.49 E1]`.
pub const MAX_POSITIONS_4_DIGIT: u16 = 20_000;

/// SC CR LF after the data of every frame.
const TAIL: usize = 4;
/// Header, station and message ID before the data of every frame.
const HEAD: usize = 6;

/// Which position query: the three differ in number width and the arm-system byte.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum PositionQueryKind {
    /// 209H: 3-digit numbers and counts, no arm system.
    Query,
    /// 21FH: 4-digit numbers and counts, no arm system.
    Query2,
    /// 22DH: 4-digit numbers and counts, a reserved `00` field, the arm systems per record
    /// (the only query that reports them `[spec p.36]`).
    #[default]
    Query3,
}

impl PositionQueryKind {
    /// The message ID.
    pub const fn id(self) -> MessageId {
        match self {
            PositionQueryKind::Query => MessageId::POSITION_QUERY,
            PositionQueryKind::Query2 => MessageId::POSITION_QUERY_2,
            PositionQueryKind::Query3 => MessageId::POSITION_QUERY_3,
        }
    }

    const fn four(self) -> bool {
        !matches!(self, PositionQueryKind::Query)
    }

    const fn arms(self) -> bool {
        matches!(self, PositionQueryKind::Query3)
    }

    /// The highest position number and count its fields hold (3 digits: 4095).
    pub const fn max_number(self) -> u16 {
        max_of(digits(self.four())) as u16
    }

    /// Characters of a reply besides its records: header to count, SC CR LF.
    const fn reply_fixed(self) -> usize {
        HEAD + if self.arms() { 2 } else { 0 } + digits(self.four()) + TAIL
    }

    /// The length of a reply carrying `records`, header to LF.
    pub fn reply_len<'r>(self, records: impl IntoIterator<Item = &'r PositionRecord>) -> usize {
        self.reply_fixed()
            + records
                .into_iter()
                .map(|r| self.record_len(r))
                .sum::<usize>()
    }

    /// Characters of `record` in this query's reply.
    pub fn record_len(self, record: &PositionRecord) -> usize {
        record_len(digits(self.four()), record.coords.len(), self.arms())
    }

    /// Whether a reply of `len` bytes may have been cut short by a reply buffer of
    /// `reply_buffer` bytes: one more record of a single axis would not have fitted.
    /// Whether a controller cuts or refuses is not stated `[inferred, PROTOCOL.md 3.24]`;
    /// a host reads on from the last number returned.
    pub fn may_be_cut(self, len: usize, reply_buffer: usize) -> bool {
        len + record_len(digits(self.four()), 1, self.arms()) > reply_buffer
    }

    /// How many records carrying `axes` axes each fit one reply in a buffer of
    /// `reply_buffer` bytes (PROTOCOL.md 3.24's table; header to LF counted `[inferred]`).
    /// A host cannot know a record's axes before it reads it: size with the controller's
    /// axis count (the worst case) `[inferred]`.
    pub fn records_fitting(self, axes: usize, reply_buffer: usize) -> usize {
        let record = record_len(digits(self.four()), axes, self.arms());
        reply_buffer.saturating_sub(self.reply_fixed()) / record
    }
}

/// Which position write: range writes carry a start number and records without one;
/// change writes carry a count and records with their own numbers.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum PositionWriteKind {
    /// 244H: range, 3 digits, no arm system.
    Range,
    /// 245H: change, 3 digits, no arm system.
    Change,
    /// 26DH: change, 4 digits, no arm system.
    Change2,
    /// 290H: range, 4 digits, reserved `00`, arm systems.
    Range3,
    /// 291H: change, 4 digits, reserved `00`, arm systems. Its printed table contradicts
    /// itself; the layout is PROTOCOL.md 3.32's reconstruction `[inferred]` (erratum E5).
    #[default]
    Change3,
}

impl PositionWriteKind {
    /// The message ID.
    pub const fn id(self) -> MessageId {
        match self {
            PositionWriteKind::Range => MessageId::POSITION_RANGE_WRITE,
            PositionWriteKind::Change => MessageId::POSITION_CHANGE_WRITE,
            PositionWriteKind::Change2 => MessageId::POSITION_CHANGE_WRITE_2,
            PositionWriteKind::Range3 => MessageId::POSITION_RANGE_WRITE_3,
            PositionWriteKind::Change3 => MessageId::POSITION_CHANGE_WRITE_3,
        }
    }

    const fn four(self) -> bool {
        !matches!(self, PositionWriteKind::Range | PositionWriteKind::Change)
    }

    /// Whether records carry the arm systems (290H, 291H).
    pub const fn arms(self) -> bool {
        matches!(self, PositionWriteKind::Range3 | PositionWriteKind::Change3)
    }

    /// Whether the command names a start number and its records carry none.
    pub const fn is_range(self) -> bool {
        matches!(self, PositionWriteKind::Range | PositionWriteKind::Range3)
    }

    /// The highest position number and count its fields hold.
    pub const fn max_number(self) -> u16 {
        max_of(digits(self.four())) as u16
    }

    /// Characters of a command besides its records.
    const fn command_fixed(self) -> usize {
        let d = digits(self.four());
        let reserved = if self.arms() { 2 } else { 0 };
        let start = if self.is_range() { d } else { 0 };
        HEAD + reserved + start + d + TAIL
    }

    /// Characters of one record carrying `axes` axes.
    fn record(self, axes: usize) -> usize {
        let number = if self.is_range() {
            0
        } else {
            digits(self.four())
        };
        record_len(number, axes, self.arms())
    }

    /// The length of the whole command frame (header to LF) for these records.
    pub fn frame_len<'r>(self, records: impl IntoIterator<Item = &'r PositionRecord>) -> usize {
        self.command_fixed()
            + records
                .into_iter()
                .map(|r| self.record(r.coords.len()))
                .sum::<usize>()
    }

    /// How many records carrying `axes` axes fit one command in a buffer of
    /// `command_buffer` bytes (PROTOCOL.md 3.24's table `[inferred arithmetic]`).
    pub fn records_fitting(self, axes: usize, command_buffer: usize) -> usize {
        command_buffer.saturating_sub(self.command_fixed()) / self.record(axes)
    }
}

/// Characters of one query-reply record: number, pattern, rates, coordinates, arm byte.
const fn record_len(number: usize, axes: usize, arms: bool) -> usize {
    number + 2 + 12 + 8 * axes + if arms { 2 } else { 0 }
}

/// The arm system a position record asks for (extended data, 2 bits per SCARA:
/// 0 none, 1 right, 2 left `[spec p.36, p.63, p.64]`; PROTOCOL.md 5 row 4: not the codes
/// of 2A1H or 2A3H).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum RecordArm {
    /// 0: no specification.
    #[default]
    Unspecified,
    /// 1: right arm system.
    Right,
    /// 2: left arm system.
    Left,
}

impl RecordArm {
    const fn code(self) -> u8 {
        match self {
            RecordArm::Unspecified => 0,
            RecordArm::Right => 1,
            RecordArm::Left => 2,
        }
    }

    const fn from_code(c: u8) -> Option<RecordArm> {
        match c {
            0 => Some(RecordArm::Unspecified),
            1 => Some(RecordArm::Right),
            2 => Some(RecordArm::Left),
            _ => None,
        }
    }
}

/// The extended-data byte of 22DH/290H/291H records: bits 4-5 SCARA 1, bits 6-7 SCARA 2,
/// bits 0-3 spare (sent 0).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct RecordArms {
    pub scara1: RecordArm,
    pub scara2: RecordArm,
}

impl RecordArms {
    fn byte(self) -> u32 {
        u32::from(self.scara1.code() << 4 | self.scara2.code() << 6)
    }

    fn from_byte(b: u8) -> Option<RecordArms> {
        if b & 0x0F != 0 {
            return None;
        }
        Some(RecordArms {
            scara1: RecordArm::from_code((b >> 4) & 3)?,
            scara2: RecordArm::from_code(b >> 6)?,
        })
    }
}

const ARM_CODES: &[(u32, &str)] = &[
    (0x00, "no arm system"),
    (0x10, "SCARA 1 right arm"),
    (0x20, "SCARA 1 left arm"),
    (0x40, "SCARA 2 right arm"),
    (0x50, "SCARA 1 and 2 right arm"),
    (0x60, "SCARA 1 left, SCARA 2 right arm"),
    (0x80, "SCARA 2 left arm"),
    (0x90, "SCARA 1 right, SCARA 2 left arm"),
    (0xA0, "SCARA 1 and 2 left arm"),
];

/// One position record (PROTOCOL.md 3.24): coordinates of the axes of its own pattern,
/// acceleration, deceleration and speed (0 = not set), the arm systems where the message
/// carries them.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct PositionRecord {
    /// Position number, from 1 `[inferred]`. In range writes it follows from the start
    /// number (record *i* at start + *i* `[inferred]`).
    pub number: u16,
    /// One coordinate per axis of the record's pattern, 0.001 mm (R: 0.001 deg
    /// `[inferred]`), signed `[inferred]`.
    pub coords: PerAxis<Milli>,
    /// 0.01 G; 0 = not set.
    pub accel: CentiG,
    /// 0.01 G; 0 = not set.
    pub decel: CentiG,
    /// mm/s; 0 = not set.
    pub speed: MmPerSec,
    /// Arm systems (22DH, 290H, 291H only; left unspecified by the others).
    pub arms: RecordArms,
}

fn unit(axis: Axis) -> AxisUnit {
    if axis.is_scara_r() {
        AxisUnit::Deg
    } else {
        AxisUnit::Mm
    }
}

impl PositionRecord {
    /// Reads one record; `number` is its number field's width (0 = none: `implied`).
    fn read(
        r: &mut Reader<'_, '_>,
        index: usize,
        number: usize,
        implied: u16,
        arms: bool,
    ) -> Result<Self, MessageError> {
        let number = if number > 0 {
            r.u16(
                Name::record("position number", index, None),
                number,
                Show::Number,
            )?
        } else {
            implied
        };
        let pattern =
            AxisPattern(r.u8(Name::record("axis pattern", index, None), 2, Show::Pattern)?);
        let accel = CentiG(r.u16(Name::record("acceleration", index, None), 4, Show::Accel)?);
        let decel = CentiG(r.u16(Name::record("deceleration", index, None), 4, Show::Accel)?);
        let speed = MmPerSec(r.u16(Name::record("speed", index, None), 4, Show::Speed)?);
        let mut coords = PerAxis::new();
        for axis in pattern {
            let v = r.coord(Name::record("coordinate", index, Some(axis)), unit(axis))?;
            coords.set(axis, v);
        }
        let arms = if arms {
            let b = r.u8(
                Name::record("extended data", index, None),
                2,
                Show::Code(ARM_CODES),
            )?;
            RecordArms::from_byte(b).ok_or_else(|| {
                r.invalid("bits 0-3 zero, each arm field 0 (none), 1 (right) or 2 (left)")
            })?
        } else {
            RecordArms::default()
        };
        Ok(PositionRecord {
            number,
            coords,
            accel,
            decel,
            speed,
            arms,
        })
    }

    fn write(&self, w: &mut Writer<'_>, number: usize, arms: bool) -> Result<(), EncodeError> {
        if number > 0 {
            w.hex("position number", u32::from(self.number), number)?;
        }
        w.hex_fit(u32::from(self.coords.pattern().0), 2);
        w.hex_fit(u32::from(self.accel.0), 4);
        w.hex_fit(u32::from(self.decel.0), 4);
        w.hex_fit(u32::from(self.speed.0), 4);
        for axis in self.coords.pattern() {
            w.coord(self.coords.get(axis).unwrap_or_default());
        }
        if arms {
            w.hex_fit(self.arms.byte(), 2);
        }
        Ok(())
    }
}

/// Writes the `00` reserved field of 22DH, 290H and 291H (`present`: the message has it).
fn write_reserved(w: &mut Writer<'_>, present: bool) {
    if present {
        w.hex_fit(0, 2);
    }
}

/// Reads `count` records whose number fields are `number` digits wide (0: none, record
/// *i* is `start` + *i*). A count the data cannot hold (each record is at least its
/// fixed part long) is refused before anything is allocated for it.
fn read_records(
    r: &mut Reader<'_, '_>,
    count: usize,
    number: usize,
    start: u16,
    arms: bool,
) -> Result<Vec<PositionRecord>, MessageError> {
    let shortest = record_len(number, 0, arms);
    if count * shortest > r.remaining() {
        return Err(r.invalid(format!(
            "at most {} records in the {} characters that follow",
            r.remaining() / shortest,
            r.remaining()
        )));
    }
    let mut records = Vec::with_capacity(count);
    for i in 0..count {
        let implied = start.saturating_add(i as u16);
        records.push(PositionRecord::read(r, i + 1, number, implied, arms)?);
    }
    Ok(records)
}

/// Reads the `00` reserved field of 22DH, 290H and 291H.
fn read_reserved(r: &mut Reader<'_, '_>) -> Result<(), MessageError> {
    if r.u8(Name::new("reserved"), 2, Show::Hex)? != 0 {
        return Err(r.invalid("00 (reserved for system use)"));
    }
    Ok(())
}

/// 209H / 21FH / 22DH command: the effective positions among `count` numbers from
/// `first`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct PositionQuery {
    pub kind: PositionQueryKind,
    /// Query head position number.
    pub first: u16,
    /// Number of query records: numbers looked at (limited by the buffers).
    pub count: u16,
}

impl PositionQuery {
    pub(crate) fn read(
        r: &mut Reader<'_, '_>,
        kind: PositionQueryKind,
    ) -> Result<Self, MessageError> {
        if kind.arms() {
            read_reserved(r)?;
        }
        let d = digits(kind.four());
        let first = r.u16(Name::new("query head position number"), d, Show::Number)?;
        let count = r.u16(Name::new("number of query records"), d, Show::Number)?;
        Ok(PositionQuery { kind, first, count })
    }

    pub(crate) fn write(&self, w: &mut Writer<'_>) -> Result<(), EncodeError> {
        write_reserved(w, self.kind.arms());
        let d = digits(self.kind.four());
        w.hex("query head position number", u32::from(self.first), d)?;
        w.hex("number of query records", u32::from(self.count), d)
    }

    /// The longest reply it may get, header to LF: every number asked for effective with
    /// all 8 axes, or the reply buffer's limit if that is smaller is the controller's
    /// business (the host allows the format's maximum).
    pub fn max_reply_len(&self) -> usize {
        self.kind.reply_fixed()
            + usize::from(self.count) * record_len(digits(self.kind.four()), 8, self.kind.arms())
    }
}

/// 209H / 21FH / 22DH reply: the effective records, each with its number.
#[derive(Clone, Debug, Default, PartialEq, Eq, Hash)]
pub struct PositionData {
    pub kind: PositionQueryKind,
    pub records: Vec<PositionRecord>,
}

impl PositionData {
    pub(crate) fn read(
        r: &mut Reader<'_, '_>,
        kind: PositionQueryKind,
    ) -> Result<Self, MessageError> {
        if kind.arms() {
            read_reserved(r)?;
        }
        let d = digits(kind.four());
        let count =
            usize::from(r.u16(Name::new("number of effective records"), d, Show::Number)?);
        let records = read_records(r, count, d, 0, kind.arms())?;
        Ok(PositionData { kind, records })
    }

    pub(crate) fn write(&self, w: &mut Writer<'_>) -> Result<(), EncodeError> {
        write_reserved(w, self.kind.arms());
        let d = digits(self.kind.four());
        let n = u32::try_from(self.records.len()).unwrap_or(u32::MAX);
        w.hex("number of effective records", n, d)?;
        for rec in &self.records {
            rec.write(w, d, self.kind.arms())?;
        }
        Ok(())
    }
}

/// 244H / 245H / 26DH / 290H / 291H command: write records. Range writes (244H, 290H)
/// send `records` to consecutive numbers from the first record's number; change writes
/// send each record's own number.
#[derive(Clone, Debug, Default, PartialEq, Eq, Hash)]
pub struct PositionWrite {
    pub kind: PositionWriteKind,
    pub records: Vec<PositionRecord>,
}

impl PositionWrite {
    pub(crate) fn read(
        r: &mut Reader<'_, '_>,
        kind: PositionWriteKind,
    ) -> Result<Self, MessageError> {
        if kind.arms() {
            read_reserved(r)?;
        }
        let d = digits(kind.four());
        let start = if kind.is_range() {
            r.u16(Name::new("change start position number"), d, Show::Number)?
        } else {
            0
        };
        let count =
            usize::from(r.u16(Name::new("number of change position data"), d, Show::Number)?);
        let number = if kind.is_range() { 0 } else { d };
        let records = read_records(r, count, number, start, kind.arms())?;
        Ok(PositionWrite { kind, records })
    }

    pub(crate) fn write(&self, w: &mut Writer<'_>) -> Result<(), EncodeError> {
        let kind = self.kind;
        write_reserved(w, kind.arms());
        let d = digits(kind.four());
        if kind.is_range() {
            let start = self.records.first().map_or(0, |r| r.number);
            for (i, rec) in self.records.iter().enumerate() {
                if usize::from(rec.number) != usize::from(start) + i {
                    return Err(w.error(
                        "position number",
                        format!(
                            "record {} is No. {}: a range write ({}) needs consecutive numbers from {start}",
                            i + 1,
                            rec.number,
                            kind.id()
                        ),
                    ));
                }
            }
            w.hex("change start position number", u32::from(start), d)?;
        }
        let n = u32::try_from(self.records.len()).unwrap_or(u32::MAX);
        w.hex("number of change position data", n, d)?;
        let number = if kind.is_range() { 0 } else { d };
        for rec in &self.records {
            rec.write(w, number, kind.arms())?;
        }
        Ok(())
    }
}

/// 244H / 245H / 26DH / 290H / 291H reply: how many records were written (range writes
/// echo the start number too).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct PositionsWritten {
    pub kind: PositionWriteKind,
    /// The start number (244H, 290H); 0 for the change writes, whose replies carry none.
    pub first: u16,
    /// Number of changed position data.
    pub count: u16,
}

impl PositionsWritten {
    pub(crate) fn read(
        r: &mut Reader<'_, '_>,
        kind: PositionWriteKind,
    ) -> Result<Self, MessageError> {
        // 291H's reply has the reserved field but no start number [spec p.64]; 290H's
        // has both (its notations swapped, erratum E3).
        if kind.arms() {
            read_reserved(r)?;
        }
        let d = digits(kind.four());
        let first = if kind.is_range() {
            r.u16(Name::new("change start position number"), d, Show::Number)?
        } else {
            0
        };
        let count = r.u16(
            Name::new("number of changed position data"),
            d,
            Show::Number,
        )?;
        Ok(PositionsWritten { kind, first, count })
    }

    pub(crate) fn write(&self, w: &mut Writer<'_>) -> Result<(), EncodeError> {
        write_reserved(w, self.kind.arms());
        let d = digits(self.kind.four());
        if self.kind.is_range() {
            w.hex("change start position number", u32::from(self.first), d)?;
        }
        w.hex("number of changed position data", u32::from(self.count), d)
    }

    /// Characters of this reply, header to LF.
    pub const fn frame_len(kind: PositionWriteKind) -> usize {
        let d = digits(kind.four());
        HEAD + if kind.arms() { 2 } else { 0 } + if kind.is_range() { d } else { 0 } + d + TAIL
    }
}

/// 26BH: move the axes of `axes` (ANDed with the record's pattern) to position
/// `position`; rates 0 take the record's value, then the parameter's `[spec p.58]`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct PositionMove {
    pub axes: AxisPattern,
    pub accel: CentiG,
    pub decel: CentiG,
    pub speed: MmPerSec,
    /// 4 digits although printed `'XXX(h)'` (PROTOCOL.md 5 row 9).
    pub position: u16,
}

impl PositionMove {
    pub(crate) fn read(r: &mut Reader<'_, '_>) -> Result<Self, MessageError> {
        let axes = r.pattern("axis pattern")?;
        let accel = r.accel("acceleration")?;
        let decel = r.accel("deceleration")?;
        let speed = r.speed("speed")?;
        let position = r.u16(Name::new("position number"), 4, Show::Number)?;
        Ok(PositionMove {
            axes,
            accel,
            decel,
            speed,
            position,
        })
    }

    pub(crate) fn write(&self, w: &mut Writer<'_>) -> Result<(), EncodeError> {
        w.hex_fit(u32::from(self.axes.0), 2);
        w.hex_fit(u32::from(self.accel.0), 4);
        w.hex_fit(u32::from(self.decel.0), 4);
        w.hex_fit(u32::from(self.speed.0), 4);
        w.hex_fit(u32::from(self.position), 4);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::protocol::{Command, Frame, Reply, ScMode, Station};

    fn cmd(s: &str) -> Command {
        let mut b = s.as_bytes().to_vec();
        b.extend_from_slice(b"\r\n");
        let f = Frame::parse(&b).unwrap();
        Command::decode(&f).unwrap()
    }

    fn reply(s: &str) -> Reply {
        let mut b = s.as_bytes().to_vec();
        b.extend_from_slice(b"\r\n");
        let f = Frame::parse(&b).unwrap();
        Reply::decode(&f).unwrap()
    }

    fn sent(c: &Command) -> String {
        let b = c.to_bytes(Station::DEFAULT, ScMode::Computed).unwrap();
        String::from_utf8(b).unwrap().trim_end().to_string()
    }

    fn answered(r: &Reply) -> String {
        String::from_utf8(r.to_bytes(Station::DEFAULT).unwrap())
            .unwrap()
            .trim_end()
            .to_string()
    }

    fn rec(number: u16, coords: &[(Axis, i32)], arms: RecordArms) -> PositionRecord {
        PositionRecord {
            number,
            coords: PerAxis::from_pairs(coords.iter().map(|&(a, v)| (a, Milli(v)))),
            arms,
            ..PositionRecord::default()
        }
    }

    const RIGHT: RecordArms = RecordArms {
        scara1: RecordArm::Right,
        scara2: RecordArm::Unspecified,
    };
    const LEFT: RecordArms = RecordArms {
        scara1: RecordArm::Left,
        scara2: RecordArm::Unspecified,
    };

    /// Every frame of PROTOCOL.md 3.50 for sections 3.25-3.33, both ways.
    #[test]
    fn the_checked_examples_of_section_3_50_decode_and_encode_back() {
        let two = vec![
            PositionRecord {
                speed: MmPerSec(100),
                ..rec(
                    1,
                    &[(Axis::A1, 100_000), (Axis::A2, -50_000)],
                    RecordArms::default(),
                )
            },
            PositionRecord {
                accel: CentiG(30),
                decel: CentiG(30),
                speed: MmPerSec(200),
                ..rec(5, &[(Axis::A1, 12_345)], RecordArms::default())
            },
        ];
        let scara = vec![
            rec(
                1,
                &[
                    (Axis::A1, 300_000),
                    (Axis::A2, -150_000),
                    (Axis::A3, 20_000),
                    (Axis::A4, 45_000),
                ],
                RIGHT,
            ),
            rec(
                2,
                &[
                    (Axis::A1, 250_000),
                    (Axis::A2, 100_000),
                    (Axis::A3, 0),
                    (Axis::A4, -90_000),
                ],
                LEFT,
            ),
        ];
        let q = |kind, first, count| Command::PositionQuery(PositionQuery { kind, first, count });
        let cases: Vec<(&str, Command)> = vec![
            ("!9920900100A60", q(PositionQueryKind::Query, 1, 10)),
            ("!9921F0001000ACE", q(PositionQueryKind::Query2, 1, 10)),
            ("!9922D00000100021E", q(PositionQueryKind::Query3, 1, 2)),
        ];
        for (text, want) in cases {
            assert_eq!(cmd(text), want, "{text}");
            assert_eq!(sent(&want), text);
        }
        let data = |kind, records: &Vec<PositionRecord>| {
            Reply::Positions(PositionData {
                kind,
                records: records.clone(),
            })
        };
        let replies = vec![
            (
                "#9920900200103000000000064000186A0FFFF3CB000501001E001E00C800003039AC",
                data(PositionQueryKind::Query, &two),
            ),
            (
                "#9921F0002000103000000000064000186A0FFFF3CB0000501001E001E00C8000030394A",
                data(PositionQueryKind::Query2, &two),
            ),
            (
                "#9922D00000200010F000000000000000493E0FFFDB61000004E200000AFC81000020F0000000000000003D090000186A000000000FFFEA07020B1",
                data(PositionQueryKind::Query3, &scara),
            ),
        ];
        for (text, want) in replies {
            assert_eq!(reply(text), want, "{text}");
            assert_eq!(answered(&want), text);
        }
        let at = |n, mm: i32| PositionRecord {
            speed: MmPerSec(100),
            ..rec(n, &[(Axis::A1, mm)], RecordArms::default())
        };
        let w = |kind, records: Vec<PositionRecord>| {
            Command::PositionWrite(PositionWrite { kind, records })
        };
        let writes = vec![
            (
                "!9924400A002010000000000640000C35001000000000064000124F8F6",
                w(
                    PositionWriteKind::Range,
                    vec![at(10, 50_000), at(11, 75_000)],
                ),
            ),
            (
                "!9924500200A010000000000640000C35001401000000000064000124F88C",
                w(
                    PositionWriteKind::Change,
                    vec![at(10, 50_000), at(20, 75_000)],
                ),
            ),
            (
                "!9926D00012710010000000000640000C35010",
                w(PositionWriteKind::Change2, vec![at(10_000, 50_000)]),
            ),
            (
                "!9929000000100010F000000000000000493E0FFFDB61000004E200000AFC81018",
                w(PositionWriteKind::Range3, vec![scara[0]]),
            ),
            (
                "!9929100000100010F000000000000000493E0FFFDB61000004E200000AFC81019",
                w(PositionWriteKind::Change3, vec![scara[0]]),
            ),
            (
                "!9926B01000000000000000AAF",
                Command::PositionMove(PositionMove {
                    axes: AxisPattern(1),
                    position: 10,
                    ..PositionMove::default()
                }),
            ),
        ];
        for (text, want) in writes {
            assert_eq!(cmd(text), want, "{text}");
            assert_eq!(sent(&want), text);
        }
        let done =
            |kind, first, count| Reply::PositionsWritten(PositionsWritten { kind, first, count });
        for (text, want) in [
            ("#9924400A00262", done(PositionWriteKind::Range, 10, 2)),
            ("#99245002C2", done(PositionWriteKind::Change, 0, 2)),
            ("#9926D000102", done(PositionWriteKind::Change2, 0, 1)),
            ("#99290000001000112", done(PositionWriteKind::Range3, 1, 1)),
            ("#9929100000152", done(PositionWriteKind::Change3, 0, 1)),
        ] {
            assert_eq!(reply(text), want, "{text}");
            assert_eq!(answered(&want), text);
        }
        assert_eq!(reply("#9926B3F"), Reply::Ack(MessageId::POSITION_MOVE));
    }

    #[test]
    fn records_fitting_match_the_table_of_section_3_24() {
        use PositionQueryKind as Q;
        use PositionWriteKind as W;
        let q = |k: Q, axes| (k.records_fitting(axes, 2048), k.records_fitting(axes, 1024));
        assert_eq!(q(Q::Query, 1), (81, 40));
        assert_eq!(q(Q::Query, 8), (25, 12));
        assert_eq!(q(Q::Query2, 4), (40, 20));
        assert_eq!(q(Q::Query3, 4), (39, 19));
        assert_eq!(q(Q::Query3, 1), (72, 36));
        let w = |k: W, axes| (k.records_fitting(axes, 2051), k.records_fitting(axes, 1023));
        assert_eq!(w(W::Range, 1), (92, 45));
        assert_eq!(w(W::Change, 4), (41, 20));
        assert_eq!(w(W::Change2, 8), (24, 12));
        assert_eq!(w(W::Range3, 3), (50, 25));
        assert_eq!(w(W::Change3, 4), (39, 19));
        assert_eq!(w(W::Change3, 8), (24, 11));
    }

    #[test]
    fn a_frame_fits_exactly_what_records_fitting_says() {
        for kind in [
            PositionWriteKind::Range,
            PositionWriteKind::Change,
            PositionWriteKind::Change2,
            PositionWriteKind::Range3,
            PositionWriteKind::Change3,
        ] {
            let n = kind.records_fitting(4, 2051);
            let records: Vec<PositionRecord> = (1..=n as u16)
                .map(|i| {
                    rec(
                        i,
                        &[(Axis::A1, 1), (Axis::A2, 2), (Axis::A3, 3), (Axis::A4, 4)],
                        RIGHT,
                    )
                })
                .collect();
            let c = Command::PositionWrite(PositionWrite { kind, records });
            let len = c
                .to_bytes(Station::DEFAULT, ScMode::Computed)
                .unwrap()
                .len();
            assert!(len <= 2051, "{kind:?}: {len}");
            assert_eq!(
                len,
                kind.frame_len(match &c {
                    Command::PositionWrite(w) => w.records.iter(),
                    _ => unreachable!(),
                })
            );
            assert!(len + kind.record(4) > 2051, "{kind:?}: one more would fit");
        }
    }

    #[test]
    fn bad_records_are_refused_with_the_field_named() {
        // Count says 2 but only one record follows.
        let text = [
            "#9922D",
            "00",
            "0002",
            "0001",
            "01",
            "000000000000",
            "00000001",
            "00",
        ];
        let frame = with_sc(&text.concat());
        let e = Reply::decode(&Frame::parse(&frame).unwrap()).unwrap_err();
        assert!(e.to_string().contains("number of effective records"), "{e}");
        // An arm field of 3.
        let text = [
            "#9922D",
            "00",
            "0001",
            "0001",
            "01",
            "000000000000",
            "00000001",
            "30",
        ];
        let frame = with_sc(&text.concat());
        let e = Reply::decode(&Frame::parse(&frame).unwrap()).unwrap_err();
        assert!(e.to_string().contains("extended data"), "{e}");
        // A record whose pattern promises two axes but carries one.
        let text = ["#9921F", "0001", "0001", "03", "000000000000", "00000001"];
        let frame = with_sc(&text.concat());
        let e = Reply::decode(&Frame::parse(&frame).unwrap()).unwrap_err();
        assert!(e.to_string().contains("coordinate"), "{e}");
        // A range write of numbers that are not consecutive cannot be encoded.
        let c = Command::PositionWrite(PositionWrite {
            kind: PositionWriteKind::Range3,
            records: vec![
                rec(3, &[(Axis::A1, 1)], RIGHT),
                rec(5, &[(Axis::A1, 1)], RIGHT),
            ],
        });
        let e = c.to_bytes(Station::DEFAULT, ScMode::Computed).unwrap_err();
        assert!(e.to_string().contains("consecutive"), "{e}");
        // A 3-digit number field holds at most 4095.
        let c = Command::PositionWrite(PositionWrite {
            kind: PositionWriteKind::Change,
            records: vec![rec(5000, &[(Axis::A1, 1)], RecordArms::default())],
        });
        assert!(c.to_bytes(Station::DEFAULT, ScMode::Computed).is_err());
    }

    fn with_sc(text: &str) -> Vec<u8> {
        let mut b = text.as_bytes().to_vec();
        let sc = crate::protocol::checksum(&b);
        b.extend_from_slice(format!("{sc:02X}\r\n").as_bytes());
        b
    }
}
