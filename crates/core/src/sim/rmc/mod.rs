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
pub use server::{EventLog, MAX_CONNECTIONS, RmcServer, ServerEvent};
