//! Teach-list JSON: the serde hooks of [`TeachPoint`] and [`TeachList`] (names, poses,
//! arm words, frame numbers and unique names checked as they are read) and serde_json
//! errors turned into a [`FileError`] that names the file's line, point and field.

use std::collections::HashMap;
use std::fmt;

use serde::de::{Error as _, SeqAccess, Visitor};
use serde::{Deserialize, Deserializer, Serializer};
use serde_json::value::RawValue;

use super::file::{FileError, not_utf8, shown, too_many};
use super::{
    MAX_FRAME_NUMBER, MAX_POINTS, TeachList, TeachPoint, arm_word, check_name, parse_arm_word,
};
use crate::protocol::ArmSystem;

impl TeachList {
    /// The list as pretty-printed JSON.
    pub fn to_json(&self) -> String {
        // Serialising these types cannot fail (string keys, no maps of other keys).
        serde_json::to_string_pretty(self).unwrap_or_default()
    }

    /// A list from JSON text (the form [`TeachList::to_json`] writes), or the first thing
    /// wrong with it. Each point is read on its own so that errors name its lines.
    pub fn from_json(text: &str) -> Result<TeachList, FileError> {
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        let raw: RawList<'_> =
            serde_json::from_str(text).map_err(|e| json_error(&e, text, 0, 0))?;
        if raw.points.len() > MAX_POINTS {
            return Err(too_many(Some(raw.points.len())));
        }
        let mut names: HashMap<String, usize> = HashMap::new();
        let mut list = TeachList::new();
        // Lines counted from where the last point started, so a long file is read once.
        let (mut counted_to, mut line0) = (0, 0);
        for (k, point) in raw.points.iter().enumerate() {
            let s = point.get();
            // Where the point starts in `text`: its line (0-based) and column (1-based).
            let offset = (s.as_ptr() as usize).saturating_sub(text.as_ptr() as usize);
            let since = text.as_bytes().get(counted_to..offset).unwrap_or_default();
            line0 += since.iter().filter(|&&b| b == b'\n').count();
            counted_to = offset.max(counted_to);
            let before = text.as_bytes().get(..offset).unwrap_or_default();
            let col0 = before.iter().rev().take_while(|&&b| b != b'\n').count();
            let p: TeachPoint =
                serde_json::from_str(s).map_err(|e| json_error(&e, s, line0, col0))?;
            if let Some(first) = names.get(&p.name) {
                return Err(FileError::new(
                    line0 + 1,
                    Some("name"),
                    format!(
                        "\"{}\" (point {}) is already used by point {}",
                        shown(&p.name),
                        k + 1,
                        first + 1
                    ),
                ));
            }
            names.insert(p.name.clone(), k);
            list.push_checked(p);
        }
        Ok(list)
    }

    /// A list from the bytes of a JSON file; bytes that are not UTF-8 are refused with
    /// their line.
    pub fn from_json_bytes(bytes: &[u8]) -> Result<TeachList, FileError> {
        match std::str::from_utf8(bytes) {
            Ok(text) => TeachList::from_json(text),
            Err(e) => Err(FileError {
                field: None,
                ..not_utf8(bytes, e.valid_up_to())
            }),
        }
    }

    /// Replaces this list with the JSON file's points, only if the whole file loads.
    pub fn load_json(&mut self, bytes: &[u8]) -> Result<(), FileError> {
        *self = TeachList::from_json_bytes(bytes)?;
        Ok(())
    }
}

/// The top level of a JSON file, each point kept as its text.
/// A file with other fields, or without `points`, is not a teach list (an object such as
/// `{}` must never load as an empty list).
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawList<'a> {
    #[serde(borrow)]
    points: Vec<&'a RawValue>,
}

/// A serde_json error in `text` as a [`FileError`], for text that starts at 0-based `line0`
/// and 0-based byte column `col0` of the file. Our own messages start "field NAME: ".
fn json_error(e: &serde_json::Error, text: &str, line0: usize, col0: usize) -> FileError {
    let full = e.to_string();
    let suffix = format!(" at line {} column {}", e.line(), e.column());
    let msg = full.strip_suffix(&suffix).unwrap_or(&full);
    let (field, msg) = match msg.strip_prefix("field ").and_then(|m| m.split_once(": ")) {
        Some((f, m)) if !f.contains(' ') => (Some(f), m),
        _ => (None, msg),
    };
    if e.line() == 0 {
        return FileError::new(line0 + 1, field, msg);
    }
    let (mut line, mut column) = (e.line(), e.column());
    if field.is_some() {
        // serde_json reports a field's error after the whitespace that follows its value,
        // which may be the next line: step back to the end of the value.
        (line, column) = end_of_value(text, line, column);
    }
    if line == 1 {
        column += col0;
    }
    FileError::new(line0 + line, field, format!("{msg} (column {column})"))
}

