//! A row as stored: 16 bytes (time, where its bytes are, kind, verdict, message ID),
//! the bytes themselves kept in the chunk's buffer.

use std::ops::Range;

use super::row::{Dir, Protocol, Verdict};

/// The longest stored form of a row's bytes: a garbage run is at most a header and
/// `MAX_FRAME_LEN` bytes [spec: PROTOCOL.md 1.3]; a frame is shorter.
pub(super) const MAX_ROW_BYTES: usize = crate::protocol::MAX_FRAME_LEN + 1;
/// The longest note (the link's reason for garbage, a time-out text) kept whole.
pub(super) const MAX_NOTE_BYTES: usize = 32 * 1024;
/// Rows per chunk times the largest row (bytes, note length, note) must fit the 28-bit
/// offset.
const _: () = assert!(
    super::CHUNK * (MAX_ROW_BYTES + 2 + MAX_NOTE_BYTES) < OFFSET_LIMIT as usize
        && MAX_ROW_BYTES <= u16::MAX as usize
);

const OFFSET_LIMIT: u32 = 1 << 28;
/// In `stored_len`: the row is Modbus/TCP (stored lengths stay below it).
const MODBUS: u16 = 1 << 15;
const _: () = assert!(MAX_ROW_BYTES < MODBUS as usize);
const ID_MASK: u16 = 0x0FFF;
/// No message ID could be read.
const NO_ID: u16 = 1 << 12;
/// The row answers the last request of its protocol before it (within
/// [`super::PAIR_REACH`] rows).
const ANSWERS: u16 = 1 << 13;
/// A note follows the stored bytes: its length (u16, little-endian), then its text.
const HAS_NOTE: u16 = 1 << 14;
/// The stored bytes are the packed form of a frame (see `packed`).
const PACKED: u16 = 1 << 15;

#[derive(Clone, Copy, Debug)]
pub(super) struct Entry {
    t_ns: u64,
    /// Bits 0-27: offset of the stored bytes in the chunk's buffer; 28-29: direction;
    /// 30-31: checksum verdict.
    place: u32,
    /// Length of the stored bytes (the note not counted), and the [`MODBUS`] bit.
    stored_len: u16,
    /// Bits 0-11: message ID (a Modbus row's function code), then the flags above.
    flags: u16,
}

const _: () = assert!(std::mem::size_of::<Entry>() == 16);

impl Entry {
    pub fn new(dir: Dir, t_ns: u64, bytes: &[u8]) -> Entry {
        let verdict = match dir {
            Dir::Timeout => Verdict::None,
            _ => Verdict::of(bytes),
        };
        Entry {
            t_ns,
            place: u32::from(dir.code()) << 28 | u32::from(verdict.code()) << 30,
            stored_len: 0,
            flags: message_id(bytes).unwrap_or(NO_ID),
        }
    }

    /// A Modbus/TCP row: no checksum to judge; its ID is the function code.
    pub fn modbus(dir: Dir, t_ns: u64, bytes: &[u8]) -> Entry {
        let function = bytes.get(crate::rmc::modbus::MBAP_LEN).copied();
        Entry {
            t_ns,
            place: u32::from(dir.code()) << 28 | u32::from(Verdict::None.code()) << 30,
            stored_len: MODBUS,
            flags: function.map_or(NO_ID, u16::from),
        }
    }

    pub fn protocol(&self) -> Protocol {
        if self.stored_len & MODBUS != 0 {
            Protocol::Modbus
        } else {
            Protocol::FormatB
        }
    }

    /// Where the stored bytes are; `len` must not exceed [`MAX_ROW_BYTES`].
    pub fn set_stored(&mut self, start: usize, len: usize, packed: bool, has_note: bool) {
        debug_assert!(start < OFFSET_LIMIT as usize && len <= MAX_ROW_BYTES);
        self.place = (self.place & !(OFFSET_LIMIT - 1)) | (start as u32 & (OFFSET_LIMIT - 1));
        self.stored_len = (self.stored_len & MODBUS) | len as u16;
        self.flags &= !(PACKED | HAS_NOTE);
        if packed {
            self.flags |= PACKED;
        }
        if has_note {
            self.flags |= HAS_NOTE;
        }
    }

