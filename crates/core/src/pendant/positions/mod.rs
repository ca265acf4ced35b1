//! The controller's position table in the pendant: the rows as read (22DH, or 21FH / 209H
//! where the controller refuses it), the operator's draft (taught, edited, imported) with
//! undo, and the write with its preview and read-back. Sans-IO: commands come out of
//! [`Positions::take_commands`], the link's events go in through [`Positions::handle_event`].

pub mod file;
mod intent;
pub mod read;
pub mod write;

use std::collections::BTreeMap;
use std::ops::RangeInclusive;
use std::time::Instant;

pub use intent::{Answer, PositionsCx, PositionsIntent};

use crate::link::{LinkEvent, NotSentReason};
use crate::protocol::{
    Axis, COMMAND_BUFFER, CentiG, Command, ErrorCode, MAX_POSITIONS_3_DIGIT, MAX_POSITIONS_4_DIGIT,
    Milli, MmPerSec, PerAxis, PositionData, PositionQueryKind, PositionRecord, PositionWriteKind,
    RecordArm, Reply,
};
use read::ReadJob;
use write::{Outcome, WriteJob};

use super::Level;

/// Axes a record may carry, to size queries for the worst case before a record is read
/// (PROTOCOL.md 3.24 `[inferred]`): the SCARA's four and two linear axes.
pub const RECORD_AXES: usize = 6;
/// The largest coordinate a cell takes, 0.001 units: the coordinate tables' lengths'.
const COORD_LIMIT: i32 = crate::pendant::coords::cell::LENGTH_LIMIT;
/// Undo steps kept.
const UNDO_DEPTH: usize = 100;

/// One row of the controller's table as the pendant knows it.
#[derive(Clone, Debug, Default, PartialEq)]
pub enum Row {
    /// Not read (yet): never shown as zeros.
    #[default]
    Unread,
    /// Read: the controller holds no data at this number.
    Empty,
    /// Read: what the controller holds.
    Held(PositionRecord),
    /// A read of it failed (why); what the controller holds is not known.
    Failed(String),
}

/// A column of the table that can be edited.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Column {
    Axis(Axis),
    Arm,
    Speed,
    Accel,
    Decel,
}

impl Column {
    /// X, Y, Z, R and the linear axes 5 and 6, then arm system and rates.
    pub const ALL: [Column; 10] = [
        Column::Axis(Axis::A1),
        Column::Axis(Axis::A2),
        Column::Axis(Axis::A3),
        Column::Axis(Axis::A4),
        Column::Axis(Axis::A5),
        Column::Axis(Axis::A6),
        Column::Arm,
        Column::Speed,
        Column::Accel,
        Column::Decel,
    ];

    /// The heading, with its unit.
    pub fn heading(self) -> &'static str {
        match self {
            Column::Axis(a) => match a.number() {
                1 => "X mm",
                2 => "Y mm",
                3 => "Z mm",
                4 => "R deg",
                5 => "Axis 5 mm",
                6 => "Axis 6 mm",
                7 => "Axis 7 mm",
                _ => "Axis 8 deg",
            },
            Column::Arm => "Arm",
            Column::Speed => "Speed mm/s",
            Column::Accel => "Accel G",
            Column::Decel => "Decel G",
        }
    }

    /// The cell's text for `rec` (empty where the record has no value).
    pub fn text(self, rec: &PositionRecord) -> String {
        match self {
            Column::Axis(a) => rec.coords.get(a).map(|v| v.to_string()).unwrap_or_default(),
            Column::Arm => arm_text(rec.arms.scara1).to_owned(),
            Column::Speed => rate(rec.speed.0, |v| v.to_string()),
            Column::Accel => rate(rec.accel.0, |v| format!("{}.{:02}", v / 100, v % 100)),
            Column::Decel => rate(rec.decel.0, |v| format!("{}.{:02}", v / 100, v % 100)),
        }
    }
}

fn rate(v: u16, show: impl Fn(u16) -> String) -> String {
    if v == 0 { String::new() } else { show(v) }
}

/// The arm system's word in the table and in files.
pub fn arm_text(a: RecordArm) -> &'static str {
    match a {
        RecordArm::Unspecified => "",
        RecordArm::Right => "right",
        RecordArm::Left => "left",
    }
}

