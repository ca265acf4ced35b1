//! The operator's console: E-stop, MODE switch, drive cut-off and alarms set from
//! outside the protocol, as typed lines (`xsel-sim`'s stdin) or as actions (the
//! pendant's Simulator panel). Sans-IO: a line in, the text to print out.

use std::fmt::Write as _;

use super::controller::Controller;
use super::state::{HomeProgress, Mode};

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
        }
    }
}

/// One console line, understood.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ConsoleCommand {
    Act(OperatorAction),
    Status,
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
}
