//! The simulated controller's signals: input and output ports, global and local flags,
//! integer, real and string variables, and output changes held by an I/O interlock.
//!
//! Pure data and checks, no protocol IO: the handlers (`handlers/signals.rs`) turn the
//! messages of PROTOCOL.md 3.34-3.43 into these calls. Every number comes from the
//! protocol's constants ([`INPUTS`], [`OUTPUTS`], [`GLOBAL_FLAGS`], [`LOCAL_FLAGS`],
//! [`PROGRAMS`], [`VarKind::numbers`]), so a hardware finding there is a one-line change
//! here too. Bits are kept one `bool` per number; on the wire they are packed 8 to a
//! group by [`BitData::from_fn`], whose bit order is the protocol's
//! ([`crate::protocol::messages::signals::group_bit`]: the lowest number of a group is
//! bit 0 `[inferred, PROTOCOL.md 3.34]`).
//!
//! Memory is fixed: every table is an array sized from those constants, and the held
//! output changes keep at most one entry per output port, so nothing grows with input.

use std::ops::Range;

use super::errors::SimError;
use crate::protocol::messages::signals::PROGRAMS;
use crate::protocol::{
    BitChange, BitData, BitQuery, BitSpace, Category, GLOBAL_FLAGS, INPUTS, LOCAL_FLAGS, OUTPUTS,
    RealEncoding, VarData, VarKind, VarQuery, VarValues, VarsWritten,
};

const fn span(r: &Range<u16>) -> usize {
    (r.end - r.start) as usize
}

const N_INPUTS: usize = span(&INPUTS.numbers);
const N_OUTPUTS: usize = span(&OUTPUTS.numbers);
const N_GLOBAL_FLAGS: usize = span(&GLOBAL_FLAGS.numbers);
const N_LOCAL_FLAGS: usize = span(&LOCAL_FLAGS.numbers);
/// Programs 1-64 with local flags and variables.
const N_PROGRAMS: usize = (PROGRAMS.end - PROGRAMS.start) as usize;
const N_INT_GLOBAL: usize = span(&VarKind::Integer.numbers(true));
const N_INT_LOCAL: usize = span(&VarKind::Integer.numbers(false));
const N_REAL_GLOBAL: usize = span(&VarKind::Real.numbers(true));
const N_REAL_LOCAL: usize = span(&VarKind::Real.numbers(false));
const N_TEXT_GLOBAL: usize = span(&VarKind::Text.numbers(true));
const N_TEXT_LOCAL: usize = span(&VarKind::Text.numbers(false));

/// One kind of variable: the global ones and each program's local ones.
#[derive(Clone)]
struct Vars<T: Copy, const G: usize, const L: usize> {
    global: [T; G],
    local: [[T; L]; N_PROGRAMS],
}

impl<T: Copy, const G: usize, const L: usize> Vars<T, G, L> {
    fn new(zero: T) -> Self {
        Vars {
            global: [zero; G],
            local: [[zero; L]; N_PROGRAMS],
        }
    }

    /// The values of `program` (0 = global) and the number of the first one.
    fn table(&self, kind: VarKind, program: u8) -> Option<(&[T], u16)> {
        let head = kind.numbers(program == 0).start;
        match program {
            0 => Some((&self.global[..], head)),
            p => Some((&self.local[program_index(p)?][..], head)),
        }
    }

    fn table_mut(&mut self, kind: VarKind, program: u8) -> Option<(&mut [T], u16)> {
        let head = kind.numbers(program == 0).start;
        match program {
            0 => Some((&mut self.global[..], head)),
            p => Some((&mut self.local[program_index(p)?][..], head)),
        }
    }

    /// The values `range` of `program`, if every number exists.
    fn slice(&self, kind: VarKind, program: u8, range: Range<u32>) -> Option<&[T]> {
        let (table, head) = self.table(kind, program)?;
        let from = usize::try_from(range.start.checked_sub(u32::from(head))?).ok()?;
        let to = usize::try_from(range.end.checked_sub(u32::from(head))?).ok()?;
        table.get(from..to)
    }

