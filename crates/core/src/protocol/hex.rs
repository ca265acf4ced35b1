//! Fixed-width ASCII hex: a lookup-table parser and upper-case writers.

/// Marks a byte that is not a hex digit (any value with the high nibble set).
const INVALID: u8 = 0xFF;

/// Digit value of every byte, `INVALID` where the byte is not `0-9`, `A-F` or `a-f`.
static LUT: [u8; 256] = build_lut();

const fn build_lut() -> [u8; 256] {
    let mut t = [INVALID; 256];
    let mut i = 0;
    while i < 10 {
        t[b'0' as usize + i] = i as u8;
        i += 1;
    }
    let mut j = 0;
    while j < 6 {
        t[b'A' as usize + j] = 10 + j as u8;
        t[b'a' as usize + j] = 10 + j as u8;
        j += 1;
    }
    t
}

/// Upper-case hex digits, as always sent.
pub(crate) const DIGITS: &[u8; 16] = b"0123456789ABCDEF";

/// Parses up to 8 hex digits (either case), most significant first.
/// `None` if any byte is not a hex digit, or if there are no digits or more than 8.
#[inline]
pub(crate) fn parse_hex(s: &[u8]) -> Option<u32> {
    if s.is_empty() || s.len() > 8 {
        return None;
    }
    let mut v: u32 = 0;
    let mut bad: u8 = 0;
    for &c in s {
        let d = LUT[c as usize];
        bad |= d;
        v = (v << 4) | u32::from(d & 0x0F);
    }
    if bad & 0xF0 != 0 { None } else { Some(v) }
}

/// Parses exactly 8 hex digits (either case) into a `u32`, eight bytes at a time (SWAR):
/// the hot path of coordinate tables.
#[inline]
pub(crate) fn parse_hex8(s: &[u8; 8]) -> Option<u32> {
    const ONES: u64 = 0x0101_0101_0101_0101;
    const HIGH: u64 = 0x8080_8080_8080_8080;
    // Most significant digit in the most significant byte.
    let x = u64::from_be_bytes(*s);
    if x & HIGH != 0 {
        return None;
    }
    // High bit of each byte set where lo <= byte <= hi (bytes are < 80H, so no carries).
    let in_range = |v: u64, lo: u8, hi: u8| {
        let ge = v.wrapping_add(ONES * u64::from(0x80 - lo));
        let gt = v.wrapping_add(ONES * u64::from(0x7F - hi));
        ge & !gt & HIGH
    };
    let digit = in_range(x, b'0', b'9');
    // Setting bit 5 maps 'A'-'F' onto 'a'-'f' and nothing else onto them.
    let alpha = in_range(x | (ONES * 0x20), b'a', b'f');
    if digit | alpha != HIGH {
        return None;
    }
    let nib = (x & (ONES * 0x0F)) + (alpha >> 7) * 9;
    let b = ((nib >> 4) | nib) & 0x00FF_00FF_00FF_00FF;
    let w = ((b >> 8) | b) & 0x0000_FFFF_0000_FFFF;
    Some((((w >> 16) | w) & 0xFFFF_FFFF) as u32)
}

/// Appends `v` as exactly `width` upper-case hex digits (`width` <= 8; higher digits of
/// `v` beyond `width` are dropped, so callers check the range first).
#[inline]
pub(crate) fn push_hex(out: &mut Vec<u8>, v: u32, width: usize) {
    let width = width.min(8);
    let mut digits = [0u8; 8];
    for (i, d) in digits.iter_mut().enumerate() {
        *d = DIGITS[((v >> (28 - 4 * i)) & 0xF) as usize];
    }
    out.extend_from_slice(digits.get(8 - width..).unwrap_or(&[]));
}

/// Whether `v` fits in `width` hex digits.
#[inline]
pub(crate) fn fits(v: u32, width: usize) -> bool {
    width >= 8 || v < (1u32 << (4 * width))
}

/// Largest value that fits in `width` hex digits.
pub(crate) fn max_for(width: usize) -> u32 {
    if width >= 8 {
        u32::MAX
    } else {
        (1u32 << (4 * width)) - 1
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_both_cases() {
        assert_eq!(parse_hex(b"FFFFEC78"), Some(0xFFFF_EC78));
        assert_eq!(parse_hex(b"ffffec78"), Some(0xFFFF_EC78));
        assert_eq!(parse_hex(b"0"), Some(0));
        assert_eq!(parse_hex8(b"0000C350"), Some(50_000));
    }

    #[test]
    fn rejects_non_digits() {
        assert_eq!(parse_hex(b"G0"), None);
        assert_eq!(parse_hex(b" 1"), None);
        assert_eq!(parse_hex(b""), None);
        assert_eq!(parse_hex(b"123456789"), None);
        assert_eq!(parse_hex8(b"0000C35@"), None);
    }

    #[test]
    fn swar_parser_agrees_with_the_table_on_every_byte_in_every_position() {
        for pos in 0..8 {
            for c in 0..=255u8 {
                let mut s = *b"8aF0c3E1";
                s[pos] = c;
                assert_eq!(parse_hex8(&s), parse_hex(&s), "{pos} {c:#x}");
            }
        }
        assert_eq!(parse_hex8(b"FFFFFFFF"), Some(u32::MAX));
        assert_eq!(parse_hex8(b"01234567"), Some(0x0123_4567));
        assert_eq!(parse_hex8(b"89abcdef"), Some(0x89AB_CDEF));
    }

    #[test]
    fn writes_upper_case_fixed_width() {
        let mut v = Vec::new();
        push_hex(&mut v, 0xFFFF_EC78, 8);
        push_hex(&mut v, 0x2c, 2);
        push_hex(&mut v, 5, 3);
        assert_eq!(v, b"FFFFEC782C005");
        assert!(fits(0xFFF, 3));
        assert!(!fits(0x1000, 3));
        assert_eq!(max_for(4), 0xFFFF);
    }
}
