//! Modbus/TCP bytes described field by field for the frame log, as Format B frames are:
//! the MBAP header, the function, the register range named by register (RMC.md section
//! 2), each 32-bit register decoded (REALs as numbers, bit registers bit by bit, the
//! Command Area as its command and parameters), exceptions by name.

use super::command::Command;
use super::modbus::{ExceptionCode, MBAP_LEN};
use super::registers::{Kind, Register, register_at};
use super::status::{ErrorBits, STATUS_BIT_NAMES, StatusBits};
use super::words::{words_to_dword, words_to_real};
use crate::protocol::Columns;
use crate::protocol::describe::{
    BitNote, ChecksumVerdict, FieldDescription, FrameDescription, Problem,
};

/// Which side of a transaction the bytes are.
#[derive(Clone, Copy, Debug)]
pub enum Role<'a> {
    Request,
    /// A reply, with its request's bytes when known (a register read's reply carries no
    /// address: the request names what was read).
    Reply {
        request: Option<&'a [u8]>,
    },
}

/// The function's name (Modbus Application Protocol).
pub fn function_name(function: u8) -> &'static str {
    match function & 0x7F {
        3 => "Read Holding Registers",
        4 => "Read Input Registers",
        6 => "Write Single Register",
        16 => "Write Multiple Registers",
        23 => "Read/Write Multiple Registers",
        _ => "function",
    }
}

/// What a request asks, in the frame log's name column: `FC3 read Status Bits..Command
/// Velocity, Axis 1`.
pub fn request_title(bytes: &[u8]) -> String {
    let Some(&function) = bytes.get(MBAP_LEN) else {
        return "Modbus (cut short)".into();
    };
    let word = |at: usize| {
        bytes
            .get(at..at + 2)
            .map(|b| u16::from_be_bytes([b[0], b[1]]))
    };
    let at = MBAP_LEN + 1;
    match (function, word(at), word(at + 2)) {
        (3, Some(address), Some(count)) => {
            format!("FC3 read {}", super::registers::range_name(address, count))
        }
        (16, Some(address), Some(count)) => {
            let command = command_in(bytes, address, at + 5).map_or(String::new(), |(c, req)| {
                format!(": {} ({}), REQ {}", c.name(), c.number(), u8::from(req))
            });
            format!(
                "FC16 write {}{command}",
                super::registers::range_name(address, count)
            )
        }
        (23, Some(address), Some(count)) => {
            format!(
                "FC23 read/write {}",
                super::registers::range_name(address, count)
            )
        }
        (f, ..) => format!("FC{f} {}", function_name(f)),
    }
}

/// What a reply says, in the name column: `FC3 reply: Status Bits..Command Velocity, Axis
/// 1`, `exception 02 (illegal data address) to FC3`.
pub fn reply_title(bytes: &[u8], request: Option<&[u8]>) -> String {
    let Some(&function) = bytes.get(MBAP_LEN) else {
        return "Modbus (cut short)".into();
    };
    if function & 0x80 != 0 {
        let code = bytes.get(MBAP_LEN + 1).copied().unwrap_or(0);
        return format!(
            "exception {code:02} ({}) to FC{}",
            ExceptionCode(code).name(),
            function & 0x7F
        );
    }
    let what = request
        .and_then(read_range)
        .map_or(String::new(), |(address, count)| {
            format!(": {}", super::registers::range_name(address, count))
        });
    match function {
        16 => {
            let written = request.map_or(String::new(), |r| {
                request_title(r)
                    .strip_prefix("FC16 write ")
                    .map_or(String::new(), |s| format!(": wrote {s}"))
            });
            format!("FC16 reply{written}")
        }
        f => format!("FC{f} reply{what}"),
    }
}

/// The registers a request reads: (address, count).
fn read_range(request: &[u8]) -> Option<(u16, u16)> {
    let word = |at: usize| {
        request
            .get(at..at + 2)
            .map(|b| u16::from_be_bytes([b[0], b[1]]))
    };
    match request.get(MBAP_LEN)? {
        3 | 23 => Some((word(MBAP_LEN + 1)?, word(MBAP_LEN + 3)?)),
        _ => None,
    }
}

/// The command a write to a Command Area carries (its data from byte `data`).
fn command_in(bytes: &[u8], address: u16, data: usize) -> Option<(Command, bool)> {
    if !register_at(address).is_command() {
        return None;
    }
    let words: Vec<u16> = bytes
        .get(data..)?
        .chunks_exact(2)
        .map(|b| u16::from_be_bytes([b[0], b[1]]))
        .collect();
    Command::from_block(&words).ok()
}

