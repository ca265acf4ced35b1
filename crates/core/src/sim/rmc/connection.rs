//! One Modbus/TCP connection to the simulated RMC, sans-IO: bytes in, every whole request
//! answered in order (RMC.md section 1: first in, first out), with its own ACK bits.

use std::time::Instant;

use super::controller::RmcController;
use super::map::Acks;
use crate::rmc::MAX_AXES;
use crate::rmc::modbus::{
    FrameBuffer, FrameError, Refusal, Response, decode_request, encode_response,
};

/// A connection's state: its per-axis ACK bits (0 when it opens, RMC.md section 5) and
/// the bytes of a request not yet whole.
#[derive(Debug, Default)]
pub struct RmcConnection {
    acks: Acks,
    frames: FrameBuffer,
}

impl RmcConnection {
    pub fn new() -> Self {
        Self {
            acks: [false; MAX_AXES],
            frames: FrameBuffer::default(),
        }
    }

    /// Bytes received at `now` (any split); the bytes to send back (every whole request
    /// answered, in order), or Err when the connection must be closed (bytes that are
    /// not Modbus/TCP). The controller's loop runs up to `now` first.
    pub fn handle_bytes(
        &mut self,
        controller: &mut RmcController,
        now: Instant,
        bytes: &[u8],
    ) -> Result<Vec<u8>, FrameError> {
        controller.advance(now);
        self.frames.push(bytes);
        let mut out = Vec::new();
        while let Some(frame) = self.frames.next_frame() {
            let frame = frame?;
            match decode_request(&frame) {
                Ok((header, request)) => {
                    let response = controller.handle(&mut self.acks, &request);
                    out.extend(encode_response(header, &response));
                }
                Err(Refusal::Exception {
                    header,
                    function,
                    code,
                }) => out.extend(encode_response(
                    header,
                    &Response::Exception { function, code },
                )),
                Err(Refusal::Close(e)) => return Err(e),
            }
        }
        Ok(out)
    }

    /// This connection's ACK bit for each axis (Status Bits bit 31 as it reads them).
    pub fn acks(&self) -> &Acks {
        &self.acks
    }
}
