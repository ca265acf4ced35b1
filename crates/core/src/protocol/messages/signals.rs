//! Signals (PROTOCOL.md 3.34-3.43): input and output ports (20BH, 20CH, 24AH), flags
//! (20DH, 24BH) and integer, real and string variables (20EH, 20FH, 210H, 24CH, 24DH).
//!
//! Every fact the pages leave open is one constant here, so a hardware finding is a
//! one-line change: the category heads, the bit order inside a 2-digit group, the
//! encoding of a double and the variable numbering.

use std::ops::Range;

use crate::protocol::error::{EncodeError, MessageError};
use crate::protocol::fields::{Name, Reader, Show};
use crate::protocol::ids::MessageId;
use crate::protocol::writer::Writer;

/// SC CR LF after the data of every frame.
const TAIL: usize = 4;
/// Header, station and message ID before the data of every frame.
const HEAD: usize = 6;

/// Bits of one 2-digit group: 8 consecutive ports or flags `[spec p.20-22]`.
pub const GROUP: u16 = 8;

/// Whether bit 0 (value 01h) of a group is its lowest-numbered port or flag. The pages
/// do not say `[inferred, PROTOCOL.md 3.34]`: this is the one place to change.
pub const LOWEST_IS_BIT_0: bool = true;

/// The bit of a group's byte that carries member `i` (0-7) of the group.
pub const fn group_bit(i: u16) -> u8 {
    let i = (i % GROUP) as u8;
    if LOWEST_IS_BIT_0 { 1 << i } else { 0x80 >> i }
}

/// The numbers of one category of bits and the head its reads are aligned to (a query
/// starts at "category head + a multiple of 8" `[spec p.20-22]`).
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct Category {
    /// What the category is called, for messages.
    pub name: &'static str,
    /// Its numbers; the first is the category head.
    pub numbers: Range<u16>,
}

impl Category {
    /// The category head.
    pub const fn head(&self) -> u16 {
        self.numbers.start
    }

    /// Whether `n` is a number of this category.
    pub fn holds(&self, n: u16) -> bool {
        self.numbers.contains(&n)
    }

    /// The first number of the group of 8 that holds `n` (the grid starts at the head).
    pub const fn group_start(&self, n: u16) -> u16 {
        let head = self.numbers.start;
        head + (n.saturating_sub(head)) / GROUP * GROUP
    }

    /// Whether a query may start at `n`.
    pub fn on_grid(&self, n: u16) -> bool {
        self.holds(n) && self.group_start(n) == n
    }
}

/// Input ports 000-299: X-SEL numbering is believed to start inputs at 000 and outputs at
/// 300 `[inferred, PROTOCOL.md 3.34]`.
pub const INPUTS: Category = Category {
    name: "input",
    numbers: 0..300,
};
/// Output ports 300-599 `[inferred, PROTOCOL.md 3.34]`.
pub const OUTPUTS: Category = Category {
    name: "output",
    numbers: 300..600,
};
/// Global flags 600-899 `[observed in a vendor manual, PROTOCOL.md 3.37]`.
pub const GLOBAL_FLAGS: Category = Category {
    name: "global flag",
    numbers: 600..900,
};
/// Local flags 900-999, one set per program `[observed in a vendor manual, 3.37]`.
pub const LOCAL_FLAGS: Category = Category {
    name: "local flag",
    numbers: 900..1000,
};

/// Programs whose local flags and variables a message may name (`00` is global). The
/// field is 2 hex digits; X-SEL J/K programs are numbered 1-64 `[inferred]`.
pub const PROGRAMS: Range<u8> = 1..65;

/// Which bits a query reads: the three differ in ID and the program field.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum BitSpace {
    /// 20BH input ports.
    #[default]
    Input,
    /// 20CH output ports.
    Output,
    /// 20DH flags, global (program 0) or a program's local ones.
    Flag,
}

impl BitSpace {
    /// The query's message ID.
    pub const fn id(self) -> MessageId {
        match self {
            BitSpace::Input => MessageId::INPUT_QUERY,
            BitSpace::Output => MessageId::OUTPUT_QUERY,
            BitSpace::Flag => MessageId::FLAG_QUERY,
        }
    }