/// Describes `bytes` as a Modbus/TCP frame, as far as they go; never fails.
pub fn describe(bytes: &[u8], role: Role<'_>) -> FrameDescription {
    let mut d = Describer {
        bytes,
        at: 0,
        out: FrameDescription {
            header: None,
            message: None,
            title: match role {
                Role::Request => request_title(bytes),
                Role::Reply { request } => reply_title(bytes, request),
            },
            fields: Vec::new(),
            checksum: ChecksumVerdict::NotUsed,
            problems: Vec::new(),
        },
    };
    d.mbap();
    if let Some(function) = d.byte("function", |f| {
        if f & 0x80 != 0 {
            format!("{f:#04x}: exception to FC{}", f & 0x7F)
        } else {
            format!("{f}: {}", function_name(f))
        }
    }) {
        match (role, function) {
            (_, f) if f & 0x80 != 0 => {
                d.byte("exception code", |c| {
                    format!("{c:02}: {}", ExceptionCode(c).name())
                });
            }
            (Role::Request, 3) => {
                d.word("start address", address_text);
                d.word("quantity", count_text);
            }
            (Role::Request, 16) => {
                let address = d.word("start address", address_text);
                d.word("quantity", count_text);
                d.byte("byte count", |n| format!("{n} bytes follow"));
                d.registers(address.unwrap_or(0));
            }
            (Role::Request, 23) => {
                d.word("read address", address_text);
                d.word("read quantity", count_text);
                let address = d.word("write address", address_text);
                d.word("write quantity", count_text);
                d.byte("byte count", |n| format!("{n} bytes follow"));
                d.registers(address.unwrap_or(0));
            }
            (Role::Reply { request }, 3 | 23) => {
                d.byte("byte count", |n| format!("{n} bytes follow"));
                match request.and_then(read_range) {
                    Some((address, _)) => d.registers(address),
                    None => d.words_unnamed(),
                }
            }
            (Role::Reply { .. }, 16) => {
                d.word("start address", address_text);
                d.word("quantity", |n| format!("{n} registers written"));
            }
            _ => d.words_unnamed(),
        }
    }
    if d.at < bytes.len() {
        d.problem(format!(
            "{} bytes after the frame's end",
            bytes.len() - d.at
        ));
    }
    d.out
}

fn address_text(a: u16) -> String {
    let r = register_at(a);
    let half = if a % 2 == 1 { " (its high word)" } else { "" };
    format!("{a}: {}{half}", r.name)
}

fn count_text(n: u16) -> String {
    let regs = if n.is_multiple_of(2) {
        format!(" ({} × 32-bit)", n / 2)
    } else {
        " (odd: registers are 32-bit)".into()
    };
    format!("{n} registers{regs}")
}

struct Describer<'a> {
    bytes: &'a [u8],
    /// The next byte to read (0-based).
    at: usize,
    out: FrameDescription,
}

