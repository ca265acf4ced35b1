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

/// Parses exactly 8 hex digits into a `u32` (the hot path of coordinate tables).
#[inline]
pub(crate) fn parse_hex8(s: &[u8; 8]) -> Option<u32> {
    let mut v: u32 = 0;
    let mut bad: u8 = 0;
    for &c in s {
        let d = LUT[c as usize];
        bad |= d;
        v = (v << 4) | u32::from(d & 0x0F);
    }
    if bad & 0xF0 != 0 { None } else { Some(v) }
}

/// Appends `v` as exactly `width` upper-case hex digits (`width` <= 8; higher digits of
/// `v` beyond `width` are dropped, so callers check the range first).
#[inline]
pub(crate) fn push_hex(out: &mut Vec<u8>, v: u32, width: usize) {
    let mut i = width.min(8);
    while i > 0 {
        i -= 1;
        out.push(DIGITS[((v >> (4 * i)) & 0xF) as usize]);
    }
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