    const fn has_program(self) -> bool {
        matches!(self, BitSpace::Flag)
    }

    /// The category `n` belongs to in this space (flags: by number, global or local).
    pub fn category(self, n: u16) -> Option<&'static Category> {
        match self {
            BitSpace::Input => Some(&INPUTS),
            BitSpace::Output => Some(&OUTPUTS),
            BitSpace::Flag if LOCAL_FLAGS.holds(n) => Some(&LOCAL_FLAGS),
            BitSpace::Flag => Some(&GLOBAL_FLAGS),
        }
        .filter(|c| c.holds(n))
    }

    /// Characters of a reply besides its groups: header to count, SC CR LF.
    const fn reply_fixed(self) -> usize {
        HEAD + if self.has_program() { 2 } else { 0 } + 8 + TAIL
    }

    /// The most bits one reply can carry in a reply buffer of `reply_buffer` bytes (a
    /// multiple of 8): 1015 groups for ports, 1014 for flags in 2048 bytes
    /// `[inferred arithmetic, PROTOCOL.md 3.34, 3.37]`.
    pub const fn max_count(self, reply_buffer: usize) -> u16 {
        let groups = reply_buffer.saturating_sub(self.reply_fixed()) / 2;
        let bits = groups * GROUP as usize;
        if bits > u16::MAX as usize {
            u16::MAX / GROUP * GROUP
        } else {
            bits as u16
        }
    }

    /// The length of a reply carrying `count` bits, header to LF.
    pub const fn reply_len(self, count: u16) -> usize {
        self.reply_fixed() + 2 * groups(count)
    }
}

/// Groups of 8 that `count` bits fill: ⌈count / 8⌉ `[inferred, PROTOCOL.md 3.34]`.
pub const fn groups(count: u16) -> usize {
    (count as usize).div_ceil(GROUP as usize)
}

/// 20BH / 20CH / 20DH command: `count` bits from `start` (a query start on the grid of
/// its category).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct BitQuery {
    pub space: BitSpace,
    /// Program of local flags; 0 = global (flags only, 0 elsewhere).
    pub program: u8,
    /// Query start port or flag number.
    pub start: u16,
    /// Number of query ports or flags.
    pub count: u16,
}

impl BitQuery {
    pub(crate) fn read(r: &mut Reader<'_, '_>, space: BitSpace) -> Result<Self, MessageError> {
        let program = read_program(r, space.has_program())?;
        let start = r.u16(Name::new("query start number"), 4, Show::Number)?;
        let count = r.u16(Name::new("number of query bits"), 4, Show::Number)?;
        Ok(BitQuery {
            space,
            program,
            start,
            count,
        })
    }

    pub(crate) fn write(&self, w: &mut Writer<'_>) -> Result<(), EncodeError> {
        write_program(w, self.space.has_program(), self.program)?;
        w.hex_fit(u32::from(self.start), 4);
        w.hex_fit(u32::from(self.count), 4);
        Ok(())
    }

    /// The longest legal reply, header to LF.
    pub const fn max_reply_len(&self) -> usize {
        self.space.reply_len(self.count)
    }
}

fn read_program(r: &mut Reader<'_, '_>, present: bool) -> Result<u8, MessageError> {
    if !present {
        return Ok(0);
    }
    r.u8(Name::new("program number"), 2, Show::Program)
}

fn write_program(w: &mut Writer<'_>, present: bool, program: u8) -> Result<(), EncodeError> {
    match present {
        true => w.hex("program number", u32::from(program), 2),
        false if program == 0 => Ok(()),
        false => Err(w.error("program number", "ports belong to no program: give 0")),
    }
}

/// 20BH / 20CH / 20DH reply: the states of `count` bits from `start`, 8 to a byte.
#[derive(Clone, Debug, Default, PartialEq, Eq, Hash)]
pub struct BitData {
    pub space: BitSpace,
    /// Program of local flags; 0 = global.
    pub program: u8,
    /// Response start number.
    pub start: u16,
    /// Number of response bits.
    pub count: u16,
    /// One byte per group of 8, in ascending order ([`group_bit`] gives the bit).
    pub groups: Vec<u8>,
}

