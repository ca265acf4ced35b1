//! The stored form of a row's bytes: a well-formed Format B frame as hex nibbles (half
//! the size), anything else byte for byte.
//!
//! A frame packs when it is a header (`!`, `#` or `&`), upper-case hex digits, an SC of
//! two more digits or `@@`, and CR LF [spec: PROTOCOL.md 1.3, 1.4]. Lower-case hex, stray
//! bytes or a missing CR LF keep the raw form, so the bytes read back are always exactly
//! the bytes that were on the line.
//!
//! A Modbus/TCP frame (binary already) is stored as a tag and its bytes, so that it too
//! may be shared or stored as a delta.
//!
//! A packed frame may be stored as a delta instead: the same length as an earlier packed
//! frame in the chunk (its reference), with the runs of bytes that changed. Polling replies differ from
//! the last one only where a position moved, so they take a tenth of the room.

use std::borrow::Cow;
use std::ops::Range;

/// Tag bits of a packed frame's first stored byte.
const HEADER_MASK: u8 = 0b0011;
const AT_AT: u8 = 0b0100;
const ODD: u8 = 0b1000;
const HEADERS: [u8; 3] = [b'!', b'#', b'&'];
/// The header bits of a Modbus frame's tag (no Format B header has them).
const MODBUS_TAG: u8 = 0b0011;
/// The first byte of a delta (a packed frame's tag never has it).
const DELTA: u8 = 0x80;

/// The value of an upper-case hex digit (`None` for anything else, lower case included).
fn nibble(b: u8) -> Option<u8> {
    match b {
        b'0'..=b'9' => Some(b - b'0'),
        b'A'..=b'F' => Some(b - b'A' + 10),
        _ => None,
    }
}

const DIGITS: &[u8; 16] = b"0123456789ABCDEF";
/// The two hex digits of each byte value.
const DIGIT_PAIRS: [[u8; 2]; 256] = {
    let mut pairs = [[0; 2]; 256];
    let mut i = 0;
    while i < 256 {
        pairs[i] = [DIGITS[i >> 4], DIGITS[i & 0xF]];
        i += 1;
    }
    pairs
};
/// Deltas of packed forms up to this long are rebuilt on the stack.
const STACK_FORM: usize = 256;

/// Appends the packed form of `bytes` to `out` and returns true, or leaves `out` as it was
/// and returns false when the bytes are not a packable frame (or have fewer than two
/// digits: nothing worth packing).
pub fn pack_into(bytes: &[u8], out: &mut Vec<u8>) -> bool {
    let Some(body) = bytes.strip_suffix(b"\r\n") else {
        return false;
    };
    let Some(header) = body
        .first()
        .and_then(|h| HEADERS.iter().position(|x| x == h))
    else {
        return false;
    };
    let (digits, at_at) = match body[1..].strip_suffix(b"@@") {
        Some(d) => (d, true),
        None => (&body[1..], false),
    };
    if digits.len() < 2 || !digits.iter().all(|&b| nibble(b).is_some()) {
        return false;
    }
    let odd = digits.len() % 2 == 1;
    out.push(header as u8 | if at_at { AT_AT } else { 0 } | if odd { ODD } else { 0 });
    for pair in digits.chunks(2) {
        let hi = nibble(pair[0]).unwrap_or(0);
        let lo = pair.get(1).and_then(|&b| nibble(b)).unwrap_or(0);
        out.push(hi << 4 | lo);
    }
    true
}

/// Appends the stored form of a Modbus/TCP frame to `out` (false, and nothing, for no
/// bytes).
pub fn pack_modbus_into(bytes: &[u8], out: &mut Vec<u8>) -> bool {
    if bytes.is_empty() {
        return false;
    }
    out.push(MODBUS_TAG);
    out.extend_from_slice(bytes);
    true
}

/// Appends the original bytes of the packed form `stored` to `out`.
pub fn unpack_into(stored: &[u8], out: &mut Vec<u8>) {
    let Some((&tag, packed)) = stored.split_first() else {
        return;
    };
    if tag & HEADER_MASK == MODBUS_TAG {
        out.extend_from_slice(packed);
        return;
    }
    out.reserve(packed.len() * 2 + 5);
    out.push(HEADERS[usize::from(tag & HEADER_MASK).min(2)]);
    for &b in packed {
        out.extend_from_slice(&DIGIT_PAIRS[usize::from(b)]);
    }
    if tag & ODD != 0 {
        out.pop();
    }
    if tag & AT_AT != 0 {
        out.extend_from_slice(b"@@");
    }
    out.extend_from_slice(b"\r\n");
}

