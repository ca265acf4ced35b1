//! The controller's signals as the operator watches them: a watch list of inputs,
//! outputs, flags and variables, read in the line time the status polls leave, forced
//! and edited behind a confirmation, each change sent once and read back.

pub mod file;
mod plan;
mod value;

use std::collections::HashMap;
use std::time::{Duration, Instant};

use serde::{Deserialize, Serialize};

use crate::link::LinkEvent;
use crate::pendant::Level;
use crate::protocol::{
    BitChange, BitData, BitSpace, Command, GLOBAL_FLAGS, INPUTS, LOCAL_FLAGS, OUTPUTS,
    RealEncoding, Reply, VarData, VarKind, VarValues, messages::signals::PROGRAMS,
};
pub use plan::{ReadPlan, plan_reads};
pub use value::Value;

/// The longest watch list: every row is read each round, so this bounds a round's
/// requests and the view's rows.
pub const MAX_ROWS: usize = 4_096;
/// The longest name beside a signal.
pub const MAX_NAME_CHARS: usize = 64;
/// Characters of a string variable row at most (one variable number per character).
pub const MAX_TEXT_CHARS: u8 = 64;
/// A round of reads starts at most this often: as the status cycle (100 ms), so the
/// frame log and the line see signals at the status' pace.
pub const MIN_ROUND: Duration = Duration::from_millis(100);
/// Signals plotted at once at most (a series each, [`crate::pendant::samples::polled::SIGNAL_ROWS`] rows).
pub const MAX_PLOTTED: usize = 16;
/// A value not read again for this long is shown stale (greyed).
pub const STALE_AFTER: Duration = Duration::from_secs(2);
/// A change stays highlighted this long.
pub const HIGHLIGHT_FOR: Duration = Duration::from_millis(1_500);
/// Rounds the refresh rate is measured over.
const RATE_ROUNDS: usize = 10;

/// What a row watches.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum SignalKind {
    Input,
    Output,
    Flag,
    Integer,
    Real,
    #[serde(rename = "string")]
    Text,
}

impl SignalKind {
    pub const ALL: [SignalKind; 6] = [
        SignalKind::Input,
        SignalKind::Output,
        SignalKind::Flag,
        SignalKind::Integer,
        SignalKind::Real,
        SignalKind::Text,
    ];

    /// The word for it: "Output".
    pub const fn label(self) -> &'static str {
        match self {
            SignalKind::Input => "Input",
            SignalKind::Output => "Output",
            SignalKind::Flag => "Flag",
            SignalKind::Integer => "Integer",
            SignalKind::Real => "Real",
            SignalKind::Text => "String",
        }
    }

    /// The word in a file: "output".
    pub const fn key(self) -> &'static str {
        match self {
            SignalKind::Input => "input",
            SignalKind::Output => "output",
            SignalKind::Flag => "flag",
            SignalKind::Integer => "integer",
            SignalKind::Real => "real",
            SignalKind::Text => "string",
        }
    }

    /// The kind a file's word names.
    pub fn from_key(s: &str) -> Option<SignalKind> {
        SignalKind::ALL
            .into_iter()
            .find(|k| k.key().eq_ignore_ascii_case(s.trim()))
    }

    /// Ports and flags: one bit each.
    pub const fn is_bit(self) -> bool {
        matches!(
            self,
            SignalKind::Input | SignalKind::Output | SignalKind::Flag
        )
    }

    /// Whether the operator may change it (outputs, flags, integer and real variables).
    pub const fn writable(self) -> bool {
        !matches!(self, SignalKind::Input | SignalKind::Text)
    }

    /// The bit space of a port or flag.
    pub const fn space(self) -> Option<BitSpace> {
        match self {
            SignalKind::Input => Some(BitSpace::Input),
            SignalKind::Output => Some(BitSpace::Output),
            SignalKind::Flag => Some(BitSpace::Flag),
            _ => None,
        }
    }

    /// The variable kind of a variable.
    pub const fn var(self) -> Option<VarKind> {
        match self {
            SignalKind::Integer => Some(VarKind::Integer),
            SignalKind::Real => Some(VarKind::Real),
            SignalKind::Text => Some(VarKind::Text),
            _ => None,
        }
    }

    /// Whether a program number applies (flags and variables; 0 = global).
    pub const fn has_program(self) -> bool {
        !matches!(self, SignalKind::Input | SignalKind::Output)
    }
}

