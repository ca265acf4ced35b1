//! Controller snapshots: what can be read of a controller in one file (the versions of
//! every unit, the position table, the coordinate tables, global flags and variables, the
//! alarm history), taken with progress and Cancel in the line time the polls leave, saved,
//! opened and compared table by table, row by row.
//!
//! The snapshot's own reads (201H, 20DH, 20EH, 20FH) go out one at a time as spare
//! requests; the position table and the alarm history are read by their own sub-models
//! (the pendant hands them over, `Pendant::snapshot_work`), so the views show what the
//! snapshot saw.

mod compare;
#[cfg(test)]
mod tests;

use std::collections::BTreeMap;
use std::time::SystemTime;

use serde::{Deserialize, Serialize};

pub use compare::{Comparison, Difference, compare};

use super::Level;
use crate::link::LinkEvent;
use crate::protocol::{
    BitData, BitQuery, BitSpace, Command, ErrorDetail, GLOBAL_FLAGS, PositionRecord, RecordArm,
    Reply, UnitType, VarKind, VarQuery, VarValues, VersionInfo, VersionQuery, ZoneRecord,
};
use crate::robot::CoordSystem;

/// The file format this pendant writes; a file with a larger number is refused.
pub const FORMAT: u32 = 1;

/// The largest snapshot file read.
pub const MAX_FILE_BYTES: u64 = 64 * 1024 * 1024;

/// Unit types asked with 201H: main CPU application, core, driver CPU, SIO board
/// (PROTOCOL.md 3.2).
pub const UNITS: std::ops::Range<u8> = 0..4;

/// One unit's 201H answer.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Version {
    pub unit: u8,
    pub model: u8,
    pub unit_code: u8,
    pub version: u16,
    /// "2024-03-15 10:20:30", as the controller says.
    pub built: String,
}

impl From<&VersionInfo> for Version {
    fn from(v: &VersionInfo) -> Self {
        Version {
            unit: v.unit.0,
            model: v.model,
            unit_code: v.unit_code,
            version: v.version,
            built: format!(
                "{:04}-{:02}-{:02} {:02}:{:02}:{:02}",
                v.year, v.month, v.day, v.hour, v.minute, v.second
            ),
        }
    }
}

/// One position of the table: coordinates by axis name (mm or deg), rates, arm system.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Position {
    pub number: u16,
    pub axes: BTreeMap<String, f64>,
    pub speed: u16,
    pub accel: u16,
    pub decel: u16,
    pub arm: String,
}

impl From<&PositionRecord> for Position {
    fn from(r: &PositionRecord) -> Self {
        Position {
            number: r.number,
            axes: r
                .coords
                .iter()
                .map(|(a, v)| (format!("axis {}", a.number()), f64::from(v.0) / 1000.0))
                .collect(),
            speed: r.speed.0,
            accel: r.accel.0,
            decel: r.decel.0,
            arm: match r.arms.scara1 {
                RecordArm::Right => "right",
                RecordArm::Left => "left",
                RecordArm::Unspecified => "",
            }
            .to_owned(),
        }
    }
}

impl Position {
    /// The record this row was read from (what the Positions view's draft takes); a
    /// row a file changed into nonsense is named.
    pub fn to_record(&self) -> Result<PositionRecord, String> {
        let mut coords = crate::protocol::PerAxis::new();
        for (name, value) in &self.axes {
            let axis = name
                .strip_prefix("axis ")
                .and_then(|n| n.parse::<u8>().ok())
                .and_then(crate::protocol::Axis::new)
                .ok_or_else(|| format!("No. {}: `{name}` is not an axis", self.number))?;
            let milli = (value * 1000.0).round();
            if !milli.is_finite() || milli.abs() > f64::from(i32::MAX) {
                return Err(format!(
                    "No. {}: {name} {value} is out of range",
                    self.number
                ));
            }
            coords.set(axis, crate::protocol::Milli(milli as i32));
        }
        let scara1 = match self.arm.as_str() {
            "right" => RecordArm::Right,
            "left" => RecordArm::Left,
            "" => RecordArm::Unspecified,
            other => {
                return Err(format!(
                    "No. {}: `{other}` is not an arm system",
                    self.number
                ));
            }
        };
        Ok(PositionRecord {
            number: self.number,
            coords,
            accel: crate::protocol::CentiG(self.accel),
            decel: crate::protocol::CentiG(self.decel),
            speed: crate::protocol::MmPerSec(self.speed),
            arms: crate::protocol::RecordArms {
                scara1,
                ..Default::default()
            },
        })
    }
}

