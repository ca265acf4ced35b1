//! Field reader: fixed-width hex fields with column-aware errors, and the optional
//! field recorder the describer uses.

use std::fmt;

use super::axis::{Axis, AxisPattern};
use super::describe::{BitNote, FieldDescription};
use super::error::{Columns, MessageError, MessageErrorKind};
use super::hex::{parse_hex, parse_hex8};
use super::ids::{ErrorCode, MessageId, Role};
use super::units::{AxisUnit, CentiG, Milli, MmPerSec, Percent};

/// A field's name: a base plus optional record and axis, formatted only when needed.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Name {
    base: &'static str,
    axis: Option<Axis>,
    record: Option<usize>,
}

impl Name {
    pub(crate) const fn new(base: &'static str) -> Name {
        Name {
            base,
            axis: None,
            record: None,
        }
    }

    pub(crate) const fn axis(base: &'static str, axis: Axis) -> Name {
        Name {
            base,
            axis: Some(axis),
            record: None,
        }
    }

    pub(crate) const fn record(base: &'static str, record: usize, axis: Option<Axis>) -> Name {
        Name {
            base,
            axis,
            record: Some(record),
        }
    }
}

impl From<&'static str> for Name {
    fn from(base: &'static str) -> Name {
        Name::new(base)
    }
}

impl fmt::Display for Name {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if let Some(r) = self.record {
            write!(f, "record {r} ")?;
        }
        if let Some(a) = self.axis {
            write!(f, "axis {} ", a.number())?;
        }
        f.write_str(self.base)
    }
}

/// One bit or bit group of a flag field, for descriptions.
pub(crate) struct BitDef {
    pub lo: u8,
    pub width: u8,
    pub name: &'static str,
    pub values: &'static [(u32, &'static str)],
}

/// A single-bit flag.
pub(crate) const fn bit(lo: u8, name: &'static str) -> BitDef {
    BitDef {
        lo,
        width: 1,
        name,
        values: &[],
    }
}

/// How a field's value is written in a description.
#[derive(Clone, Copy)]
pub(crate) enum Show {
    /// Decimal number.
    Number,
    /// Hex number with `H` suffix.
    Hex,
    /// 0.01 G; 0 = parameter value.
    Accel,
    /// mm/s; 0 = parameter value.
    Speed,
    /// %; 0 = parameter value.
    Pct,
    /// Signed coordinate with unit.
    Coord(AxisUnit),
    /// Unsigned magnitude with unit.
    Magnitude(AxisUnit),
    /// Axis pattern.
    Pattern,
    /// Flag bits.
    Bits(&'static [BitDef]),
    /// Enumerated code.
    Code(&'static [(u32, &'static str)]),
    /// Controller error number.
    Error,
    /// Program number: 0 = global.
    Program,
    /// Program number: 0 = every running program (254H, 255H, 257H).
    ProgramOrAll,
    /// A group of 8 ports or flags from the given number: which are ON.
    Group(u16),
    /// Signed 32-bit two's complement.
    Signed,
    /// One character as 2 hex digits.
    Char,
}

fn render(show: Show, v: u32, width: usize) -> (String, Vec<BitNote>) {
    let param = |s: String| {
        if v == 0 {
            format!("{s} (use parameter value)")
        } else {
            s
        }
    };
    match show {
        Show::Number => (v.to_string(), Vec::new()),
        Show::Hex => (format!("{v:0width$X}H"), Vec::new()),
        Show::Accel => (param(CentiG(v as u16).to_string()), Vec::new()),
        Show::Speed => (param(MmPerSec(v as u16).to_string()), Vec::new()),
        Show::Pct => (param(Percent(v as u16).to_string()), Vec::new()),
        Show::Coord(u) => (Milli::from_wire(v).with_unit(u).to_string(), Vec::new()),
        Show::Magnitude(u) => (format!("{}.{:03} {u}", v / 1000, v % 1000), Vec::new()),
        Show::Pattern => (AxisPattern(v as u8).to_string(), Vec::new()),
        Show::Error => (ErrorCode(v as u16).to_string(), Vec::new()),
        Show::Program if v == 0 => ("0 (global)".to_string(), Vec::new()),
        Show::ProgramOrAll if v == 0 => ("0 (every running program)".to_string(), Vec::new()),
        Show::Program | Show::ProgramOrAll => (format!("program {v}"), Vec::new()),
        Show::Group(first) => (group_text(first, v as u8), Vec::new()),
        Show::Signed => ((v as i32).to_string(), Vec::new()),
        Show::Char => (
            format!("'{}' ({v:02X}H)", (v as u8).escape_ascii()),
            Vec::new(),
        ),
        Show::Code(table) => {
            let text = match table.iter().find(|(c, _)| *c == v) {
                Some((_, t)) => format!("{v} = {t}"),
                None => format!("{v} (reserved)"),
            };
            (text, Vec::new())
        }
        Show::Bits(defs) => {
            let notes = defs
                .iter()
                .map(|d| {
                    let mask = (1u32 << d.width) - 1;
                    let value = (v >> d.lo) & mask;
                    let label = if d.width == 1 {
                        format!("bit {} {}", d.lo, d.name)
                    } else {
                        format!("bits {}-{} {}", d.lo, d.lo + d.width - 1, d.name)
                    };
                    let meaning = d.values.iter().find(|(c, _)| *c == value).map(|(_, t)| *t);
                    BitNote {
                        label,
                        value,
                        meaning,
                    }
                })
                .collect();
            (format!("{v:0width$X}H"), notes)
        }
    }
}