/// One signal of the controller: an input, output, flag or variable (program 0 =
/// global, else that program's local one).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub struct Signal {
    pub kind: SignalKind,
    #[serde(default)]
    pub program: u8,
    pub number: u16,
}

impl Signal {
    pub const fn new(kind: SignalKind, program: u8, number: u16) -> Self {
        Signal {
            kind,
            program,
            number,
        }
    }

    /// Whether the controller has it (numbering per PROTOCOL.md 3.34-3.43, whose
    /// categories and variable ranges are inferred), or why not, in words for the row.
    pub fn check(&self, chars: u8) -> Result<(), String> {
        let what = self.kind.label();
        if self.kind.has_program() && self.program != 0 && !PROGRAMS.contains(&self.program) {
            return Err(format!(
                "program {} does not exist: 0 (global) or {}-{}",
                self.program,
                PROGRAMS.start,
                PROGRAMS.end - 1
            ));
        }
        let range = match (self.kind, self.program) {
            (SignalKind::Input, _) => INPUTS.numbers,
            (SignalKind::Output, _) => OUTPUTS.numbers,
            (SignalKind::Flag, 0) => GLOBAL_FLAGS.numbers,
            (SignalKind::Flag, _) => LOCAL_FLAGS.numbers,
            (kind, p) => kind.var().map(|v| v.numbers(p == 0)).unwrap_or(0..0),
        };
        let last = if self.kind == SignalKind::Text {
            self.number.saturating_add(u16::from(chars.max(1)) - 1)
        } else {
            self.number
        };
        if range.contains(&self.number) && range.contains(&last) {
            return Ok(());
        }
        let scope = match (self.kind.has_program(), self.program) {
            (false, _) => String::new(),
            (true, 0) => " global".to_owned(),
            (true, p) => format!(" local (program {p})"),
        };
        Err(format!(
            "{what} {} is not a{scope} {} number: {}-{}",
            self.number,
            what.to_lowercase(),
            range.start,
            range.end.saturating_sub(1)
        ))
    }
}

impl std::fmt::Display for Signal {
    /// "Output 305", "Flag 905 (program 3)".
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{} {}", self.kind.label(), self.number)?;
        if self.kind.has_program() && self.program != 0 {
            write!(f, " (program {})", self.program)?;
        }
        Ok(())
    }
}

/// One row of the watch list.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct WatchRow {
    pub signal: Signal,
    /// The operator's name for it (may be empty).
    #[serde(default)]
    pub name: String,
    /// String variables: characters read from the number (one per variable number).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub chars: u8,
    /// Drawn in the Plots pane.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub plot: bool,
}

fn is_zero(n: &u8) -> bool {
    *n == 0
}

impl WatchRow {
    pub fn new(signal: Signal, name: impl Into<String>) -> Self {
        WatchRow {
            signal,
            name: name.into(),
            chars: if signal.kind == SignalKind::Text {
                16
            } else {
                0
            },
            plot: false,
        }
    }

    /// "Output 305 'gripper close'".
    pub fn label(&self) -> String {
        if self.name.is_empty() {
            self.signal.to_string()
        } else {
            format!("{} '{}'", self.signal, self.name)
        }
    }

    /// The numbers this row reads.
    pub fn numbers(&self) -> std::ops::Range<u16> {
        let n = self.signal.number;
        let len = if self.signal.kind == SignalKind::Text {
            u16::from(self.chars.max(1))
        } else {
            1
        };
        n..n.saturating_add(len)
    }
}

