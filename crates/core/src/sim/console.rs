//! The operator's console: E-stop, MODE switch, drive cut-off, alarms, the position table
//! and the signals (inputs, flags, variables, I/O interlock) set from outside the protocol,
//! as typed lines (`xsel-sim`'s stdin) or as actions (the pendant's Simulator panel).
//! Sans-IO: a line in, the text to print out.

use std::fmt::Write as _;

use super::controller::Controller;
use super::state::{HomeProgress, Mode};
use crate::protocol::{BitSpace, PositionRecord, RealEncoding, RecordArm, VarKind};

/// The most positions `positions` lists in one go (the rest are counted).
pub const POSITION_LIST_LIMIT: usize = 20;

/// What an operator can do to the simulated controller besides the protocol.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OperatorAction {
    EmergencyStop(bool),
    Mode(Mode),
    DriveCutOff(bool),
    /// Raises an alarm with this 3-hex-digit code, on an axis (1-8) or the system.
    Alarm {
        code: u16,
        axis: Option<u8>,
    },
    /// Clears the pending alarm, as 252H does.
    ClearAlarm,
    /// Clears the positions numbered `from..=to`.
    ClearPositions {
        from: u16,
        to: u16,
    },
    /// Switches input port `number` (a sensor).
    Input {
        number: u16,
        on: bool,
    },
    /// The I/O interlock: output changes (24AH) are held while it is on and applied in
    /// order when it goes off.
    Interlock(bool),
    /// How real variables travel (20FH, 24DH).
    RealEncoding(RealEncoding),
}

impl OperatorAction {
    /// Applies the action; the line to show.
    pub fn apply(self, c: &mut Controller) -> String {
        match self {
            OperatorAction::EmergencyStop(on) => {
                c.set_emergency_stop(on);
                format!("E-stop {}", on_off(on))
            }
            OperatorAction::Mode(mode) => {
                c.set_mode(mode);
                format!("mode {}", mode_name(mode))
            }
            OperatorAction::DriveCutOff(on) => {
                c.set_drive_cut_off(on);
                format!("drive cut-off {}", on_off(on))
            }
            OperatorAction::Alarm { code, axis } => {
                c.raise_alarm(code, axis, "alarm raised by the operator");
                match axis {
                    Some(a) => format!("alarm {code:03X} on axis {a}: servos off, moves stopped"),
                    None => format!("alarm {code:03X}: servos off, moves stopped"),
                }
            }
            OperatorAction::ClearAlarm => {
                c.reset_alarm();
                "alarm cleared".to_owned()
            }
            OperatorAction::ClearPositions { from, to } => {
                let n = c.clear_positions(from, to);
                format!("positions {from}-{to} cleared ({n} held data)")
            }
            OperatorAction::Input { number, on } => match c.signals_mut().set_input(number, on) {
                Ok(()) => format!("input {number} {}", on_off(on)),
                Err(e) => e,
            },
            OperatorAction::Interlock(true) => {
                c.signals_mut().set_interlock(true);
                "I/O interlock on: output changes held".to_owned()
            }
            OperatorAction::Interlock(false) => {
                let n = c.signals_mut().set_interlock(false);
                format!("I/O interlock off: {n} held output changes applied")
            }
            OperatorAction::RealEncoding(e) => {
                c.set_real_encoding(e);
                format!("real variables travel {} (20FH, 24DH)", encoding_name(e))
            }
        }
    }
}

/// A value typed for a variable.
#[derive(Debug, Clone, PartialEq)]
pub enum VarValue {
    Int(i32),
    Real(f64),
    /// Characters from a string column on.
    Text(String),
}

/// One console line, understood.
#[derive(Debug, Clone, PartialEq)]
pub enum ConsoleCommand {
    Act(OperatorAction),
    Status,
    /// Lists the inputs and outputs that are on and the held output changes.
    Io,
    /// Shows (`set` none) or switches a flag; program 0 = global.
    Flag {
        number: u16,
        program: u8,
        set: Option<bool>,
    },
    /// Shows (`set` none) or sets a variable; program 0 = global.
    Var {
        kind: VarKind,
        number: u16,
        program: u8,
        set: Option<VarValue>,
    },
    /// Lists the positions numbered `from..=to` (at most [`POSITION_LIST_LIMIT`]).
    Positions {
        from: u16,
        to: u16,
    },
    Help,
    Quit,
}

