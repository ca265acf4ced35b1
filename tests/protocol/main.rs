//! The Format B codec: allocation, properties, and the vectors of the spec and of observed hosts.
//!
//! One test binary for the group: each links the whole app, so fewer binaries build faster.

#[path = "../vectors/mod.rs"]
mod vectors;

mod alloc;
mod props;
mod vectors_examples;
mod vectors_observed;