/// The list an X-SEL pendant starts with: the first 32 inputs and outputs and the
/// global flags' first 32.
pub fn default_rows() -> Vec<WatchRow> {
    let range = |kind, head: u16| {
        (head..head + 32).map(move |n| WatchRow::new(Signal::new(kind, 0, n), ""))
    };
    range(SignalKind::Input, INPUTS.head())
        .chain(range(SignalKind::Output, OUTPUTS.head()))
        .chain(range(SignalKind::Flag, GLOBAL_FLAGS.head()))
        .collect()
}

/// What is known of one watched signal.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RowState {
    pub value: Option<Value>,
    /// When it was last read.
    pub read_at: Option<Instant>,
    /// When it last changed (not its first reading).
    pub changed_at: Option<Instant>,
    /// Changes seen since it was added.
    pub changes: u64,
    /// Why the last read of it failed (cleared by the next good read).
    pub error: Option<String>,
}

/// A change the operator asked for, shown for confirmation: "Output 305 'gripper close'
/// OFF -> ON".
#[derive(Clone, Debug, PartialEq)]
pub struct Proposal {
    pub signal: Signal,
    pub label: String,
    pub from: Option<Value>,
    pub to: Value,
    /// A program was running when it was asked: confirming needs the risk taken.
    pub program_running: bool,
}

impl Proposal {
    /// The sentence the confirmation shows.
    pub fn text(&self, encoding: RealEncoding) -> String {
        let from = self
            .from
            .as_ref()
            .map_or("?".to_owned(), |v| v.show(encoding));
        format!("{} {from} -> {}", self.label, self.to.show(encoding))
    }
}

/// A change sent, awaiting its reply, then its read-back.
#[derive(Clone, Debug, PartialEq)]
struct Change {
    proposal: Proposal,
    /// The reply came: the read-back is on its way.
    acknowledged: bool,
}

/// A plotted signal's new value.
#[derive(Clone, Debug, PartialEq)]
pub struct SignalSample {
    pub at: Instant,
    pub signal: Signal,
    /// The trace's name: the signal ("Output 305"), which a rename does not change.
    pub label: String,
    pub value: f64,
    /// A port or flag (a lane), not a number.
    pub bit: bool,
}

/// The state of the controller the signals' checks need, from the pendant.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SignalsCx {
    /// The line is up and the controller answers, or why not.
    pub ready: Result<(), String>,
    /// 215H: a program runs (None: not known yet).
    pub program_running: Option<bool>,
    /// 215H status byte 2 bit 3: output changes are held by the I/O interlock.
    pub io_interlock: bool,
}

/// One thing the operator asked of the Signals view.
#[derive(Clone, Debug, PartialEq)]
pub enum SignalsIntent {
    /// Watch `count` signals of `kind` from `number` (a range), named `name` (numbered
    /// when more than one), strings `chars` long.
    Add {
        signal: Signal,
        count: u16,
        name: String,
        chars: u8,
    },
    Remove(Signal),
    Rename(Signal, String),
    Plot(Signal, bool),
    /// Back to the default list.
    Defaults,
    Clear,
    /// The view is shown (reads run while it is, or while a row is plotted).
    Watch(bool),
    /// The encoding of this controller's doubles.
    RealEncoding(RealEncoding),
    /// A value typed (or a bit toggled) for a signal: asks for confirmation.
    Propose {
        signal: Signal,
        text: String,
    },
    /// Send the proposal (`take_the_risk`: the operator confirmed a running program).
    Confirm {
        take_the_risk: bool,
    },
    Cancel,
    /// A watch-list file's rows (or why it could not be read) replace the list.
    Import {
        path: String,
        read: Result<Vec<WatchRow>, String>,
    },
}

