//! Format B framing written again from PROTOCOL.md 1.4, not with the crate's encoder, for
//! the tests that speak to the simulator or the window as an independent host would: the
//! SC is the low byte of the sum of every byte before it, as two upper-case hex digits.
#![allow(dead_code)] // each test binary uses its own subset

/// The SC of a frame whose bytes before the SC are `body`.
pub fn sc(body: &str) -> String {
    format!(
        "{:02X}",
        body.bytes().fold(0u32, |s, b| s + u32::from(b)) & 0xFF
    )
}

/// `body`, its SC, CR and LF.
pub fn frame(body: &str) -> Vec<u8> {
    format!("{body}{}\r\n", sc(body)).into_bytes()
}