/// Which of the 8 bits of a group from `first` are ON, by number.
fn group_text(first: u16, byte: u8) -> String {
    use super::messages::signals::group_bit;
    let on: Vec<String> = (0..8u16)
        .filter(|&i| byte & group_bit(i) != 0)
        .map(|i| first.saturating_add(i).to_string())
        .collect();
    let last = first.saturating_add(7);
    match on.len() {
        0 => format!("{first}-{last}: all OFF"),
        8 => format!("{first}-{last}: all ON"),
        _ => format!("{first}-{last}: ON {}", on.join(", ")),
    }
}

/// Reads the data fields of one message, left to right, with the frame columns of each
/// field for error messages; optionally records every field for a description.
pub(crate) struct Reader<'a, 'r> {
    data: &'a [u8],
    pos: usize,
    col0: usize,
    message: Option<MessageId>,
    role: Role,
    rec: Option<&'r mut Vec<FieldDescription>>,
    last: (Name, usize, usize),
}

impl<'a, 'r> Reader<'a, 'r> {
    /// `col0` is the frame column of `data[0]` (1-based).
    pub(crate) fn new(
        data: &'a [u8],
        col0: usize,
        message: Option<MessageId>,
        role: Role,
        rec: Option<&'r mut Vec<FieldDescription>>,
    ) -> Self {
        Reader {
            data,
            pos: 0,
            col0,
            message,
            role,
            rec,
            last: (Name::new("data"), 0, 0),
        }
    }