/// One record of a coordinate table (mm, deg).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Frame {
    pub number: usize,
    pub x: f64,
    pub y: f64,
    pub z: f64,
    pub r: f64,
}

impl Frame {
    fn of(number: usize, c: &CoordSystem) -> Frame {
        let p = c.offset();
        Frame {
            number,
            x: p.x,
            y: p.y,
            z: p.z,
            r: p.r,
        }
    }
}

/// One interference zone: a box by two corners in base coordinates (mm, deg) on the
/// axes its record names, and the record's unread tail raw (PROTOCOL.md 3.46).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Zone {
    pub number: u8,
    pub corner1: BTreeMap<String, f64>,
    pub corner2: BTreeMap<String, f64>,
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub tail: String,
}

impl Zone {
    fn of(number: u8, r: &ZoneRecord) -> Zone {
        let corner = |c: &crate::protocol::PerAxis<crate::protocol::Milli>| {
            c.iter()
                .map(|(a, v)| (format!("axis {}", a.number()), f64::from(v.0) / 1000.0))
                .collect()
        };
        Zone {
            number,
            corner1: corner(&r.corner1),
            corner2: corner(&r.corner2),
            tail: r.surplus_text(),
        }
    }
}

/// One record of the alarm history.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct AlarmEntry {
    pub record: u16,
    pub code: u16,
    pub details: [u32; 8],
    pub message: String,
}

impl From<(u16, &ErrorDetail)> for AlarmEntry {
    fn from((record, d): (u16, &ErrorDetail)) -> Self {
        AlarmEntry {
            record,
            code: d.error.0,
            details: d.details,
            message: d.message_text(),
        }
    }
}

/// What was read of a controller at one time.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Snapshot {
    pub format: u32,
    /// The program that wrote it: "xsel-pendant 0.1.0".
    pub written_by: String,
    /// When it was taken, RFC 3339 UTC.
    pub taken: String,
    /// The line it was read over.
    pub line: String,
    pub versions: Vec<Version>,
    pub positions: Vec<Position>,
    pub work: Vec<Frame>,
    pub tool: Vec<Frame>,
    /// Global flags (600-899) that are on.
    pub flags_on: Vec<u16>,
    /// Global integer variables (200-299) that are not 0.
    pub integers: BTreeMap<u16, i32>,
    /// Global real variables (300-399) that are not 0, as the 16 hex digits on the wire
    /// (PROTOCOL.md 3.40: the encoding is a controller setting).
    pub reals: BTreeMap<u16, String>,
    pub alarms: Vec<AlarmEntry>,
    /// The interference zones defined (2A2H); absent from files written before zones
    /// were read (they load as none).
    #[serde(default)]
    pub zones: Vec<Zone>,
    /// What could not be read, and why.
    pub missing: Vec<String>,
}

impl Snapshot {
    /// A new, empty snapshot stamped now.
    pub fn begun(line: &str, wall: SystemTime) -> Snapshot {
        Snapshot {
            format: FORMAT,
            written_by: format!("xsel-pendant {}", env!("CARGO_PKG_VERSION")),
            taken: humantime::format_rfc3339_seconds(wall).to_string(),
            line: line.to_owned(),
            ..Snapshot::default()
        }
    }

    /// The file's bytes (pretty JSON: a person can read and diff it).
    pub fn to_json(&self) -> Vec<u8> {
        serde_json::to_vec_pretty(self).unwrap_or_default()
    }

    /// A snapshot file's bytes; a newer format, a file cut short or not a snapshot are
    /// named.
    pub fn from_json(bytes: &[u8]) -> Result<Snapshot, String> {
        #[derive(Deserialize)]
        struct Head {
            format: u32,
        }
        let head: Head = serde_json::from_slice(bytes).map_err(|e| {
            if e.is_eof() {
                format!("cut short ({e}): nothing was changed")
            } else {
                format!("not a snapshot file ({e})")
            }
        })?;
        if head.format > FORMAT {
            return Err(format!(
                "written by a newer xsel-pendant (format {}; this one reads {FORMAT})",
                head.format
            ));
        }
        serde_json::from_slice(bytes).map_err(|e| format!("not a snapshot file ({e})"))
    }

