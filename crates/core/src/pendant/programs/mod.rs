//! The controller's programs as the operator runs them: each one's state polled with
//! 213H, and run, pause, one step, resume and end (253H-257H) asked for behind the
//! readiness checks and, where the arm may move, a confirmation (PROTOCOL.md 3.44-3.45).

mod listing;
#[cfg(test)]
mod tests;

use std::collections::BTreeMap;
use std::time::{Duration, Instant};

use crate::link::LinkEvent;
use crate::pendant::Level;
use crate::protocol::{
    ALL_PROGRAMS, Command, ErrorCode, PROGRAMS, ProgramAction, ProgramCall, ProgramStatus,
    ProgramStatusQuery, Reply,
};
pub use listing::{ListedProgram, ListedStep, Listing, MAX_FILE_BYTES};

/// A round of status reads starts at most this often: the status cycle's pace.
pub const MIN_ROUND: Duration = Duration::from_millis(100);
/// Programs of the sweep read in one round besides the selected and started ones: the
/// whole range is read every `64 / SWEEP` rounds (1.6 s at the fastest).
pub const SWEEP: u8 = 4;
/// A status not read again for this long is shown stale.
pub const STALE_AFTER: Duration = Duration::from_secs(2);

/// Where one program is, as read and as this window remembers it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ProgramState {
    /// Not read yet (or not since the line came back).
    Unknown,
    NotStarted,
    Running,
    /// Started, and paused from this window (213H has no paused bit: the window
    /// remembers its own 255H and 256H `[inferred, PROTOCOL.md 3.44]`).
    Paused,
    /// Not started, with the error the controller ended it with.
    Error {
        code: ErrorCode,
        step: u16,
    },
}

impl ProgramState {
    /// The state in a word or two, for the table.
    pub fn text(self) -> String {
        match self {
            ProgramState::Unknown => "not read".to_owned(),
            ProgramState::NotStarted => "not started".to_owned(),
            ProgramState::Running => "running".to_owned(),
            ProgramState::Paused => "paused".to_owned(),
            ProgramState::Error { code, step } => format!("error {code} at step {step}"),
        }
    }

    /// Started: running or paused.
    pub fn started(self) -> bool {
        matches!(self, ProgramState::Running | ProgramState::Paused)
    }
}

/// One program's row.
#[derive(Clone, Debug, Default)]
pub struct ProgramRow {
    /// The last 213H answer and when it came.
    pub status: Option<(ProgramStatus, Instant)>,
    /// Paused by this window's 255H or 256H, and not run or resumed since.
    pub paused_here: bool,
    /// Started from this window (run, one step or resume confirmed here).
    pub started_here: bool,
    /// The operator confirmed that this program may move the arm; Step and Resume then
    /// go without asking until it ends or STOP.
    pub confirmed: bool,
    /// The last read was refused or never answered: why.
    pub failed: Option<String>,
}

impl ProgramRow {
    /// The state the view shows.
    pub fn state(&self) -> ProgramState {
        match self.status {
            None => ProgramState::Unknown,
            Some((s, _)) if s.started() && self.paused_here => ProgramState::Paused,
            Some((s, _)) if s.started() => ProgramState::Running,
            Some((s, _)) => match s.error() {
                Some((code, step)) => ProgramState::Error { code, step },
                None => ProgramState::NotStarted,
            },
        }
    }

    /// The executing step, when valid.
    pub fn step(&self) -> Option<u16> {
        self.status.and_then(|(s, _)| s.executing_step())
    }
}

/// An operation waiting for the operator's confirmation.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Proposal {
    pub call: ProgramCall,
    /// The question, naming the program and what the arm will do.
    pub text: String,
}

/// The state of the controller and the window the checks need, from the pendant.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ProgramsCx {
    /// The line is up and the controller answers, or why not.
    pub ready: Result<(), String>,
    /// The arm may be moved (servo on, homed, no E-stop, no alarm...), or why not.
    pub motion: Result<(), String>,
    /// A jog or move of this window runs, or a STOP latch holds: why programs wait.
    pub jogging: Option<String>,
}

