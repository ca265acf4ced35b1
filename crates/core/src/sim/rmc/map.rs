//! The simulator's register map (RMC.md section 2): which 32-bit registers a request may
//! read or write, and the Modbus exception for any other (nothing changes then).

use super::controller::RmcController;
use crate::rmc::modbus::{ExceptionCode, Request, Response};
use crate::rmc::registers::{
    CONTROLLER_STATUS, CPU_MODULE_ID, MAX_READ, MAX_WRITE, RMC151E_ID, STATUS_REGISTERS,
};
use crate::rmc::words::{dword_to_words, real_to_words, words_to_real};
use crate::rmc::{AxisId, Command, MAX_AXES, StatusBits};

/// One connection's ACK bit per axis (RMC.md section 5: ACK is kept per channel).
pub type Acks = [bool; MAX_AXES];

/// Registers in one axis's block of the Command Area: %MD40.(10n..10n+9).
const COMMAND_REGISTERS: u16 = 20;
/// Elements of the axis parameter file %MD(24+n) the map covers: 0 (Position Scale)
/// through 56 (In Position Tolerance); those not modelled read 0.
const PARAMETER_ELEMENTS: u16 = 57;
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
            if let Some(off) = within(axis.status_block(), STATUS_REGISTERS) {
                Some(Place::Status(axis, off / 2))
            } else if let Some(off) = within(axis.position_scale(), 2 * PARAMETER_ELEMENTS) {
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
                [*regs.get(at)?, *regs.get(at + 1)?]
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

    /// Registers `address..address + count`, whole 32-bit registers only.
    fn read(&self, acks: &Acks, address: u16, count: u16) -> Result<Vec<u16>, Refused> {
        if count == 0 || count > MAX_READ {
            return Err(VALUE);
        }
        // Whole 32-bit registers: even address and count [I: RMC.md section 7 leaves the
        // code for a misaligned request open].
        if !address.is_multiple_of(2) || !count.is_multiple_of(2) {
            return Err(ADDRESS);
        }
        let mut words = Vec::with_capacity(usize::from(count));
        for i in (0..count).step_by(2) {
            let at = address.checked_add(i).ok_or(ADDRESS)?;
            words.extend(self.read_dword(acks, at).ok_or(ADDRESS)?);
        }
        Ok(words)
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