impl BitData {
    /// A reply of `count` bits from `start`, `state(n)` giving each.
    pub fn from_fn(
        space: BitSpace,
        program: u8,
        start: u16,
        count: u16,
        mut state: impl FnMut(u16) -> bool,
    ) -> Self {
        let mut groups = vec![0u8; groups(count)];
        for i in 0..count {
            if state(start.saturating_add(i)) {
                groups[usize::from(i / GROUP)] |= group_bit(i);
            }
        }
        BitData {
            space,
            program,
            start,
            count,
            groups,
        }
    }

    /// The state of bit number `n`, if the reply carries it.
    pub fn get(&self, n: u16) -> Option<bool> {
        let i = n.checked_sub(self.start).filter(|&i| i < self.count)?;
        let byte = self.groups.get(usize::from(i / GROUP))?;
        Some(byte & group_bit(i) != 0)
    }

    /// Every bit carried, with its number.
    pub fn iter(&self) -> impl Iterator<Item = (u16, bool)> + '_ {
        (0..self.count).filter_map(move |i| {
            let n = self.start.checked_add(i)?;
            Some((n, self.get(n)?))
        })
    }

    pub(crate) fn read(r: &mut Reader<'_, '_>, space: BitSpace) -> Result<Self, MessageError> {
        let program = read_program(r, space.has_program())?;
        let start = r.u16(Name::new("response start number"), 4, Show::Number)?;
        let count = r.u16(Name::new("number of response bits"), 4, Show::Number)?;
        let n = groups(count);
        if 2 * n > r.remaining() {
            return Err(r.invalid(format!(
                "{count} bits need {n} 2-digit groups; {} follow",
                r.remaining() / 2
            )));
        }
        let mut bytes = Vec::with_capacity(n);
        for i in 0..n {
            let first = start.saturating_add(i as u16 * GROUP);
            bytes.push(r.u8(
                Name::record("group of 8", i + 1, None),
                2,
                Show::Group(first),
            )?);
        }
        Ok(BitData {
            space,
            program,
            start,
            count,
            groups: bytes,
        })
    }

    pub(crate) fn write(&self, w: &mut Writer<'_>) -> Result<(), EncodeError> {
        if self.groups.len() != groups(self.count) {
            return Err(w.error(
                "bit data",
                format!(
                    "{} bits need {} groups, {} given",
                    self.count,
                    groups(self.count),
                    self.groups.len()
                ),
            ));
        }
        write_program(w, self.space.has_program(), self.program)?;
        w.hex_fit(u32::from(self.start), 4);
        w.hex_fit(u32::from(self.count), 4);
        for &b in &self.groups {
            w.hex_fit(u32::from(b), 2);
        }
        Ok(())
    }
}

/// 24AH: switch one output port; 24BH: switch one flag (global, or a program's local
/// flag). The reply is the plain acknowledge.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct BitChange {
    /// [`BitSpace::Output`] (24AH) or [`BitSpace::Flag`] (24BH); inputs cannot be changed.
    pub space: BitSpace,
    /// Program of a local flag; 0 = global (flags only).
    pub program: u8,
    /// Output port or flag number.
    pub number: u16,
    /// The new state.
    pub on: bool,
}

const CHANGE_CODES: &[(u32, &str)] = &[(0, "OFF"), (1, "ON")];

impl BitChange {
    /// The message ID: 24AH for outputs, 24BH for flags.
    pub const fn id(&self) -> MessageId {
        match self.space {
            BitSpace::Flag => MessageId::FLAG_CHANGE,
            _ => MessageId::OUTPUT_CHANGE,
        }
    }

