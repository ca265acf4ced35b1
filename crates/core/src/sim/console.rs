//! The operator's console: E-stop, MODE switch, drive cut-off, alarms and the position
//! table set from outside the protocol, as typed lines (`xsel-sim`'s stdin) or as actions
//! (the pendant's Simulator panel). Sans-IO: a line in, the text to print out.

use std::fmt::Write as _;

use super::controller::Controller;
use super::state::{HomeProgress, Mode};
use crate::protocol::{PositionRecord, RecordArm};

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
        }
    }
}

/// One console line, understood.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ConsoleCommand {
    Act(OperatorAction),
    Status,
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
  help                this text
  quit                stop the simulator (as Ctrl-C)";

/// Parses one console line (case-insensitive, extra spaces allowed).
pub fn parse(line: &str) -> Result<ConsoleCommand, String> {
    let lower = line.trim().to_ascii_lowercase();
    let words: Vec<&str> = lower.split_whitespace().collect();
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