/// Parses a cell typed by the operator into `rec` (empty: no value), with the coordinate
/// tables' rules: a number with at most 3 decimals, within the wire's range.
pub fn parse_cell(rec: &mut PositionRecord, column: Column, text: &str) -> Result<(), String> {
    let t = text.trim();
    match column {
        Column::Axis(a) => {
            if t.is_empty() {
                rec.coords.remove(a);
                return Ok(());
            }
            // The teach list's exact parser: digits, a dot, 3 decimals, no float rounding.
            let v = crate::pendant::teach::file::parse_milli(t)?;
            if v.unsigned_abs() > COORD_LIMIT.unsigned_abs() {
                return Err(format!(
                    "{} is out of range ({} to {})",
                    Milli(v),
                    Milli(-COORD_LIMIT),
                    Milli(COORD_LIMIT)
                ));
            }
            rec.coords.set(a, Milli(v));
        }
        Column::Arm => {
            rec.arms.scara1 = match t.to_ascii_lowercase().as_str() {
                "" | "-" | "none" => RecordArm::Unspecified,
                "right" | "r" => RecordArm::Right,
                "left" | "l" => RecordArm::Left,
                _ => return Err(format!("`{t}` is not an arm system: right, left or empty")),
            }
        }
        Column::Speed => {
            rec.speed = MmPerSec(parse_whole(t, "speed")?);
        }
        Column::Accel | Column::Decel => {
            let g = if t.is_empty() {
                0.0
            } else {
                parse_decimal(t, 2)?
            };
            let cg = (g * 100.0).round();
            if !(0.0..=f64::from(u16::MAX)).contains(&cg) {
                return Err(format!("{t} G is out of range (0 to 655.35)"));
            }
            let v = CentiG(cg as u16);
            if column == Column::Accel {
                rec.accel = v;
            } else {
                rec.decel = v;
            }
        }
    }
    Ok(())
}

fn parse_decimal(t: &str, decimals: usize) -> Result<f64, String> {
    // Digits, one point, a leading sign: no exponent, no "inf" (a number read as typed).
    let digits = t.strip_prefix(['-', '+']).unwrap_or(t);
    if digits.is_empty()
        || !digits.chars().all(|c| c.is_ascii_digit() || c == '.')
        || digits.matches('.').count() > 1
    {
        return Err(format!("`{t}` is not a number"));
    }
    let v: f64 = t.parse().map_err(|_| format!("`{t}` is not a number"))?;
    if !v.is_finite() {
        return Err(format!("`{t}` is not a number"));
    }
    if let Some((_, frac)) = t.split_once('.')
        && frac.trim_end_matches('0').len() > decimals
    {
        return Err(format!("{t}: at most {decimals} decimals"));
    }
    Ok(v)
}

fn parse_whole(t: &str, what: &str) -> Result<u16, String> {
    if t.is_empty() {
        return Ok(0);
    }
    t.parse()
        .map_err(|_| format!("{what} `{t}` is not a whole number from 0 to 65535"))
}

/// What the table shows: a range of numbers, only used rows, only rows that differ.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Filter {
    pub from: u16,
    pub to: u16,
    pub used_only: bool,
    pub differ_only: bool,
}

impl Default for Filter {
    fn default() -> Self {
        Filter {
            from: 1,
            to: MAX_POSITIONS_4_DIGIT,
            used_only: false,
            differ_only: false,
        }
    }
}

/// One row of the write preview: old -> new, and whether the arm could go there.
#[derive(Clone, Debug, PartialEq)]
pub struct PreviewRow {
    pub number: u16,
    pub old: Row,
    pub new: PositionRecord,
    /// The same checks as a step, from where the arm is now (`Err`: why not).
    pub check: Result<(), String>,
}

/// The write the operator is asked to confirm.
#[derive(Clone, Debug, PartialEq)]
pub struct Preview {
    pub rows: Vec<PreviewRow>,
    pub kind: PositionWriteKind,
    /// 215H says a program runs: writing needs the operator's explicit "I take the risk".
    pub program_running: bool,
}

/// The controller's position table, the operator's draft and the read or write going on.
#[derive(Debug)]
pub struct Positions {
    /// The query the controller answers (22DH first; 21FH, then 209H, after an `&`).
    pub kind: PositionQueryKind,
    /// The reply buffer queries are sized to.
    pub reply_buffer: usize,
    rows: Vec<Row>,
    draft: BTreeMap<u16, PositionRecord>,
    /// Names kept beside numbers (the pendant's own; the controller has none). Read
    /// here; changed with [`Positions::set_name`].
    pub names: BTreeMap<u16, String>,
    undo: Vec<Vec<(u16, Option<PositionRecord>)>>,
    redo: Vec<Vec<(u16, Option<PositionRecord>)>>,
    pub read: Option<ReadJob>,
    pub write: Option<WriteJob>,
    /// The last write, ended: each row's outcome.
    pub last_write: Option<WriteJob>,
    pub preview: Option<Preview>,
    /// The pane's last word (read done, refused, written).
    pub feedback: Option<(Level, String)>,
    commands: Vec<(Command, bool)>,
    /// A Go that flips the arm, waiting for a second press until then.
    pub(crate) go_confirm: Option<(u16, Instant)>,
    /// Counts changes to rows and draft: a view's filtered numbers stay valid while it
    /// holds.
    revision: u64,
    /// Counts changes to the draft and the names (what is saved between runs).
    work_revision: u64,
}

