//! Housekeeping messages: 200H test call, 201H version query, 216H error details.

use std::fmt;

use crate::protocol::error::{EncodeError, MessageError};
use crate::protocol::fields::{Name, Reader, Show, decimal, printable};
use crate::protocol::ids::ErrorCode;
use crate::protocol::writer::Writer;

/// 200H test data: 0 to 10 printable ASCII characters, echoed by the controller.
/// [inferred] PROTOCOL.md 3.1: layout unknown; a host sends 10 characters.
#[derive(Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct TestData {
    len: u8,
    bytes: [u8; 10],
}

impl TestData {
    /// At most this many characters.
    pub const MAX_LEN: usize = 10;

    /// No data (the `!9920025` form).
    pub const EMPTY: TestData = TestData {
        len: 0,
        bytes: [0; 10],
    };

    /// Test data from 0-10 printable ASCII characters; `None` otherwise.
    pub fn new(data: &[u8]) -> Option<TestData> {
        if data.len() > Self::MAX_LEN || !data.iter().all(|&c| printable(c)) {
            return None;
        }
        let mut bytes = [0; 10];
        bytes.get_mut(..data.len())?.copy_from_slice(data);
        Some(TestData {
            len: data.len() as u8,
            bytes,
        })
    }

    /// The characters.
    pub fn as_bytes(&self) -> &[u8] {
        self.bytes.get(..usize::from(self.len)).unwrap_or(&[])
    }

    pub(crate) fn read(r: &mut Reader<'_, '_>) -> Result<Self, MessageError> {
        let n = r.remaining();
        if n > Self::MAX_LEN {
            let _ = r.text(Name::new("test data"), n, |_| true, "");
            return Err(r.invalid("0 to 10 characters"));
        }
        if n == 0 {
            return Ok(TestData::EMPTY);
        }
        let raw = r.text(
            Name::new("test data"),
            n,
            printable,
            "printable ASCII characters",
        )?;
        TestData::new(raw).ok_or_else(|| r.invalid("0 to 10 printable ASCII characters"))
    }

    pub(crate) fn write(&self, w: &mut Writer<'_>) -> Result<(), EncodeError> {
        w.bytes(self.as_bytes());
        Ok(())
    }
}

impl fmt::Debug for TestData {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "TestData(\"{}\")", self.as_bytes().escape_ascii())
    }
}

/// Unit type of a 201H version query (2 hex digits).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct UnitType(pub u8);

impl UnitType {
    /// 0: main CPU application.
    pub const MAIN_APPLICATION: UnitType = UnitType(0);
    /// 1: main CPU core.
    pub const MAIN_CORE: UnitType = UnitType(1);
    /// 2: driver CPU.
    pub const DRIVER: UnitType = UnitType(2);
    /// 3: mounted SIO board.
    pub const SIO_BOARD: UnitType = UnitType(3);
}

const UNIT_CODES: &[(u32, &str)] = &[
    (0, "main CPU application"),
    (1, "main CPU core"),
    (2, "driver CPU"),
    (3, "mounted SIO board"),
];

/// 201H command: which software's version to report.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct VersionQuery {
    /// Unit type.
    pub unit: UnitType,
    /// Device number of that type, from 0 (1 hex digit).
    pub device: u8,
}

impl VersionQuery {
    pub(crate) fn read(r: &mut Reader<'_, '_>) -> Result<Self, MessageError> {
        let unit = UnitType(r.u8(Name::new("unit type"), 2, Show::Code(UNIT_CODES))?);
        let device = r.u8(Name::new("device number"), 1, Show::Number)?;
        Ok(VersionQuery { unit, device })
    }

    pub(crate) fn write(&self, w: &mut Writer<'_>) -> Result<(), EncodeError> {
        w.hex_fit(u32::from(self.unit.0), 2);
        w.hex("device number", u32::from(self.device), 1)
    }
}

/// 201H reply: version and build time-stamp of the queried software (PROTOCOL.md 3.2).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct VersionInfo {
    /// Unit type (echo).
    pub unit: UnitType,
    /// Device number (echo, 1 hex digit).
    pub device: u8,
    /// Model code.
    pub model: u8,
    /// Unit code.
    pub unit_code: u8,
    /// Version number.
    pub version: u16,
    /// Year, e.g. 2024.
    pub year: u16,
    /// Month, 1-12.
    pub month: u8,
    /// Day, 1-31.
    pub day: u8,
    /// Hour, 0-23.
    pub hour: u8,
    /// Minute.
    pub minute: u8,
    /// Second.
    pub second: u8,
}