    fn slice_mut(&mut self, kind: VarKind, program: u8, range: Range<u32>) -> Option<&mut [T]> {
        let (table, head) = self.table_mut(kind, program)?;
        let from = usize::try_from(range.start.checked_sub(u32::from(head))?).ok()?;
        let to = usize::try_from(range.end.checked_sub(u32::from(head))?).ok()?;
        table.get_mut(from..to)
    }
}

/// Index of program `p` (1-64) in the local tables.
fn program_index(p: u8) -> Option<usize> {
    PROGRAMS
        .contains(&p)
        .then(|| usize::from(p - PROGRAMS.start))
}

/// A program field: 0 (global) or a program 1-64.
fn check_program(program: u8) -> Result<(), SimError> {
    if program == 0 || PROGRAMS.contains(&program) {
        Ok(())
    } else {
        Err(SimError::BadValue)
    }
}

/// The flag category a program field names: 00 the global flags, a program 1-64 its
/// local flags; anything else none.
fn flag_category(program: u8) -> Option<&'static Category> {
    match program {
        0 => Some(&GLOBAL_FLAGS),
        p if PROGRAMS.contains(&p) => Some(&LOCAL_FLAGS),
        _ => None,
    }
}

/// The simulator's signals.
#[derive(Clone)]
pub struct Signals {
    inputs: [bool; N_INPUTS],
    outputs: [bool; N_OUTPUTS],
    global_flags: [bool; N_GLOBAL_FLAGS],
    local_flags: [[bool; N_LOCAL_FLAGS]; N_PROGRAMS],
    ints: Vars<i32, N_INT_GLOBAL, N_INT_LOCAL>,
    reals: Vars<f64, N_REAL_GLOBAL, N_REAL_LOCAL>,
    text: Vars<u8, N_TEXT_GLOBAL, N_TEXT_LOCAL>,
    /// The I/O interlock: output changes are held while it is on.
    interlock: bool,
    /// Output changes accepted under the interlock, oldest first; at most one per output
    /// (a newer change of the same output replaces the older one and goes last).
    held: Vec<(u16, bool)>,
}

impl Default for Signals {
    fn default() -> Self {
        Self::new()
    }
}

impl std::fmt::Debug for Signals {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Signals")
            .field("interlock", &self.interlock)
            .field("held", &self.held)
            .finish_non_exhaustive()
    }
}

impl Signals {
    /// Everything off and zero, the interlock off.
    pub fn new() -> Self {
        Signals {
            inputs: [false; N_INPUTS],
            outputs: [false; N_OUTPUTS],
            global_flags: [false; N_GLOBAL_FLAGS],
            local_flags: [[false; N_LOCAL_FLAGS]; N_PROGRAMS],
            ints: Vars::new(0),
            reals: Vars::new(0.0),
            text: Vars::new(0),
            interlock: false,
            held: Vec::with_capacity(N_OUTPUTS),
        }
    }

    /// The bits of one category: the category, its states (indexed from its head).
    fn bits(&self, space: BitSpace, program: u8) -> Option<(&'static Category, &[bool])> {
        match space {
            BitSpace::Input => Some((&INPUTS, &self.inputs[..])),
            BitSpace::Output => Some((&OUTPUTS, &self.outputs[..])),
            BitSpace::Flag => match program {
                0 => Some((&GLOBAL_FLAGS, &self.global_flags[..])),
                p => Some((&LOCAL_FLAGS, &self.local_flags[program_index(p)?][..])),
            },
        }
    }

    fn bits_mut(&mut self, space: BitSpace, program: u8) -> Option<&mut [bool]> {
        match space {
            BitSpace::Input => Some(&mut self.inputs[..]),
            BitSpace::Output => Some(&mut self.outputs[..]),
            BitSpace::Flag => match program {
                0 => Some(&mut self.global_flags[..]),
                p => Some(&mut self.local_flags[program_index(p)?][..]),
            },
        }
    }