/// The console's help text.
pub const CONSOLE_HELP: &str = "\
Console commands (one a line on stdin):
  estop on|off        emergency stop (servos drop, moves stop; commands refused B04)
  mode manual|auto    MODE switch (commands that act are refused B05 in MANUAL)
  cutoff on|off       drive source cut-off (refused B06)
  alarm CODE [AXIS]   raise an alarm, CODE 3 hex digits (e.g. alarm C74 4); B07 until reset
  alarm clear         clear the pending alarm (as 252H does)
  status              mode, E-stop, cut-off, alarm, servo and home per axis, joints
  positions [FROM [TO]]        list stored positions (20 at most; FROM alone: from there)
  positions clear [FROM [TO]]  clear all positions, or No. FROM (to TO)
  in N on|off         switch input port N (a sensor), e.g. in 3 on
  io                  inputs and outputs that are ON, and output changes held
  flag N [P]          show flag N: a global flag, or a local flag of program P
  flag N on|off [P]   switch flag N (24BH does the same on the line)
  var int|real|str N [P]         show a variable (global without P; str: from column N)
  var int|real N = VALUE [P]     set a variable; var str N = \"TEXT\" [P] sets columns
  interlock on|off    I/O interlock: 24AH changes held until off (238H bit 0 drops them)
  real-encoding plain|swapped    how 20FH/24DH carry a double (PROTOCOL.md 3.40)
  help                this text
  quit                stop the simulator (as Ctrl-C)";

/// Parses one console line (case-insensitive, extra spaces allowed).
pub fn parse(line: &str) -> Result<ConsoleCommand, String> {
    let lower = line.trim().to_ascii_lowercase();
    let words: Vec<&str> = lower.split_whitespace().collect();
    if words.first() == Some(&"var") {
        return parse_var(line);
    }
    let on = |w: Option<&&str>, what: &str| match w.copied() {
        Some("on") => Ok(true),
        Some("off") => Ok(false),
        _ => Err(format!("{what} needs on or off, e.g. `{what} on`")),
    };
    let act = |a| Ok(ConsoleCommand::Act(a));
    match words.first().copied() {
        Some("help" | "?") => Ok(ConsoleCommand::Help),
        Some("status") => Ok(ConsoleCommand::Status),
        Some("quit" | "exit") => Ok(ConsoleCommand::Quit),
        Some("estop") => act(OperatorAction::EmergencyStop(on(words.get(1), "estop")?)),
        Some("cutoff") => act(OperatorAction::DriveCutOff(on(words.get(1), "cutoff")?)),
        Some("mode") => match words.get(1).copied() {
            Some("manual") => act(OperatorAction::Mode(Mode::Manual)),
            Some("auto") => act(OperatorAction::Mode(Mode::Auto)),
            _ => Err("mode needs manual or auto, e.g. `mode manual`".into()),
        },
        Some("in" | "input") => {
            let number = port_number(words.get(1), "in")?;
            let on = on(words.get(2), "in N")?;
            no_more(&words, 3)?;
            act(OperatorAction::Input { number, on })
        }
        Some("io") => {
            no_more(&words, 1)?;
            Ok(ConsoleCommand::Io)
        }
        Some("interlock") => act(OperatorAction::Interlock(on(words.get(1), "interlock")?)),
        Some("real-encoding") => match words.get(1).copied() {
            Some("plain") => act(OperatorAction::RealEncoding(RealEncoding::Plain)),
            Some("swapped" | "word-swapped") => {
                act(OperatorAction::RealEncoding(RealEncoding::WordSwapped))
            }
            _ => Err("real-encoding needs plain or swapped, e.g. `real-encoding swapped`".into()),
        },
        Some("flag") => {
            let number = port_number(words.get(1), "flag")?;
            let (set, rest) = match words.get(2).copied() {
                Some("on") => (Some(true), 3),
                Some("off") => (Some(false), 3),
                _ => (None, 2),
            };
            let program = program_number(words.get(rest))?;
            no_more(&words, rest + 1)?;
            Ok(ConsoleCommand::Flag {
                number,
                program,
                set,
            })
        }
        Some("positions" | "pos") => match words.get(1).copied() {
            Some("clear") => {
                let (from, to) = position_range(&words[2..], true)?;
                act(OperatorAction::ClearPositions { from, to })
            }
            _ => {
                let (from, to) = position_range(&words[1..], false)?;
                Ok(ConsoleCommand::Positions { from, to })
            }
        },
        Some("alarm") => match words.get(1).copied() {
            Some("clear" | "reset") => act(OperatorAction::ClearAlarm),
            Some(code) => {
                let code = parse_code(code)?;
                let axis = match words.get(2) {
                    None => None,
                    Some(a) => Some(
                        a.parse::<u8>()
                            .ok()
                            .filter(|a| (1..=8).contains(a))
                            .ok_or_else(|| format!("`{a}` is not an axis number 1-8"))?,
                    ),
                };
                act(OperatorAction::Alarm { code, axis })
            }
            None => Err("alarm needs a code (3 hex digits, e.g. `alarm C74`) or `clear`".into()),
        },
        Some(other) => Err(format!("unknown command `{other}`; `help` lists them")),
        None => Err("empty line; `help` lists the commands".into()),
    }
}

