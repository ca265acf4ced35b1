//! Modbus/TCP framing for the RMC (RMC.md section 1), both roles: frames are cut from the
//! stream by their MBAP header first, then the PDU is decoded by `modbus-core` (a whole
//! frame only: its own stream decoder reads past a partial FC16 header). Only what the
//! pendant and the simulator use: FC3, FC16, FC23 and exceptions.

use modbus_core::tcp::{Header as CoreHeader, RequestAdu, ResponseAdu, client, server};
use modbus_core::{
    Data, ExceptionResponse, FunctionCode, Request as CoreRequest, RequestPdu,
    Response as CoreResponse, ResponsePdu,
};

/// The MBAP header: transaction, protocol, length, unit.
pub const MBAP_LEN: usize = 7;
/// The longest Modbus/TCP frame: the header and a 253-byte PDU.
pub const MAX_FRAME: usize = MBAP_LEN + 253;

/// A frame's transaction number and unit ID.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Header {
    pub transaction: u16,
    pub unit: u8,
}

/// A request, as the client sends it and the server reads it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Request {
    /// FC3, Read Holding Registers.
    Read { address: u16, count: u16 },
    /// FC16, Write Multiple Registers.
    Write { address: u16, words: Vec<u16> },
    /// FC23, Read/Write Multiple Registers (the write happens first).
    ReadWrite {
        read_address: u16,
        read_count: u16,
        write_address: u16,
        words: Vec<u16>,
    },
    /// Any other function (the server answers exception 01).
    Other { function: u8 },
}

impl Request {
    pub fn function(&self) -> u8 {
        match self {
            Request::Read { .. } => 3,
            Request::Write { .. } => 16,
            Request::ReadWrite { .. } => 23,
            Request::Other { function } => *function,
        }
    }
}

/// A Modbus exception code.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ExceptionCode(pub u8);

impl ExceptionCode {
    pub const ILLEGAL_FUNCTION: Self = Self(1);
    pub const ILLEGAL_DATA_ADDRESS: Self = Self(2);
    pub const ILLEGAL_DATA_VALUE: Self = Self(3);
    pub const SERVER_DEVICE_FAILURE: Self = Self(4);

    pub fn name(self) -> &'static str {
        match self.0 {
            1 => "illegal function",
            2 => "illegal data address",
            3 => "illegal data value",
            4 => "server device failure",
            5 => "acknowledge",
            6 => "server device busy",
            _ => "unknown exception",
        }
    }
}

/// A response, as the server sends it and the client reads it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Response {
    /// FC3 or FC23: the registers read.
    Registers { function: u8, words: Vec<u16> },
    /// FC16: where and how many were written.
    Written { address: u16, count: u16 },
    /// An exception to `function`.
    Exception { function: u8, code: ExceptionCode },
}

/// Why bytes are not a frame: the connection cannot be trusted after it.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum FrameError {
    #[error("protocol ID {0} is not Modbus (0)")]
    NotModbus(u16),
    #[error("MBAP length {0} is outside 2..=254")]
    BadLength(u16),
    #[error("the PDU could not be read: {0}")]
    BadPdu(String),
    #[error("a response with function {0:#04x} was not expected")]
    Unexpected(u8),
}

/// How much of `buf` is the first frame.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Cut {
    /// The first frame is the first this many bytes.
    Whole(usize),
    /// More bytes are needed.
    Partial,
    /// The header is not Modbus/TCP.
    Bad(FrameError),
}

/// Finds the first frame by its MBAP header.
pub fn cut(buf: &[u8]) -> Cut {
    let Some(header) = buf.get(..MBAP_LEN) else {
        return Cut::Partial;
    };
    let protocol = u16::from_be_bytes([header[2], header[3]]);
    let length = u16::from_be_bytes([header[4], header[5]]);
    if protocol != 0 {
        return Cut::Bad(FrameError::NotModbus(protocol));
    }
    // The length counts the unit ID and the PDU: a function code at least, 253 at most.
    if !(2..=254).contains(&length) {
        return Cut::Bad(FrameError::BadLength(length));
    }
    let total = 6 + usize::from(length);
    if buf.len() >= total {
        Cut::Whole(total)
    } else {
        Cut::Partial
    }
}

