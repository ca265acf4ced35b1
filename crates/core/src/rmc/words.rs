//! 32-bit values as two Modbus registers, least-significant word first (RMC.md section 1:
//! 0x11223344 goes on the wire as `33 44 11 22`) [V for REALs, I for DWORDs].

/// A DWORD as its two registers, low word first.
pub fn dword_to_words(value: u32) -> [u16; 2] {
    [value as u16, (value >> 16) as u16]
}

/// A DWORD from its two registers, low word first.
pub fn words_to_dword(words: [u16; 2]) -> u32 {
    u32::from(words[0]) | (u32::from(words[1]) << 16)
}

/// A REAL (f32) as its two registers, low word first.
pub fn real_to_words(value: f32) -> [u16; 2] {
    dword_to_words(value.to_bits())
}

/// A REAL (f32) from its two registers, low word first.
pub fn words_to_real(words: [u16; 2]) -> f32 {
    f32::from_bits(words_to_dword(words))
}

/// The 32-bit register at `element` of `regs` (two words each), if `regs` holds it.
pub fn dword_at(regs: &[u16], element: usize) -> Option<u32> {
    let low = *regs.get(2 * element)?;
    let high = *regs.get(2 * element + 1)?;
    Some(words_to_dword([low, high]))
}

/// The REAL at `element` of `regs`, if `regs` holds it.
pub fn real_at(regs: &[u16], element: usize) -> Option<f32> {
    dword_at(regs, element).map(f32::from_bits)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn low_word_goes_first() {
        assert_eq!(dword_to_words(0x1122_3344), [0x3344, 0x1122]);
        assert_eq!(words_to_dword([0x3344, 0x1122]), 0x1122_3344);
        assert_eq!(real_to_words(1.0), [0x0000, 0x3F80]);
        assert_eq!(words_to_real([0x0000, 0x3F80]), 1.0);
        // On the wire each word is big-endian: 33 44 11 22.
        let bytes: Vec<u8> = dword_to_words(0x1122_3344)
            .iter()
            .flat_map(|w| w.to_be_bytes())
            .collect();
        assert_eq!(bytes, [0x33, 0x44, 0x11, 0x22]);
    }

    #[test]
    fn a_register_past_the_end_is_none() {
        let regs = [1, 0, 2];
        assert_eq!(dword_at(&regs, 0), Some(1));
        assert_eq!(dword_at(&regs, 1), None);
    }
}