impl Describer<'_> {
    fn problem(&mut self, message: String) {
        self.out.problems.push(Problem {
            column: self.at + 1,
            message,
        });
    }

    /// The next `len` bytes as a field, or `None` (and a problem) when cut short.
    fn take(&mut self, name: &str, len: usize) -> Option<&[u8]> {
        let Some(raw) = self.bytes.get(self.at..self.at + len) else {
            self.problem(format!("cut short before the {name}"));
            self.at = self.bytes.len();
            return None;
        };
        self.at += len;
        Some(raw)
    }

    fn push(&mut self, name: String, len: usize, value: String, bits: Vec<BitNote>) {
        let first = self.at + 1 - len;
        let raw = self.bytes[self.at - len..self.at]
            .iter()
            .map(|b| format!("{b:02X}"))
            .collect::<Vec<_>>()
            .join(" ");
        self.out.fields.push(FieldDescription {
            name,
            columns: Columns::new(first, self.at),
            raw,
            value,
            bits,
        });
    }

    fn byte(&mut self, name: &str, text: impl FnOnce(u8) -> String) -> Option<u8> {
        let v = self.take(name, 1)?[0];
        self.push(name.into(), 1, text(v), Vec::new());
        Some(v)
    }

    fn word(&mut self, name: &str, text: impl FnOnce(u16) -> String) -> Option<u16> {
        let b = self.take(name, 2)?;
        let v = u16::from_be_bytes([b[0], b[1]]);
        self.push(name.into(), 2, text(v), Vec::new());
        Some(v)
    }

    fn mbap(&mut self) {
        if self.bytes.len() < MBAP_LEN {
            self.problem(format!(
                "{} bytes: too short for the MBAP header ({MBAP_LEN} bytes)",
                self.bytes.len()
            ));
        }
        self.word("transaction", |t| t.to_string());
        let at = self.at;
        if let Some(p) = self.word("protocol", |p| {
            if p == 0 {
                "0: Modbus".into()
            } else {
                format!("{p}: not Modbus (0)")
            }
        }) && p != 0
        {
            self.out.problems.push(Problem {
                column: at + 1,
                message: format!("protocol ID {p} is not Modbus (0)"),
            });
        }
        let at = self.at;
        let rest = self.bytes.len().saturating_sub(6);
        if let Some(n) = self.word("length", |n| format!("{n} bytes follow"))
            && usize::from(n) != rest
        {
            self.out.problems.push(Problem {
                column: at + 1,
                message: format!("the length says {n} bytes follow, {rest} do"),
            });
        }
        self.byte("unit", |u| u.to_string());
    }

    /// 32-bit registers from `address` to the end, each named and decoded.
    fn registers(&mut self, address: u16) {
        let mut address = address;
        while self.bytes.len() - self.at >= 4 {
            let b = &self.bytes[self.at..self.at + 4];
            // Each register's low word first (RMC.md section 1).
            let low = u16::from_be_bytes([b[0], b[1]]);
            let high = u16::from_be_bytes([b[2], b[3]]);
            self.at += 4;
            let register = register_at(address);
            let (value, bits) = register_value(&register, [low, high]);
            self.push(register.name, 4, value, bits);
            address = address.wrapping_add(2);
        }
        if self.at < self.bytes.len() {
            self.words_unnamed();
        }
    }

    /// The rest as plain 16-bit words.
    fn words_unnamed(&mut self) {
        let mut i = 0;
        while self.bytes.len() - self.at >= 2 {
            self.word(&format!("word {i}"), |w| format!("{w} ({w:#06x})"));
            i += 1;
        }
        if self.at < self.bytes.len() {
            self.take("last byte", 1);
            self.push(
                "odd byte".into(),
                1,
                "a word cut in half".into(),
                Vec::new(),
            );
        }
    }
}

/// A register's value in words and its bits, where it is a bit register.
fn register_value(register: &Register, words: [u16; 2]) -> (String, Vec<BitNote>) {
    let (name, unit) = (register.name.as_str(), register.unit);
    match register.kind {
        Kind::Dword => {
            let v = words_to_dword(words);
            let bits = if name.starts_with("Status Bits") {
                STATUS_BIT_NAMES
                    .iter()
                    .map(|&(bit, tag)| bit_note(bit, tag, StatusBits(v).bit(bit)))
                    .collect()
            } else if name.starts_with("Error Bits") {
                (0..32)
                    .filter(|&b| ErrorBits(v).bit(b))
                    .map(|b| bit_note(b, "set", true))
                    .zip(ErrorBits(v).names())
                    .map(|(mut note, name)| {
                        note.label = format!("{} {name}", note.label.trim_end_matches(" set"));
                        note
                    })
                    .collect()
            } else if name.starts_with("Controller Status") {
                vec![
                    BitNote {
                        label: "bit 0 RUN (1) / PROGRAM (0)".into(),
                        value: v & 1,
                        meaning: Some(if v & 1 != 0 { "RUN" } else { "PROGRAM" }),
                    },
                    bit_note(1, "Controller Enabled", v & 2 != 0),
                ]
            } else {
                Vec::new()
            };
            (format!("{v} ({v:#010x})"), bits)
        }
        Kind::Real => {
            let v = words_to_real(words);
            let mut text = if unit.is_empty() {
                v.to_string()
            } else {
                format!("{v} {unit}")
            };
            if register.is_command()
                && let Ok((c, req)) = Command::from_block(&[words[0], words[1]])
            {
                text = format!(
                    "{text}: {} ({}), REQ {}",
                    c.name(),
                    c.number(),
                    u8::from(req)
                );
            }
            (text, Vec::new())
        }
    }
}