/// Where a field's value ends, from the position serde_json gives for an error raised
/// after the value: past the whitespace that follows it and, for the last field, the
/// point's closing brace (its `line`:`column` is the last byte read, 1-based).
fn end_of_value(text: &str, line: usize, column: usize) -> (usize, usize) {
    let start: usize = text
        .split_inclusive('\n')
        .take(line.saturating_sub(1))
        .map(str::len)
        .sum();
    let read = text
        .as_bytes()
        .get(..(start + column).min(text.len()))
        .unwrap_or_default();
    let read = read.trim_ascii_end();
    let read = read.strip_suffix(b"}").unwrap_or(read).trim_ascii_end();
    let line = 1 + read.iter().filter(|&&b| b == b'\n').count();
    let column = read.iter().rev().take_while(|&&b| b != b'\n').count();
    (line, column.max(1))
}

/// A checked name (trimmed).
pub(super) fn de_name<'de, D: Deserializer<'de>>(d: D) -> Result<String, D::Error> {
    let name = String::deserialize(d)?;
    check_name(&name).map_err(|e| D::Error::custom(format!("field name: {e}")))
}

/// The RMC axes' positions in 0.001 pu, at most 8.
pub(super) fn de_axes<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<i32>, D::Error> {
    let wide = Vec::<i64>::deserialize(d)?;
    if wide.len() > crate::rmc::MAX_AXES {
        return Err(D::Error::custom(format!(
            "field axes: {} values, an RMC151 has at most 8 axes",
            wide.len()
        )));
    }
    wide.into_iter()
        .map(|v| {
            i32::try_from(v).map_err(|_| {
                D::Error::custom(format!(
                    "field axes: {v} is out of range (-2147483648 to 2147483647)"
                ))
            })
        })
        .collect()
}

/// Four positions in wire units; a value outside i32 gets our message.
pub(super) fn de_pose<'de, D: Deserializer<'de>>(d: D) -> Result<[i32; 4], D::Error> {
    let wide = <[i64; 4]>::deserialize(d)?;
    let mut pose = [0i32; 4];
    for (slot, v) in pose.iter_mut().zip(wide) {
        *slot = i32::try_from(v).map_err(|_| {
            D::Error::custom(format!(
                "field pose: {v} is out of range (-2147483648 to 2147483647)"
            ))
        })?;
    }
    Ok(pose)
}

/// The arm system as its file word.
pub(super) fn ser_arm<S: Serializer>(arm: &ArmSystem, s: S) -> Result<S::Ok, S::Error> {
    s.serialize_str(arm_word(*arm))
}

/// The arm system from its file word (any letter case).
pub(super) fn de_arm<'de, D: Deserializer<'de>>(d: D) -> Result<ArmSystem, D::Error> {
    let w = String::deserialize(d)?;
    parse_arm_word(&w).ok_or_else(|| {
        D::Error::custom(format!(
            "field arm: \"{}\" is not an arm system (use right, left or undetermined)",
            shown(&w)
        ))
    })
}

fn de_frame<'de, D: Deserializer<'de>>(d: D, what: &str, max: u8) -> Result<u8, D::Error> {
    let v = i64::deserialize(d)?;
    u8::try_from(v)
        .ok()
        .filter(|n| *n <= max)
        .ok_or_else(|| D::Error::custom(format!("field {what}: {v} is out of range (0-{max})")))
}

/// A work coordinate system number, 0-31.
pub(super) fn de_work<'de, D: Deserializer<'de>>(d: D) -> Result<u8, D::Error> {
    de_frame(d, "work", MAX_FRAME_NUMBER)
}

/// A tool coordinate system number, 0-127.
pub(super) fn de_tool<'de, D: Deserializer<'de>>(d: D) -> Result<u8, D::Error> {
    de_frame(d, "tool", MAX_FRAME_NUMBER)
}

/// Deserialises the points of a [`TeachList`], refusing a duplicate name where it occurs.
pub(super) fn de_points<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<TeachPoint>, D::Error> {
    struct Points;
    impl<'de> Visitor<'de> for Points {
        type Value = Vec<TeachPoint>;

        fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
            f.write_str("a list of teach points")
        }

        fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Self::Value, A::Error> {
            let mut names: HashMap<String, usize> = HashMap::new();
            let mut points = Vec::new();
            while let Some(p) = seq.next_element::<TeachPoint>()? {
                if let Some(first) = names.get(&p.name) {
                    return Err(A::Error::custom(format!(
                        "field name: \"{}\" is already used by point {}",
                        shown(&p.name),
                        first + 1
                    )));
                }
                names.insert(p.name.clone(), points.len());
                points.push(p);
            }
            Ok(points)
        }
    }
    d.deserialize_seq(Points)
}
