//! The SC (sum check) field: low byte of the sum of the frame's bytes (PROTOCOL.md 1.4).

use std::fmt;

/// Sum check of `bytes` (header up to the last data character, CR LF and SC excluded):
/// the sum of the byte values, modulo 256, no complement (PROTOCOL.md 1.4).
#[inline]
pub fn checksum(bytes: &[u8]) -> u8 {
    // Chunked so the compiler vectorises the sum.
    let mut acc = [0u8; 32];
    let mut chunks = bytes.chunks_exact(32);
    for c in &mut chunks {
        for (a, b) in acc.iter_mut().zip(c) {
            *a = a.wrapping_add(*b);
        }
    }
    let mut sum = chunks
        .remainder()
        .iter()
        .fold(0u8, |s, &b| s.wrapping_add(b));
    for a in acc {
        sum = sum.wrapping_add(a);
    }
    sum
}

/// The SC field of a received frame, as it was read.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Sc {
    /// Two hex digits that match the frame's sum (verified on parse).
    Valid(u8),
    /// The literal `@@` some hosts send instead of a sum (PROTOCOL.md 1.4): accepted without
    /// a check, and reported as such so the frame log can flag it.
    AtAt,
}

impl fmt::Display for Sc {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Sc::Valid(v) => write!(f, "{v:02X}"),
            Sc::AtAt => f.write_str("@@"),
        }
    }
}

/// What to put in the SC position when encoding a command.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum ScMode {
    /// The computed sum (always correct; the default).
    #[default]
    Computed,
    /// The literal `@@` (a debug setting; PROTOCOL.md 1.4).
    AtAt,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn worked_examples_of_section_1_4() {
        assert_eq!(checksum(b"!9921201"), 0x89);
        assert_eq!(checksum(b"#99232"), 0x2C);
        assert_eq!(checksum(b"#99212021C00000000002715"), 0xAF);
    }

    #[test]
    fn long_input_matches_naive_sum() {
        let bytes: Vec<u8> = (0..1000u32).map(|i| (i * 7 + 3) as u8).collect();
        let naive = bytes.iter().fold(0u8, |s, &b| s.wrapping_add(b));
        assert_eq!(checksum(&bytes), naive);
    }

    #[test]
    fn sc_displays_like_the_wire() {
        assert_eq!(Sc::Valid(0x0A).to_string(), "0A");
        assert_eq!(Sc::AtAt.to_string(), "@@");
    }
}
