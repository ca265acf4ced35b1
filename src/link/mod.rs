//! The IO engine: one thread owns the transport; queue, priorities, timeouts, polling.

mod engine;
pub mod event;
mod events;
pub mod handle;
pub mod health;
mod lease;
pub mod ports;
pub mod probe;
pub mod reason;
pub mod request;
pub mod schedule;
pub mod shutdown;
pub mod sync;
pub mod table;
pub mod timing;
mod transaction;
pub mod transport;

pub use event::LinkEvent;
pub use handle::{Connector, LinkConfig, LinkHandle, Repaint, spawn};
// The line settings moved below `link` and `sim`; `link::line` keeps naming them.
pub use crate::line::{self, LineSettings, Parity};
pub use reason::{BadInput, IoFailure, LineDownReason, NotSentReason};
pub use request::{Origin, Priority, RequestId};
pub use schedule::Polling;
pub use shutdown::{ShutdownReport, StopOutcome};
pub use table::TableRequest;
pub use transport::{SerialTransport, StreamTransport, TcpTransport, Transport};