    /// One line: when, over what, how much.
    pub fn summary(&self) -> String {
        let mut s = format!(
            "{} over {}: {} position(s), {} alarm(s), {} flag(s) on, {} variable(s) set, {} zone(s)",
            self.taken,
            self.line,
            self.positions.len(),
            self.alarms.len(),
            self.flags_on.len(),
            self.integers.len() + self.reals.len(),
            self.zones.len()
        );
        if !self.missing.is_empty() {
            s.push_str(&format!("; not read: {}", self.missing.join("; ")));
        }
        s
    }
}

/// The parts of a snapshot, read in this order.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Part {
    Versions,
    Flags,
    Integers,
    Reals,
    /// Read by the positions sub-model.
    Positions,
    /// Read by the alarms sub-model.
    Alarms,
    /// Copied from the coordinate tables read at connect.
    Tables,
    /// Read by the zones sub-model.
    Zones,
}

const PARTS: [Part; 8] = [
    Part::Versions,
    Part::Flags,
    Part::Integers,
    Part::Reals,
    Part::Positions,
    Part::Alarms,
    Part::Tables,
    Part::Zones,
];

impl Part {
    pub fn name(self) -> &'static str {
        match self {
            Part::Versions => "versions (201H)",
            Part::Flags => "global flags (20DH)",
            Part::Integers => "integer variables (20EH)",
            Part::Reals => "real variables (20FH)",
            Part::Positions => "position table",
            Part::Alarms => "alarm history",
            Part::Tables => "coordinate tables",
            Part::Zones => "interference zones (2A2H)",
        }
    }
}

/// A snapshot being taken.
#[derive(Clone, Debug)]
struct Taking {
    part: usize,
    /// The unit asked next (versions).
    unit: u8,
    /// The command on its way.
    in_flight: Option<Command>,
    /// A part read by another sub-model has been handed over.
    handed: bool,
    snapshot: Snapshot,
}

/// What the operator asks of the snapshots.
#[derive(Clone, Debug, PartialEq)]
pub enum SnapshotIntent {
    Take,
    Cancel,
    /// Compare the latest with the one before it.
    CompareLast,
    /// A snapshot file read (or why not): compared with the latest.
    Opened {
        path: String,
        read: Result<Box<Snapshot>, String>,
    },
    /// The positions of the older snapshot (the one compared against, or a file opened)
    /// into the Positions view's draft, to be written with its preview: never sent by
    /// itself.
    RestorePositions,
    /// A snapshot written to a file (or why not).
    Saved {
        path: String,
        result: Result<(), String>,
    },
}

/// The snapshots of this session: the one being taken, the latest two, a file opened,
/// the last comparison.
#[derive(Debug, Default)]
pub struct Snapshots {
    taking: Option<Taking>,
    pub latest: Option<Snapshot>,
    pub previous: Option<Snapshot>,
    pub comparison: Option<Comparison>,
    pub feedback: Option<(Level, String)>,
    commands: Vec<Command>,
}

impl Snapshots {
    /// The snapshot positions are restored from: the older of the last two (or the file
    /// opened), else the only one.
    pub fn restore_source(&self) -> Option<&Snapshot> {
        self.previous.as_ref().or(self.latest.as_ref())
    }

    /// The part being read, when a snapshot is being taken.
    pub fn part(&self) -> Option<Part> {
        self.taking.as_ref().map(|t| PARTS[t.part])
    }

    /// Parts done and in all.
    pub fn progress(&self) -> Option<(usize, usize)> {
        self.taking.as_ref().map(|t| (t.part, PARTS.len()))
    }

    /// Whether a part read by another sub-model was handed over.
    pub fn handed(&self) -> bool {
        self.taking.as_ref().is_some_and(|t| t.handed)
    }

    /// Commands to send (spare line time).
    pub fn take_commands(&mut self) -> Vec<Command> {
        std::mem::take(&mut self.commands)
    }

    /// Whether `command` is the snapshot's read on its way.
    pub fn owns(&self, command: &Command) -> bool {
        self.taking
            .as_ref()
            .is_some_and(|t| t.in_flight.as_ref() == Some(command))
    }

    fn say(&mut self, level: Level, text: String) -> Option<(Level, String)> {
        self.feedback = Some((level, text.clone()));
        Some((level, text))
    }

