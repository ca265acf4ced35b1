//! The IO engine: one thread owns the transport; queue, priorities, timeouts, polling.