    pub(crate) fn read(r: &mut Reader<'_, '_>, space: BitSpace) -> Result<Self, MessageError> {
        let program = read_program(r, space.has_program())?;
        let number = r.u16(Name::new("number"), 4, Show::Number)?;
        let on = match r.u8(Name::new("change type"), 1, Show::Code(CHANGE_CODES))? {
            0 => false,
            1 => true,
            _ => return Err(r.invalid("0 (OFF) or 1 (ON); bits 1-3 are reserved, fixed 0")),
        };
        Ok(BitChange {
            space,
            program,
            number,
            on,
        })
    }

    pub(crate) fn write(&self, w: &mut Writer<'_>) -> Result<(), EncodeError> {
        if self.space == BitSpace::Input {
            return Err(w.error("port", "inputs cannot be changed (24AH switches outputs)"));
        }
        write_program(w, self.space.has_program(), self.program)?;
        w.hex_fit(u32::from(self.number), 4);
        w.hex_fit(u32::from(self.on), 1);
        Ok(())
    }
}

/// How a double travels in 16 hex digits: "selected in accordance with the condition"
/// (firmware version and Other parameter No. 46, which a host cannot read) `[spec p.24]`.
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize,
)]
pub enum RealEncoding {
    /// The 8 bytes most significant first: 1.5 is `3FF8000000000000`.
    #[default]
    Plain,
    /// Lower 4 bytes, then upper 4 bytes: 1.5 is `000000003FF80000` (J/K main
    /// application V0.41 or earlier, or parameter 46 bits 0-3 = 0).
    WordSwapped,
}

impl RealEncoding {
    /// The value the 16 digits `word` (as read, most significant digit first) carry.
    pub fn decode(self, word: RealWord) -> f64 {
        f64::from_bits(self.swap(word.0))
    }

    /// The 16 digits that carry `value`.
    pub fn encode(self, value: f64) -> RealWord {
        RealWord(self.swap(value.to_bits()))
    }

    const fn swap(self, bits: u64) -> u64 {
        match self {
            RealEncoding::Plain => bits,
            RealEncoding::WordSwapped => bits.rotate_left(32),
        }
    }

    /// Whether `word` reads as an ordinary number this way but as a subnormal, NaN or
    /// absurd magnitude the other way: the sign that the chosen encoding is wrong
    /// `[inferred, PROTOCOL.md 3.40]`.
    pub fn looks_wrong(self, word: RealWord) -> bool {
        let other = match self {
            RealEncoding::Plain => RealEncoding::WordSwapped,
            RealEncoding::WordSwapped => RealEncoding::Plain,
        };
        !ordinary(self.decode(word)) && ordinary(other.decode(word))
    }
}

/// Zero, or a finite normal number of a magnitude a program would use.
fn ordinary(v: f64) -> bool {
    v == 0.0 || (v.is_normal() && (1e-9..1e12).contains(&v.abs()))
}

/// A real variable's 16 hex digits as they stand on the wire (read most significant
/// digit first); [`RealEncoding`] says which double they carry.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct RealWord(pub u64);

/// Which variables: integer (20EH, 24CH), real (20FH, 24DH) or string (210H).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum VarKind {
    #[default]
    Integer,
    Real,
    /// One character per variable number `[inferred from the 2-digit data, 3.43]`.
    Text,
}

impl VarKind {
    /// The query's message ID.
    pub const fn query_id(self) -> MessageId {
        match self {
            VarKind::Integer => MessageId::INTEGER_QUERY,
            VarKind::Real => MessageId::REAL_QUERY,
            VarKind::Text => MessageId::STRING_QUERY,
        }
    }

    /// The change's message ID (strings have none: no string change was found).
    pub const fn change_id(self) -> Option<MessageId> {
        match self {
            VarKind::Integer => Some(MessageId::INTEGER_CHANGE),
            VarKind::Real => Some(MessageId::REAL_CHANGE),
            VarKind::Text => None,
        }
    }

    /// Hex digits per value: 8 (signed 32-bit), 16 (a double), 2 (a character).
    pub const fn width(self) -> usize {
        match self {
            VarKind::Integer => 8,
            VarKind::Real => 16,
            VarKind::Text => 2,
        }
    }