/// A port, flag or variable number (decimal, as the controller numbers them).
fn port_number(w: Option<&&str>, what: &str) -> Result<u16, String> {
    match w {
        Some(w) => w
            .parse::<u16>()
            .map_err(|_| format!("`{w}` is not a number (decimal, e.g. `{what} 3`)")),
        None => Err(format!("{what} needs a number, e.g. `{what} 3`")),
    }
}

/// An optional program number: none = 0 (global); the range is checked by the signals.
fn program_number(w: Option<&&str>) -> Result<u8, String> {
    match w {
        None => Ok(0),
        Some(w) => w
            .parse::<u8>()
            .map_err(|_| format!("`{w}` is not a program number (0 = global, 1-64)")),
    }
}

/// Refuses words after the first `n`.
fn no_more(words: &[&str], n: usize) -> Result<(), String> {
    match words.get(n) {
        None => Ok(()),
        Some(w) => Err(format!("unexpected `{w}`; `help` lists the commands")),
    }
}

/// `var int|real|str N [P]`, `var int|real N = VALUE [P]`, `var str N = "TEXT" [P]`
/// (the text keeps its case).
fn parse_var(line: &str) -> Result<ConsoleCommand, String> {
    let usage = "var needs int, real or str and a number, e.g. `var int 200` or `var int 200 = 5`";
    let (head, value) = match line.split_once('=') {
        Some((h, v)) => (h, Some(v.trim())),
        None => (line, None),
    };
    let lower = head.trim().to_ascii_lowercase();
    let words: Vec<&str> = lower.split_whitespace().collect();
    let kind = match words.get(1).copied() {
        Some("int" | "integer") => VarKind::Integer,
        Some("real") => VarKind::Real,
        Some("str" | "string") => VarKind::Text,
        _ => return Err(usage.into()),
    };
    let number = port_number(words.get(2), &format!("var {}", words[1]))?;
    let Some(value) = value else {
        let program = program_number(words.get(3))?;
        no_more(&words, 4)?;
        return Ok(ConsoleCommand::Var {
            kind,
            number,
            program,
            set: None,
        });
    };
    no_more(&words, 3)?;
    let (value, rest) = if kind == VarKind::Text && value.starts_with('"') {
        let body = &value[1..];
        let end = body
            .find('"')
            .ok_or("the text needs its closing quote, e.g. `var str 1 = \"HELLO\"`")?;
        (&body[..end], body[end + 1..].trim())
    } else {
        match value.split_once(char::is_whitespace) {
            Some((v, rest)) => (v, rest.trim()),
            None => (value, ""),
        }
    };
    let rest: Vec<&str> = rest.split_whitespace().collect();
    let program = program_number(rest.first())?;
    no_more(&rest, 1)?;
    let set = match kind {
        VarKind::Integer => VarValue::Int(value.parse::<i32>().map_err(|_| {
            format!("`{value}` is not an integer variable's value (-2147483648 to 2147483647)")
        })?),
        VarKind::Real => VarValue::Real(
            value
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| format!("`{value}` is not a real number (e.g. 1.5 or -2e3)"))?,
        ),
        VarKind::Text if value.is_empty() || !value.is_ascii() => {
            return Err(format!("`{value}` is not text of ASCII characters"));
        }
        VarKind::Text => VarValue::Text(value.to_owned()),
    };
    Ok(ConsoleCommand::Var {
        kind,
        number,
        program,
        set: Some(set),
    })
}