    /// Applies one intent; the words for the operator come back.
    pub fn apply(
        &mut self,
        intent: SnapshotIntent,
        line: Option<&str>,
        wall: SystemTime,
    ) -> Option<(Level, String)> {
        match intent {
            SnapshotIntent::Take => {
                let Some(line) = line else {
                    return self.say(Level::Warning, "no snapshot: the line is down".into());
                };
                if self.taking.is_some() {
                    return self.say(Level::Warning, "a snapshot is being taken".into());
                }
                self.taking = Some(Taking {
                    part: 0,
                    unit: UNITS.start,
                    in_flight: None,
                    handed: false,
                    snapshot: Snapshot::begun(line, wall),
                });
                self.ask();
                self.say(Level::Info, "taking a snapshot".into())
            }
            SnapshotIntent::Cancel => {
                self.taking.take()?;
                self.say(Level::Info, "snapshot cancelled: nothing kept".into())
            }
            SnapshotIntent::CompareLast => {
                let (Some(old), Some(new)) = (&self.previous, &self.latest) else {
                    return self.say(
                        Level::Warning,
                        "take two snapshots (or open one) to compare".into(),
                    );
                };
                let c = compare(old, new);
                let said = c.summary();
                self.comparison = Some(c);
                self.say(Level::Info, said)
            }
            SnapshotIntent::Opened { path, read } => match read {
                Err(e) => self.say(Level::Warning, format!("{path}: {e}")),
                Ok(opened) => {
                    let opened = *opened;
                    let Some(latest) = &self.latest else {
                        self.latest = Some(opened);
                        return self.say(
                            Level::Info,
                            format!("{path} opened: take a snapshot to compare it with now"),
                        );
                    };
                    let c = compare(&opened, latest);
                    let said = format!("{path} against the latest: {}", c.summary());
                    self.previous = Some(opened);
                    self.comparison = Some(c);
                    self.say(Level::Info, said)
                }
            },
            // The pendant carries it out (it crosses into the Positions view).
            SnapshotIntent::RestorePositions => None,
            SnapshotIntent::Saved { path, result } => match result {
                Ok(()) => self.say(Level::Info, format!("snapshot saved to {path}")),
                Err(e) => self.say(Level::Error, format!("snapshot not saved: {e}")),
            },
        }
    }

    /// Queues the next read of the part in hand, or moves on.
    fn ask(&mut self) {
        let Some(t) = self.taking.as_mut() else {
            return;
        };
        if t.in_flight.is_some() {
            return;
        }
        let command = match PARTS[t.part] {
            Part::Versions => Command::Version(VersionQuery {
                unit: UnitType(t.unit),
                device: 0,
            }),
            Part::Flags => Command::BitQuery(BitQuery {
                space: BitSpace::Flag,
                program: 0,
                start: GLOBAL_FLAGS.numbers.start,
                count: GLOBAL_FLAGS.numbers.end - GLOBAL_FLAGS.numbers.start,
            }),
            Part::Integers | Part::Reals => {
                let kind = if PARTS[t.part] == Part::Integers {
                    VarKind::Integer
                } else {
                    VarKind::Real
                };
                let numbers = kind.numbers(true);
                Command::VarQuery(VarQuery {
                    kind,
                    program: 0,
                    start: numbers.start,
                    count: u8::try_from(numbers.end - numbers.start).unwrap_or(u8::MAX),
                })
            }
            // Read by others: the pendant hands them over.
            Part::Positions | Part::Alarms | Part::Tables | Part::Zones => return,
        };
        t.in_flight = Some(command.clone());
        self.commands.push(command);
    }

    /// The part in hand is done: the next one, or the snapshot is complete.
    fn next_part(&mut self) -> Option<(Level, String)> {
        let t = self.taking.as_mut()?;
        t.part += 1;
        t.handed = false;
        t.in_flight = None;
        if t.part < PARTS.len() {
            self.ask();
            return None;
        }
        let done = self.taking.take()?.snapshot;
        let said = format!("snapshot taken: {}", done.summary());
        self.previous = self.latest.replace(done);
        self.say(Level::Info, said)
    }

    /// A part read by another sub-model has been handed over to it.
    pub fn handed_over(&mut self) {
        if let Some(t) = self.taking.as_mut() {
            t.handed = true;
        }
    }

    /// A part read by another sub-model: its result (or why it is missing).
    pub fn part_read(&mut self, fill: impl FnOnce(&mut Snapshot)) -> Option<(Level, String)> {
        fill(&mut self.taking.as_mut()?.snapshot);
        self.next_part()
    }