    /// The state of port or flag `n` (`program` 0 = global flags; ignored for ports).
    pub fn bit(&self, space: BitSpace, program: u8, n: u16) -> Option<bool> {
        let program = if space == BitSpace::Flag { program } else { 0 };
        let (cat, states) = self.bits(space, program)?;
        if space == BitSpace::Flag && flag_category(program) != Some(cat) {
            return None;
        }
        states.get(usize::from(n.checked_sub(cat.head())?)).copied()
    }

    fn set_bit(&mut self, space: BitSpace, program: u8, n: u16, on: bool) -> Result<(), SimError> {
        let cat = match space {
            BitSpace::Input => &INPUTS,
            BitSpace::Output => &OUTPUTS,
            BitSpace::Flag => flag_category(program).ok_or(SimError::BadValue)?,
        };
        if !cat.holds(n) {
            return Err(SimError::BadValue);
        }
        let states = self.bits_mut(space, program).ok_or(SimError::BadValue)?;
        states[usize::from(n - cat.head())] = on;
        Ok(())
    }

    /// 20BH / 20CH / 20DH: the states asked for. Refused (A03) unless the start is on its
    /// category's grid, the whole range lies in that one category (20DH: program 00 the
    /// global flags, a program 1-64 its local flags), and the count is 1 to `max`.
    /// PROTOCOL.md does not say whether a controller cuts a longer read to the buffer or
    /// refuses it; the simulator refuses `[the simulator's choice]`. A count that is not a
    /// multiple of 8 fills ⌈count / 8⌉ groups, the unused bits 0.
    pub fn read_bits(&self, q: &BitQuery, max: u16) -> Result<BitData, SimError> {
        let program = if q.space == BitSpace::Flag {
            q.program
        } else {
            0
        };
        let (cat, states) = self.bits(q.space, program).ok_or(SimError::BadValue)?;
        if q.count == 0 {
            return Err(SimError::BadValue);
        }
        let last = u32::from(q.start) + u32::from(q.count) - 1;
        let fits = q.count <= max
            && cat.on_grid(q.start)
            && u16::try_from(last).is_ok_and(|last| cat.holds(last));
        if !fits {
            return Err(SimError::BadValue);
        }
        let head = cat.head();
        Ok(BitData::from_fn(q.space, program, q.start, q.count, |n| {
            states[usize::from(n - head)]
        }))
    }

    /// 24AH / 24BH: an output port (A03 for any other number), held while the I/O
    /// interlock is on; a global flag with program 00 or a local flag with a program 1-64
    /// (A03 for anything else). Flags are never held.
    pub fn change_bit(&mut self, c: &BitChange) -> Result<(), SimError> {
        match c.space {
            BitSpace::Input => Err(SimError::BadValue),
            BitSpace::Output if !OUTPUTS.holds(c.number) => Err(SimError::BadValue),
            BitSpace::Output if self.interlock => {
                self.held.retain(|&(n, _)| n != c.number);
                self.held.push((c.number, c.on));
                Ok(())
            }
            space => self.set_bit(space, c.program, c.number, c.on),
        }
    }

    /// A program's BTON / BTOF or output column: output port `n` (never held by the I/O
    /// interlock: the program is the controller), a global flag, or a local flag of
    /// `program` (900-999).
    pub(crate) fn set_by_program(&mut self, n: u16, program: u8, on: bool) -> Result<(), SimError> {
        if OUTPUTS.holds(n) {
            self.set_bit(BitSpace::Output, 0, n, on)
        } else if GLOBAL_FLAGS.holds(n) {
            self.set_bit(BitSpace::Flag, 0, n, on)
        } else {
            self.set_bit(BitSpace::Flag, program, n, on)
        }
    }

    /// Sets input port `n` (the operator's sensor); the refusal as text.
    pub fn set_input(&mut self, n: u16, on: bool) -> Result<(), String> {
        self.set_bit(BitSpace::Input, 0, n, on)
            .map_err(|_| not_in(&INPUTS, n))
    }

    /// Sets a flag: global with program 0, else that program's local flag.
    pub fn set_flag(&mut self, n: u16, program: u8, on: bool) -> Result<(), String> {
        self.set_bit(BitSpace::Flag, program, n, on)
            .map_err(|_| flag_refusal(n, program))
    }

