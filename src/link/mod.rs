//! The IO engine: one thread owns the transport; queue, priorities, timeouts, polling.

pub mod health;
pub mod line;
pub mod ports;
pub mod timing;
pub mod transport;