/// Stores the packed form at `buf[start..]` as a delta against the packed form of the
/// same length at `buf[reference..]` (the runs of bytes that changed), when that takes at
/// most half the room. Returns whether it did.
pub fn delta_against(buf: &mut Vec<u8>, start: usize, reference: usize) -> bool {
    let (before, new) = buf.split_at(start);
    let Some(old) = before.get(reference..reference + new.len()) else {
        return false;
    };
    let mut form = vec![DELTA];
    push_varint(&mut form, start - reference);
    push_varint(&mut form, new.len());
    let (mut at, mut copied_to) = (0, 0);
    while at < new.len() && form.len() * 2 <= new.len() {
        if old[at] == new[at] {
            at += 1;
            continue;
        }
        // A run of changes; gaps of up to two equal bytes cost less inside it than as
        // a new run's header.
        let run_start = at;
        let mut run_end = at + 1;
        while run_end < new.len()
            && (run_end..(run_end + 3).min(new.len())).any(|i| old[i] != new[i])
        {
            run_end += 1;
        }
        push_varint(&mut form, run_start - copied_to);
        push_varint(&mut form, run_end - run_start);
        form.extend_from_slice(&new[run_start..run_end]);
        (at, copied_to) = (run_end, run_end);
    }
    if form.len() * 2 > new.len() {
        return false;
    }
    buf.truncate(start);
    buf.extend_from_slice(&form);
    true
}

/// Whether the stored form at `buf[at]` is the packed form `form`.
pub fn packed_form_is(buf: &[u8], at: Range<usize>, form: &[u8]) -> bool {
    with_packed_form(buf, at, |f| f == form)
}

/// Calls `f` with the packed form of the stored form at `buf[at]`: itself, or rebuilt
/// from a delta (on the stack when short; empty when the delta is damaged).
fn with_packed_form<R>(buf: &[u8], at: Range<usize>, f: impl FnOnce(&[u8]) -> R) -> R {
    let stored = buf.get(at.clone()).unwrap_or_default();
    if stored.first().is_none_or(|&t| t & DELTA == 0) {
        return f(stored);
    }
    let mut delta = &stored[1..];
    let header = read_varint(&mut delta).zip(read_varint(&mut delta));
    let Some(old) = header.and_then(|(back, len)| {
        let from = at.start.checked_sub(back)?;
        buf.get(from..)?.get(..len)
    }) else {
        return f(&[]);
    };
    if old.len() <= STACK_FORM {
        let mut form = [0u8; STACK_FORM];
        let len = rebuild(old, delta, &mut form).unwrap_or(0);
        f(&form[..len])
    } else {
        let mut form = vec![0u8; old.len()];
        let len = rebuild(old, delta, &mut form).unwrap_or(0);
        f(&form[..len])
    }
}

/// Writes into `form` the packed form that the runs of `delta` make of `old`; its length.
fn rebuild(old: &[u8], mut delta: &[u8], form: &mut [u8]) -> Option<usize> {
    let form = form.get_mut(..old.len())?;
    form.copy_from_slice(old);
    let mut at = 0;
    while !delta.is_empty() {
        at += read_varint(&mut delta)?;
        let run = read_varint(&mut delta)?;
        let (bytes, rest) = delta.split_at_checked(run)?;
        form.get_mut(at..at + run)?.copy_from_slice(bytes);
        at += run;
        delta = rest;
    }
    Some(old.len())
}

fn push_varint(out: &mut Vec<u8>, mut v: usize) {
    while v >= 0x80 {
        out.push(v as u8 | 0x80);
        v >>= 7;
    }
    out.push(v as u8);
}

fn read_varint(input: &mut &[u8]) -> Option<usize> {
    let mut v = 0usize;
    for shift in (0..35).step_by(7) {
        let (&b, rest) = input.split_first()?;
        *input = rest;
        v |= usize::from(b & 0x7F) << shift;
        if b & 0x80 == 0 {
            return Some(v);
        }
    }
    None
}

/// Appends the original bytes of the row stored at `buf[at]` to `out`.
pub fn write_original(buf: &[u8], at: Range<usize>, packed: bool, out: &mut Vec<u8>) {
    if packed {
        with_packed_form(buf, at, |form| unpack_into(form, out));
    } else {
        out.extend_from_slice(buf.get(at).unwrap_or_default());
    }
}

/// The original bytes of the row stored at `buf[at]`: borrowed when raw, rebuilt when
/// packed.
pub fn original(buf: &[u8], at: Range<usize>, packed: bool) -> Cow<'_, [u8]> {
    if packed {
        let mut out = Vec::new();
        write_original(buf, at, true, &mut out);
        Cow::Owned(out)
    } else {
        Cow::Borrowed(buf.get(at).unwrap_or_default())
    }
}

