//! A signal's value as read, shown and typed: a bit, an integer, a real's 16 digits, a
//! string's characters.

use super::SignalKind;
use crate::protocol::{RealEncoding, RealWord};

/// What a signal holds.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Value {
    Bit(bool),
    Int(i32),
    /// As it stands on the wire: the controller's encoding says which double it is.
    Real(RealWord),
    Text(Vec<u8>),
}

impl Value {
    /// Words for the view: "ON", "-12", "1.5", "\"HELLO\"".
    pub fn show(&self, encoding: RealEncoding) -> String {
        match self {
            Value::Bit(true) => "ON".to_owned(),
            Value::Bit(false) => "OFF".to_owned(),
            Value::Int(v) => v.to_string(),
            Value::Real(w) if encoding.looks_wrong(*w) => format!(
                "{} (check the real encoding: {:016X})",
                encoding.decode(*w),
                w.0
            ),
            Value::Real(w) => encoding.decode(*w).to_string(),
            Value::Text(t) => {
                let end = t.iter().position(|&c| c == 0).unwrap_or(t.len());
                format!("\"{}\"", t[..end].escape_ascii())
            }
        }
    }

    /// The number a plot draws (bits 0 or 1; strings none).
    pub fn as_f64(&self, encoding: RealEncoding) -> Option<f64> {
        match self {
            Value::Bit(b) => Some(f64::from(u8::from(*b))),
            Value::Int(v) => Some(f64::from(*v)),
            Value::Real(w) => Some(encoding.decode(*w)).filter(|v| v.is_finite()),
            Value::Text(_) => None,
        }
    }

    /// A value typed for a signal of `kind`: ON/OFF/1/0 for bits (empty toggles
    /// `current`), a 32-bit integer, a finite real.
    pub fn parse(
        kind: SignalKind,
        text: &str,
        current: Option<&Value>,
        encoding: RealEncoding,
    ) -> Result<Value, String> {
        let t = text.trim();
        match kind {
            SignalKind::Input | SignalKind::Output | SignalKind::Flag => {
                match t.to_ascii_lowercase().as_str() {
                    "on" | "1" | "true" => Ok(Value::Bit(true)),
                    "off" | "0" | "false" => Ok(Value::Bit(false)),
                    "" | "toggle" => match current {
                        Some(Value::Bit(b)) => Ok(Value::Bit(!b)),
                        _ => Err("not read yet: say ON or OFF".to_owned()),
                    },
                    _ => Err(format!("`{t}` is not ON or OFF")),
                }
            }
            SignalKind::Integer => t
                .parse::<i32>()
                .map(Value::Int)
                .map_err(|_| format!("`{t}` is not an integer from {} to {}", i32::MIN, i32::MAX)),
            SignalKind::Real => match t.parse::<f64>() {
                Ok(v) if v.is_finite() => Ok(Value::Real(encoding.encode(v))),
                _ => Err(format!("`{t}` is not a finite number (e.g. 1.5 or -2e3)")),
            },
            SignalKind::Text => {
                Err("string variables cannot be written (no change message exists)".to_owned())
            }
        }
    }
}
