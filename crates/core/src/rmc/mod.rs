//! Delta RMC151 over Modbus/TCP (RMC.md), sans-IO: the register map, typed commands and
//! status, Modbus/TCP framing, and the link core the shared driver runs.

pub mod command;
pub mod describe;
pub mod modbus;
pub mod registers;
pub mod status;
pub mod words;

pub use command::{Command, CommandError, MoveAbsolute, MoveRelative};
pub use registers::{AxisId, MAX_AXES};
pub use status::{AxisStatus, ControllerStatus, ErrorBits, StatusBits, TgPhase};
pub mod handle;
pub mod link;

pub use handle::{EVENT_BACKLOG, RmcHandle, RmcRepaint, spawn};
pub use link::{HoldJog, RmcCore, RmcEvent, RmcLinkConfig, RmcRequest};