fn encoding_name(e: RealEncoding) -> &'static str {
    match e {
        RealEncoding::Plain => "plain",
        RealEncoding::WordSwapped => "word-swapped",
    }
}

/// "global" or "of program 3".
fn whose(program: u8) -> String {
    match program {
        0 => "global".to_owned(),
        p => format!("of program {p}"),
    }
}

/// Numbers on one line, or "none".
fn numbers_line(numbers: impl Iterator<Item = u16>) -> String {
    let list: Vec<String> = numbers.map(|n| n.to_string()).collect();
    if list.is_empty() {
        "none".to_owned()
    } else {
        list.join(" ")
    }
}

/// The inputs and outputs that are on, the interlock and the held output changes.
pub fn list_io(c: &Controller) -> String {
    let s = c.signals();
    let mut out = format!(
        "inputs on: {}\noutputs on: {}\nI/O interlock {}",
        numbers_line(s.ports_on(BitSpace::Input)),
        numbers_line(s.ports_on(BitSpace::Output)),
        on_off(s.interlock()),
    );
    if !s.held().is_empty() {
        let held: Vec<String> = s
            .held()
            .iter()
            .map(|&(n, on)| format!("{n} {}", if on { "ON" } else { "OFF" }))
            .collect();
        let _ = write!(
            out,
            "\nheld output changes (oldest first): {}",
            held.join(", ")
        );
    }
    out
}

/// Shows or switches a flag.
fn flag_line(c: &mut Controller, number: u16, program: u8, set: Option<bool>) -> String {
    if let Some(on) = set
        && let Err(e) = c.signals_mut().set_flag(number, program, on)
    {
        return e;
    }
    match c.signals().flag(number, program) {
        Ok(on) => format!("flag {number} ({}) {}", whose(program), on_off(on)),
        Err(e) => e,
    }
}

/// Shows or sets a variable.
fn var_line(
    c: &mut Controller,
    kind: VarKind,
    n: u16,
    program: u8,
    set: Option<VarValue>,
) -> String {
    let s = c.signals_mut();
    let done = match set {
        None => Ok(()),
        Some(VarValue::Int(v)) => s.set_int(n, program, v),
        Some(VarValue::Real(v)) => s.set_real(n, program, v),
        Some(VarValue::Text(t)) => s.set_text(n, program, t.as_bytes()),
    };
    let shown = done.and_then(|()| match kind {
        VarKind::Integer => s.int(n, program).map(|v| v.to_string()),
        VarKind::Real => s.real(n, program).map(|v| v.to_string()),
        VarKind::Text => s
            .text(n, program)
            .map(|t| format!("{:?}", String::from_utf8_lossy(&t))),
    });
    match shown {
        Ok(v) if kind == VarKind::Text => {
            format!("{} from column {n} ({}) = {v}", kind.name(), whose(program))
        }
        Ok(v) => format!("{} {n} ({}) = {v}", kind.name(), whose(program)),
        Err(e) => e,
    }
}

