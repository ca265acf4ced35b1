//! The IO engine: one thread owns the transport; queue, priorities, timeouts, polling.

mod engine;
pub mod event;
pub mod handle;
pub mod health;
pub mod line;
pub mod ports;
pub mod probe;
pub mod request;
pub mod schedule;
pub mod sync;
pub mod table;
pub mod timing;
mod transaction;
pub mod transport;

pub use event::LinkEvent;
pub use handle::{Connector, LinkConfig, LinkHandle, Repaint, spawn};
pub use line::{LineSettings, Parity};
pub use request::{Origin, Priority, RequestId};
pub use schedule::Polling;
pub use table::TableRequest;
pub use transport::{SerialTransport, StreamTransport, TcpTransport, Transport};