/// The header and PDU of a whole frame (one [`cut`] said was whole).
fn split(frame: &[u8]) -> Result<(Header, &[u8]), FrameError> {
    match cut(frame) {
        Cut::Whole(n) => {
            let header = Header {
                transaction: u16::from_be_bytes([frame[0], frame[1]]),
                unit: frame[6],
            };
            Ok((header, frame.get(MBAP_LEN..n).unwrap_or_default()))
        }
        Cut::Partial => Err(FrameError::BadPdu("the frame is cut short".into())),
        Cut::Bad(e) => Err(e),
    }
}

fn words_of(bytes: &[u8]) -> Vec<u16> {
    bytes
        .chunks_exact(2)
        .map(|b| u16::from_be_bytes([b[0], b[1]]))
        .collect()
}

fn core_header(h: Header) -> CoreHeader {
    CoreHeader {
        transaction_id: h.transaction,
        unit_id: h.unit,
    }
}

/// A request's bytes (the client's side). Words beyond what one frame can carry are
/// the caller's mistake: the frame then carries none and the server refuses it.
pub fn encode_request(header: Header, request: &Request) -> Vec<u8> {
    let mut data_buf = [0u8; 256];
    let mut out = [0u8; MAX_FRAME];
    let words: &[u16] = match request {
        Request::Write { words, .. } | Request::ReadWrite { words, .. } => words,
        _ => &[],
    };
    // modbus-core sizes the PDU by the slice it is given: exactly the words' bytes.
    let data_len = (2 * words.len()).min(data_buf.len());
    let data = Data::from_words(words, &mut data_buf[..data_len]);
    let pdu = match (request, data) {
        (Request::Read { address, count }, _) => {
            CoreRequest::ReadHoldingRegisters(*address, *count)
        }
        (Request::Write { address, .. }, Ok(data)) => {
            CoreRequest::WriteMultipleRegisters(*address, data)
        }
        (
            Request::ReadWrite {
                read_address,
                read_count,
                write_address,
                ..
            },
            Ok(data),
        ) => CoreRequest::ReadWriteMultipleRegisters(
            *read_address,
            *read_count,
            *write_address,
            data,
        ),
        (request, _) => CoreRequest::Custom(FunctionCode::new(request.function()), &[]),
    };
    let adu = RequestAdu {
        hdr: core_header(header),
        pdu: RequestPdu(pdu),
    };
    match client::encode_request(adu, &mut out) {
        Ok(n) => out.get(..n).unwrap_or_default().to_vec(),
        Err(_) => Vec::new(),
    }
}

/// A response's bytes (the server's side).
pub fn encode_response(header: Header, response: &Response) -> Vec<u8> {
    let mut data_buf = [0u8; 256];
    let mut out = [0u8; MAX_FRAME];
    let pdu = match response {
        Response::Registers { function, words } => {
            match Data::from_words(words, &mut data_buf[..(2 * words.len()).min(256)]) {
                Ok(data) if *function == 23 => Ok(CoreResponse::ReadWriteMultipleRegisters(data)),
                Ok(data) => Ok(CoreResponse::ReadHoldingRegisters(data)),
                Err(_) => exception(*function, ExceptionCode::SERVER_DEVICE_FAILURE),
            }
        }
        Response::Written { address, count } => {
            Ok(CoreResponse::WriteMultipleRegisters(*address, *count))
        }
        Response::Exception { function, code } => exception(*function, *code),
    };
    let adu = ResponseAdu {
        hdr: core_header(header),
        pdu: ResponsePdu(pdu),
    };
    match server::encode_response(adu, &mut out) {
        Ok(n) => out.get(..n).unwrap_or_default().to_vec(),
        // An exception code modbus-core does not know: written by hand.
        Err(_) => {
            let (function, code) = match response {
                Response::Exception { function, code } => (*function, code.0),
                _ => (0, ExceptionCode::SERVER_DEVICE_FAILURE.0),
            };
            let mut frame = Vec::with_capacity(9);
            frame.extend(header.transaction.to_be_bytes());
            frame.extend([0, 0, 0, 3, header.unit, function | 0x80, code]);
            frame
        }
    }
}

fn exception(
    function: u8,
    code: ExceptionCode,
) -> Result<CoreResponse<'static>, ExceptionResponse> {
    let exception = match code.0 {
        1 => modbus_core::Exception::IllegalFunction,
        2 => modbus_core::Exception::IllegalDataAddress,
        3 => modbus_core::Exception::IllegalDataValue,
        _ => modbus_core::Exception::ServerDeviceFailure,
    };
    Err(ExceptionResponse {
        function: FunctionCode::new(function),
        exception,
    })
}