/// The watch list, what was read, the change waiting for confirmation or its reply.
#[derive(Debug)]
pub struct Signals {
    rows: Vec<WatchRow>,
    states: HashMap<Signal, RowState>,
    pub encoding: RealEncoding,
    /// The reads of one round, planned from the rows (again when they change).
    plan: Option<Vec<ReadPlan>>,
    /// Reads of the current round not answered yet (a read-back of a change may be the
    /// same query: one answer takes out one of them, whichever it was).
    in_flight: Vec<Command>,
    round_started: Option<Instant>,
    /// How long the last rounds took, start to start.
    rounds: std::collections::VecDeque<Duration>,
    watching: bool,
    pub proposal: Option<Proposal>,
    change: Option<Change>,
    /// The last word for the view.
    pub feedback: Option<(Level, String)>,
    commands: Vec<(Command, bool)>,
    samples: Vec<SignalSample>,
    revision: u64,
}

impl Default for Signals {
    fn default() -> Self {
        Self::new(default_rows())
    }
}

impl Signals {
    pub fn new(rows: Vec<WatchRow>) -> Self {
        Signals {
            rows,
            states: HashMap::new(),
            encoding: RealEncoding::default(),
            plan: None,
            in_flight: Vec::new(),
            round_started: None,
            rounds: Default::default(),
            watching: false,
            proposal: None,
            change: None,
            feedback: None,
            commands: Vec::new(),
            samples: Vec::new(),
            revision: 0,
        }
    }

    pub fn rows(&self) -> &[WatchRow] {
        &self.rows
    }

    pub fn state(&self, signal: &Signal) -> Option<&RowState> {
        self.states.get(signal)
    }

    /// The watch list and the real encoding as saved between runs.
    pub fn saved(&self) -> Vec<u8> {
        file::to_json(&self.rows, self.encoding).into_bytes()
    }

    /// Takes back what [`Signals::saved`] wrote (checked as an imported file).
    pub fn restore(&mut self, rows: Vec<WatchRow>, encoding: Option<RealEncoding>) {
        self.rows = rows;
        self.encoding = encoding.unwrap_or_default();
        self.edited();
    }

    /// Changes with every edit of the list (for saving it).
    pub fn revision(&self) -> u64 {
        self.revision
    }

    /// Whether a row's value is out of date at `now`.
    pub fn is_stale(&self, signal: &Signal, now: Instant) -> bool {
        self.states
            .get(signal)
            .and_then(|s| s.read_at)
            .is_none_or(|t| now.saturating_duration_since(t) > STALE_AFTER)
    }

    /// Rounds per second over the last rounds (None before two rounds).
    pub fn refresh_rate(&self) -> Option<f64> {
        let total: Duration = self.rounds.iter().sum();
        (!self.rounds.is_empty() && !total.is_zero())
            .then(|| self.rounds.len() as f64 / total.as_secs_f64())
    }

    /// Reads of the current round not answered yet.
    pub fn reads_in_flight(&self) -> usize {
        self.in_flight.len()
    }

    /// Requests in one round.
    pub fn reads_per_round(&self) -> usize {
        self.plan
            .as_ref()
            .map_or_else(|| plan_reads(&self.rows).len(), Vec::len)
    }

    /// Whether a change is on its way (sent, or awaiting its read-back).
    pub fn change_pending(&self) -> bool {
        self.change.is_some()
    }

    /// Commands for the link: (command, at the user's priority) — reads are spare.
    pub fn take_commands(&mut self) -> Vec<(Command, bool)> {
        std::mem::take(&mut self.commands)
    }

    /// New values of plotted rows.
    pub fn take_samples(&mut self) -> Vec<SignalSample> {
        std::mem::take(&mut self.samples)
    }

    /// Whether this model sent `command` (its events come back here).
    pub fn owns(command: &Command) -> bool {
        matches!(
            command,
            Command::BitQuery(_)
                | Command::BitChange(_)
                | Command::VarQuery(_)
                | Command::VarWrite(_)
        )
    }

    fn edited(&mut self) {
        self.plan = None;
        self.revision += 1;
        let watched: std::collections::HashSet<Signal> =
            self.rows.iter().map(|r| r.signal).collect();
        self.states.retain(|s, _| watched.contains(s));
    }

