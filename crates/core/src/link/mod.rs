//! The link: one driver thread per line (`driver`) running a sans-IO protocol core
//! (`core`'s face; Format B in `format_b`), and the handle the application talks to it
//! through. Queue, priorities, time-outs, polling and the safety STOPs live in the core.

pub mod core;
pub(crate) mod driver;
pub mod event;
mod event_out;
pub mod format_b;
pub mod handle;
pub mod health;
pub mod lease;
pub mod poll_answers;
pub mod probe;
pub mod reason;
pub mod request;
pub mod schedule;
pub mod sync;
pub mod table;
pub mod timing;
pub mod transport;

pub use driver::Connector;
pub use event::LinkEvent;
pub use format_b::{ShutdownReport, StopOutcome};
pub use handle::{EVENT_BACKLOG, LinkConfig, LinkHandle, Repaint, StopSender, spawn};
pub use lease::{JOG_LEASE, RENEW_EVERY};
pub use poll_answers::PollAnswers;
pub use reason::{BadInput, IoFailure, LineDownReason, NotSentReason};
pub use request::{Origin, Priority, RequestId};
pub use schedule::Polling;
pub use table::TableRequest;
pub use transport::{SerialTransport, StreamTransport, TcpTransport, Transport};