    /// The most values one query may ask for: what a reply buffer of `reply_buffer`
    /// bytes holds (header to count 13, SC CR LF), at most 255 (2 digits): 126 reals in
    /// 2048 bytes `[inferred arithmetic, PROTOCOL.md 3.40]`.
    pub const fn max_count(self, reply_buffer: usize) -> u8 {
        let n = reply_buffer.saturating_sub(13 + TAIL) / self.width();
        if n > 255 { 255 } else { n as u8 }
    }

    /// The most values one change may carry in a command buffer of `command_buffer`
    /// bytes: 254 integers or 127 reals in 2051 `[inferred arithmetic, 3.41, 3.42]`.
    pub const fn max_write(self, command_buffer: usize) -> u8 {
        self.max_count(command_buffer)
    }

    /// The numbers of global (`global`) or local variables of this kind, X-SEL J/K
    /// numbering: integers global 200-299 and local 1-99, reals global 300-399 and local
    /// 100-199 `[inferred from vendor manuals; not on the spec pages]`; string columns
    /// 1-999 either way (PROTOCOL.md names none, and its 210H example reads global
    /// columns 1-5) `[inferred]`.
    pub const fn numbers(self, global: bool) -> Range<u16> {
        match (self, global) {
            (VarKind::Integer, true) => 200..300,
            (VarKind::Integer, false) => 1..100,
            (VarKind::Real, true) => 300..400,
            (VarKind::Real, false) => 100..200,
            (VarKind::Text, _) => 1..1000,
        }
    }

    /// Words for messages: "integer variable".
    pub const fn name(self) -> &'static str {
        match self {
            VarKind::Integer => "integer variable",
            VarKind::Real => "real variable",
            VarKind::Text => "string variable",
        }
    }
}

/// The values of consecutive variables of one kind.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub enum VarValues {
    Integer(Vec<i32>),
    Real(Vec<RealWord>),
    /// One byte (character) per variable number.
    Text(Vec<u8>),
}

impl Default for VarValues {
    fn default() -> Self {
        VarValues::Integer(Vec::new())
    }
}

impl VarValues {
    pub const fn kind(&self) -> VarKind {
        match self {
            VarValues::Integer(_) => VarKind::Integer,
            VarValues::Real(_) => VarKind::Real,
            VarValues::Text(_) => VarKind::Text,
        }
    }

    pub fn len(&self) -> usize {
        match self {
            VarValues::Integer(v) => v.len(),
            VarValues::Real(v) => v.len(),
            VarValues::Text(v) => v.len(),
        }
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    fn read(r: &mut Reader<'_, '_>, kind: VarKind, count: usize) -> Result<Self, MessageError> {
        let width = kind.width();
        if count * width > r.remaining() {
            return Err(r.invalid(format!(
                "{count} values need {} characters; {} follow",
                count * width,
                r.remaining()
            )));
        }
        let name = |i| Name::record(kind.name(), i + 1, None);
        Ok(match kind {
            VarKind::Integer => VarValues::Integer(
                (0..count)
                    .map(|i| Ok(r.hex(name(i), 8, Show::Signed)? as i32))
                    .collect::<Result<_, MessageError>>()?,
            ),
            VarKind::Real => VarValues::Real(
                (0..count)
                    .map(|i| Ok(RealWord(r.word64(name(i))?)))
                    .collect::<Result<_, MessageError>>()?,
            ),
            VarKind::Text => VarValues::Text(
                (0..count)
                    .map(|i| r.u8(name(i), 2, Show::Char))
                    .collect::<Result<_, MessageError>>()?,
            ),
        })
    }

    fn write(&self, w: &mut Writer<'_>) {
        match self {
            VarValues::Integer(v) => v.iter().for_each(|&x| w.hex_fit(x as u32, 8)),
            VarValues::Real(v) => v.iter().for_each(|x| {
                w.hex_fit((x.0 >> 32) as u32, 8);
                w.hex_fit(x.0 as u32, 8);
            }),
            VarValues::Text(v) => v.iter().for_each(|&c| w.hex_fit(u32::from(c), 2)),
        }
    }
}

/// Program, start number and count: the head every variable message shares.
fn read_var_head(
    r: &mut Reader<'_, '_>,
    what: &'static str,
) -> Result<(u8, u16, u8), MessageError> {
    let program = read_program(r, true)?;
    let start = r.u16(Name::new("start variable number"), 3, Show::Number)?;
    let count = r.u8(Name::new(what), 2, Show::Number)?;
    Ok((program, start, count))
}

fn write_var_head(
    w: &mut Writer<'_>,
    program: u8,
    start: u16,
    count: usize,
) -> Result<(), EncodeError> {
    write_program(w, true, program)?;
    w.hex("start variable number", u32::from(start), 3)?;
    let count = u32::try_from(count).unwrap_or(u32::MAX);
    w.hex("number of variables", count, 2)
}

/// 20EH / 20FH / 210H command: `count` variables of `kind` from `start`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct VarQuery {
    pub kind: VarKind,
    /// 0 = global; otherwise the program whose local variables are read.
    pub program: u8,
    /// Query start variable number (3 digits).
    pub start: u16,
    /// Number of variables (string: characters).
    pub count: u8,
}