    /// Once a frame: a new round of reads when the last one is answered, rows are
    /// watched (the view shown or a row plotted) and the line is up.
    pub fn tick(&mut self, now: Instant, line_up: bool) {
        let wanted = self.watching || self.rows.iter().any(|r| r.plot);
        if !wanted || !line_up || !self.in_flight.is_empty() || self.rows.is_empty() {
            return;
        }
        if let Some(start) = self.round_started {
            if now.saturating_duration_since(start) < MIN_ROUND {
                return;
            }
            if self.rounds.len() == RATE_ROUNDS {
                self.rounds.pop_front();
            }
            self.rounds.push_back(now.saturating_duration_since(start));
        }
        let plan = self.plan.get_or_insert_with(|| plan_reads(&self.rows));
        self.in_flight = plan.iter().map(|p| p.command.clone()).collect();
        self.round_started = Some(now);
        self.commands
            .extend(plan.iter().map(|p| (p.command.clone(), false)));
    }

    /// The line went away: reads in flight are gone, values are kept (greyed as they
    /// age), a change awaiting its reply is said to be unknown.
    pub fn line_gone(&mut self) -> Option<String> {
        self.in_flight.clear();
        self.round_started = None;
        self.rounds.clear();
        self.change.take().map(|c| {
            format!(
                "{}: the line went down before the change was confirmed; read it again",
                c.proposal.label
            )
        })
    }

    /// STOP: a change waiting for confirmation is forgotten; one confirmed but not yet
    /// handed to the link (`dropped`) is never sent.
    pub fn stopped(&mut self, dropped: bool) -> Option<String> {
        self.proposal = None;
        if !dropped {
            return None;
        }
        self.change.take().map(|c| {
            format!(
                "{}: not sent: STOP came first",
                c.proposal.text(self.encoding)
            )
        })
    }

    /// Applies one intent; the words for the operator come back.
    pub fn apply(
        &mut self,
        intent: SignalsIntent,
        cx: SignalsCx,
        now: Instant,
    ) -> Option<(Level, String)> {
        let said = match intent {
            SignalsIntent::Add {
                signal,
                count,
                name,
                chars,
            } => self.add(signal, count, name, chars),
            SignalsIntent::Remove(s) => {
                self.rows.retain(|r| r.signal != s);
                self.edited();
                Ok(None)
            }
            SignalsIntent::Rename(s, name) => check_name(&name).map(|name| {
                if let Some(r) = self.rows.iter_mut().find(|r| r.signal == s) {
                    r.name = name;
                }
                self.revision += 1;
                None
            }),
            SignalsIntent::Plot(s, on) => {
                let plotted = self.rows.iter().filter(|r| r.plot).count();
                if on && plotted >= MAX_PLOTTED {
                    Err(format!("at most {MAX_PLOTTED} signals are plotted at once"))
                } else {
                    if let Some(r) = self.rows.iter_mut().find(|r| r.signal == s) {
                        r.plot = on;
                    }
                    self.revision += 1;
                    Ok(None)
                }
            }
            SignalsIntent::Defaults => {
                self.rows = default_rows();
                self.edited();
                Ok(Some("watch list back to its defaults".to_owned()))
            }
            SignalsIntent::Clear => {
                self.rows.clear();
                self.edited();
                Ok(None)
            }
            SignalsIntent::Watch(on) => {
                self.watching = on;
                Ok(None)
            }
            SignalsIntent::RealEncoding(e) => {
                self.encoding = e;
                self.revision += 1;
                Ok(None)
            }
            SignalsIntent::Propose { signal, text } => self.propose(signal, &text, &cx),
            SignalsIntent::Confirm { take_the_risk } => self.confirm(take_the_risk, &cx),
            SignalsIntent::Cancel => {
                self.proposal = None;
                Ok(None)
            }
            SignalsIntent::Import { path, read } => match read {
                Ok(rows) => {
                    let n = rows.len();
                    self.rows = rows;
                    self.edited();
                    Ok(Some(format!("{path}: {n} rows in the watch list")))
                }
                Err(e) => Err(format!("{path}: the watch list is unchanged: {e}")),
            },
        };
        let _ = now;
        let said = match said {
            Ok(Some(text)) => Some((Level::Info, text)),
            Ok(None) => None,
            Err(text) => Some((Level::Warning, text)),
        };
        if let Some(s) = &said {
            self.feedback = Some(s.clone());
        }
        said
    }

