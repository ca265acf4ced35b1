//! The simulator's register map (RMC.md section 2): which 32-bit registers a request may
//! read or write, and the Modbus exception for any other (nothing changes then).

use super::controller::RmcController;
use crate::rmc::modbus::{ExceptionCode, Request, Response};
use crate::rmc::registers::{CONTROLLER_STATUS, CPU_MODULE_ID, MAX_READ, MAX_WRITE, RMC151E_ID};
use crate::rmc::words::{dword_to_words, real_to_words, words_to_real};
use crate::rmc::{AxisId, Command, MAX_AXES, StatusBits};

/// One connection's ACK bit per axis (RMC.md section 5: ACK is kept per channel).
pub type Acks = [bool; MAX_AXES];

/// Registers in one axis's block of the Command Area: %MD40.(10n..10n+9).
const COMMAND_REGISTERS: u16 = 20;
/// Registers of one axis's status file %MD(8+n) and parameter file %MD(24+n): the whole
/// file, 256 elements (PDU address = 2 x (256 x file + element), RMC.md section 1), so
/// that a read of up to 125 registers anywhere in them succeeds, as a Modbus client
/// expects. Elements the simulator does not model (beyond Command Velocity, 57, in the
/// status file; all but Position Scale 0, Offset 1 and In Position Tolerance 56 in the
/// parameter file) read 0. RMC.md gives no file lengths [U]: the simulator's choice.
const FILE_REGISTERS: u16 = 512;
const SCALE: u16 = 0;
const OFFSET: u16 = 1;
const TOLERANCE: u16 = 56;

type Refused = ExceptionCode;
const ADDRESS: Refused = ExceptionCode::ILLEGAL_DATA_ADDRESS;
const VALUE: Refused = ExceptionCode::ILLEGAL_DATA_VALUE;

/// Where a 32-bit register lies in an axis's files, if it does.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Place {
    Status(AxisId, u16),
    Parameter(AxisId, u16),
    CommandArea,
}

impl RmcController {
    /// Answers one request for a connection whose ACK bits are `acks`. FC23 writes first,
    /// then reads; a request answered with an exception changes nothing.
    pub fn handle(&mut self, acks: &mut Acks, request: &Request) -> Response {
        let function = request.function();
        let answer = match request {
            Request::Read { address, count } => self
                .read(acks, *address, *count)
                .map(|words| Response::Registers { function, words }),
            Request::Write { address, words } => {
                self.write(acks, *address, words)
                    .map(|()| Response::Written {
                        address: *address,
                        count: words.len() as u16,
                    })
            }
            Request::ReadWrite {
                read_address,
                read_count,
                write_address,
                words,
            } => self
                .read(acks, *read_address, *read_count)
                .and_then(|_| self.write(acks, *write_address, words))
                .and_then(|()| self.read(acks, *read_address, *read_count))
                .map(|words| Response::Registers { function, words }),
            Request::Other { .. } => Err(ExceptionCode::ILLEGAL_FUNCTION),
        };
        answer.unwrap_or_else(|code| Response::Exception { function, code })
    }

    /// The axis, if configured, whose register `address` is; and where in its files.
    fn place(&self, address: u16) -> Option<Place> {
        let within = |base: u16, len: u16| address.checked_sub(base).filter(|off| *off < len);
        AxisId::first(self.axis_count()).find_map(|axis| {
            if let Some(off) = within(axis.status_block(), FILE_REGISTERS) {
                Some(Place::Status(axis, off / 2))
            } else if let Some(off) = within(axis.position_scale(), FILE_REGISTERS) {
                Some(Place::Parameter(axis, off / 2))
            } else if within(axis.command_block(), COMMAND_REGISTERS).is_some()
                || within(axis.command_block_low(), COMMAND_REGISTERS).is_some()
            {
                Some(Place::CommandArea)
            } else {
                None
            }
        })
    }

    /// One 32-bit register as its two words; `None` where nothing is mapped.
    fn read_dword(&self, acks: &Acks, address: u16) -> Option<[u16; 2]> {
        match address {
            CPU_MODULE_ID => return Some(dword_to_words(RMC151E_ID)),
            CONTROLLER_STATUS => return Some(dword_to_words(self.controller_status())),
            _ => {}
        }
        let axis = |id: AxisId| self.axes.get(id.index());
        Some(match self.place(address)? {
            Place::Status(id, element) => {
                let mut status = axis(id)?.status();
                let ack = acks.get(id.index()).copied().unwrap_or(false);
                status.bits = status.bits.with(StatusBits::ACK, ack);
                let regs = status.encode();
                let at = 2 * usize::from(element);
                match (regs.get(at), regs.get(at + 1)) {
                    (Some(&lo), Some(&hi)) => [lo, hi],
                    // Beyond what the simulator models (RMC.md lists elements 0-57).
                    _ => [0, 0],
                }
            }
            Place::Parameter(id, element) => {
                let a = axis(id)?;
                real_to_words(match element {
                    SCALE => a.scale,
                    OFFSET => a.offset,
                    TOLERANCE => a.tolerance,
                    _ => 0.0,
                })
            }
            // Write-only: reads answer 0s [I].
            Place::CommandArea => [0, 0],
        })
    }