    /// A flag's state, or why there is none.
    pub fn flag(&self, n: u16, program: u8) -> Result<bool, String> {
        self.bit(BitSpace::Flag, program, n)
            .ok_or_else(|| flag_refusal(n, program))
    }

    /// Whether the I/O interlock is on (215H status byte 2 bit 3).
    pub fn interlock(&self) -> bool {
        self.interlock
    }

    /// Switches the I/O interlock; switching it off applies the held output changes in
    /// the order they came. The number of changes applied.
    pub fn set_interlock(&mut self, on: bool) -> usize {
        self.interlock = on;
        if on {
            return 0;
        }
        let held = std::mem::take(&mut self.held);
        for &(n, state) in &held {
            self.outputs[usize::from(n - OUTPUTS.head())] = state;
        }
        let applied = held.len();
        // Keep the allocation: the list never needs more than one entry per output.
        self.held = held;
        self.held.clear();
        applied
    }

    /// Output changes held by the interlock, oldest first: (port, new state).
    pub fn held(&self) -> &[(u16, bool)] {
        &self.held
    }

    /// 238H with its appended byte bit 0: drops the held output changes; how many.
    pub fn cancel_held(&mut self) -> usize {
        let n = self.held.len();
        self.held.clear();
        n
    }

    /// Ports of `space` (inputs or outputs) that are on, ascending.
    pub fn ports_on(&self, space: BitSpace) -> impl Iterator<Item = u16> + '_ {
        let (cat, states) = match space {
            BitSpace::Output => (&OUTPUTS, &self.outputs[..]),
            _ => (&INPUTS, &self.inputs[..]),
        };
        states
            .iter()
            .zip(cat.numbers.clone())
            .filter(|(on, _)| **on)
            .map(|(_, n)| n)
    }

    /// Flags that are on: global (program 0) or the local flags of `program`.
    pub fn flags_on(&self, program: u8) -> impl Iterator<Item = u16> + '_ {
        let cat = flag_category(program);
        let states = self
            .bits(BitSpace::Flag, program)
            .map_or(&[][..], |(_, s)| s);
        states
            .iter()
            .zip(cat.map_or(0..0, |c| c.numbers.clone()))
            .filter(|(on, _)| **on)
            .map(|(_, n)| n)
    }

    /// The numbers `start..start + count` of `kind` for `program`, checked: program 00 or
    /// 1-64, count 1 to `max`, every number one of [`VarKind::numbers`] `[inferred
    /// numbering, PROTOCOL.md 3.39-3.43]`; A03 otherwise.
    fn var_range(
        kind: VarKind,
        program: u8,
        start: u16,
        count: usize,
        max: u8,
    ) -> Result<Range<u32>, SimError> {
        check_program(program)?;
        let numbers = kind.numbers(program == 0);
        let end = u32::from(start) + count as u32;
        let fits = count >= 1
            && count <= usize::from(max)
            && u32::from(numbers.start) <= u32::from(start)
            && end <= u32::from(numbers.end);
        if fits {
            Ok(u32::from(start)..end)
        } else {
            Err(SimError::BadValue)
        }
    }

    /// 20EH / 20FH / 210H: the values asked for (reals sent in `encoding`); A03 unless
    /// [`Signals::var_range`] holds with `max` the most values a reply carries.
    pub fn read_vars(
        &self,
        q: &VarQuery,
        encoding: RealEncoding,
        max: u8,
    ) -> Result<VarData, SimError> {
        let range = Self::var_range(q.kind, q.program, q.start, usize::from(q.count), max)?;
        let bad = || SimError::BadValue;
        let (kind, program) = (q.kind, q.program);
        let values = match kind {
            VarKind::Integer => VarValues::Integer(
                self.ints
                    .slice(kind, program, range)
                    .ok_or_else(bad)?
                    .to_vec(),
            ),
            VarKind::Real => VarValues::Real(
                self.reals
                    .slice(kind, program, range)
                    .ok_or_else(bad)?
                    .iter()
                    .map(|&v| encoding.encode(v))
                    .collect(),
            ),
            VarKind::Text => VarValues::Text(
                self.text
                    .slice(kind, program, range)
                    .ok_or_else(bad)?
                    .to_vec(),
            ),
        };
        Ok(VarData {
            program,
            start: q.start,
            values,
        })
    }

    /// 24CH / 24DH: stores the values (reals decoded with `encoding`), the whole write
    /// checked first (a refused write changes nothing); `max` is the most values a
    /// command carries. The reply echoes program, start and count.
    pub fn write_vars(
        &mut self,
        d: &VarData,
        encoding: RealEncoding,
        max: u8,
    ) -> Result<VarsWritten, SimError> {
        let kind = d.kind();
        let range = Self::var_range(kind, d.program, d.start, d.values.len(), max)?;
        let bad = || SimError::BadValue;
        match &d.values {
            VarValues::Integer(v) => self
                .ints
                .slice_mut(kind, d.program, range)
                .ok_or_else(bad)?
                .copy_from_slice(v),
            VarValues::Real(v) => {
                let to = self
                    .reals
                    .slice_mut(kind, d.program, range)
                    .ok_or_else(bad)?;
                for (slot, word) in to.iter_mut().zip(v) {
                    *slot = encoding.decode(*word);
                }
            }
            // No string change message exists (PROTOCOL.md 3.43).
            VarValues::Text(_) => return Err(SimError::UnknownMessage),
        }
        Ok(VarsWritten {
            kind,
            program: d.program,
            start: d.start,
            count: d.values.len() as u8,
        })
    }

    /// An integer variable (program 0 = global), or why there is none.
    pub fn int(&self, n: u16, program: u8) -> Result<i32, String> {
        let r = u32::from(n)..u32::from(n) + 1;
        self.ints
            .slice(VarKind::Integer, program, r)
            .map(|v| v[0])
            .ok_or_else(|| var_refusal(VarKind::Integer, n, program))
    }

    /// Sets an integer variable.
    pub fn set_int(&mut self, n: u16, program: u8, value: i32) -> Result<(), String> {
        let r = u32::from(n)..u32::from(n) + 1;
        self.ints
            .slice_mut(VarKind::Integer, program, r)
            .map(|v| v[0] = value)
            .ok_or_else(|| var_refusal(VarKind::Integer, n, program))
    }

    /// A real variable.
    pub fn real(&self, n: u16, program: u8) -> Result<f64, String> {
        let r = u32::from(n)..u32::from(n) + 1;
        self.reals
            .slice(VarKind::Real, program, r)
            .map(|v| v[0])
            .ok_or_else(|| var_refusal(VarKind::Real, n, program))
    }

    /// Sets a real variable.
    pub fn set_real(&mut self, n: u16, program: u8, value: f64) -> Result<(), String> {
        let r = u32::from(n)..u32::from(n) + 1;
        self.reals
            .slice_mut(VarKind::Real, program, r)
            .map(|v| v[0] = value)
            .ok_or_else(|| var_refusal(VarKind::Real, n, program))
    }

    /// The string from column `n`: its characters up to the first NUL or the last column.
    pub fn text(&self, n: u16, program: u8) -> Result<Vec<u8>, String> {
        let end = u32::from(VarKind::Text.numbers(program == 0).end);
        let chars = self
            .text
            .slice(VarKind::Text, program, u32::from(n)..end)
            .filter(|c| !c.is_empty())
            .ok_or_else(|| var_refusal(VarKind::Text, n, program))?;
        Ok(chars.iter().copied().take_while(|&c| c != 0).collect())
    }

    /// Writes `text` into the columns from `n` and a NUL after it when a column is left;
    /// refused whole when it does not fit.
    pub fn set_text(&mut self, n: u16, program: u8, text: &[u8]) -> Result<(), String> {
        let numbers = VarKind::Text.numbers(program == 0);
        let end = (u32::from(n) + text.len() as u32 + 1).min(u32::from(numbers.end));
        let to = self
            .text
            .slice_mut(VarKind::Text, program, u32::from(n)..end)
            .filter(|to| to.len() >= text.len() && !to.is_empty())
            .ok_or_else(|| {
                format!(
                    "{} characters from column {n} do not fit: {}",
                    text.len(),
                    var_numbers(VarKind::Text, program)
                )
            })?;
        to[..text.len()].copy_from_slice(text);
        if let Some(nul) = to.get_mut(text.len()) {
            *nul = 0;
        }
        Ok(())
    }
}