    fn add(
        &mut self,
        signal: Signal,
        count: u16,
        name: String,
        chars: u8,
    ) -> Result<Option<String>, String> {
        let name = check_name(&name)?;
        let count = count.max(1);
        if signal.kind == SignalKind::Text && !(1..=MAX_TEXT_CHARS).contains(&chars) {
            return Err(format!("a string row reads 1-{MAX_TEXT_CHARS} characters"));
        }
        let step = if signal.kind == SignalKind::Text {
            u16::from(chars)
        } else {
            1
        };
        let mut new = Vec::new();
        for i in 0..count {
            let number = signal
                .number
                .checked_add(i.saturating_mul(step))
                .ok_or("numbers beyond 65535")?;
            let s = Signal { number, ..signal };
            s.check(chars)?;
            if self.rows.iter().any(|r| r.signal == s) {
                continue;
            }
            let name = match (name.is_empty(), count) {
                (true, _) => String::new(),
                (false, 1) => name.clone(),
                (false, _) => format!("{name} {}", i + 1),
            };
            new.push(WatchRow {
                chars: if s.kind == SignalKind::Text { chars } else { 0 },
                ..WatchRow::new(s, name)
            });
        }
        if self.rows.len() + new.len() > MAX_ROWS {
            return Err(format!(
                "the watch list holds at most {MAX_ROWS} rows ({} now)",
                self.rows.len()
            ));
        }
        let n = new.len();
        self.rows.extend(new);
        self.edited();
        Ok(Some(match n {
            0 => "already watched".to_owned(),
            1 => format!("watching {signal}"),
            _ => format!("watching {n} rows from {signal}"),
        }))
    }

    fn propose(
        &mut self,
        signal: Signal,
        text: &str,
        cx: &SignalsCx,
    ) -> Result<Option<String>, String> {
        let label = self
            .rows
            .iter()
            .find(|r| r.signal == signal)
            .map_or_else(|| signal.to_string(), WatchRow::label);
        if !signal.kind.writable() {
            return Err(format!(
                "{label}: {}s cannot be changed from a host",
                signal.kind.label().to_lowercase()
            ));
        }
        signal.check(0).map_err(|e| format!("{label}: {e}"))?;
        let from = self.states.get(&signal).and_then(|s| s.value.clone());
        let to = Value::parse(signal.kind, text, from.as_ref(), self.encoding)
            .map_err(|e| format!("{label}: {e}"))?;
        self.proposal = Some(Proposal {
            signal,
            label,
            from,
            to,
            program_running: cx.program_running == Some(true),
        });
        Ok(None)
    }

    fn confirm(&mut self, take_the_risk: bool, cx: &SignalsCx) -> Result<Option<String>, String> {
        let Some(p) = self.proposal.clone() else {
            return Ok(None);
        };
        let text = p.text(self.encoding);
        if let Err(why) = &cx.ready {
            return Err(format!("not sent: {text}: {why}"));
        }
        if cx.program_running == Some(true) && !take_the_risk {
            self.proposal = Some(Proposal {
                program_running: true,
                ..p
            });
            return Err(format!(
                "not sent: a program is running and may drive {}: confirm the risk to send it",
                p.signal
            ));
        }
        if let Some(c) = &self.change {
            return Err(format!(
                "not sent: {} is still being confirmed",
                c.proposal.label
            ));
        }
        let command = match (&p.to, p.signal.kind.space(), p.signal.kind.var()) {
            (Value::Bit(on), Some(space), _) => Command::BitChange(BitChange {
                space,
                program: p.signal.program,
                number: p.signal.number,
                on: *on,
            }),
            (Value::Int(v), _, Some(VarKind::Integer)) => Command::VarWrite(VarData {
                program: p.signal.program,
                start: p.signal.number,
                values: VarValues::Integer(vec![*v]),
            }),
            (Value::Real(w), _, Some(VarKind::Real)) => Command::VarWrite(VarData {
                program: p.signal.program,
                start: p.signal.number,
                values: VarValues::Real(vec![*w]),
            }),
            _ => return Err(format!("not sent: {text}: not a value for it")),
        };
        self.proposal = None;
        self.commands.push((command, true));
        self.change = Some(Change {
            proposal: p,
            acknowledged: false,
        });
        Ok(Some(format!("sending {text}")))
    }