/// One thing the operator asked of the Programs view.
#[derive(Clone, Debug, PartialEq)]
pub enum ProgramsIntent {
    /// The view is shown (its reads run while it is, or while a program started here runs).
    Watch(bool),
    /// The program the view follows (read every round, its listing shown).
    Select(u8),
    /// Run, end, pause, one step or resume one program (run and one step ask first).
    Ask(ProgramAction, u8),
    /// End every running program (254H `00`).
    EndAll,
    /// Send the operation asked about.
    Confirm,
    Cancel,
    /// A program listing read from a file (or why it could not be).
    Listing {
        path: String,
        read: Result<Listing, String>,
    },
}

/// The programs: their rows, the operation waiting for confirmation, the last word.
#[derive(Debug, Default)]
pub struct Programs {
    rows: BTreeMap<u8, ProgramRow>,
    pub selected: Option<u8>,
    watching: bool,
    round_started: Option<Instant>,
    /// Where the sweep of every program goes on from.
    sweep_next: u8,
    /// Status reads sent and not answered yet.
    in_flight: Vec<u8>,
    pub proposal: Option<Proposal>,
    /// The last word for the view.
    pub feedback: Option<(Level, String)>,
    pub listing: Option<Listing>,
    commands: Vec<(Command, bool)>,
}

impl Programs {
    /// Every program number the controller is believed to have (`PROGRAMS`).
    pub fn numbers() -> impl Iterator<Item = u8> {
        PROGRAMS
    }

    /// The row of program `n` (an empty one when never read).
    pub fn row(&self, n: u8) -> ProgramRow {
        self.rows.get(&n).cloned().unwrap_or_default()
    }

    /// Whether `n`'s status is older than [`STALE_AFTER`] (or was never read).
    pub fn is_stale(&self, n: u8, now: Instant) -> bool {
        self.rows
            .get(&n)
            .and_then(|r| r.status)
            .is_none_or(|(_, at)| now.saturating_duration_since(at) > STALE_AFTER)
    }