/// The `format` of the saved work's file.
const SAVED_FORMAT: &str = "xsel-positions-work 1";

/// The operator's work read back from its file, every row checked.
#[derive(Debug)]
pub struct RestoredWork {
    rows: Vec<(PositionRecord, Option<String>)>,
    names: BTreeMap<u16, String>,
}

impl RestoredWork {
    /// Reads what [`Positions::saved`] wrote, or says why not (the file is then set aside
    /// and its last good copy read, as every work file's).
    pub fn parse(bytes: &[u8]) -> Result<RestoredWork, String> {
        let saved: SavedWork = serde_json::from_slice(bytes).map_err(|e| e.to_string())?;
        if saved.format != SAVED_FORMAT {
            return Err(format!("format `{}` is not `{SAVED_FORMAT}`", saved.format));
        }
        let rows = file::parse(saved.draft.as_bytes()).map_err(|e| e.to_string())?;
        let max = MAX_POSITIONS_4_DIGIT;
        if let Some(n) = saved.names.keys().find(|&&n| n == 0 || n > max) {
            return Err(format!(
                "a name for No. {n}, which is not a position number"
            ));
        }
        Ok(RestoredWork {
            rows,
            names: saved.names,
        })
    }
}

/// The operator's work on the position table, as saved between runs.
#[derive(serde::Serialize, serde::Deserialize)]
struct SavedWork {
    format: String,
    /// The draft, as a position file (JSON).
    draft: String,
    /// Names of numbers not in the draft.
    #[serde(default)]
    names: BTreeMap<u16, String>,
}

impl Default for Positions {
    fn default() -> Self {
        Positions::new()
    }
}

impl Positions {
    pub fn new() -> Self {
        Positions {
            kind: PositionQueryKind::Query3,
            reply_buffer: crate::protocol::REPLY_BUFFER,
            rows: vec![Row::Unread; usize::from(MAX_POSITIONS_4_DIGIT)],
            draft: BTreeMap::new(),
            names: BTreeMap::new(),
            undo: Vec::new(),
            redo: Vec::new(),
            read: None,
            write: None,
            last_write: None,
            preview: None,
            feedback: None,
            commands: Vec::new(),
            go_confirm: None,
            revision: 0,
            work_revision: 0,
        }
    }

    /// Whether the answers to `command` are the position table's (its reads and writes;
    /// 2D6H Go is followed as a move).
    pub fn owns(command: &Command) -> bool {
        matches!(
            command,
            Command::PositionQuery(_) | Command::PositionWrite(_)
        )
    }

    /// The highest position number of the controller (as far as its answers tell).
    pub fn capacity(&self) -> u16 {
        match self.kind {
            PositionQueryKind::Query => MAX_POSITIONS_3_DIGIT,
            _ => MAX_POSITIONS_4_DIGIT,
        }
    }

    /// Commands for the link, in order; `true`: at the user's priority (writes), `false`:
    /// in the background, giving way to the status polls (reads).
    pub fn take_commands(&mut self) -> Vec<(Command, bool)> {
        std::mem::take(&mut self.commands)
    }