/// The first original byte (the header, for a frame) of the row stored at `buf[at]`.
pub fn first_byte(buf: &[u8], at: Range<usize>, packed: bool) -> Option<u8> {
    if !packed {
        return buf.get(at)?.first().copied();
    }
    with_packed_form(buf, at, |form| {
        let first = *form.first()?;
        if first & HEADER_MASK == MODBUS_TAG {
            form.get(1).copied()
        } else {
            Some(HEADERS[usize::from(first & HEADER_MASK)])
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn round_trip(bytes: &[u8]) -> Option<Vec<u8>> {
        let mut stored = Vec::new();
        pack_into(bytes, &mut stored).then(|| {
            assert!(
                stored.len() < bytes.len(),
                "{:?} did not shrink",
                bytes.escape_ascii()
            );
            assert_eq!(
                first_byte(&stored, 0..stored.len(), true),
                bytes.first().copied()
            );
            original(&stored, 0..stored.len(), true).into_owned()
        })
    }

    #[test]
    fn frames_pack_to_about_half_and_come_back_exactly() {
        let reply =
            b"#992A10100000F1C000000000493E01C000000FFFDB6101C00000000004E201C0000000000AFC811\r\n";
        let mut stored = Vec::new();
        assert!(pack_into(reply, &mut stored));
        assert_eq!(stored.len(), 1 + 40);
        for frame in [
            &reply[..],
            b"!992A10F0DD\r\n",
            b"!99212@@\r\n",
            b"&99C1F00\r\n",
            b"#9921\r\n",
        ] {
            assert_eq!(
                round_trip(frame).as_deref(),
                Some(frame),
                "{:?}",
                frame.escape_ascii()
            );
        }
    }

    #[test]
    fn anything_but_a_clean_frame_stays_raw() {
        for raw in [
            &b"!992a10F0DD\r\n"[..], // lower-case hex is kept as typed
            b"!992A10F0DD\n",
            b"!992A10F0DD\r\n\r\n",
            b"\x02!99212\r\n",
            b"?99212AB\r\n",
            b"!9\r\n",
            b"",
            b"!99 212\r\n",
        ] {
            assert_eq!(round_trip(raw), None, "{:?}", raw.escape_ascii());
        }
    }

    #[test]
    fn a_moved_position_is_stored_as_a_small_delta_and_comes_back_exactly() {
        let body = "#992A10100000F1C000000000493E01C000000FFFDB6101C00000000004E201C000000";
        let frame = |pos: u32| format!("{body}{pos:08X}11\r\n").into_bytes();
        let mut buf = Vec::new();
        assert!(pack_into(&frame(0xAFC8), &mut buf));
        let full = buf.len();
        let mut rows = vec![(0..full, frame(0xAFC8))];
        for pos in [0xAFD0, 0xB000, 0x1_0000] {
            let start = buf.len();
            assert!(pack_into(&frame(pos), &mut buf));
            assert!(delta_against(&mut buf, start, 0));
            assert!(
                buf.len() - start <= 10,
                "{} bytes for a moved position",
                buf.len() - start
            );
            rows.push((start..buf.len(), frame(pos)));
        }
        for (at, bytes) in rows {
            assert_eq!(original(&buf, at.clone(), true).as_ref(), bytes.as_slice());
            assert_eq!(first_byte(&buf, at, true), Some(b'#'));
        }
        // A frame that differs all over stays whole.
        let start = buf.len();
        assert!(pack_into(
            b"#992A1FFFFFFFFFFFFFFFFFFFFFFFFFFFFFFFFFFFFFFFFFFFFFFFFFFFFFFFFFFFFFFFFFFFFFFFFFF\r\n",
            &mut buf
        ));
        assert!(!delta_against(&mut buf, start, 0));
        assert_eq!(buf.len() - start, full);
    }

    proptest! {
        #[test]
        fn any_bytes_come_back_exactly(bytes in proptest::collection::vec(
            prop_oneof![Just(b'!'), Just(b'#'), Just(b'@'), Just(b'\r'), Just(b'\n'),
                        Just(b'A'), Just(b'f'), Just(b'0'), Just(b'9'), any::<u8>()],
            0..40,
        )) {
            let mut stored = Vec::new();
            if pack_into(&bytes, &mut stored) {
                prop_assert_eq!(original(&stored, 0..stored.len(), true).into_owned(), bytes);
            } else {
                prop_assert!(stored.is_empty());
            }
        }

        #[test]
        fn deltas_come_back_exactly(
            a in proptest::collection::vec(0u8..16, 2..60),
            edits in proptest::collection::vec((any::<prop::sample::Index>(), 0u8..16), 0..6),
        ) {
            let hex = |d: &[u8]| {
                let mut f = vec![b'#'];
                f.extend(d.iter().map(|&n| DIGITS[usize::from(n)]));
                f.extend_from_slice(b"\r\n");
                f
            };
            let mut b = a.clone();
            for (i, v) in edits {
                b[i.index(a.len())] = v;
            }
            let mut buf = Vec::new();
            prop_assert!(pack_into(&hex(&a), &mut buf));
            let start = buf.len();
            prop_assert!(pack_into(&hex(&b), &mut buf));
            delta_against(&mut buf, start, 0);
            prop_assert_eq!(original(&buf, start..buf.len(), true).into_owned(), hex(&b));
            prop_assert_eq!(original(&buf, 0..start, true).into_owned(), hex(&a));
        }
    }
}