impl VersionInfo {
    pub(crate) fn read(r: &mut Reader<'_, '_>) -> Result<Self, MessageError> {
        let q = VersionQuery::read(r)?;
        let n = |s| Name::new(s);
        Ok(VersionInfo {
            unit: q.unit,
            device: q.device,
            model: r.u8(n("model code"), 2, Show::Hex)?,
            unit_code: r.u8(n("unit code"), 2, Show::Hex)?,
            version: r.u16(n("version number"), 4, Show::Hex)?,
            year: r.u16(n("year"), 4, Show::Number)?,
            month: r.u8(n("month"), 2, Show::Number)?,
            day: r.u8(n("day"), 2, Show::Number)?,
            hour: r.u8(n("hour"), 2, Show::Number)?,
            minute: r.u8(n("minute"), 2, Show::Number)?,
            second: r.u8(n("second"), 2, Show::Number)?,
        })
    }

    pub(crate) fn write(&self, w: &mut Writer<'_>) -> Result<(), EncodeError> {
        VersionQuery {
            unit: self.unit,
            device: self.device,
        }
        .write(w)?;
        w.hex_fit(u32::from(self.model), 2);
        w.hex_fit(u32::from(self.unit_code), 2);
        w.hex_fit(u32::from(self.version), 4);
        w.hex_fit(u32::from(self.year), 4);
        for v in [self.month, self.day, self.hour, self.minute, self.second] {
            w.hex_fit(u32::from(v), 2);
        }
        Ok(())
    }
}

/// 216H command: which error's details to report (PROTOCOL.md 3.5).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ErrorDetailQuery {
    /// Type 0: system error; `latest` = false for the critical-level one.
    System {
        /// Latest (true) or critical-level (false) error.
        latest: bool,
    },
    /// Type 1: axis error of this axis number.
    Axis {
        /// Axis number.
        axis: u8,
    },
    /// Type 2: program error of this program number.
    Program {
        /// Program number.
        program: u8,
    },
    /// Type 3: error-list record (from 1).
    ListRecord {
        /// Record number.
        record: u8,
    },
    /// Type 5: error-list record with extended record count (3 hex digits).
    ExtendedListRecord {
        /// Record number.
        record: u16,
    },
}

impl Default for ErrorDetailQuery {
    fn default() -> Self {
        ErrorDetailQuery::System { latest: true }
    }
}

const DETAIL_TYPES: &[(u32, &str)] = &[
    (0, "system error"),
    (1, "axis error"),
    (2, "program error"),
    (3, "error-list record"),
    (5, "error-list record, extended count"),
];

impl ErrorDetailQuery {
    pub(crate) fn read(r: &mut Reader<'_, '_>) -> Result<Self, MessageError> {
        let t1 = r.u8(Name::new("type 1"), 1, Show::Code(DETAIL_TYPES))?;
        if !matches!(t1, 0..=3 | 5) {
            return Err(r.invalid("0, 1, 2, 3 or 5 (4 is reserved)"));
        }
        let t2 = r.u8(Name::new("type 2"), 2, Show::Number)?;
        let q = match t1 {
            0 if t2 <= 1 => ErrorDetailQuery::System { latest: t2 == 1 },
            0 => return Err(r.invalid("00 (critical-level error) or 01 (latest error)")),
            1 => ErrorDetailQuery::Axis { axis: t2 },
            2 => ErrorDetailQuery::Program { program: t2 },
            3 => ErrorDetailQuery::ListRecord { record: t2 },
            _ if t2 != 0 => return Err(r.invalid("00 (unused for type 5)")),
            _ => ErrorDetailQuery::ExtendedListRecord { record: 0 },
        };
        let rec = r.u16(Name::new("record number"), 3, Show::Number)?;
        match q {
            ErrorDetailQuery::ExtendedListRecord { .. } => {
                Ok(ErrorDetailQuery::ExtendedListRecord { record: rec })
            }
            _ if rec != 0 => Err(r.invalid("000 (only used for type 5)")),
            q => Ok(q),
        }
    }