    /// The next `len` characters without consuming them, unless recording (then the
    /// field-by-field path must run).
    pub(crate) fn peek_block(&self, len: usize) -> Option<&'a [u8]> {
        if self.rec.is_some() {
            return None;
        }
        self.data.get(self.pos..self.pos + len)
    }

    /// Consumes `len` characters already checked through [`Reader::peek_block`].
    pub(crate) fn skip(&mut self, len: usize) {
        self.pos = (self.pos + len).min(self.data.len());
    }

    /// Data characters not read yet.
    pub(crate) fn remaining(&self) -> usize {
        self.data.len().saturating_sub(self.pos)
    }

    fn cols(&self, pos: usize, width: usize) -> Columns {
        Columns::new(self.col0 + pos, self.col0 + pos + width.max(1) - 1)
    }

    fn err(&self, kind: MessageErrorKind) -> MessageError {
        MessageError {
            message: self.message,
            role: self.role,
            kind,
        }
    }

    #[cold]
    fn missing(&self, name: Name, width: usize) -> MessageError {
        self.err(MessageErrorKind::Missing {
            field: name.to_string(),
            columns: self.cols(self.pos, width),
            data_len: self.data.len(),
        })
    }

    #[cold]
    fn bad(&self, name: Name, pos: usize, raw: &[u8], expected: String) -> MessageError {
        self.err(MessageErrorKind::BadCharacters {
            field: name.to_string(),
            columns: self.cols(pos, raw.len()),
            raw: raw.escape_ascii().to_string(),
            expected,
        })
    }

    /// Takes `width` raw characters.
    #[inline]
    pub(crate) fn take(&mut self, name: Name, width: usize) -> Result<&'a [u8], MessageError> {
        let start = self.pos;
        match self.data.get(start..start + width) {
            Some(s) => {
                self.last = (name, start, width);
                self.pos = start + width;
                Ok(s)
            }
            None => Err(self.missing(name, width)),
        }
    }

    /// The hex value `width` digits at `offset` from the start of the data, without
    /// consuming anything (for fields whose unit depends on a later field).
    pub(crate) fn peek_hex(&self, offset: usize, width: usize) -> Option<u32> {
        self.data.get(offset..offset + width).and_then(parse_hex)
    }

    fn record(&mut self, name: Name, pos: usize, raw: &[u8], value: String, bits: Vec<BitNote>) {
        let columns = self.cols(pos, raw.len());
        if let Some(rec) = self.rec.as_deref_mut() {
            rec.push(FieldDescription {
                name: name.to_string(),
                columns,
                raw: raw.escape_ascii().to_string(),
                value,
                bits,
            });
        }
    }

    /// A `width`-digit hex field (`width` <= 8), either case.
    #[inline]
    pub(crate) fn hex(
        &mut self,
        name: Name,
        width: usize,
        show: Show,
    ) -> Result<u32, MessageError> {
        let pos = self.pos;
        let raw = self.take(name, width)?;
        let Some(v) = parse_hex(raw) else {
            return Err(self.bad(name, pos, raw, format!("{width} hex digits")));
        };
        if self.rec.is_some() {
            let (value, bits) = render(show, v, width);
            self.record(name, pos, raw, value, bits);
        }
        Ok(v)
    }

    pub(crate) fn u8(&mut self, name: Name, width: usize, show: Show) -> Result<u8, MessageError> {
        Ok(self.hex(name, width.min(2), show)? as u8)
    }

    pub(crate) fn u16(
        &mut self,
        name: Name,
        width: usize,
        show: Show,
    ) -> Result<u16, MessageError> {
        Ok(self.hex(name, width.min(4), show)? as u16)
    }

    pub(crate) fn pattern(&mut self, name: &'static str) -> Result<AxisPattern, MessageError> {
        Ok(AxisPattern(self.u8(Name::new(name), 2, Show::Pattern)?))
    }

    pub(crate) fn accel(&mut self, name: &'static str) -> Result<CentiG, MessageError> {
        Ok(CentiG(self.u16(Name::new(name), 4, Show::Accel)?))
    }

    pub(crate) fn speed(&mut self, name: &'static str) -> Result<MmPerSec, MessageError> {
        Ok(MmPerSec(self.u16(Name::new(name), 4, Show::Speed)?))
    }

    pub(crate) fn percent(&mut self, name: &'static str) -> Result<Percent, MessageError> {
        Ok(Percent(self.u16(Name::new(name), 4, Show::Pct)?))
    }

    pub(crate) fn error_code(&mut self, name: Name) -> Result<ErrorCode, MessageError> {
        Ok(ErrorCode(self.u16(name, 3, Show::Error)?))
    }

    /// An 8-digit signed (two's complement) coordinate.
    #[inline]
    pub(crate) fn coord(&mut self, name: Name, unit: AxisUnit) -> Result<Milli, MessageError> {
        if self.rec.is_none() {
            // Hot path (coordinate tables): one bounds check, one table-driven parse.
            let pos = self.pos;
            if let Some(chunk) = self
                .data
                .get(pos..pos + 8)
                .and_then(|s| <&[u8; 8]>::try_from(s).ok())
                && let Some(v) = parse_hex8(chunk)
            {
                self.last = (name, pos, 8);
                self.pos = pos + 8;
                return Ok(Milli::from_wire(v));
            }
        }
        Ok(Milli::from_wire(self.hex(name, 8, Show::Coord(unit))?))
    }

    /// 16 hex digits (a double's bits, PROTOCOL.md 3.40), most significant first; the
    /// description gives both encodings' readings.
    pub(crate) fn word64(&mut self, name: Name) -> Result<u64, MessageError> {
        let pos = self.pos;
        let raw = self.take(name, 16)?;
        let (Some(hi), Some(lo)) = (parse_hex(&raw[..8]), parse_hex(&raw[8..])) else {
            return Err(self.bad(name, pos, raw, "16 hex digits".to_string()));
        };
        let v = (u64::from(hi) << 32) | u64::from(lo);
        if self.rec.is_some() {
            let plain = f64::from_bits(v);
            let swapped = f64::from_bits(v.rotate_left(32));
            let value = format!("{plain} (most significant first) / {swapped} (word-swapped)");
            self.record(name, pos, raw, value, Vec::new());
        }
        Ok(v)
    }

    /// Raw text of `width` characters, checked with `ok` (for 200H data, 216H text and
    /// decimal fields).
    pub(crate) fn text(
        &mut self,
        name: Name,
        width: usize,
        ok: fn(u8) -> bool,
        expected: &str,
    ) -> Result<&'a [u8], MessageError> {
        let pos = self.pos;
        let raw = self.take(name, width)?;
        if !raw.iter().all(|&c| ok(c)) {
            return Err(self.bad(name, pos, raw, format!("{width} {expected}")));
        }
        if self.rec.is_some() {
            let value = format!("\"{}\"", raw.escape_ascii());
            self.record(name, pos, raw, value, Vec::new());
        }
        Ok(raw)
    }

    /// An error about the value of the field read last.
    #[cold]
    pub(crate) fn invalid(&self, expected: impl Into<String>) -> MessageError {
        let (name, pos, width) = self.last;
        let raw = self.data.get(pos..pos + width).unwrap_or(&[]);
        self.err(MessageErrorKind::Invalid {
            field: name.to_string(),
            columns: self.cols(pos, width),
            raw: raw.escape_ascii().to_string(),
            expected: expected.into(),
        })
    }

    /// Checks that every data character was used.
    pub(crate) fn finish(&self) -> Result<(), MessageError> {
        let n = self.remaining();
        if n == 0 {
            return Ok(());
        }
        let rest = self.data.get(self.pos..).unwrap_or(&[]);
        let shown = rest.get(..rest.len().min(24)).unwrap_or(&[]);
        let mut raw = shown.escape_ascii().to_string();
        if rest.len() > shown.len() {
            raw.push('…');
        }
        Err(self.err(MessageErrorKind::Trailing {
            columns: self.cols(self.pos, n),
            raw,
        }))
    }
}