    /// The positions read: every record the table held.
    pub fn positions_read(records: &[PositionRecord]) -> impl FnOnce(&mut Snapshot) + '_ {
        move |s| s.positions = records.iter().map(Position::from).collect()
    }

    /// The defined zones as read, or why they are missing.
    pub fn zones_read(
        read: &[(u8, ZoneRecord)],
        failed: Option<String>,
    ) -> impl FnOnce(&mut Snapshot) + '_ {
        move |s| match failed {
            Some(why) => s.missing.push(format!("interference zones: {why}")),
            None => s.zones = read.iter().map(|(n, r)| Zone::of(*n, r)).collect(),
        }
    }

    /// The coordinate tables read at connect (or why they are missing).
    pub fn tables(
        work: Option<&[Option<CoordSystem>]>,
        tool: Option<&[Option<CoordSystem>]>,
    ) -> impl FnOnce(&mut Snapshot) {
        let frames = |t: Option<&[Option<CoordSystem>]>| {
            t.map(|records| {
                records
                    .iter()
                    .enumerate()
                    .filter_map(|(n, c)| c.as_ref().map(|c| Frame::of(n, c)))
                    .collect::<Vec<_>>()
            })
        };
        let (work, tool) = (frames(work), frames(tool));
        move |s| {
            for (name, frames, slot) in [("work", work, &mut s.work), ("tool", tool, &mut s.tool)] {
                match frames {
                    Some(f) => *slot = f,
                    None => s
                        .missing
                        .push(format!("the {name} coordinate table was not read")),
                }
            }
        }
    }

    /// One event of the link for the snapshot's own reads.
    pub fn handle_event(&mut self, event: &LinkEvent) -> Option<(Level, String)> {
        let t = self.taking.as_mut()?;
        let (command, outcome) = match event {
            LinkEvent::Reply { command, reply, .. } => (command, Ok(reply)),
            LinkEvent::ErrorReply { command, code, .. } => {
                (command, Err(format!("refused: error {code}")))
            }
            LinkEvent::Timeout {
                command,
                retrying: false,
                ..
            } => (command, Err("no answer".to_owned())),
            LinkEvent::NotSent {
                command, reason, ..
            } => (command, Err(format!("not sent: {reason}"))),
            _ => return None,
        };
        if t.in_flight.as_ref() != Some(command) {
            return None;
        }
        t.in_flight = None;
        let part = PARTS[t.part];
        let s = &mut t.snapshot;
        match (part, outcome) {
            (Part::Versions, Ok(Reply::Version(v))) => s.versions.push(Version::from(v)),
            (Part::Flags, Ok(Reply::Bits(b))) => s.flags_on = flags_on(b),
            (Part::Integers | Part::Reals, Ok(Reply::Vars(v))) => {
                let numbers = v.start..;
                match &v.values {
                    VarValues::Integer(values) => {
                        s.integers = numbers
                            .zip(values.iter().copied())
                            .filter(|(_, x)| *x != 0)
                            .collect()
                    }
                    VarValues::Real(values) => {
                        s.reals = numbers
                            .zip(values.iter())
                            .filter(|(_, w)| w.0 != 0)
                            .map(|(n, w)| (n, format!("{:016X}", w.0)))
                            .collect()
                    }
                    VarValues::Text(_) => {}
                }
            }
            (part, Ok(reply)) => s.missing.push(format!(
                "{}: an unexpected reply ({:?})",
                part.name(),
                reply.id()
            )),
            (Part::Versions, Err(why)) => s.missing.push(format!("unit {}: {why}", t.unit)),
            (part, Err(why)) => s.missing.push(format!("{}: {why}", part.name())),
        }
        if part == Part::Versions && t.unit + 1 < UNITS.end {
            t.unit += 1;
            self.ask();
            return None;
        }
        self.next_part()
    }

    /// The line went down: a snapshot being taken is dropped, said.
    pub fn line_gone(&mut self) -> Option<(Level, String)> {
        self.taking.take()?;
        self.say(
            Level::Warning,
            "snapshot dropped: the line went down while it was taken".into(),
        )
    }
}

/// The flags of a 20DH answer that are on.
fn flags_on(b: &BitData) -> Vec<u16> {
    (b.start..b.start.saturating_add(b.count))
        .filter(|&n| b.get(n) == Some(true))
        .collect()
}