    pub(crate) fn write(&self, w: &mut Writer<'_>) -> Result<(), EncodeError> {
        let (t1, t2, rec) = match *self {
            ErrorDetailQuery::System { latest } => (0, u8::from(latest), 0),
            ErrorDetailQuery::Axis { axis } => (1, axis, 0),
            ErrorDetailQuery::Program { program } => (2, program, 0),
            ErrorDetailQuery::ListRecord { record } => (3, record, 0),
            ErrorDetailQuery::ExtendedListRecord { record } => (5, 0, record),
        };
        w.hex_fit(t1, 1);
        w.hex_fit(u32::from(t2), 2);
        w.hex("record number", u32::from(rec), 3)
    }
}

/// 216H reply: error number, eight detail words, reserved digits and message text.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct ErrorDetail {
    /// Error number.
    pub error: ErrorCode,
    /// Details 1-8 as sent (8 hex digits each). Detail 4 may be negative (two's
    /// complement): read it with `as i32`.
    pub details: [u32; 8],
    /// The 15 reserved decimal digits (fields of 2,2,2,1,2,2,4), kept as received.
    pub reserved: [u8; 15],
    /// Message text (at most 255 bytes, no CR or LF; always empty on R/S/RX/SX/RXD/SXD/TTA).
    pub message: Vec<u8>,
}

impl Default for ErrorDetail {
    fn default() -> Self {
        ErrorDetail {
            error: ErrorCode::NONE,
            details: [0; 8],
            reserved: *b"000000000000000",
            message: Vec::new(),
        }
    }
}

const RESERVED_WIDTHS: [usize; 7] = [2, 2, 2, 1, 2, 2, 4];
const DETAIL_NAMES: [&str; 8] = [
    "detail 1 (program number / system-down type)",
    "detail 2 (step number / system-down code)",
    "detail 3 (axis number / system-down info 1)",
    "detail 4 (point number / system-down info 2)",
    "detail 5",
    "detail 6",
    "detail 7",
    "detail 8",
];

impl ErrorDetail {
    /// The message text for display (invalid UTF-8 replaced).
    pub fn message_text(&self) -> String {
        String::from_utf8_lossy(&self.message).into_owned()
    }

    pub(crate) fn read(r: &mut Reader<'_, '_>) -> Result<Self, MessageError> {
        let error = r.error_code(Name::new("error number"))?;
        let mut details = [0u32; 8];
        for (d, name) in details.iter_mut().zip(DETAIL_NAMES) {
            *d = r.hex(Name::new(name), 8, Show::Hex)?;
        }
        let mut reserved = [b'0'; 15];
        let mut at = 0;
        for w in RESERVED_WIDTHS {
            let raw = r.text(Name::new("reserved"), w, decimal, "decimal digits")?;
            if let Some(dst) = reserved.get_mut(at..at + w) {
                dst.copy_from_slice(raw);
            }
            at += w;
        }
        let n = usize::from(r.u8(Name::new("message byte count"), 2, Show::Number)?);
        let message = if n == 0 {
            Vec::new()
        } else {
            r.text(
                Name::new("message text"),
                n,
                |c| c != b'\r' && c != b'\n',
                "characters without CR or LF",
            )?
            .to_vec()
        };
        Ok(ErrorDetail {
            error,
            details,
            reserved,
            message,
        })
    }

    pub(crate) fn write(&self, w: &mut Writer<'_>) -> Result<(), EncodeError> {
        w.hex("error number", u32::from(self.error.0), 3)?;
        for d in self.details {
            w.hex_fit(d, 8);
        }
        if !self.reserved.iter().all(u8::is_ascii_digit) {
            return Err(w.error("reserved", "must be 15 decimal digits"));
        }
        let n = self.message.len();
        if n > 255 || self.message.iter().any(|&c| c == b'\r' || c == b'\n') {
            return Err(w.error("message text", "must be at most 255 bytes without CR or LF"));
        }
        w.bytes(&self.reserved);
        w.hex_fit(n as u32, 2);
        w.bytes(&self.message);
        Ok(())
    }
}
