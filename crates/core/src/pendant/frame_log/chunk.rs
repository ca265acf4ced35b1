//! A chunk of rows with the buffer their bytes are stored in, and the index that lets a
//! filling chunk keep a repeated frame once and a changed one as a delta.

use std::collections::HashMap;
use std::hash::{BuildHasher, RandomState};

use super::CHUNK;
use super::entry::Entry;
use super::packed;
use super::row::Protocol;

/// Rows and the bytes they point into.
#[derive(Clone, Debug, Default)]
pub struct Chunk {
    pub(super) entries: Vec<Entry>,
    pub(super) bytes: Vec<u8>,
}

impl Chunk {
    pub(super) fn new() -> Self {
        Self {
            entries: Vec::with_capacity(CHUNK),
            bytes: Vec::with_capacity(CHUNK * 8),
        }
    }

    /// Bytes of memory held (capacity counted).
    pub(super) fn memory_bytes(&self) -> usize {
        self.entries.capacity() * size_of::<Entry>() + self.bytes.capacity()
    }

    /// Stores `bytes` (packed when a clean frame, or Modbus) on their own: start, length,
    /// packed.
    pub(super) fn store_alone(&mut self, bytes: &[u8], protocol: Protocol) -> (usize, usize, bool) {
        let start = self.bytes.len();
        let packed = match protocol {
            Protocol::FormatB => packed::pack_into(bytes, &mut self.bytes),
            Protocol::Modbus => packed::pack_modbus_into(bytes, &mut self.bytes),
        };
        if !packed {
            self.bytes.extend_from_slice(bytes);
        }
        (start, self.bytes.len() - start, packed)
    }
}

/// Same protocol, kind and message ID, same packed length: frames that may be stored as
/// deltas of each other.
type Kind = (Protocol, u8, Option<u16>, usize);

/// What the open chunk holds: where each packed form is stored (by the form's hash,
/// checked against the bytes on a hit), and per kind the last one stored whole.
#[derive(Clone, Debug, Default)]
pub(super) struct OpenIndex {
    hasher: RandomState,
    seen: HashMap<u64, (usize, usize)>,
    whole: HashMap<Kind, usize>,
}

impl OpenIndex {
    /// Stores `bytes` of the row `e` in `chunk`: a packed frame seen before in the chunk
    /// is shared, one close to the last whole one of its kind becomes a delta. Raw bytes
    /// are stored on their own (they could equal a packed form of other bytes).
    pub(super) fn store(
        &mut self,
        chunk: &mut Chunk,
        bytes: &[u8],
        e: &Entry,
    ) -> (usize, usize, bool) {
        let (start, len, packed) = chunk.store_alone(bytes, e.protocol());
        if !packed {
            return (start, len, packed);
        }
        let (before, form) = chunk.bytes.split_at(start);
        let hash = self.hasher.hash_one(form);
        if let Some(&(earlier, earlier_len)) = self.seen.get(&hash)
            && packed::packed_form_is(before, earlier..earlier + earlier_len, form)
        {
            chunk.bytes.truncate(start);
            return (earlier, earlier_len, packed);
        }
        let kind = (e.protocol(), e.dir().code(), e.id(), len);
        let delta = self
            .whole
            .get(&kind)
            .is_some_and(|&reference| packed::delta_against(&mut chunk.bytes, start, reference));
        if !delta {
            self.whole.insert(kind, start);
        }
        let len = chunk.bytes.len() - start;
        self.seen.insert(hash, (start, len));
        (start, len, packed)
    }

    /// Bytes of memory held (the tables' capacity).
    pub(super) fn memory_bytes(&self) -> usize {
        self.seen.capacity() * (size_of::<(u64, (usize, usize))>() + 1)
            + self.whole.capacity() * (size_of::<(Kind, usize)>() + 1)
    }
}
