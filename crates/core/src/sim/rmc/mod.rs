//! A simulated Delta RMC151E over Modbus/TCP (RMC.md sections 2-5), so the pendant's RMC
//! link can be tested without the hardware.
//!
//! - [`RmcController`]: sans-IO, every axis (target generator, Actual's lag, soft travel
//!   limits, latched Error Bits) and the register map; time comes in as `now` arguments.
//! - [`RmcConnection`]: one Modbus/TCP connection's bytes and its own ACK bits.
//! - [`RmcServer`]: both served on std threads (the `rmc-sim` binary).
//!
//! What the simulator decides where the reference is silent: Last Error Numbers
//! [`ERROR_NOT_ENABLED`] and [`ERROR_BAD_PARAMETER`] (its own codes [U]); a command
//! number that is not a whole number 0..512 answers exception 03 [I]; a write in the
//! Command Area must start at an axis's block (several axes' blocks may follow, 20
//! registers each); Position Scale and Offset are stored and read back but positions are
//! not scaled; the Command Position is not clipped to the travel limits: the Target halts
//! at the limit instead (Halted, Error Bit 4 or 5), and TG Done stays clear there, since
//! Target never reached Command.
//!
//! Function codes (RMC.md section 1 lists 3, 4, 6, 8, 16, 23; what each does to a 32-bit
//! register is the simulator's choice): FC4 reads the same map as FC3; reads (FC3, FC4,
//! FC23) take any address and count up to 125, each 16-bit register being its half of a
//! 32-bit one, and every element of a configured axis's status and parameter files reads
//! (0 where not modelled), so 125 registers read wherever the map is contiguous; FC6
//! writes one half of Position Scale, Offset or In Position Tolerance (the Command Area:
//! exception 02, a block runs only whole from FC16); FC8 answers sub-function 0 (Return
//! Query Data) with the request, any other with exception 01. Writes (FC16, FC23) still
//! take whole 32-bit registers only (exception 02 otherwise) [I].

mod axis;
mod connection;
mod controller;
mod map;
mod profile;
mod server;

#[cfg(test)]
mod tests;
#[cfg(test)]
mod wire_tests;

pub use axis::{DEFAULT_TOLERANCE, ERROR_BAD_PARAMETER, ERROR_NOT_ENABLED, ERROR_PROGRAM_MODE};
pub use connection::RmcConnection;
pub use controller::{LOOP, RmcAction, RmcConfig, RmcController};
pub use map::Acks;
pub use server::{
    DEFAULT_IDLE_TIMEOUT, EventLog, MAX_CONNECTIONS, RmcServer, ServeOptions, ServerEvent,
};
