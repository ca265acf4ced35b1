//! The IO engine: one thread owns the transport; queue, priorities, timeouts, polling.

pub mod line;
pub mod ports;
pub mod transport;
