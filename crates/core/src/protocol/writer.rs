//! Field writer: fixed-width upper-case hex fields and whole-frame assembly with SC.

use std::fmt;

use super::checksum::{ScMode, checksum};
use super::error::EncodeError;
use super::hex::{fits, max_for, push_hex};
use super::ids::{Header, MessageId, Station};
use super::units::Milli;

/// Writes the data fields of one message (always upper-case hex).
pub(crate) struct Writer<'b> {
    out: &'b mut Vec<u8>,
    message: MessageId,
}

impl Writer<'_> {
    #[cold]
    fn too_big(&self, field: &str, v: u32, width: usize) -> EncodeError {
        EncodeError {
            message: self.message,
            field: field.to_string(),
            reason: format!(
                "= {v} does not fit {width} hex digits (max {})",
                max_for(width)
            ),
        }
    }

    /// An error about `field`.
    #[cold]
    pub(crate) fn error(&self, field: impl fmt::Display, reason: impl Into<String>) -> EncodeError {
        EncodeError {
            message: self.message,
            field: field.to_string(),
            reason: reason.into(),
        }
    }

    #[inline]
    pub(crate) fn hex(&mut self, field: &str, v: u32, width: usize) -> Result<(), EncodeError> {
        if !fits(v, width) {
            return Err(self.too_big(field, v, width));
        }
        push_hex(self.out, v, width);
        Ok(())
    }

    /// Writes a value known to fit.
    #[inline]
    pub(crate) fn hex_fit(&mut self, v: u32, width: usize) {
        push_hex(self.out, v, width);
    }

    #[inline]
    pub(crate) fn coord(&mut self, v: Milli) {
        push_hex(self.out, v.to_wire(), 8);
    }

    pub(crate) fn bytes(&mut self, b: &[u8]) {
        self.out.extend_from_slice(b);
    }
}

/// A command frame from data characters as they are (a first contact's probes, which
/// include requests no typed command would make): header, station, ID, `data`, SC (or
/// `@@`), CR LF.
pub fn command_frame(station: Station, id: MessageId, data: &[u8], sc: ScMode) -> Vec<u8> {
    let mut out = Vec::with_capacity(data.len() + 10);
    // The body only copies bytes: it cannot fail.
    let _ = encode_frame(&mut out, Header::Command, station, Some(id), id, sc, |w| {
        w.bytes(data);
        Ok(())
    });
    out
}

/// Writes one whole frame: header, station, ID (if any), the body, SC, CR LF. On error
/// nothing is left in `out`.
#[inline]
pub(crate) fn encode_frame(
    out: &mut Vec<u8>,
    header: Header,
    station: Station,
    id: Option<MessageId>,
    message: MessageId,
    sc: ScMode,
    body: impl FnOnce(&mut Writer<'_>) -> Result<(), EncodeError>,
) -> Result<(), EncodeError> {
    let start = out.len();
    out.push(header.byte());
    push_hex(out, u32::from(station.0), 2);
    if let Some(id) = id {
        push_hex(out, u32::from(id.0), 3);
    }
    let mut w = Writer {
        out: &mut *out,
        message,
    };
    if let Err(e) = body(&mut w) {
        out.truncate(start);
        return Err(e);
    }
    match sc {
        ScMode::Computed => {
            let sum = checksum(out.get(start..).unwrap_or(&[]));
            push_hex(out, u32::from(sum), 2);
        }
        ScMode::AtAt => out.extend_from_slice(b"@@"),
    }
    out.extend_from_slice(b"\r\n");
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn writer_refuses_values_that_do_not_fit() {
        let mut out = Vec::new();
        let e = encode_frame(
            &mut out,
            Header::Command,
            Station::DEFAULT,
            Some(MessageId::HOME),
            MessageId::HOME,
            ScMode::Computed,
            |w| w.hex("search speed", 5000, 3),
        )
        .unwrap_err();
        assert_eq!(
            e.to_string(),
            "cannot encode 233H: field 'search speed' = 5000 does not fit 3 hex digits (max 4095)"
        );
        assert!(out.is_empty());
    }
}