    /// The records the controller holds, as read, by number.
    pub fn held(&self) -> impl Iterator<Item = &PositionRecord> + '_ {
        self.rows.iter().filter_map(|r| match r {
            Row::Held(p) => Some(p),
            _ => None,
        })
    }

    /// The controller's row `n` (1-based); `Unread` outside the table.
    pub fn row(&self, n: u16) -> &Row {
        static UNREAD: Row = Row::Unread;
        n.checked_sub(1)
            .and_then(|i| self.rows.get(usize::from(i)))
            .unwrap_or(&UNREAD)
    }

    fn row_mut(&mut self, n: u16) -> Option<&mut Row> {
        self.revision += 1;
        n.checked_sub(1)
            .and_then(|i| self.rows.get_mut(usize::from(i)))
    }

    /// The draft's record for `n`, where the operator has one.
    pub fn draft(&self, n: u16) -> Option<&PositionRecord> {
        self.draft.get(&n)
    }

    /// What the table shows for `n`: the draft's record, else the controller's.
    pub fn shown(&self, n: u16) -> Option<PositionRecord> {
        self.draft.get(&n).copied().or(match self.row(n) {
            Row::Held(r) => Some(*r),
            _ => None,
        })
    }

    /// Whether the draft's row `n` differs from what the controller is known to hold.
    pub fn differs(&self, n: u16) -> bool {
        match (self.draft.get(&n), self.row(n)) {
            (None, _) => false,
            (Some(d), Row::Held(h)) => !same(d, h),
            (Some(_), _) => true,
        }
    }

    /// The draft's rows that differ from the controller, ascending.
    pub fn changed(&self) -> Vec<PositionRecord> {
        self.draft
            .values()
            .filter(|r| self.differs(r.number))
            .copied()
            .collect()
    }

    /// The name beside `n` (`None`: none).
    pub fn set_name(&mut self, n: u16, name: Option<String>) {
        self.work_revision += 1;
        match name {
            Some(name) => self.names.insert(n, name),
            None => self.names.remove(&n),
        };
    }

    /// Changes so far to the operator's work (the draft and the names): what is saved
    /// between runs.
    pub fn work_revision(&self) -> u64 {
        self.work_revision
    }

    /// The operator's work as saved between runs: the draft as a position file (JSON,
    /// names beside its rows) and the names of numbers not in the draft.
    pub fn saved(&self) -> Vec<u8> {
        let rows: Vec<(PositionRecord, Option<String>)> = self
            .draft
            .values()
            .map(|r| (*r, self.names.get(&r.number).cloned()))
            .collect();
        let names: BTreeMap<u16, String> = self
            .names
            .iter()
            .filter(|(n, _)| !self.draft.contains_key(n))
            .map(|(n, s)| (*n, s.clone()))
            .collect();
        let saved = SavedWork {
            format: SAVED_FORMAT.into(),
            draft: file::to_json(&rows),
            names,
        };
        serde_json::to_vec(&saved).unwrap_or_default()
    }

    /// Takes back the work saved by [`Positions::saved`] (read with [`RestoredWork::parse`]):
    /// how many draft rows and names of numbers not in it. Undo starts empty.
    pub fn restore(&mut self, work: RestoredWork) -> (usize, usize) {
        let counts = (work.rows.len(), work.names.len());
        self.draft.clear();
        self.names = work.names;
        for (r, name) in work.rows {
            if let Some(name) = name {
                self.names.insert(r.number, name);
            }
            self.draft.insert(r.number, r);
        }
        self.undo.clear();
        self.redo.clear();
        self.revision += 1;
        counts
    }

    /// Changes so far to the rows and the draft (what [`Positions::visible`] depends on).
    pub fn revision(&self) -> u64 {
        self.revision
    }

    /// The numbers the table shows under `filter`, ascending.
    pub fn visible(&self, filter: &Filter) -> Vec<u16> {
        let to = filter.to.min(self.capacity());
        (filter.from.max(1)..=to)
            .filter(|&n| {
                (!filter.used_only
                    || self.draft.contains_key(&n)
                    || matches!(self.row(n), Row::Held(_)))
                    && (!filter.differ_only || self.differs(n))
            })
            .collect()
    }

    /// The last write's outcome for row `n`.
    pub fn outcome(&self, n: u16) -> Option<&Outcome> {
        self.write
            .as_ref()
            .or(self.last_write.as_ref())
            .and_then(|w| w.outcomes.get(&n))
    }

    /// Whether a read or write is going on.
    pub fn busy(&self) -> bool {
        self.read.is_some() || self.write.is_some()
    }

    // ---- reading ----

    /// Numbers per query: the records of the worst case that fit the reply buffer.
    fn chunk(&self) -> u16 {
        let fit = self.kind.records_fitting(RECORD_AXES, self.reply_buffer);
        fit.clamp(1, usize::from(self.kind.max_number())) as u16
    }

    /// Reads the numbers of `range` (clipped to the table).
    pub fn start_read(&mut self, range: RangeInclusive<u16>) -> Result<(), String> {
        if self.write.is_some() {
            return Err("a write is in progress".into());
        }
        let (from, to) = (*range.start(), (*range.end()).min(self.capacity()));
        if from == 0 || from > to {
            return Err(format!("no position numbers in {from}-{}", range.end()));
        }
        self.begin_read(vec![from..=to], false);
        Ok(())
    }

    fn begin_read(&mut self, parts: Vec<RangeInclusive<u16>>, verifies: bool) {
        for n in parts.iter().flat_map(|r| r.clone()) {
            if let Some(r) = self.row_mut(n) {
                *r = Row::Unread;
            }
        }
        let mut job = ReadJob::new(self.kind, parts, self.chunk(), verifies);
        self.commands
            .extend(job.next_queries().into_iter().map(|c| (c, false)));
        self.read = Some(job);
    }

    /// Stops the read: what is on its way is still taken in; the rest stays unread.
    pub fn cancel_read(&mut self) -> Option<String> {
        let job = self.read.as_mut()?;
        job.stop_asking();
        Some(format!(
            "read cancelled after {} of {} numbers",
            job.done,
            job.total()
        ))
    }

    /// Takes a reply's records in; `Ok(Some(range))`: the reply may have been cut short by
    /// the reply buffer, and `range` (after its last record) is to be read again.
    fn take_in(
        &mut self,
        data: &PositionData,
        first: u16,
        count: u16,
    ) -> Result<Option<RangeInclusive<u16>>, String> {
        let mut end = u32::from(first) + u32::from(count);
        let asked_end = end;
        let mut prev = 0u16;
        for rec in &data.records {
            let n = u32::from(rec.number);
            if n < u32::from(first) || n >= end || rec.number <= prev {
                return Err(format!(
                    "record No. {} is outside {first}-{} or out of order",
                    rec.number,
                    end - 1
                ));
            }
            prev = rec.number;
        }
        let len = data.kind.reply_len(&data.records);
        // Cut at this controller's buffer, or at the small one of the J/K/TT models
        // whichever this one has: a needless query after a full reply costs little.
        let cut = [self.reply_buffer, crate::protocol::SMALL_REPLY_BUFFER]
            .into_iter()
            .any(|buffer| len <= buffer && data.kind.may_be_cut(len, buffer));
        let mut again = None;
        if prev > 0 && cut && u32::from(prev) + 1 < end {
            // Numbers after the last record are not known to be empty.
            end = u32::from(prev) + 1;
            again = Some(prev + 1..=(asked_end - 1) as u16);
        }
        for n in first..(end.min(u32::from(u16::MAX)) as u16) {
            if let Some(r) = self.row_mut(n) {
                *r = Row::Empty;
            }
        }
        for rec in &data.records {
            if let Some(r) = self.row_mut(rec.number) {
                *r = Row::Held(*rec);
            }
        }
        Ok(again)
    }

    fn fail_rows(&mut self, first: u16, count: u16, why: &str) {
        for n in first..first.saturating_add(count) {
            if let Some(r) = self.row_mut(n) {
                *r = Row::Failed(why.to_owned());
            }
        }
    }

    /// Applies one event of the link; what the operator should read, if anything.
    pub fn handle_event(&mut self, event: &LinkEvent) -> Vec<(Level, String)> {
        let mut said = Vec::new();
        match event {
            LinkEvent::Reply { command, reply, .. } => match (command, reply) {
                (Command::PositionQuery(q), Reply::Positions(data)) => {
                    if self.read.as_mut().is_some_and(|j| j.answered(q)) {
                        match self.take_in(data, q.first, q.count) {
                            Ok(None) => {}
                            Ok(Some(rest)) => {
                                if let Some(job) = self.read.as_mut() {
                                    job.read_again(rest);
                                }
                            }
                            Err(why) => {
                                said.push((Level::Error, format!("positions {}: {why}", q.first)));
                                self.fail_rows(q.first, q.count, &why);
                            }
                        }
                    }
                }
                (Command::PositionWrite(w), Reply::PositionsWritten(done)) => {
                    if let Some(job) = self.write.as_mut().filter(|j| j.is_sent(w)) {
                        job.frame_written(done.count);
                    }
                }
                _ => return said,
            },
            LinkEvent::ErrorReply { command, code, .. } => match command {
                Command::PositionQuery(q) => {
                    if self.read.as_mut().is_some_and(|j| j.answered(q)) {
                        self.query_refused(q.first, q.count, *code, &mut said);
                    }
                }
                Command::PositionWrite(w) => self.write_failed(
                    w,
                    Outcome::NotWritten(format!("the controller answered & {code}")),
                    format!("stopped: the controller refused an earlier frame (& {code})"),
                ),
                _ => return said,
            },
            LinkEvent::Timeout {
                command, retrying, ..
            } => match command {
                Command::PositionQuery(q) if !retrying => {
                    if self.read.as_mut().is_some_and(|j| j.answered(q)) {
                        self.fail_rows(q.first, q.count, "no valid reply");
                    }
                }
                Command::PositionWrite(w) if !retrying => self.write_failed(
                    w,
                    Outcome::Unknown("no reply in time".into()),
                    "stopped: an earlier frame got no reply".into(),
                ),
                _ => return said,
            },
            LinkEvent::Interrupted { command, .. } => match command {
                Command::PositionQuery(q) => {
                    if self.read.as_mut().is_some_and(|j| j.answered(q)) {
                        self.fail_rows(q.first, q.count, "the line was lost");
                    }
                }
                Command::PositionWrite(w) => self.write_failed(
                    w,
                    Outcome::Unknown("the line was lost before the answer".into()),
                    "the line was lost".into(),
                ),
                _ => return said,
            },
            LinkEvent::NotSent {
                command, reason, ..
            } => match command {
                Command::PositionQuery(q) => {
                    if self.read.as_mut().is_some_and(|j| j.answered(q)) {
                        self.fail_rows(q.first, q.count, &format!("not sent: {reason}"));
                    }
                }
                Command::PositionWrite(w) => {
                    let why = match reason {
                        NotSentReason::StopCameFirst => "STOP came first".to_owned(),
                        r => r.to_string(),
                    };
                    self.write_failed(w, Outcome::NotWritten(why.clone()), why);
                }
                _ => return said,
            },
            _ => return said,
        }
        self.advance(&mut said);
        said
    }

    /// An `&` to a query: the first one to 22DH or 21FH tries the older query; otherwise
    /// the chunk's rows are marked with the code.
    fn query_refused(
        &mut self,
        first: u16,
        count: u16,
        code: ErrorCode,
        said: &mut Vec<(Level, String)>,
    ) {
        let Some(job) = self.read.as_ref() else {
            return;
        };
        let older = match job.kind {
            PositionQueryKind::Query3 => Some(PositionQueryKind::Query2),
            PositionQueryKind::Query2 => Some(PositionQueryKind::Query),
            PositionQueryKind::Query => None,
        };
        // Only a refusal of the very first chunk says the controller lacks the message.
        let first_chunk = job.done == u32::from(count) && first == *job.span().start();
        if let (Some(older), true) = (older, first_chunk) {
            let (parts, verifies) = (job.parts.clone(), job.verifies);
            said.push((
                Level::Info,
                format!(
                    "the controller answered & {code} to {}: reading with {}",
                    job.kind.id(),
                    older.id()
                ),
            ));
            self.kind = older;
            // Anything still in flight of the refused kind is ignored when it answers.
            let cap = self.capacity();
            let parts = parts
                .into_iter()
                .filter(|r| *r.start() <= cap)
                .map(|r| *r.start()..=(*r.end()).min(cap))
                .collect();
            self.begin_read(parts, verifies);
            return;
        }
        self.fail_rows(first, count, &format!("the controller answered & {code}"));
    }

    fn write_failed(&mut self, w: &crate::protocol::PositionWrite, on_line: Outcome, rest: String) {
        if let Some(job) = self.write.as_mut().filter(|j| j.is_sent(w)) {
            job.frame_ended(on_line, Some(rest));
        }
    }

    /// Sends what comes next: queries to keep the read going, the next write frame, the
    /// read-back after a write; ends what is finished.
    fn advance(&mut self, said: &mut Vec<(Level, String)>) {
        if let Some(mut job) = self.read.take() {
            let next = job.next_queries();
            self.commands.extend(next.into_iter().map(|c| (c, false)));
            if job.is_finished() {
                self.read_ended(&job, said);
            } else {
                self.read = Some(job);
            }
        }
        let chunk = self.chunk();
        let reading = self.read.is_some();
        if let Some(mut job) = self.write.take() {
            if let Some(frame) = job.next_frame() {
                self.commands.push((Command::PositionWrite(frame), true));
            } else if job.is_sent_out() && !reading {
                let numbers = job.to_read_back();
                if !job.read_back && !numbers.is_empty() {
                    job.read_back = true;
                    self.write = Some(job);
                    self.begin_read(read::ranges(&numbers, chunk / 2), true);
                    return;
                }
                said.push(self.write_ended(&job));
                self.last_write = Some(job);
                return;
            }
            self.write = Some(job);
        }
    }

    fn read_ended(&mut self, job: &ReadJob, said: &mut Vec<(Level, String)>) {
        let numbers = || job.parts.iter().flat_map(|r| r.clone());
        let failed = numbers()
            .filter(|&n| matches!(self.row(n), Row::Failed(_) | Row::Unread))
            .count();
        let held = numbers()
            .filter(|&n| matches!(self.row(n), Row::Held(_)))
            .count();
        if job.verifies {
            self.verify(numbers().collect());
            return;
        }
        let range = job.span();
        let text = format!(
            "read positions {}-{}: {held} used{}",
            range.start(),
            range.end(),
            if failed > 0 {
                format!(", {failed} not read (marked in the table)")
            } else {
                String::new()
            }
        );
        let level = if failed > 0 {
            Level::Warning
        } else {
            Level::Info
        };
        self.feedback = Some((level, text.clone()));
        said.push((level, text));
    }

    /// Compares the read-back with what was written, row by row; rows the controller
    /// holds leave the draft.
    fn verify(&mut self, numbers: Vec<u16>) {
        let Some(job) = self.write.as_mut() else {
            return;
        };
        for n in numbers {
            let Some(wrote) = job.written.get(&n).copied() else {
                continue;
            };
            if !matches!(
                job.outcomes.get(&n),
                Some(Outcome::Written | Outcome::Unknown(_))
            ) {
                continue;
            }
            let outcome = match self.rows.get(usize::from(n) - 1) {
                Some(Row::Held(h)) if same(h, &wrote) => Outcome::Holds,
                Some(Row::Held(h)) => Outcome::Differs(difference(&wrote, h)),
                Some(Row::Empty) => Outcome::Differs("the controller holds no data".into()),
                Some(Row::Failed(why)) => Outcome::Unknown(format!("read-back failed: {why}")),
                _ => Outcome::Unknown("not read back".into()),
            };
            if outcome == Outcome::Holds {
                self.draft.remove(&n);
                self.revision += 1;
                self.work_revision += 1;
            }
            job.outcomes.insert(n, outcome);
        }
    }

    fn write_ended(&mut self, job: &WriteJob) -> (Level, String) {
        let t = job.tally();
        let mut text = format!(
            "write ended: the controller holds {} of {} rows",
            t.holds,
            job.outcomes.len()
        );
        for (n, what) in [
            (t.differs, "read back different"),
            (t.not_written, "not written"),
            (t.unknown, "unknown (read again)"),
            (t.pending, "written but not read back"),
        ] {
            if n > 0 {
                text.push_str(&format!(", {n} {what}"));
            }
        }
        text.push_str(
            ". Whether it keeps them after power-off is not known from the protocol: save with the controller's own tools (PROTOCOL.md 3.48)",
        );
        let level = if t.holds == job.outcomes.len() {
            Level::Info
        } else {
            Level::Warning
        };
        self.feedback = Some((level, text.clone()));
        (level, text)
    }

    // ---- the draft ----

    fn edit(&mut self, changes: Vec<(u16, Option<PositionRecord>)>) {
        self.revision += 1;
        self.work_revision += 1;
        let mut before = Vec::with_capacity(changes.len());
        for (n, new) in changes {
            let old = match new {
                Some(r) => self.draft.insert(n, r),
                None => self.draft.remove(&n),
            };
            before.push((n, old));
        }
        self.undo.push(before);
        if self.undo.len() > UNDO_DEPTH {
            self.undo.remove(0);
        }
        self.redo.clear();
    }

    /// Undoes the last draft edit; false when there is none.
    pub fn undo(&mut self) -> bool {
        self.swap(true)
    }

    /// Redoes the last undone edit; false when there is none.
    pub fn redo(&mut self) -> bool {
        self.swap(false)
    }

    pub fn can_undo(&self) -> bool {
        !self.undo.is_empty()
    }

    pub fn can_redo(&self) -> bool {
        !self.redo.is_empty()
    }

    fn swap(&mut self, undo: bool) -> bool {
        let step = if undo {
            self.undo.pop()
        } else {
            self.redo.pop()
        };
        let Some(step) = step else {
            return false;
        };
        self.revision += 1;
        self.work_revision += 1;
        let mut back = Vec::with_capacity(step.len());
        for (n, rec) in step.into_iter().rev() {
            let old = match rec {
                Some(r) => self.draft.insert(n, r),
                None => self.draft.remove(&n),
            };
            back.push((n, old));
        }
        if undo {
            self.redo.push(back);
        } else {
            self.undo.push(back);
        }
        true
    }

    /// Puts `rec` into the draft at its number (Teach here, a typed row).
    pub fn put(&mut self, rec: PositionRecord) -> Result<(), String> {
        self.check_number(rec.number)?;
        self.edit(vec![(rec.number, Some(rec))]);
        Ok(())
    }

    fn check_number(&self, n: u16) -> Result<(), String> {
        if n == 0 || n > self.capacity() {
            return Err(format!(
                "No. {n} is not a position number (1 to {})",
                self.capacity()
            ));
        }
        Ok(())
    }

    /// A typed cell: checked, then into the draft (starting from what the row shows).
    pub fn set_cell(&mut self, n: u16, column: Column, text: &str) -> Result<(), String> {
        self.check_number(n)?;
        let mut rec = self.shown(n).unwrap_or(PositionRecord {
            number: n,
            ..PositionRecord::default()
        });
        parse_cell(&mut rec, column, text)?;
        if rec.coords.pattern().is_empty() {
            return Err(format!(
                "No. {n} would hold no coordinate: clear it on the controller instead"
            ));
        }
        self.edit(vec![(n, Some(rec))]);
        Ok(())
    }

    /// Row `n` of the draft back to the controller's.
    pub fn revert(&mut self, n: u16) {
        if self.draft.contains_key(&n) {
            self.edit(vec![(n, None)]);
        }
    }

    /// Records from a file into the draft, as one undo step.
    pub fn import(
        &mut self,
        records: Vec<(PositionRecord, Option<String>)>,
    ) -> Result<usize, String> {
        for (r, _) in &records {
            self.check_number(r.number)?;
        }
        let n = records.len();
        let mut changes = Vec::with_capacity(n);
        for (r, name) in records {
            if let Some(name) = name.filter(|s| !s.trim().is_empty()) {
                self.set_name(r.number, Some(name));
            }
            changes.push((r.number, Some(r)));
        }
        self.edit(changes);
        Ok(n)
    }

    // ---- writing ----

    /// The write that fits the query the controller answers: 290H with arm systems
    /// (PROTOCOL.md 3.32 prefers it to 291H, whose layout is reconstructed), 26DH after
    /// 21FH, 244H after 209H.
    pub fn write_kind(&self) -> PositionWriteKind {
        match self.kind {
            PositionQueryKind::Query3 => PositionWriteKind::Range3,
            PositionQueryKind::Query2 => PositionWriteKind::Change2,
            PositionQueryKind::Query => PositionWriteKind::Range,
        }
    }

    /// The preview of writing the changed rows; `check` says whether the arm could go to
    /// a record (the same checks as a step).
    pub fn preview(
        &mut self,
        program_running: bool,
        check: impl Fn(&PositionRecord) -> Result<(), String>,
    ) -> Result<(), String> {
        if self.busy() {
            return Err("a read or write is in progress".into());
        }
        let changed = self.changed();
        if changed.is_empty() {
            return Err("no row of the draft differs from the controller".into());
        }
        let rows = changed
            .into_iter()
            .map(|new| PreviewRow {
                number: new.number,
                old: self.row(new.number).clone(),
                check: check(&new),
                new,
            })
            .collect();
        self.preview = Some(Preview {
            rows,
            kind: self.write_kind(),
            program_running,
        });
        Ok(())
    }

    /// Writes what the preview shows. `program_running` is 215H's word now; with a
    /// program running the write needs `take_the_risk`.
    pub fn confirm_write(
        &mut self,
        program_running: bool,
        take_the_risk: bool,
    ) -> Result<usize, String> {
        let Some(preview) = self.preview.take() else {
            return Err("nothing to write: no preview".into());
        };
        if program_running && !take_the_risk {
            self.preview = Some(Preview {
                program_running,
                ..preview
            });
            return Err("a program is running: confirm the risk to write anyway".into());
        }
        if self.busy() {
            return Err("a read or write is in progress".into());
        }
        let records: Vec<PositionRecord> = preview.rows.iter().map(|r| r.new).collect();
        let n = records.len();
        self.write = Some(WriteJob::new(preview.kind, &records, COMMAND_BUFFER));
        let mut said = Vec::new();
        self.advance(&mut said);
        Ok(n)
    }

    /// Forgets the preview.
    pub fn cancel_preview(&mut self) {
        self.preview = None;
    }

    /// The line went down: reads and writes end where they are.
    /// What was read is forgotten too: the next line may reach another controller (or
    /// this one changed meanwhile), and Go checks the record the controller will use.
    /// The draft and the names stay.
    pub fn line_gone(&mut self) {
        self.read = None;
        if let Some(mut job) = self.write.take() {
            job.frame_ended(
                Outcome::Unknown("the line went down before the answer".into()),
                Some("the line went down".into()),
            );
            self.last_write = Some(job);
        }
        self.preview = None;
        self.go_confirm = None;
        self.rows.fill(Row::Unread);
        self.kind = PositionQueryKind::Query3;
        self.revision += 1;
    }
}