    /// Registers `address..address + count` (FC3, FC4 and FC23's read), word by word:
    /// each 16-bit register is its half of a 32-bit one, so a read may start or end in
    /// the middle of one, and any count up to 125 succeeds where the map is contiguous.
    /// RMC.md section 1 asks hosts for whole 32-bit registers [I] but documents no
    /// exception for a read that is not; the simulator chooses to answer the halves
    /// (a client reading 125 registers, an odd count, is served).
    pub(super) fn read(&self, acks: &Acks, address: u16, count: u16) -> Result<Vec<u16>, Refused> {
        if count == 0 || count > MAX_READ {
            return Err(VALUE);
        }
        let end = u32::from(address) + u32::from(count);
        if end > u32::from(u16::MAX) + 1 {
            return Err(ADDRESS);
        }
        let mut words = Vec::with_capacity(usize::from(count));
        let mut at = u32::from(address & !1);
        while at < end {
            let pair = u16::try_from(at)
                .ok()
                .and_then(|a| self.read_dword(acks, a))
                .ok_or(ADDRESS)?;
            if at >= u32::from(address) {
                words.push(pair[0]);
            }
            if at + 1 < end {
                words.push(pair[1]);
            }
            at += 2;
        }
        Ok(words)
    }

    /// FC6, Write Single Register: one 16-bit half of a writable parameter (Position
    /// Scale, Position Offset, In Position Tolerance); the other half keeps its value, and
    /// the 32-bit value that results is checked as an FC16 write's is (exception 03 if it
    /// is not a finite number). RMC.md lists FC6 but not what it does to a 32-bit
    /// register: this is the simulator's choice. The Command Area is refused with
    /// exception 02: a command and its parameters are written in one FC16 (section 4),
    /// and a half-written block must not run.
    pub(super) fn write_single(
        &mut self,
        acks: &Acks,
        address: u16,
        value: u16,
    ) -> Result<(), Refused> {
        let even = address & !1;
        let Some(Place::Parameter(_, SCALE | OFFSET | TOLERANCE)) = self.place(even) else {
            return Err(ADDRESS);
        };
        let mut pair = self.read_dword(acks, even).ok_or(ADDRESS)?;
        pair[usize::from(address & 1)] = value;
        self.write_parameters(even, &pair)
    }

    /// Writes `words` at `address`: command blocks (each run at once) or axis parameters.
    fn write(&mut self, acks: &mut Acks, address: u16, words: &[u16]) -> Result<(), Refused> {
        if words.is_empty() || words.len() > usize::from(MAX_WRITE) {
            return Err(VALUE);
        }
        if !address.is_multiple_of(2) || !words.len().is_multiple_of(2) {
            return Err(ADDRESS);
        }
        let end = usize::from(address) + words.len();
        if end > usize::from(u16::MAX) + 1 {
            return Err(ADDRESS);
        }
        let first = AxisId::first(self.axis_count())
            .find(|a| address == a.command_block() || address == a.command_block_low());
        match first {
            Some(axis) => self.write_commands(acks, axis, words),
            None => self.write_parameters(address, words),
        }
    }

    /// Command blocks from `first`'s on, one axis per 20 registers: all decoded before
    /// any runs; each sets this connection's ACK for its axis to its REQ (section 5).
    fn write_commands(
        &mut self,
        acks: &mut Acks,
        first: AxisId,
        words: &[u16],
    ) -> Result<(), Refused> {
        let mut commands = Vec::new();
        for (i, block) in words.chunks(usize::from(COMMAND_REGISTERS)).enumerate() {
            let axis = AxisId::new(first.index() + i)
                .filter(|a| a.index() < self.axis_count())
                .ok_or(ADDRESS)?;
            // A command number that is not a whole number 0..512 [I: exception 03].
            let (command, req) = Command::from_block(block).map_err(|_| VALUE)?;
            commands.push((axis, command, req));
        }
        for (axis, command, req) in commands {
            self.command(axis, command);
            if let Some(ack) = acks.get_mut(axis.index()) {
                *ack = req;
            }
        }
        Ok(())
    }

    /// Position Scale, Position Offset and In Position Tolerance of configured axes; a
    /// value that is not a finite number is exception 03. Nothing else is writable.
    fn write_parameters(&mut self, address: u16, words: &[u16]) -> Result<(), Refused> {
        let mut values = Vec::new();
        for (i, pair) in words.chunks_exact(2).enumerate() {
            let at = address.checked_add(2 * i as u16).ok_or(ADDRESS)?;
            let Some(Place::Parameter(axis, element @ (SCALE | OFFSET | TOLERANCE))) =
                self.place(at)
            else {
                return Err(ADDRESS);
            };
            let value = words_to_real([pair[0], pair[1]]);
            if !value.is_finite() || (element == TOLERANCE && value < 0.0) {
                return Err(VALUE);
            }
            values.push((axis, element, value));
        }
        for (axis, element, value) in values {
            if let Some(a) = self.axes.get_mut(axis.index()) {
                match element {
                    SCALE => a.scale = value,
                    OFFSET => a.offset = value,
                    _ => a.tolerance = value,
                }
            }
        }
        Ok(())
    }
}