/// Printable ASCII (20H-7EH).
pub(crate) fn printable(c: u8) -> bool {
    (0x20..=0x7E).contains(&c)
}

/// A decimal digit.
pub(crate) fn decimal(c: u8) -> bool {
    c.is_ascii_digit()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn reader(data: &[u8]) -> Reader<'_, 'static> {
        Reader::new(
            data,
            7,
            Some(MessageId::SCARA_MOVE_RELATIVE),
            Role::Command,
            None,
        )
    }

    #[test]
    fn bad_hex_names_field_columns_and_expectation() {
        let mut r = reader(b"0F00000000G0 1");
        r.pattern("axis pattern").unwrap();
        r.accel("acceleration").unwrap();
        r.accel("deceleration").unwrap();
        let e = r.speed("speed").unwrap_err();
        assert_eq!(
            e.to_string(),
            "2D5H command: field 'speed' at columns 17-20 is 'G0 1' — expected 4 hex digits"
        );
    }

    #[test]
    fn missing_field_says_where_the_data_stops() {
        let mut r = reader(b"0F00");
        r.pattern("axis pattern").unwrap();
        let e = r.accel("acceleration").unwrap_err();
        assert_eq!(
            e.to_string(),
            "2D5H command: field 'acceleration' at columns 9-12 is missing — the data has only 4 characters"
        );
    }

    #[test]
    fn trailing_data_is_reported() {
        let mut r = reader(b"0FXYZ");
        r.pattern("axis pattern").unwrap();
        let e = r.finish().unwrap_err();
        assert_eq!(
            e.to_string(),
            "2D5H command: unexpected extra data 'XYZ' at columns 9-11 after the last field"
        );
    }

    #[test]
    fn invalid_value_quotes_the_last_field() {
        let mut r = reader(b"1C");
        r.u8(Name::new("positioning operation type"), 2, Show::Hex)
            .unwrap();
        let e = r.invalid("bits 1-2 = 1 (selected work coordinate system)");
        assert_eq!(
            e.to_string(),
            "2D5H command: field 'positioning operation type' at columns 7-8 is '1C' — expected bits 1-2 = 1 (selected work coordinate system)"
        );
    }

    #[test]
    fn coordinates_decode_signed_in_both_cases() {
        let mut r = reader(b"FFFFEC78ffffec780000C350");
        let n = Name::new("x");
        assert_eq!(r.coord(n, AxisUnit::Mm).unwrap(), Milli(-5000));
        assert_eq!(r.coord(n, AxisUnit::Mm).unwrap(), Milli(-5000));
        assert_eq!(r.coord(n, AxisUnit::Mm).unwrap(), Milli(50_000));
        let e = r
            .coord(Name::axis("target", Axis::A2), AxisUnit::Mm)
            .unwrap_err();
        assert!(
            e.to_string()
                .contains("'axis 2 target' at columns 31-38 is missing"),
            "{e}"
        );
        let mut r = reader(b"0000C35Z");
        let e = r
            .coord(Name::axis("target", Axis::A1), AxisUnit::Mm)
            .unwrap_err();
        assert!(
            e.to_string()
                .contains("is '0000C35Z' — expected 8 hex digits"),
            "{e}"
        );
    }

    #[test]
    fn recorder_describes_bits() {
        const BITS: &[BitDef] = &[
            bit(0, "servo axis in use"),
            BitDef {
                lo: 1,
                width: 2,
                name: "home state",
                values: &[(0, "not done"), (1, "homing"), (2, "done")],
            },
            bit(3, "servo on"),
        ];
        let mut rec = Vec::new();
        let mut r = Reader::new(b"0C", 9, None, Role::Reply, Some(&mut rec));
        r.u8(Name::axis("status", Axis::A1), 2, Show::Bits(BITS))
            .unwrap();
        let f = &rec[0];
        assert_eq!(f.name, "axis 1 status");
        assert_eq!(f.columns, Columns::new(9, 10));
        assert_eq!(f.bits[1].to_string(), "bits 1-2 home state = 2 (done)");
        assert_eq!(f.bits[2].to_string(), "bit 3 servo on = 1");
    }
}