/// Two records hold the same data (the number aside).
pub fn same(a: &PositionRecord, b: &PositionRecord) -> bool {
    a.coords == b.coords
        && a.accel == b.accel
        && a.decel == b.decel
        && a.speed == b.speed
        && a.arms == b.arms
}

/// What differs between what was written and what was read back, in words.
fn difference(wrote: &PositionRecord, holds: &PositionRecord) -> String {
    let mut parts = Vec::new();
    for c in Column::ALL {
        let (a, b) = (c.text(wrote), c.text(holds));
        if a != b {
            parts.push(format!(
                "{} {} -> {}",
                c.heading(),
                if a.is_empty() { "empty" } else { &a },
                if b.is_empty() { "empty" } else { &b }
            ));
        }
    }
    if parts.is_empty() {
        "the arm system of SCARA 2".into()
    } else {
        parts.join(", ")
    }
}

/// A record at `number` of the pose `[x, y, z, r]` (wire units) with the arm system.
pub fn record_of_pose(number: u16, pose: [i32; 4], arm: RecordArm) -> PositionRecord {
    let axes = [Axis::A1, Axis::A2, Axis::A3, Axis::A4];
    PositionRecord {
        number,
        coords: PerAxis::from_pairs(axes.into_iter().zip(pose.map(Milli))),
        arms: crate::protocol::RecordArms {
            scara1: arm,
            scara2: RecordArm::Unspecified,
        },
        ..PositionRecord::default()
    }
}

#[cfg(test)]
mod tests;