    pub fn stored(&self) -> Range<usize> {
        let start = (self.place & (OFFSET_LIMIT - 1)) as usize;
        start..start + usize::from(self.stored_len & !MODBUS)
    }

    pub fn packed(&self) -> bool {
        self.flags & PACKED != 0
    }

    pub fn has_note(&self) -> bool {
        self.flags & HAS_NOTE != 0
    }

    pub fn t_ns(&self) -> u64 {
        self.t_ns
    }

    pub fn dir(&self) -> Dir {
        Dir::from_code((self.place >> 28 & 0b11) as u8)
    }

    pub fn verdict(&self) -> Verdict {
        Verdict::from_code((self.place >> 30) as u8)
    }

    pub fn id(&self) -> Option<u16> {
        (self.flags & NO_ID == 0).then_some(self.flags & ID_MASK)
    }

    /// Takes the request's ID (an `&` reply and a time-out have none of their own).
    pub fn take_id(&mut self, id: Option<u16>) {
        if self.id().is_none()
            && let Some(id) = id
        {
            self.flags = (self.flags & !(NO_ID | ID_MASK)) | (id & ID_MASK);
        }
    }

    /// The row answers the last request of its protocol before it: each line has one
    /// request outstanding, so every row of a line after a request answers it.
    pub fn answers(&self) -> bool {
        self.flags & ANSWERS != 0
    }

    pub fn set_answers(&mut self) {
        self.flags |= ANSWERS;
    }
}

/// The message ID in columns 4-6 [spec: PROTOCOL.md 1.3]; `&` replies carry none.
fn message_id(bytes: &[u8]) -> Option<u16> {
    crate::protocol::peek::message_id(bytes).map(|id| id.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_field_reads_back_as_set() {
        let mut e = Entry::new(Dir::Garbage, u64::MAX - 1, b"!992A1@@\r\n");
        e.set_stored(OFFSET_LIMIT as usize - 1, MAX_ROW_BYTES, true, true);
        e.set_answers();
        assert_eq!(e.t_ns(), u64::MAX - 1);
        assert_eq!(e.dir(), Dir::Garbage);
        assert_eq!(e.verdict(), Verdict::AtAt);
        assert_eq!(e.id(), Some(0x2A1));
        assert_eq!(
            e.stored(),
            OFFSET_LIMIT as usize - 1..OFFSET_LIMIT as usize - 1 + MAX_ROW_BYTES
        );
        assert!(e.packed() && e.has_note() && e.answers());
        assert_eq!(e.protocol(), Protocol::FormatB);

        let mut t = Entry::new(Dir::Timeout, 0, b"");
        assert_eq!(
            (t.dir(), t.verdict(), t.id()),
            (Dir::Timeout, Verdict::None, None)
        );
        t.take_id(Some(0xFFF));
        assert_eq!(t.id(), Some(0xFFF));
        t.take_id(Some(0x212));
        assert_eq!(t.id(), Some(0xFFF), "an ID once set stays");
        assert!(!t.packed() && !t.has_note() && !t.answers());
        let mut m = Entry::modbus(Dir::Received, 5, &[0, 1, 0, 0, 0, 3, 1, 0x83, 2]);
        m.set_stored(9, MAX_ROW_BYTES, true, false);
        assert_eq!(m.protocol(), Protocol::Modbus);
        assert_eq!((m.id(), m.verdict()), (Some(0x83), Verdict::None));
        assert_eq!(
            m.stored(),
            9..9 + MAX_ROW_BYTES,
            "the Modbus bit is not a length"
        );
        assert_eq!(Entry::new(Dir::Sent, 0, b"!99+FF00\r\n").id(), None);
    }
}