    /// Applies an event that answers one of this model's commands; what to tell the
    /// operator comes back. `cx` says whether the I/O interlock holds outputs.
    pub fn handle_event(
        &mut self,
        event: &LinkEvent,
        cx: SignalsCx,
        now: Instant,
    ) -> Vec<(Level, String)> {
        let mut said = Vec::new();
        match event {
            LinkEvent::Reply { command, reply, .. } => match (command, reply) {
                (Command::BitQuery(_), Reply::Bits(d)) => {
                    self.read_done(command);
                    self.take_bits(d, now);
                    self.check_back(command, &cx, &mut said);
                }
                (Command::VarQuery(_), Reply::Vars(d)) => {
                    self.read_done(command);
                    self.take_vars(d, now);
                    self.check_back(command, &cx, &mut said);
                }
                (Command::BitChange(_) | Command::VarWrite(_), _) => {
                    if let Some(c) = self.change.as_mut() {
                        c.acknowledged = true;
                        let back = read_back(&c.proposal.signal);
                        self.commands.push((back, true));
                    }
                }
                _ => {
                    self.read_done(command);
                }
            },
            LinkEvent::ErrorReply { command, code, .. } => {
                if self.read_done(command) {
                    self.mark_failed(command, format!("refused: error {code}"));
                } else if let Some(c) = self.change_for(command) {
                    said.push((
                        Level::Error,
                        format!(
                            "{}: the controller refused the change: error {code}",
                            c.proposal.label
                        ),
                    ));
                }
            }
            // The link sends a query again: its last word is still to come.
            LinkEvent::Timeout { retrying: true, .. } => {}
            LinkEvent::Timeout { command, .. } | LinkEvent::Interrupted { command, .. } => {
                if self.read_done(command) {
                    // A reply that did not decode (a group short of its count) ends so
                    // too: the frame log shows what came.
                    self.mark_failed(
                        command,
                        "no valid reply (the frame log shows what came)".to_owned(),
                    );
                } else if let Some(c) = self.change_for(command) {
                    // Sent once, never again: what the controller holds is read back.
                    said.push((
                        Level::Warning,
                        format!(
                            "{}: no reply to the change (not sent again): reading back what the controller holds",
                            c.proposal.label
                        ),
                    ));
                    self.commands.push((read_back(&c.proposal.signal), true));
                    self.change = Some(Change {
                        acknowledged: true,
                        ..c
                    });
                }
            }
            LinkEvent::NotSent {
                command, reason, ..
            } => {
                if !self.read_done(command)
                    && let Some(c) = self.change_for(command)
                {
                    said.push((
                        Level::Warning,
                        format!("{}: not sent: {reason}", c.proposal.label),
                    ));
                }
            }
            _ => {}
        }
        if let Some(s) = said.last() {
            self.feedback = Some(s.clone());
        }
        said
    }

    /// A round's read answered (true), or the command was not a round's read.
    fn read_done(&mut self, command: &Command) -> bool {
        let ours = matches!(command, Command::BitQuery(_) | Command::VarQuery(_));
        if let Some(i) = self.in_flight.iter().position(|c| c == command) {
            self.in_flight.swap_remove(i);
        }
        ours
    }

    /// The change `command` carried, taken (its story ends here).
    fn change_for(&mut self, command: &Command) -> Option<Change> {
        matches!(command, Command::BitChange(_) | Command::VarWrite(_))
            .then(|| self.change.take())
            .flatten()
    }

