//! The simulated X-SEL SCARA controller: a Format B slave built on protocol and robot.

pub mod pipe;