/// Reads a whole response frame (the client's side).
pub fn decode_response(frame: &[u8]) -> Result<(Header, Response), FrameError> {
    let (header, pdu) = split(frame)?;
    let function = *pdu.first().ok_or(FrameError::BadLength(1))?;
    if function & 0x80 != 0 {
        let code = *pdu
            .get(1)
            .ok_or_else(|| FrameError::BadPdu("an exception without its code".into()))?;
        return Ok((
            header,
            Response::Exception {
                function: function & 0x7F,
                code: ExceptionCode(code),
            },
        ));
    }
    let response = CoreResponse::try_from(pdu).map_err(|e| FrameError::BadPdu(e.to_string()))?;
    let response = match response {
        CoreResponse::ReadHoldingRegisters(data)
        | CoreResponse::ReadWriteMultipleRegisters(data) => {
            let words = words_of(data.payload());
            Response::Registers { function, words }
        }
        CoreResponse::WriteMultipleRegisters(address, count) => {
            Response::Written { address, count }
        }
        _ => return Err(FrameError::Unexpected(function)),
    };
    Ok((header, response))
}

/// A request the server cannot carry out: answered with an exception, or (a frame that is
/// not Modbus) by closing the connection.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Refusal {
    Exception {
        header: Header,
        function: u8,
        code: ExceptionCode,
    },
    Close(FrameError),
}

/// Reads a whole request frame (the server's side); counts and byte counts that disagree
/// are exception 03.
pub fn decode_request(frame: &[u8]) -> Result<(Header, Request), Refusal> {
    let (header, pdu) = split(frame).map_err(Refusal::Close)?;
    let function = pdu.first().copied().unwrap_or(0);
    let refuse = |code| Refusal::Exception {
        header,
        function,
        code,
    };
    if !matches!(function, 3 | 16 | 23) {
        return Ok((header, Request::Other { function }));
    }
    let request =
        CoreRequest::try_from(pdu).map_err(|_| refuse(ExceptionCode::ILLEGAL_DATA_VALUE))?;
    let checked = |data: Data<'_>| {
        let words = words_of(data.payload());
        if words.len() == data.len() && data.payload().len() == 2 * data.len() {
            Ok(words)
        } else {
            Err(refuse(ExceptionCode::ILLEGAL_DATA_VALUE))
        }
    };
    let request = match request {
        CoreRequest::ReadHoldingRegisters(address, count) => Request::Read { address, count },
        CoreRequest::WriteMultipleRegisters(address, data) => Request::Write {
            address,
            words: checked(data)?,
        },
        CoreRequest::ReadWriteMultipleRegisters(read_address, read_count, write_address, data) => {
            Request::ReadWrite {
                read_address,
                read_count,
                write_address,
                words: checked(data)?,
            }
        }
        _ => Request::Other { function },
    };
    Ok((header, request))
}

/// Bytes from a stream, cut into whole frames; holds at most one frame's worth.
#[derive(Debug, Default)]
pub struct FrameBuffer {
    buf: Vec<u8>,
    /// The bytes dropped with the last error (for the frame log).
    discarded: Vec<u8>,
}

impl FrameBuffer {
    pub fn push(&mut self, bytes: &[u8]) {
        self.buf.extend_from_slice(bytes);
    }

    /// The next whole frame; an error means the stream is not Modbus/TCP (and the
    /// buffer is emptied).
    pub fn next_frame(&mut self) -> Option<Result<Vec<u8>, FrameError>> {
        match cut(&self.buf) {
            Cut::Whole(n) => Some(Ok(self.buf.drain(..n).collect())),
            Cut::Partial => None,
            Cut::Bad(e) => {
                self.discarded = std::mem::take(&mut self.buf);
                Some(Err(e))
            }
        }
    }

    pub fn is_empty(&self) -> bool {
        self.buf.is_empty()
    }

    /// The bytes the last error dropped.
    pub fn discarded(&self) -> &[u8] {
        &self.discarded
    }

    pub fn clear(&mut self) {
        self.buf.clear();
        self.discarded.clear();
    }
}

#[cfg(test)]
#[path = "modbus_tests.rs"]
mod tests;