    fn mark_failed(&mut self, command: &Command, why: String) {
        let covered = |r: &WatchRow| plan::covers(command, r);
        for r in self.rows.iter().filter(|r| covered(r)) {
            self.states.entry(r.signal).or_default().error = Some(why.clone());
        }
    }

    fn set(&mut self, row: usize, value: Value, now: Instant) {
        let r = &self.rows[row];
        if r.plot
            && let Some(v) = value.as_f64(self.encoding)
        {
            self.samples.push(SignalSample {
                at: now,
                signal: r.signal,
                label: r.signal.to_string(),
                value: v,
                bit: r.signal.kind.is_bit(),
            });
        }
        let state = self.states.entry(r.signal).or_default();
        if state.value.as_ref() != Some(&value) {
            if state.value.is_some() {
                state.changed_at = Some(now);
                state.changes += 1;
            }
            state.value = Some(value);
        }
        state.read_at = Some(now);
        state.error = None;
    }

    fn take_bits(&mut self, d: &BitData, now: Instant) {
        for i in 0..self.rows.len() {
            let s = self.rows[i].signal;
            if s.kind.space() == Some(d.space)
                && (d.space != BitSpace::Flag || s.program == d.program)
                && let Some(on) = d.get(s.number)
            {
                self.set(i, Value::Bit(on), now);
            }
        }
    }

    fn take_vars(&mut self, d: &VarData, now: Instant) {
        let span = d.numbers();
        for i in 0..self.rows.len() {
            let r = &self.rows[i];
            if r.signal.kind.var() != Some(d.kind()) || r.signal.program != d.program {
                continue;
            }
            let numbers = r.numbers();
            if numbers.start < span.start || numbers.end > span.end {
                continue;
            }
            let at = usize::from(numbers.start - span.start);
            let value = match &d.values {
                VarValues::Integer(v) => Value::Int(v[at]),
                VarValues::Real(v) => Value::Real(v[at]),
                VarValues::Text(v) => Value::Text(v[at..at + numbers.len()].to_vec()),
            };
            self.set(i, value, now);
        }
    }

    /// After a read that carries it: the change awaiting its read-back is judged.
    fn check_back(&mut self, read: &Command, cx: &SignalsCx, said: &mut Vec<(Level, String)>) {
        let Some(c) = self.change.as_ref().filter(|c| c.acknowledged) else {
            return;
        };
        let p = &c.proposal;
        // Only a read that carries the changed signal says what it holds now.
        if !plan::covers(read, &WatchRow::new(p.signal, "")) {
            return;
        }
        let Some(now) = self.states.get(&p.signal).and_then(|s| s.value.clone()) else {
            return;
        };
        let shown = now.show(self.encoding);
        let text = if now == p.to {
            (Level::Info, format!("{} is {shown} (read back)", p.label))
        } else if p.signal.kind == SignalKind::Output && cx.io_interlock {
            (
                Level::Warning,
                format!(
                    "{} reads {shown}: the change is held by the I/O interlock and takes effect when it ends (STOP cancels it)",
                    p.label
                ),
            )
        } else {
            (
                Level::Warning,
                format!(
                    "{} reads {shown}, not {}: something else drives it (a program or a system function)",
                    p.label,
                    p.to.show(self.encoding)
                ),
            )
        };
        said.push(text);
        self.change = None;
    }
}

/// The query that reads `signal` back after a change: its group of 8, or the variable.
fn read_back(signal: &Signal) -> Command {
    let row = WatchRow::new(*signal, "");
    plan_reads(std::slice::from_ref(&row))
        .into_iter()
        .next()
        .map(|p| p.command)
        .unwrap_or(Command::SystemStatus)
}

fn check_name(name: &str) -> Result<String, String> {
    let name = name.trim();
    if name.chars().count() > MAX_NAME_CHARS || name.chars().any(char::is_control) {
        return Err(format!(
            "a name is at most {MAX_NAME_CHARS} characters, without control characters"
        ));
    }
    Ok(name.to_owned())
}

#[cfg(test)]
mod tests;