fn bit_note(bit: u32, tag: &str, on: bool) -> BitNote {
    BitNote {
        label: format!("bit {bit} {tag}"),
        value: u32::from(on),
        meaning: None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rmc::modbus::{Header, Request, Response, encode_request, encode_response};
    use crate::rmc::{AxisId, AxisStatus, MoveRelative};
    use crate::robot::RelativeTo;

    const H: Header = Header {
        transaction: 7,
        unit: 1,
    };

    #[test]
    fn a_move_relative_write_reads_as_its_command_and_parameters() {
        let axis = AxisId::new(0).unwrap();
        let command = Command::MoveRelative(MoveRelative {
            distance: 10.0,
            speed: 5.0,
            accel: 100.0,
            decel: 100.0,
            relative_to: RelativeTo::Target,
        });
        let bytes = encode_request(
            H,
            &Request::Write {
                address: axis.command_block(),
                words: command.block(true),
            },
        );
        let d = describe(&bytes, Role::Request);
        assert_eq!(
            d.title,
            "FC16 write Command Area, Axis 1: Move Relative (21), REQ 1"
        );
        assert!(d.problems.is_empty(), "{:?}", d.problems);
        let value = |name: &str| {
            d.fields
                .iter()
                .find(|f| f.name == name)
                .map(|f| f.value.clone())
                .unwrap_or_else(|| panic!("no field {name} in {d}"))
        };
        assert_eq!(value("transaction"), "7");
        assert_eq!(
            value("start address"),
            "20480: Command Area: command, Axis 1"
        );
        assert_eq!(
            value("Command Area: command, Axis 1"),
            "277: Move Relative (21), REQ 1"
        );
        assert_eq!(value("Command Area: parameter 1, Axis 1"), "10");
        assert_eq!(value("Command Area: parameter 5, Axis 1"), "2");
        // Columns are byte positions: the command's REAL is bytes 14-17.
        let f = d
            .fields
            .iter()
            .find(|f| f.name.ends_with("command, Axis 1"))
            .unwrap();
        assert_eq!((f.columns.first, f.columns.last), (14, 17));
        // 277.0 is 0x438A8000: its low word first (RMC.md section 1).
        assert_eq!(f.raw, "80 00 43 8A");
    }

    #[test]
    fn a_status_reply_names_each_register_with_the_request_beside_it() {
        let axis = AxisId::new(1).unwrap();
        let request = encode_request(
            H,
            &Request::Read {
                address: axis.status_block(),
                count: crate::rmc::registers::STATUS_REGISTERS,
            },
        );
        let status = AxisStatus {
            bits: StatusBits(0).with(StatusBits::IN_POSITION, true),
            actual_position: 12.5,
            command_position: 12.5,
            ..AxisStatus::default()
        };
        let reply = encode_response(
            H,
            &Response::Registers {
                function: 3,
                words: status.encode(),
            },
        );
        assert_eq!(
            describe(&request, Role::Request).title,
            "FC3 read Status Bits..Command Velocity, Axis 2"
        );
        let d = describe(
            &reply,
            Role::Reply {
                request: Some(&request),
            },
        );
        assert_eq!(d.title, "FC3 reply: Status Bits..Command Velocity, Axis 2");
        assert!(d.problems.is_empty(), "{:?}", d.problems);
        let field = |name: &str| d.fields.iter().find(|f| f.name == name).unwrap();
        assert_eq!(field("Actual Position, Axis 2").value, "12.5 pu");
        let bits = &field("Status Bits, Axis 2").bits;
        assert!(
            bits.iter()
                .any(|b| b.label == "bit 0 In Position" && b.value == 1)
        );
        // Without its request a reply is still read, word by word.
        let blind = describe(&reply, Role::Reply { request: None });
        assert_eq!(blind.title, "FC3 reply");
        assert!(blind.fields.iter().any(|f| f.name == "word 0"));
    }

    #[test]
    fn exceptions_and_damage_are_named() {
        let reply = encode_response(
            H,
            &Response::Exception {
                function: 3,
                code: ExceptionCode::ILLEGAL_DATA_ADDRESS,
            },
        );
        let d = describe(&reply, Role::Reply { request: None });
        assert_eq!(d.title, "exception 02 (illegal data address) to FC3");
        assert!(d.problems.is_empty());
        let cut = describe(&reply[..5], Role::Reply { request: None });
        assert!(!cut.problems.is_empty());
        let d = describe(&[0, 1, 0, 9, 0, 2, 1, 3], Role::Request);
        assert!(
            d.problems.iter().any(|p| p.message.contains("not Modbus")),
            "{:?}",
            d.problems
        );
    }

    proptest::proptest! {
        #[test]
        fn any_bytes_are_described_without_panicking(bytes in proptest::collection::vec(0u8.., 0..300), req in proptest::collection::vec(0u8.., 0..20)) {
            describe(&bytes, Role::Request);
            describe(&bytes, Role::Reply { request: Some(&req) });
            request_title(&bytes);
            reply_title(&bytes, Some(&req));
        }
    }
}
