//! One Modbus/TCP connection to the simulated RMC, sans-IO: bytes in, every whole request
//! answered in order (RMC.md section 1: first in, first out), with its own ACK bits.
//!
//! Function codes (RMC.md section 1 lists 3, 4, 6, 8, 16 and 23): FC3, FC16 and FC23 go
//! through the project's codec; FC4, FC6 and FC8, which the pendant never sends, are
//! read and answered here from the frame's bytes. Any other function is exception 01.

use std::time::Instant;

use super::controller::RmcController;
use super::map::Acks;
use crate::rmc::MAX_AXES;
use crate::rmc::modbus::{
    ExceptionCode, FrameBuffer, FrameError, MBAP_LEN, Refusal, Response, decode_request,
    encode_response,
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
            if let Some(reply) = self.other_function(controller, &frame) {
                out.extend(reply);
                continue;
            }
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

    /// FC4 (Read Input Registers: the same map as FC3, RMC.md being silent on any
    /// difference), FC6 (Write Single Register, echoed) and FC8 (Diagnostics: sub-function
    /// 0, Return Query Data, echoes the request; any other sub-function is exception 01,
    /// as the Modbus specification has it for one a server does not support). `None` for
    /// the other functions. A PDU of the wrong length is exception 03.
    fn other_function(&mut self, controller: &mut RmcController, frame: &[u8]) -> Option<Vec<u8>> {
        let &function = frame.get(MBAP_LEN)?;
        if !matches!(function, 4 | 6 | 8) {
            return None;
        }
        let pdu = frame.get(MBAP_LEN..).unwrap_or_default();
        let word = |at: usize| -> Option<u16> {
            Some(u16::from_be_bytes([*pdu.get(at)?, *pdu.get(at + 1)?]))
        };
        let fields = (pdu.len() == 5).then(|| word(1).zip(word(3))).flatten();
        let answer: Result<Vec<u8>, ExceptionCode> = match (function, fields) {
            (4, Some((address, count))) => {
                controller.read(&self.acks, address, count).map(|words| {
                    let mut out = vec![4, (2 * words.len()) as u8];
                    out.extend(words.iter().flat_map(|w| w.to_be_bytes()));
                    out
                })
            }
            (6, Some((address, value))) => controller
                .write_single(&self.acks, address, value)
                .map(|()| pdu.to_vec()),
            (8, _) if pdu.len() >= 3 => match word(1) {
                Some(0) => Ok(pdu.to_vec()),
                _ => Err(ExceptionCode::ILLEGAL_FUNCTION),
            },
            _ => Err(ExceptionCode::ILLEGAL_DATA_VALUE),
        };
        let body = answer.unwrap_or_else(|code| vec![function | 0x80, code.0]);
        let mut out = Vec::with_capacity(MBAP_LEN + body.len());
        out.extend(frame.get(..4).unwrap_or_default());
        out.extend((body.len() as u16 + 1).to_be_bytes());
        out.push(frame.get(6).copied().unwrap_or(0));
        out.extend(body);
        Some(out)
    }

    /// This connection's ACK bit for each axis (Status Bits bit 31 as it reads them).
    pub fn acks(&self) -> &Acks {
        &self.acks
    }
}
