//! Helpers shared by the protocol vector tests: frames from PROTOCOL.md text, typed
//! decode with round-trip checks.
#![allow(dead_code)]

use xsel_pendant::protocol::*;

pub fn wire(s: &str) -> Vec<u8> {
    let mut v = s.as_bytes().to_vec();
    v.extend_from_slice(b"\r\n");
    v
}

pub fn frame(s: &str) -> OwnedFrame {
    Frame::parse(&wire(s))
        .unwrap_or_else(|e| panic!("{s}: {e}"))
        .into_owned()
}

pub fn cmd(s: &str) -> Command {
    Command::decode(&frame(s)).unwrap_or_else(|e| panic!("{s}: {e}"))
}

pub fn reply(s: &str) -> Reply {
    Reply::decode(&frame(s)).unwrap_or_else(|e| panic!("{s}: {e}"))
}

/// Decodes a computed-SC command, checks the SC is valid, and that it re-encodes exactly.
pub fn cmd_vector(s: &str) -> Command {
    let f = frame(s);
    assert!(matches!(f.sc(), Sc::Valid(_)), "{s}");
    let c = cmd(s);
    let again = c.to_bytes(Station::DEFAULT, ScMode::Computed).unwrap();
    assert_eq!(
        String::from_utf8_lossy(&again),
        String::from_utf8_lossy(&wire(s)),
        "{c:?}"
    );
    let d = describe(&wire(s));
    assert!(d.is_ok(), "{d}");
    c
}

pub fn reply_vector(s: &str) -> Reply {
    let f = frame(s);
    assert!(matches!(f.sc(), Sc::Valid(_)), "{s}");
    let r = reply(s);
    let again = r.to_bytes(Station::DEFAULT).unwrap();
    assert_eq!(
        String::from_utf8_lossy(&again),
        String::from_utf8_lossy(&wire(s)),
        "{r:?}"
    );
    let d = describe(&wire(s));
    assert!(d.is_ok(), "{d}");
    r
}

/// An `@@` command: decodes as given, SC reported as `@@`, re-encodes with `@@` exactly,
/// and with a computed SC gives the section's recomputed value.
pub fn at_at_vector(s: &str, real_sc: &str) -> Command {
    let f = frame(s);
    assert_eq!(f.sc(), Sc::AtAt, "{s}");
    let c = cmd(s);
    let again = c.to_bytes(Station::DEFAULT, ScMode::AtAt).unwrap();
    assert_eq!(again, wire(s), "{c:?}");
    let computed = c.to_bytes(Station::DEFAULT, ScMode::Computed).unwrap();
    let body = &s[..s.len() - 2];
    assert_eq!(
        String::from_utf8_lossy(&computed),
        format!("{body}{real_sc}\r\n")
    );
    c
}

pub fn t(v: i32) -> Milli {
    Milli(v)
}

pub fn axes<T: Copy + Default>(vals: &[(u8, T)]) -> PerAxis<T> {
    PerAxis::from_pairs(vals.iter().map(|&(n, v)| (Axis::new(n).unwrap(), v)))
}