/// A position range from `[FROM [TO]]`: none = all; FROM alone = that one (`single`) or
/// from there on.
fn position_range(words: &[&str], single: bool) -> Result<(u16, u16), String> {
    let number = |w: &str| {
        w.parse::<u16>()
            .ok()
            .filter(|n| *n >= 1)
            .ok_or_else(|| format!("`{w}` is not a position number (1 to 65535)"))
    };
    match words {
        [] => Ok((1, u16::MAX)),
        [from] if single => number(from).map(|n| (n, n)),
        [from] => Ok((number(from)?, u16::MAX)),
        [from, to] => {
            let (from, to) = (number(from)?, number(to)?);
            if from > to {
                return Err(format!("position range {from}-{to} runs backwards"));
            }
            Ok((from, to))
        }
        _ => Err("positions takes at most two numbers, e.g. `positions 1 50`".into()),
    }
}

/// One stored position in a line: coordinates of its axes, arm system, rates.
pub fn position_line(r: &PositionRecord) -> String {
    let names = ["X", "Y", "Z", "R", "axis5", "axis6", "axis7", "axis8"];
    let mut s = format!("No. {}:", r.number);
    for (axis, v) in r.coords.iter() {
        let _ = write!(s, " {} {v}", names[axis.index()]);
    }
    match r.arms.scara1 {
        RecordArm::Unspecified => {}
        RecordArm::Right => s.push_str(", right arm"),
        RecordArm::Left => s.push_str(", left arm"),
    }
    let _ = write!(
        s,
        ", speed {} mm/s, accel {}, decel {}",
        r.speed.0, r.accel, r.decel
    );
    s
}

/// The positions numbered `from..=to`, at most [`POSITION_LIST_LIMIT`] lines, the rest
/// counted with the command that lists them.
pub fn list_positions(c: &Controller, from: u16, to: u16) -> String {
    let mut found = c.positions().range(from..=to);
    let mut out = format!(
        "{} positions stored (numbers 1-{} on this model)",
        c.positions().len(),
        c.max_position()
    );
    let mut last = None;
    for r in found.by_ref().take(POSITION_LIST_LIMIT).map(|(_, r)| r) {
        let _ = write!(out, "\n{}", position_line(r));
        last = Some(r.number);
    }
    let more = found.count();
    match last {
        None => {
            let _ = write!(out, "\nnone in {from}-{to}");
        }
        Some(n) if more > 0 => {
            let _ = write!(
                out,
                "\n... {more} more; `positions {}` lists on",
                n.saturating_add(1)
            );
        }
        Some(_) => {}
    }
    out
}

/// A 3-hex-digit error code, not 000.
pub fn parse_code(s: &str) -> Result<u16, String> {
    let t = s.trim();
    match crate::protocol::peek::hex_digits(t) {
        Some(code) if t.len() == 3 && code != 0 => Ok(code as u16),
        _ => Err(format!(
            "`{s}` is not an alarm code: 3 hex digits, not 000 (e.g. C74)"
        )),
    }
}

/// Runs one line: the text to print, and whether the operator asked to quit.
pub fn run_line(line: &str, c: &mut Controller) -> (String, bool) {
    match parse(line) {
        Ok(ConsoleCommand::Act(a)) => (a.apply(c), false),
        Ok(ConsoleCommand::Status) => (status(c), false),
        Ok(ConsoleCommand::Io) => (list_io(c), false),
        Ok(ConsoleCommand::Flag {
            number,
            program,
            set,
        }) => (flag_line(c, number, program, set), false),
        Ok(ConsoleCommand::Var {
            kind,
            number,
            program,
            set,
        }) => (var_line(c, kind, number, program, set), false),
        Ok(ConsoleCommand::Positions { from, to }) => (list_positions(c, from, to), false),
        Ok(ConsoleCommand::Help) => (CONSOLE_HELP.to_owned(), false),
        Ok(ConsoleCommand::Quit) => ("stopping".to_owned(), true),
        Err(e) => (e, false),
    }
}

fn on_off(on: bool) -> &'static str {
    if on { "on" } else { "off" }
}

fn mode_name(mode: Mode) -> &'static str {
    match mode {
        Mode::Auto => "AUTO",
        Mode::Manual => "MANUAL",
    }
}