/// "input 300 does not exist (inputs are 0-299)".
fn not_in(cat: &Category, n: u16) -> String {
    format!(
        "{} {n} does not exist ({}s are {}-{})",
        cat.name,
        cat.name,
        cat.numbers.start,
        cat.numbers.end - 1
    )
}

fn flag_refusal(n: u16, program: u8) -> String {
    match flag_category(program) {
        None => format!(
            "program {program} does not exist (0 = global, {}-{})",
            PROGRAMS.start,
            PROGRAMS.end - 1
        ),
        Some(cat) if program == 0 && LOCAL_FLAGS.holds(n) => {
            format!(
                "{} {n} needs a program ({}s belong to one)",
                LOCAL_FLAGS.name, cat.name
            )
        }
        Some(cat) => not_in(cat, n),
    }
}

/// "integer variables of program 3 are 1-99".
fn var_numbers(kind: VarKind, program: u8) -> String {
    let r = kind.numbers(program == 0);
    let whose = match program {
        0 => "global".to_owned(),
        p => format!("of program {p}"),
    };
    format!("{}s {whose} are {}-{}", kind.name(), r.start, r.end - 1)
}

fn var_refusal(kind: VarKind, n: u16, program: u8) -> String {
    if check_program(program).is_err() {
        return format!(
            "program {program} does not exist (0 = global, {}-{})",
            PROGRAMS.start,
            PROGRAMS.end - 1
        );
    }
    format!(
        "{} {n} does not exist: {}",
        kind.name(),
        var_numbers(kind, program)
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::protocol::{REPLY_BUFFER, RealWord};

    const MAX_BITS: u16 = BitSpace::Input.max_count(REPLY_BUFFER);

    fn q(space: BitSpace, program: u8, start: u16, count: u16) -> BitQuery {
        BitQuery {
            space,
            program,
            start,
            count,
        }
    }

    fn change(space: BitSpace, program: u8, number: u16, on: bool) -> BitChange {
        BitChange {
            space,
            program,
            number,
            on,
        }
    }

    #[test]
    fn bit_reads_pack_in_the_protocols_order_and_refuse_what_does_not_fit() {
        let mut s = Signals::new();
        for n in [0, 2, 15] {
            s.set_input(n, true).unwrap();
        }
        let r = s
            .read_bits(&q(BitSpace::Input, 0, 0, 16), MAX_BITS)
            .unwrap();
        assert_eq!(r.groups, [0x05, 0x80], "PROTOCOL.md 3.34's example");
        // 10 bits: two groups, the unused bits 0.
        s.set_input(10, true).unwrap();
        s.set_input(11, true).unwrap();
        let r = s.read_bits(&q(BitSpace::Input, 0, 8, 3), MAX_BITS).unwrap();
        assert_eq!(r.groups, [0x04]);
        let r = s
            .read_bits(&q(BitSpace::Input, 0, 0, 11), MAX_BITS)
            .unwrap();
        assert_eq!(r.groups, [0x05, 0x04]);
        let refused = |q: BitQuery| s.read_bits(&q, MAX_BITS).unwrap_err();
        let head = OUTPUTS.head();
        for bad in [
            q(BitSpace::Input, 0, 4, 8),                            // off the grid
            q(BitSpace::Input, 0, head - 8, 16),                    // inputs into outputs
            q(BitSpace::Output, 0, head - 8, 8),                    // an input with 20CH
            q(BitSpace::Input, 0, 0, 0),                            // nothing
            q(BitSpace::Flag, 0, LOCAL_FLAGS.head(), 8),            // a local flag, program 00
            q(BitSpace::Flag, 1, GLOBAL_FLAGS.head(), 8),           // a global flag, program 1
            q(BitSpace::Flag, PROGRAMS.end, LOCAL_FLAGS.head(), 8), // no such program
            q(BitSpace::Flag, 0, LOCAL_FLAGS.head() - 8, 16),       // global into local
        ] {
            assert_eq!(refused(bad), SimError::BadValue, "{bad:?}");
        }
        // The count limit, on a small buffer where it binds inside one category.
        let small = BitSpace::Input.max_count(64);
        assert!(s.read_bits(&q(BitSpace::Input, 0, 0, small), small).is_ok());
        assert_eq!(
            s.read_bits(&q(BitSpace::Input, 0, 0, small + 8), small),
            Err(SimError::BadValue)
        );
    }

    #[test]
    fn flags_are_global_with_program_00_and_local_per_program() {
        let mut s = Signals::new();
        let (g, l) = (GLOBAL_FLAGS.head(), LOCAL_FLAGS.head());
        s.change_bit(&change(BitSpace::Flag, 0, g, true)).unwrap();
        s.change_bit(&change(BitSpace::Flag, 3, l + 1, true))
            .unwrap();
        assert_eq!(s.flag(g, 0), Ok(true));
        assert_eq!(s.flag(l + 1, 3), Ok(true));
        assert_eq!(s.flag(l + 1, 4), Ok(false), "each program its own");
        let r = s.read_bits(&q(BitSpace::Flag, 3, l, 8), MAX_BITS).unwrap();
        assert_eq!((r.program, r.groups.as_slice()), (3, &[0x02][..]));
        for bad in [
            change(BitSpace::Flag, 0, l, true),
            change(BitSpace::Flag, 1, g, true),
            change(BitSpace::Flag, PROGRAMS.end, l, true),
            change(BitSpace::Flag, 0, GLOBAL_FLAGS.numbers.start - 1, true),
            change(BitSpace::Output, 0, OUTPUTS.head() - 1, true),
            change(BitSpace::Output, 0, OUTPUTS.numbers.end, true),
            change(BitSpace::Input, 0, 0, true),
        ] {
            assert_eq!(s.change_bit(&bad), Err(SimError::BadValue), "{bad:?}");
        }
        assert!(s.flag(l, 0).unwrap_err().contains("needs a program"));
        assert_eq!(s.flags_on(0).collect::<Vec<_>>(), [g]);
        assert_eq!(s.flags_on(3).collect::<Vec<_>>(), [l + 1]);
    }

    #[test]
    fn the_interlock_holds_output_changes_until_released_or_cancelled() {
        let mut s = Signals::new();
        let o = OUTPUTS.head();
        s.set_interlock(true);
        s.change_bit(&change(BitSpace::Output, 0, o, true)).unwrap();
        s.change_bit(&change(BitSpace::Output, 0, o + 1, true))
            .unwrap();
        s.change_bit(&change(BitSpace::Output, 0, o, false))
            .unwrap();
        s.change_bit(&change(BitSpace::Output, 0, o, true)).unwrap();
        // Flags are not held.
        s.change_bit(&change(BitSpace::Flag, 0, GLOBAL_FLAGS.head(), true))
            .unwrap();
        assert_eq!(s.flag(GLOBAL_FLAGS.head(), 0), Ok(true));
        assert_eq!(s.ports_on(BitSpace::Output).count(), 0, "held, not applied");
        assert_eq!(s.held(), [(o + 1, true), (o, true)], "one entry per output");
        assert_eq!(s.set_interlock(false), 2);
        assert_eq!(s.ports_on(BitSpace::Output).collect::<Vec<_>>(), [o, o + 1]);
        assert!(s.held().is_empty());
        s.set_interlock(true);
        s.change_bit(&change(BitSpace::Output, 0, o, false))
            .unwrap();
        assert_eq!(s.cancel_held(), 1);
        assert_eq!(s.set_interlock(false), 0);
        assert_eq!(
            s.bit(BitSpace::Output, 0, o),
            Some(true),
            "the change was dropped"
        );
        // Bounded: a flood of changes keeps one entry per output.
        s.set_interlock(true);
        for k in 0..10_000u32 {
            let n = OUTPUTS.head() + (k % span(&OUTPUTS.numbers) as u32) as u16;
            s.change_bit(&change(BitSpace::Output, 0, n, k % 2 == 0))
                .unwrap();
        }
        assert_eq!(s.held().len(), span(&OUTPUTS.numbers));
    }

    #[test]
    fn variables_read_and_write_whole_or_not_at_all() {
        let mut s = Signals::new();
        let max = VarKind::Integer.max_write(2051);
        let ints = VarData {
            program: 0,
            start: 200,
            values: VarValues::Integer(vec![123, -1]),
        };
        let w = s.write_vars(&ints, RealEncoding::Plain, max).unwrap();
        assert_eq!(
            (w.kind, w.program, w.start, w.count),
            (VarKind::Integer, 0, 200, 2)
        );
        let q = |kind, program, start, count| VarQuery {
            kind,
            program,
            start,
            count,
        };
        let r = s
            .read_vars(&q(VarKind::Integer, 0, 200, 2), RealEncoding::Plain, max)
            .unwrap();
        assert_eq!(r.values, VarValues::Integer(vec![123, -1]));
        // Local variables per program.
        s.set_int(1, 5, 7).unwrap();
        assert_eq!(s.int(1, 5), Ok(7));
        assert_eq!(s.int(1, 6), Ok(0));
        // A write running past the last number changes nothing.
        let top = VarKind::Integer.numbers(true).end;
        let over = VarData {
            program: 0,
            start: top - 1,
            values: VarValues::Integer(vec![5, 6]),
        };
        assert_eq!(
            s.write_vars(&over, RealEncoding::Plain, max),
            Err(SimError::BadValue)
        );
        assert_eq!(s.int(top - 1, 0), Ok(0));
        for bad in [
            q(VarKind::Integer, 0, 199, 1),
            q(VarKind::Integer, 0, top - 1, 2),
            q(VarKind::Integer, 0, 200, 0),
            q(VarKind::Integer, PROGRAMS.end, 1, 1),
            q(VarKind::Real, 0, 100, 1),
            q(VarKind::Text, 0, 998, 5),
        ] {
            assert_eq!(
                s.read_vars(&bad, RealEncoding::Plain, max),
                Err(SimError::BadValue),
                "{bad:?}"
            );
        }
        assert_eq!(
            s.read_vars(&q(VarKind::Integer, 0, 200, 3), RealEncoding::Plain, 2),
            Err(SimError::BadValue),
            "over the count limit"
        );
        // Reals: stored as f64, sent and taken in the encoding asked for.
        let real = VarData {
            program: 0,
            start: 300,
            values: VarValues::Real(vec![RealWord(0x0000_0000_3FF8_0000)]),
        };
        s.write_vars(&real, RealEncoding::WordSwapped, max).unwrap();
        assert_eq!(s.real(300, 0), Ok(1.5));
        let r = s
            .read_vars(&q(VarKind::Real, 0, 300, 1), RealEncoding::Plain, max)
            .unwrap();
        assert_eq!(
            r.values,
            VarValues::Real(vec![RealWord(0x3FF8_0000_0000_0000)])
        );
        // Strings: one character a column.
        s.set_text(1, 1, b"HELLO").unwrap();
        let r = s
            .read_vars(&q(VarKind::Text, 1, 1, 5), RealEncoding::Plain, max)
            .unwrap();
        assert_eq!(r.values, VarValues::Text(b"HELLO".to_vec()));
        assert_eq!(s.text(2, 1), Ok(b"ELLO".to_vec()));
        let last = VarKind::Text.numbers(false).end - 1;
        assert!(s.set_text(last, 1, b"AB").is_err());
        s.set_text(last, 1, b"Z").unwrap();
        assert_eq!(s.text(last, 1), Ok(b"Z".to_vec()));
        assert!(s.int(100, 0).unwrap_err().contains("global are 200-299"));
        assert!(s.real(5, 65).unwrap_err().contains("program 65"));
    }
}