    /// Programs started (as last read).
    pub fn started(&self) -> impl Iterator<Item = u8> + '_ {
        self.rows
            .iter()
            .filter(|(_, r)| r.state().started())
            .map(|(n, _)| *n)
    }

    /// Commands for the link: (command, at the user's priority) — status reads are spare.
    pub fn take_commands(&mut self) -> Vec<(Command, bool)> {
        std::mem::take(&mut self.commands)
    }

    /// Whether this model sent `command` (its events come back here). The link's own
    /// 254H `00` after a STOP comes here too.
    pub fn owns(command: &Command) -> bool {
        matches!(command, Command::ProgramStatus(_) | Command::Program(_))
    }

    /// Once a frame: a round of 213H reads when the last is answered, while the view is
    /// shown or a program started here runs, and the line is up.
    pub fn tick(&mut self, now: Instant, line_up: bool) {
        let started_here = self.rows.values().any(|r| r.started_here);
        if !(self.watching || started_here) || !line_up || !self.in_flight.is_empty() {
            return;
        }
        if self
            .round_started
            .is_some_and(|t| now.saturating_duration_since(t) < MIN_ROUND)
        {
            return;
        }
        self.round_started = Some(now);
        let mut wanted: Vec<u8> = self.selected.into_iter().collect();
        wanted.extend(
            self.rows
                .iter()
                .filter(|(_, r)| r.started_here || r.state().started())
                .map(|(n, _)| *n),
        );
        if self.watching {
            let span = PROGRAMS.end - PROGRAMS.start;
            for i in 0..SWEEP {
                let n = PROGRAMS.start + (self.sweep_next.wrapping_add(i)) % span;
                wanted.push(n);
            }
            self.sweep_next = (self.sweep_next + SWEEP) % span;
        }
        wanted.sort_unstable();
        wanted.dedup();
        for n in wanted {
            self.in_flight.push(n);
            self.commands.push((
                Command::ProgramStatus(ProgramStatusQuery { program: n }),
                false,
            ));
        }
    }

    /// The line went away: reads in flight are gone; a program started here is paused
    /// by the link when the line comes back (255H `00` after its STOP).
    pub fn line_gone(&mut self) -> Option<String> {
        self.in_flight.clear();
        self.round_started = None;
        self.proposal = None;
        let here: Vec<u8> = self
            .rows
            .iter()
            .filter(|(_, r)| r.started_here && r.state() == ProgramState::Running)
            .map(|(n, _)| *n)
            .collect();
        for r in self.rows.values_mut() {
            r.status = None;
        }
        (!here.is_empty()).then(|| {
            format!(
                "the line went down while program {} ran: when it comes back, the pendant stops the arm and pauses every program (238H, 255H 00) before anything else",
                list(&here)
            )
        })
    }

    /// STOP: the question is forgotten, every confirmation taken back; the link ends the
    /// programs (238H, 254H `00`, 238H).
    pub fn stopped(&mut self) {
        self.proposal = None;
        for r in self.rows.values_mut() {
            r.confirmed = false;
            r.paused_here = false;
        }
    }

    /// Applies one intent; the words for the operator come back.
    pub fn apply(
        &mut self,
        intent: ProgramsIntent,
        cx: &ProgramsCx,
        _now: Instant,
    ) -> Option<(Level, String)> {
        let said = match intent {
            ProgramsIntent::Watch(on) => {
                self.watching = on;
                Ok(None)
            }
            ProgramsIntent::Select(n) => self.check_number(n).map(|()| {
                self.selected = Some(n);
                None
            }),
            ProgramsIntent::Ask(action, n) => self.ask(action, n, cx),
            ProgramsIntent::EndAll => cx.ready.clone().map(|()| {
                self.send(ProgramCall::END_ALL);
                Some("ending every running program (254H 00)".to_owned())
            }),
            ProgramsIntent::Confirm => match self.proposal.take() {
                None => Ok(None),
                Some(p) => self
                    .check(p.call.action, p.call.program, cx)
                    .map(|()| Some(self.confirmed(p.call))),
            },
            ProgramsIntent::Cancel => {
                self.proposal = None;
                Ok(None)
            }
            ProgramsIntent::Listing { path, read } => match read {
                Ok(listing) => {
                    let said = listing.summary();
                    if self.selected.is_none() {
                        self.selected = listing.programs.first().map(|p| p.number);
                    }
                    self.listing = Some(listing);
                    Ok(Some(said))
                }
                Err(e) => Err(format!("{path}: {e}")),
            },
        };
        let said = match said {
            Ok(None) => return None,
            Ok(Some(text)) => (Level::Info, text),
            Err(text) => (Level::Warning, text),
        };
        self.feedback = Some(said.clone());
        Some(said)
    }

    fn check_number(&self, n: u8) -> Result<(), String> {
        if PROGRAMS.contains(&n) {
            Ok(())
        } else {
            Err(format!(
                "program {n} does not exist: programs are numbered {}-{}",
                PROGRAMS.start,
                PROGRAMS.end - 1
            ))
        }
    }

    /// Whether `action` may go to program `n` now, and if not, why.
    fn check(&self, action: ProgramAction, n: u8, cx: &ProgramsCx) -> Result<(), String> {
        self.check_number(n)?;
        let what = format!("{} program {n}", action.name());
        cx.ready.clone().map_err(|why| format!("{what}: {why}"))?;
        let state = self.row(n).state();
        match (action, state) {
            (_, ProgramState::Unknown) if action != ProgramAction::End => {
                return Err(format!("{what}: its status was not read yet"));
            }
            (ProgramAction::Run, s) if s.started() => {
                return Err(format!("{what}: it is {} already", s.text()));
            }
            (ProgramAction::Step, ProgramState::Running) => {
                return Err(format!("{what}: it is running: pause it first"));
            }
            (ProgramAction::Pause, s) if s != ProgramState::Running => {
                return Err(format!("{what}: it is {}", s.text()));
            }
            (ProgramAction::Resume, s) if s != ProgramState::Paused => {
                return Err(format!("{what}: it is {}, not paused here", s.text()));
            }
            (ProgramAction::End, s) if !s.started() && s != ProgramState::Unknown => {
                return Err(format!("{what}: it is {}", s.text()));
            }
            _ => {}
        }
        if action.may_move() {
            cx.motion.clone().map_err(|why| format!("{what}: {why}"))?;
            if let Some(why) = &cx.jogging {
                return Err(format!("{what}: {why}"));
            }
        }
        Ok(())
    }

    fn ask(
        &mut self,
        action: ProgramAction,
        n: u8,
        cx: &ProgramsCx,
    ) -> Result<Option<String>, String> {
        self.proposal = None;
        self.check(action, n, cx)?;
        let row = self.row(n);
        let asks = match action {
            ProgramAction::Run => true,
            ProgramAction::Step | ProgramAction::Resume => !row.confirmed,
            ProgramAction::End | ProgramAction::Pause => false,
        };
        let call = ProgramCall { action, program: n };
        if !asks {
            return Ok(Some(self.confirmed(call)));
        }
        let name = self
            .listing
            .as_ref()
            .and_then(|l| l.name(n))
            .map(|name| format!(" \"{name}\""))
            .unwrap_or_default();
        let verb = match action {
            ProgramAction::Run => "Run",
            ProgramAction::Step => "Run one step of",
            _ => "Resume",
        };
        self.proposal = Some(Proposal {
            call,
            text: format!(
                "{verb} program {n}{name}? The controller moves the arm at the program's own speeds and accelerations: the pendant's reduced jog speed does not apply. STOP (or Esc) ends it."
            ),
        });
        Ok(None)
    }

    /// The operation goes out: the row remembers what this window did.
    fn confirmed(&mut self, call: ProgramCall) -> String {
        let row = self.rows.entry(call.program).or_default();
        match call.action {
            ProgramAction::Run | ProgramAction::Resume => {
                row.confirmed = true;
                row.started_here = true;
                row.paused_here = false;
            }
            ProgramAction::Step => {
                row.confirmed = true;
                row.started_here = true;
                row.paused_here = true;
            }
            ProgramAction::Pause => row.paused_here = true,
            ProgramAction::End => {}
        }
        self.send(call);
        format!("program {}: {} sent", call.program, call.action.name())
    }

    fn send(&mut self, call: ProgramCall) {
        self.commands.push((Command::Program(call), true));
    }

    /// Applies an event that answers one of this model's commands (or the link's 254H
    /// after a STOP); what to tell the operator comes back.
    pub fn handle_event(&mut self, event: &LinkEvent, now: Instant) -> Vec<(Level, String)> {
        let mut said = Vec::new();
        match event {
            LinkEvent::Reply {
                command: Command::ProgramStatus(q),
                reply: Reply::ProgramStatus(s),
                ..
            } => {
                self.read_done(q.program);
                self.take_status(q.program, *s, now, &mut said);
            }
            LinkEvent::Reply {
                command: Command::Program(call),
                ..
            } => said.push((Level::Info, acknowledged(*call))),
            LinkEvent::ErrorReply { command, code, .. } => match command {
                Command::ProgramStatus(q) => {
                    self.read_done(q.program);
                    self.rows.entry(q.program).or_default().failed =
                        Some(format!("refused: error {code}"));
                }
                Command::Program(call) => {
                    self.undo(*call);
                    said.push((
                        Level::Error,
                        format!(
                            "{}: the controller refused it: error {code}",
                            describe(*call)
                        ),
                    ));
                }
                _ => {}
            },
            // The link sends a query again: its last word is still to come.
            LinkEvent::Timeout { retrying: true, .. } => {}
            LinkEvent::Timeout { command, .. } | LinkEvent::Interrupted { command, .. } => {
                match command {
                    Command::ProgramStatus(q) => {
                        self.read_done(q.program);
                        self.rows.entry(q.program).or_default().failed =
                            Some("no valid reply (the frame log shows what came)".to_owned());
                    }
                    Command::Program(call) => said.push((
                        Level::Warning,
                        format!(
                            "{}: no reply (not sent again): the next status read tells what the controller did",
                            describe(*call)
                        ),
                    )),
                    _ => {}
                }
            }
            LinkEvent::NotSent {
                command, reason, ..
            } => match command {
                Command::ProgramStatus(q) => self.read_done(q.program),
                Command::Program(call) => {
                    self.undo(*call);
                    said.push((
                        Level::Warning,
                        format!("{}: not sent: {reason}", describe(*call)),
                    ));
                }
                _ => {}
            },
            _ => {}
        }
        said
    }

    fn read_done(&mut self, n: u8) {
        if let Some(i) = self.in_flight.iter().position(|&m| m == n) {
            self.in_flight.swap_remove(i);
        }
    }

    /// An operation that did not happen: the row forgets what it assumed.
    fn undo(&mut self, call: ProgramCall) {
        if let Some(row) = self.rows.get_mut(&call.program)
            && matches!(call.action, ProgramAction::Pause | ProgramAction::Step)
        {
            row.paused_here = false;
        }
    }

    /// A 213H answer: the row takes it, and a start, an end, an error or a new step
    /// (while stepping) is said.
    fn take_status(
        &mut self,
        n: u8,
        status: ProgramStatus,
        now: Instant,
        said: &mut Vec<(Level, String)>,
    ) {
        let row = self.rows.entry(n).or_default();
        let before = row.status.map(|(s, _)| s);
        let was = row.state();
        row.failed = None;
        row.status = Some((status, now));
        if !status.started() {
            // Ended (by itself, by an error, by another tool or by STOP).
            row.paused_here = false;
            row.confirmed = false;
            row.started_here = false;
        }
        let is = row.state();
        let Some(before) = before else {
            if let ProgramState::Error { code, step } = is
                && status.started()
            {
                said.push((Level::Error, error_text(n, code, step)));
            }
            return;
        };
        match (was.started(), is) {
            (false, s) if s.started() => said.push((
                Level::Info,
                format!("program {n} started{}", at_step(status.step)),
            )),
            (true, ProgramState::Error { code, step }) => {
                said.push((Level::Error, error_text(n, code, step)));
            }
            (true, ProgramState::NotStarted) => {
                said.push((Level::Info, format!("program {n} ended")));
            }
            (true, ProgramState::Paused) if before.step != status.step => said.push((
                Level::Info,
                format!("program {n} paused{}", at_step(status.step)),
            )),
            _ => {}
        }
    }
}

fn at_step(step: u16) -> String {
    if step == 0 {
        String::new()
    } else {
        format!(" at step {step}")
    }
}

fn error_text(n: u8, code: ErrorCode, step: u16) -> String {
    format!(
        "program {n} stopped with error {:03X} at step {step}: {}",
        code.0,
        code.describe()
    )
}

/// "program 1: run" or "every running program: end".
fn describe(call: ProgramCall) -> String {
    if call.program == ALL_PROGRAMS {
        format!("every running program: {}", call.action.name())
    } else {
        format!("program {}: {}", call.program, call.action.name())
    }
}

fn acknowledged(call: ProgramCall) -> String {
    match (call.action, call.program) {
        (ProgramAction::End, ALL_PROGRAMS) => "every program ended (254H 00 answered)".to_owned(),
        (ProgramAction::Pause, ALL_PROGRAMS) => {
            "every program paused (255H 00 answered)".to_owned()
        }
        _ => format!("{}: acknowledged", describe(call)),
    }
}

fn list(numbers: &[u8]) -> String {
    numbers
        .iter()
        .map(u8::to_string)
        .collect::<Vec<_>>()
        .join(", ")
}