impl VarQuery {
    pub(crate) fn read(r: &mut Reader<'_, '_>, kind: VarKind) -> Result<Self, MessageError> {
        let (program, start, count) = read_var_head(r, "number of query variables")?;
        Ok(VarQuery {
            kind,
            program,
            start,
            count,
        })
    }

    pub(crate) fn write(&self, w: &mut Writer<'_>) -> Result<(), EncodeError> {
        write_var_head(w, self.program, self.start, usize::from(self.count))
    }

    /// The longest legal reply, header to LF.
    pub const fn max_reply_len(&self) -> usize {
        HEAD + 7 + self.count as usize * self.kind.width() + TAIL
    }
}

/// 20EH / 20FH / 210H reply, and 24CH / 24DH command: consecutive values from `start`.
#[derive(Clone, Debug, Default, PartialEq, Eq, Hash)]
pub struct VarData {
    /// 0 = global; otherwise the program of local variables.
    pub program: u8,
    /// First variable number.
    pub start: u16,
    /// The values, `values.len()` of them (at most 255).
    pub values: VarValues,
}

impl VarData {
    pub const fn kind(&self) -> VarKind {
        self.values.kind()
    }

    /// The query's (or change's) numbers.
    pub fn numbers(&self) -> Range<u16> {
        self.start..self.start.saturating_add(self.values.len() as u16)
    }

    pub(crate) fn read(r: &mut Reader<'_, '_>, kind: VarKind) -> Result<Self, MessageError> {
        let (program, start, count) = read_var_head(r, "number of variables")?;
        let values = VarValues::read(r, kind, usize::from(count))?;
        Ok(VarData {
            program,
            start,
            values,
        })
    }

    pub(crate) fn write(&self, w: &mut Writer<'_>) -> Result<(), EncodeError> {
        write_var_head(w, self.program, self.start, self.values.len())?;
        self.values.write(w);
        Ok(())
    }

    /// The frame length of this data as a 24CH / 24DH command, header to LF.
    pub fn command_len(&self) -> usize {
        HEAD + 7 + self.values.len() * self.kind().width() + TAIL
    }
}

/// 24CH / 24DH reply: how many variables were changed from `start`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct VarsWritten {
    pub kind: VarKind,
    pub program: u8,
    pub start: u16,
    pub count: u8,
}

impl VarsWritten {
    /// Its frame length, header to LF (17).
    pub const FRAME_LEN: usize = HEAD + 7 + TAIL;

    pub(crate) fn read(r: &mut Reader<'_, '_>, kind: VarKind) -> Result<Self, MessageError> {
        let (program, start, count) = read_var_head(r, "number of changed variables")?;
        Ok(VarsWritten {
            kind,
            program,
            start,
            count,
        })
    }

    pub(crate) fn write(&self, w: &mut Writer<'_>) -> Result<(), EncodeError> {
        write_var_head(w, self.program, self.start, usize::from(self.count))
    }
}

#[cfg(test)]
#[path = "signals_tests.rs"]
mod tests;