/// The controller's operator state in a few lines.
pub fn status(c: &Controller) -> String {
    let s = c.snapshot();
    let mut out = format!(
        "mode {}, E-stop {}, drive cut-off {}, alarm {}",
        mode_name(s.mode),
        on_off(s.emergency_stop),
        on_off(s.drive_cut_off),
        s.alarm
            .as_ref()
            .map_or("none".to_owned(), |a| format!("{:03X}", a.code)),
    );
    for (i, a) in s
        .axes
        .iter()
        .enumerate()
        .take(4 + usize::from(c.config().linear_axes))
    {
        let home = match a.home {
            HomeProgress::NotDone => "not homed",
            HomeProgress::Homing { .. } => "homing",
            HomeProgress::Done => "homed",
        };
        let _ = write!(out, "\naxis {}: servo {}, {home}", i + 1, on_off(a.servo));
    }
    let j = s.joints;
    let _ = write!(
        out,
        "\njoints J1 {:.3} deg, J2 {:.3} deg, Z {:.3} mm, R {:.3} deg",
        j.j1, j.j2, j.z, j.j4
    );
    let programs = c.programs();
    for n in programs.numbers() {
        if let Some(line) = programs.describe(n) {
            let _ = write!(out, "\n{line}");
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::SimSetup;

    #[test]
    fn lines_set_the_operator_states_and_bad_ones_say_why() {
        let mut c = Controller::new(SimSetup::default());
        assert_eq!(run_line("estop on", &mut c).0, "E-stop on");
        assert!(c.snapshot().emergency_stop);
        run_line("  ESTOP   off ", &mut c);
        assert!(!c.snapshot().emergency_stop);
        run_line("mode manual", &mut c);
        assert_eq!(c.mode(), Mode::Manual);
        run_line("cutoff on", &mut c);
        assert!(c.snapshot().drive_cut_off);
        run_line("alarm c74 4", &mut c);
        let alarm = c.snapshot().alarm.expect("alarm raised");
        assert_eq!((alarm.code, alarm.axis), (0xC74, Some(4)));
        assert!(run_line("status", &mut c).0.contains("alarm C74"));
        run_line("alarm clear", &mut c);
        assert_eq!(c.snapshot().alarm, None);
        assert!(run_line("quit", &mut c).1);
        assert!(
            run_line("positions clear 5 3", &mut c)
                .0
                .contains("backwards")
        );
        assert!(
            run_line("positions 0", &mut c)
                .0
                .contains("not a position number")
        );
        assert!(
            run_line("positions 1 2 3", &mut c)
                .0
                .contains("at most two")
        );
        for (bad, says) in [
            ("estop maybe", "on or off"),
            ("mode fast", "manual or auto"),
            ("alarm 000", "not 000"),
            ("alarm C7", "3 hex digits"),
            ("alarm C74 9", "axis number"),
            ("fly", "unknown command"),
            ("", "empty line"),
        ] {
            let (text, quit) = run_line(bad, &mut c);
            assert!(text.contains(says) && !quit, "{bad:?}: {text}");
        }
    }

    #[test]
    fn signals_are_set_shown_and_refused_with_reasons() {
        let mut c = Controller::new(SimSetup::default());
        let mut say = |line: &str| run_line(line, &mut c).0;
        assert_eq!(say("in 3 on"), "input 3 on");
        assert_eq!(say("IN 15 on"), "input 15 on");
        assert!(say("in 300 on").contains("input 300 does not exist (inputs are 0-299)"));
        assert_eq!(
            say("io"),
            "inputs on: 3 15\noutputs on: none\nI/O interlock off"
        );
        assert_eq!(say("flag 600 on"), "flag 600 (global) on");
        assert_eq!(say("flag 600"), "flag 600 (global) on");
        assert_eq!(say("flag 905 on 3"), "flag 905 (of program 3) on");
        assert_eq!(say("flag 905 4"), "flag 905 (of program 4) off");
        assert!(say("flag 905 on").contains("needs a program"));
        assert!(say("flag 905 on 65").contains("program 65 does not exist"));
        assert_eq!(
            say("var int 200 = -7"),
            "integer variable 200 (global) = -7"
        );
        assert_eq!(
            say("var int 5=12 3"),
            "integer variable 5 (of program 3) = 12"
        );
        assert_eq!(say("var int 5 3"), "integer variable 5 (of program 3) = 12");
        assert_eq!(
            say("var real 300 = 1.5"),
            "real variable 300 (global) = 1.5"
        );
        assert_eq!(
            say("var str 1 = \"Hi There\" 2"),
            "string variable from column 1 (of program 2) = \"Hi There\""
        );
        assert_eq!(
            say("var str 4 2"),
            "string variable from column 4 (of program 2) = \"There\""
        );
        assert!(say("var int 100").contains("global are 200-299"));
        assert!(say("var int 200 = 3000000000").contains("not an integer"));
        assert!(say("var real 300 = nan").contains("not a real number"));
        assert!(say("var bool 1").contains("int, real or str"));
        assert_eq!(say("interlock on"), "I/O interlock on: output changes held");
        c.signals_mut()
            .change_bit(&crate::protocol::BitChange {
                space: BitSpace::Output,
                program: 0,
                number: 300,
                on: true,
            })
            .unwrap();
        let mut say = |line: &str| run_line(line, &mut c).0;
        assert!(say("io").ends_with("held output changes (oldest first): 300 ON"));
        assert_eq!(
            say("interlock off"),
            "I/O interlock off: 1 held output changes applied"
        );
        assert!(say("io").contains("outputs on: 300\n"));
        assert_eq!(
            say("real-encoding swapped"),
            "real variables travel word-swapped (20FH, 24DH)"
        );
        assert_eq!(c.config().real_encoding, RealEncoding::WordSwapped);
        for (bad, says) in [
            ("in 3", "on or off"),
            ("in x on", "not a number"),
            ("io 3", "unexpected"),
            ("interlock maybe", "on or off"),
            ("real-encoding big", "plain or swapped"),
            ("flag", "needs a number"),
            ("var str 1 = \"open", "closing quote"),
        ] {
            let text = run_line(bad, &mut c).0;
            assert!(text.contains(says), "{bad:?}: {text}");
        }
    }

    #[test]
    fn positions_are_listed_bounded_and_cleared() {
        use crate::protocol::{Axis, CentiG, Milli, MmPerSec, PerAxis, RecordArms};
        let mut c = Controller::new(SimSetup::default());
        c.positions_mut().clear();
        assert!(run_line("positions", &mut c).0.contains("none in 1-65535"));
        for n in 1..=30u16 {
            let r = PositionRecord {
                number: n,
                coords: PerAxis::from_pairs([(Axis::A1, Milli(-1500)), (Axis::A4, Milli(90_000))]),
                speed: MmPerSec(100),
                accel: CentiG(30),
                arms: RecordArms {
                    scara1: RecordArm::Right,
                    scara2: RecordArm::Unspecified,
                },
                ..PositionRecord::default()
            };
            c.positions_mut().insert(n, r);
        }
        let text = run_line("positions", &mut c).0;
        assert_eq!(text.lines().count(), 1 + POSITION_LIST_LIMIT + 1, "{text}");
        assert!(
            text.contains(
                "No. 1: X -1.500 R 90.000, right arm, speed 100 mm/s, accel 0.30 G, decel 0.00 G"
            ),
            "{text}"
        );
        assert!(
            text.ends_with("... 10 more; `positions 21` lists on"),
            "{text}"
        );
        let text = run_line("pos 25 26", &mut c).0;
        assert_eq!(text.lines().count(), 3, "{text}");
        assert_eq!(
            run_line("positions clear 5", &mut c).0,
            "positions 5-5 cleared (1 held data)"
        );
        assert_eq!(
            run_line("positions clear 10 19", &mut c).0,
            "positions 10-19 cleared (10 held data)"
        );
        assert_eq!(c.positions().len(), 19);
        assert_eq!(
            run_line("positions clear", &mut c).0,
            "positions 1-65535 cleared (19 held data)"
        );
        assert!(c.positions().is_empty());
    }
}
