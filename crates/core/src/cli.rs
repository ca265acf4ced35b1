//! The pendant's command line: its flags, their checks (values, addresses, output folders,
//! flags that do nothing in the mode chosen), and the line they open.

use crate::line::address;
use std::ffi::OsString;
use std::path::Path;

use clap::{ArgMatches, CommandFactory, FromArgMatches, Parser};

use crate::line::{LineSettings, LineSettingsError, Parity};
use crate::pendant::{ConnectionSettings, LineKind};
use crate::protocol::Station;
use crate::robot::RobotModel;
pub use crate::session::Connection;
use crate::session::load_model;

/// Teach pendant for IAI SCARA robots on X-SEL controllers (serial protocol Format B).
/// With no --port or --tcp it talks to the built-in simulated controller.
///
/// Every flag is checked the same way whatever the line: a bad value, or a flag that does
/// nothing in the mode chosen, ends the program with exit code 2 and one line on stderr
/// naming the flag.
#[derive(Parser, Debug, Clone)]
#[command(name = "xsel-pendant", version)]
pub struct Args {
    /// Serial port of the controller, e.g. /dev/ttyUSB0 or COM3.
    #[arg(long, conflicts_with = "tcp")]
    pub port: Option<String>,
    /// A serial-to-Ethernet bridge or `xsel-sim --tcp`, as HOST:PORT (port 1-65535; an
    /// IPv6 address in brackets, [::1]:5099).
    #[arg(long, value_name = "ADDR", value_parser = parse_tcp)]
    pub tcp: Option<String>,
    /// Baud rate (9600-230400). The built-in simulator is paced at it.
    #[arg(long, default_value_t = 115_200, value_parser = parse_baud)]
    pub baud: u32,
    /// Data bits (7 or 8).
    #[arg(long, default_value_t = 8, value_parser = parse_data_bits)]
    pub data_bits: u8,
    /// Parity: none, odd or even.
    #[arg(long, default_value = "none", value_parser = parse_parity)]
    pub parity: Parity,
    /// Stop bits (1 or 2).
    #[arg(long, default_value_t = 1, value_parser = parse_stop_bits)]
    pub stop_bits: u8,
    /// Station number, exactly 2 hex digits.
    #[arg(long, default_value = "99")]
    pub station: Station,
    /// Robot model: a TOML file or scara-500 / scara-250.
    #[arg(long, default_value = "scara-500")]
    pub robot: String,
    /// Use the built-in simulated controller (the default when no --port or --tcp is
    /// given; in the window it replaces the saved connection).
    #[arg(long, conflicts_with_all = ["port", "tcp"])]
    pub sim: bool,
    /// The window's own link thread owns the serial port or TCP bridge, with no guardian
    /// process. By default a guardian (this program, started by the window) owns it and
    /// sends 238H STOP when the window's process exits, crashes, is killed or stopped
    /// while motion may run. Use this flag only where a second process cannot run; the
    /// built-in simulator never has a guardian. Neither replaces a hard-wired enabling
    /// switch and E-stop in the controller's safety circuit.
    #[arg(long)]
    pub no_guardian: bool,
    /// A Delta RMC151 beside the robot, as HOST[:PORT] (port 502 when none is given, else
    /// 1-65535), or `sim` for the built-in simulated RMC151 (the default, or the saved
    /// address). The window only: the text mode and the pictures never connect it.
    #[arg(long, value_name = "ADDR", value_parser = parse_rmc, conflicts_with = "no_rmc")]
    pub rmc: Option<String>,
    /// No RMC151: its axes tab stays disconnected (the window only).
    #[arg(long)]
    pub no_rmc: bool,
    /// Text mode: no window; print the X-SEL controller's state once (see --watch). It
    /// reads the X-SEL only: the RMC151's axes are shown in the window alone (--rmc is
    /// refused here).
    #[arg(long)]
    pub headless: bool,
    /// Text mode, printing the X-SEL controller and the arm until Ctrl-C (implies
    /// --headless); the RMC151's axes are not shown (the window shows them).
    #[arg(long)]
    pub watch: bool,
    /// Draw the arm view into this PNG file and exit: no window, no GPU, no line. The pose
    /// comes from --joints or --pose (default: the model's home), the robot from --robot.
    /// Its folder must exist (none is created).
    #[arg(long, value_name = "FILE")]
    pub render_png: Option<std::path::PathBuf>,
    /// For --render-png: the joints J1,J2,Z,J4 (deg, deg, mm, deg).
    #[arg(
        long,
        value_name = "J1,J2,Z,J4",
        requires = "render_png",
        conflicts_with = "pose",
        allow_hyphen_values = true
    )]
    pub joints: Option<String>,
    /// For --render-png: the flange pose X,Y,Z,R in the base frame (mm, deg), reached
    /// with the arm system of --arm.
    #[arg(
        long,
        value_name = "X,Y,Z,R",
        requires = "render_png",
        allow_hyphen_values = true
    )]
    pub pose: Option<String>,
    /// For --render-png: the arm system of --pose and --target, right or left.
    #[arg(long, default_value = "right", requires = "render_png")]
    pub arm: String,
    /// For --render-png: a target X,Y (base frame, mm) drawn as the ghost of a move
    /// there, coloured by the reach check.
    #[arg(
        long,
        value_name = "X,Y",
        requires = "render_png",
        allow_hyphen_values = true
    )]
    pub target: Option<String>,
    /// For --render-png (1280x800 unless named) and --plot-png (1600x900): the picture's
    /// size, WIDTHxHEIGHT pixels (16 to 16384 each).
    #[arg(long)]
    pub size: Option<String>,
    /// For --render-png and --plot-png: the light theme (the default is dark).
    #[arg(long)]
    pub light: bool,
    /// Paint a saved capture (the Plots pane's "Save capture", --capture) into this PNG
    /// file and exit: its positions on one axis, velocities on another, bits and phases
    /// beneath; no window, no GPU, no line. 1600x900 unless --size names another. Its
    /// folder must exist (none is created).
    #[arg(
        long,
        value_name = "FILE",
        requires = "capture",
        conflicts_with = "render_png"
    )]
    pub plot_png: Option<std::path::PathBuf>,
    /// For --plot-png: the capture file (CSV) to paint.
    #[arg(long, value_name = "FILE", requires = "plot_png")]
    pub capture: Option<std::path::PathBuf>,
    /// Run the first-contact report against the controller on --port / --tcp (or the
    /// built-in simulator) and write it to this new text file, then exit: only queries
    /// are sent (no motion, no writes). An existing file is never written over; its
    /// folder must exist.
    #[arg(long, value_name = "FILE", conflicts_with_all = ["render_png", "plot_png", "headless", "watch"])]
    pub first_contact: Option<std::path::PathBuf>,
    /// Take a controller snapshot (versions, position table, coordinate tables, global
    /// flags and variables, alarm history) on --port / --tcp (or the built-in
    /// simulator) and write it to this new JSON file, then exit: only queries are sent.
    /// An existing file is never written over; its folder must exist.
    #[arg(long, value_name = "FILE", conflicts_with_all = ["render_png", "plot_png", "headless", "watch", "first_contact"])]
    pub snapshot: Option<std::path::PathBuf>,
    /// How the window is drawn: glow (OpenGL, the default: the least memory) or wgpu
    /// (Vulkan, DirectX 12, Metal or OpenGL; builds with the `wgpu` feature), for a
    /// graphics driver that fails with one.
    #[arg(long, value_enum, default_value_t = Renderer::Glow)]
    pub renderer: Renderer,
    /// The flags given on the command line (not defaulted), as `--name`, in order.
    #[arg(skip)]
    pub given: Vec<String>,
}

/// What the pendant does with its flags: one of six modes, chosen by them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    /// `--snapshot`: a controller snapshot written to a file.
    Snapshot,
    /// `--first-contact`: the read-only report written to a file.
    Contact,
    /// `--plot-png`: a saved capture painted into a PNG.
    Plot,
    /// `--render-png`: the arm view drawn into a PNG.
    Render,
    /// `--headless` / `--watch`: the X-SEL's state printed.
    Text,
    /// The window.
    Window,
}

impl Mode {
    /// "with --plot-png", as the refusal of a flag says it.
    fn phrase(self) -> &'static str {
        match self {
            Mode::Contact => "with --first-contact",
            Mode::Snapshot => "with --snapshot",
            Mode::Plot => "with --plot-png",
            Mode::Render => "with --render-png",
            Mode::Text => "in the text mode (--headless, --watch)",
            Mode::Window => "in the window",
        }
    }
}

/// Each flag that does something in some modes only: the modes it serves, and what it
/// is for (said when it is refused elsewhere). Flags not listed serve every mode.
const SERVES: &[(&str, &[Mode], &str)] = {
    use Mode::*;
    const LINE: &str = "it sets the X-SEL's line, which only the window, the text mode, --first-contact and --snapshot open";
    const RENDER: &str = "it is for --render-png only";
    const PICTURE: &str = "it is for --render-png and --plot-png only";
    const RMC: &str = "only the window connects the RMC151 (the text mode reads the X-SEL alone)";
    &[
        ("--port", &[Text, Window, Contact, Snapshot], LINE),
        ("--tcp", &[Text, Window, Contact, Snapshot], LINE),
        ("--baud", &[Text, Window, Contact, Snapshot], LINE),
        ("--data-bits", &[Text, Window, Contact, Snapshot], LINE),
        ("--parity", &[Text, Window, Contact, Snapshot], LINE),
        ("--stop-bits", &[Text, Window, Contact, Snapshot], LINE),
        ("--station", &[Text, Window, Contact, Snapshot], LINE),
        ("--sim", &[Text, Window, Contact, Snapshot], LINE),
        (
            "--robot",
            &[Text, Window, Render, Contact, Snapshot],
            "it names the robot of the window, the text mode, --render-png and the built-in simulator of --first-contact and --snapshot",
        ),
        (
            "--no-guardian",
            &[Window],
            "only the window starts a guardian process (the text mode's own link owns its line)",
        ),
        ("--rmc", &[Window], RMC),
        ("--no-rmc", &[Window], RMC),
        ("--headless", &[Text], "it chooses the text mode"),
        ("--watch", &[Text], "it chooses the text mode"),
        ("--joints", &[Render], RENDER),
        ("--pose", &[Render], RENDER),
        ("--arm", &[Render], RENDER),
        ("--target", &[Render], RENDER),
        ("--size", &[Render, Plot], PICTURE),
        ("--light", &[Render, Plot], PICTURE),
        ("--renderer", &[Window], "it is for the window only"),
    ]
};

/// Parses the pendant's command line and checks it whole before anything starts: a bad
/// value, an address out of range, a missing output folder or a flag that does nothing
/// in the mode chosen ends the program with exit code 2 and one line naming the flag
/// (`--help` and `--version` print as usual).
pub fn parse_or_exit() -> Args {
    match try_parse_from(std::env::args_os()) {
        Ok(args) => args,
        Err(e) => crate::flags::exit_on_clap_error("xsel-pendant", &e),
    }
}

/// [`parse_or_exit`] without the exit: the program's name first, then its flags.
pub fn try_parse_from<I, T>(argv: I) -> Result<Args, clap::Error>
where
    I: IntoIterator<Item = T>,
    T: Into<OsString> + Clone,
{
    let matches = Args::command().try_get_matches_from(argv)?;
    let mut args = Args::from_arg_matches(&matches)?;
    args.given = given(&matches);
    args.check()
        .map_err(|e| clap::Error::raw(clap::error::ErrorKind::ArgumentConflict, e))?;
    Ok(args)
}

/// The flags given on the command line, as `--name`, in the order given.
fn given(matches: &ArgMatches) -> Vec<String> {
    let command = Args::command();
    let mut given: Vec<(usize, String)> = matches
        .ids()
        .filter(|id| {
            matches.value_source(id.as_str()) == Some(clap::parser::ValueSource::CommandLine)
        })
        .filter_map(|id| {
            let arg = command.get_arguments().find(|a| a.get_id() == id)?;
            let at = matches.index_of(id.as_str()).unwrap_or(usize::MAX);
            Some((at, format!("--{}", arg.get_long()?)))
        })
        .collect();
    given.sort();
    given.into_iter().map(|(_, name)| name).collect()
}

/// Why an output file cannot be written where it is named: its folder is missing (none
/// is created) or is not a folder.
fn output_folder(flag: &str, path: &Path) -> Result<(), String> {
    let dir = path
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    if dir.is_dir() {
        Ok(())
    } else if dir.exists() {
        Err(format!(
            "{flag} {}: {} is not a folder",
            path.display(),
            dir.display()
        ))
    } else {
        Err(format!(
            "{flag} {}: the folder {} does not exist (no folder is created)",
            path.display(),
            dir.display()
        ))
    }
}

/// The window's renderer (`--renderer`).
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Renderer {
    Glow,
    Wgpu,
}

/// Whether the command line (program name first) names the robot's connection: any flag
/// or value but `--renderer` (how to draw) and `--rmc` / `--no-rmc` (the RMC151).
pub fn names_a_connection(argv: impl IntoIterator<Item = std::ffi::OsString>) -> bool {
    let mut args = argv.into_iter().skip(1);
    while let Some(a) = args.next() {
        // The renderer and the RMC151 are not the robot's line.
        if a == "--renderer" || a == "--rmc" {
            args.next();
        } else if !["--renderer=", "--rmc=", "--no-rmc"]
            .iter()
            .any(|p| a.to_string_lossy().starts_with(p))
        {
            return true;
        }
    }
    false
}

/// A flag value that cannot be used.
#[derive(Debug, thiserror::Error)]
pub enum CliError {
    #[error("{flag}: {source}")]
    Line {
        flag: &'static str,
        source: LineSettingsError,
    },
    #[error("--robot: `{name}`: {reason}")]
    Robot { name: String, reason: String },
}

impl Args {
    /// The line settings, checked as a whole (the same checks for every kind of line).
    pub fn line_settings(&self) -> Result<LineSettings, CliError> {
        let line = LineSettings {
            baud: self.baud,
            data_bits: self.data_bits,
            parity: self.parity,
            stop_bits: self.stop_bits,
        };
        line.validate().map_err(|source| CliError::Line {
            flag: match source {
                LineSettingsError::Baud(_) => "--baud",
                LineSettingsError::DataBits(_) => "--data-bits",
                LineSettingsError::StopBits(_) => "--stop-bits",
            },
            source,
        })?;
        Ok(line)
    }

    /// The connection these flags name, as the window keeps it.
    pub fn connection_settings(&self) -> ConnectionSettings {
        let mut c = ConnectionSettings {
            baud: self.baud,
            data_bits: self.data_bits,
            parity: self.parity,
            stop_bits: self.stop_bits,
            station: self.station.0,
            robot: self.robot.clone(),
            ..ConnectionSettings::default()
        };
        if let Some(port) = &self.port {
            c.kind = LineKind::Serial;
            c.port = port.clone();
        } else if let Some(addr) = &self.tcp {
            c.kind = LineKind::Tcp;
            c.tcp = addr.clone();
        }
        c
    }

    /// Text mode rather than the window.
    pub fn is_headless(&self) -> bool {
        self.headless || self.watch
    }

    /// The mode the flags choose (as `main` runs them: a picture first, then text).
    pub fn mode(&self) -> Mode {
        if self.first_contact.is_some() {
            Mode::Contact
        } else if self.snapshot.is_some() {
            Mode::Snapshot
        } else if self.plot_png.is_some() {
            Mode::Plot
        } else if self.render_png.is_some() {
            Mode::Render
        } else if self.is_headless() {
            Mode::Text
        } else {
            Mode::Window
        }
    }

    /// The checks clap cannot make: every flag given does something in the mode chosen,
    /// and an output file's folder exists. One sentence naming the flag, or `Ok`.
    pub fn check(&self) -> Result<(), String> {
        let mode = self.mode();
        for flag in &self.given {
            if let Some((_, modes, what)) = SERVES.iter().find(|(f, ..)| f == flag)
                && !modes.contains(&mode)
            {
                return Err(format!("{flag} does nothing {}: {what}", mode.phrase()));
            }
        }
        if let Some(path) = &self.render_png {
            output_folder("--render-png", path)?;
        }
        if let Some(path) = &self.plot_png {
            output_folder("--plot-png", path)?;
        }
        for (flag, path) in [
            ("--first-contact", &self.first_contact),
            ("--snapshot", &self.snapshot),
        ] {
            if let Some(path) = path {
                output_folder(flag, path)?;
                if path.exists() {
                    return Err(format!(
                        "{flag} {}: the file exists (it is never written over)",
                        path.display()
                    ));
                }
            }
        }
        Ok(())
    }

    /// The robot model named by `--robot`.
    pub fn model(&self) -> Result<RobotModel, CliError> {
        load_model(&self.robot).map_err(|reason| CliError::Robot {
            name: self.robot.clone(),
            reason,
        })
    }
}

/// Checks every flag, then prepares the line: a serial port, a TCP bridge, or the
/// built-in simulator (started here, paced at the baud rate). Nothing is opened yet
/// except the simulator; the connector opens the line when called.
pub fn connection(args: &Args) -> Result<Connection, CliError> {
    args.line_settings()?;
    let model = args.model()?;
    Ok(Connection::prepare_in_process(
        &args.connection_settings(),
        model,
    ))
}

/// An error message for a line setting, as clap shows it after the flag's name.
fn line_error(line: LineSettings) -> Result<(), String> {
    line.validate().map_err(|e| e.to_string())
}

fn parse_number<T: std::str::FromStr>(s: &str, what: &str) -> Result<T, String> {
    s.trim()
        .parse()
        .map_err(|_| format!("`{s}` is not a number of {what}"))
}

fn parse_baud(s: &str) -> Result<u32, String> {
    let baud = parse_number(s, "bits per second")?;
    line_error(LineSettings {
        baud,
        ..LineSettings::default()
    })?;
    Ok(baud)
}

fn parse_data_bits(s: &str) -> Result<u8, String> {
    let data_bits = s
        .trim()
        .parse()
        .map_err(|_| format!("data bits must be 7 or 8, not `{s}`"))?;
    line_error(LineSettings {
        data_bits,
        ..LineSettings::default()
    })?;
    Ok(data_bits)
}

fn parse_stop_bits(s: &str) -> Result<u8, String> {
    let stop_bits = s
        .trim()
        .parse()
        .map_err(|_| format!("stop bits must be 1 or 2, not `{s}`"))?;
    line_error(LineSettings {
        stop_bits,
        ..LineSettings::default()
    })?;
    Ok(stop_bits)
}

fn parse_parity(s: &str) -> Result<Parity, String> {
    match s.to_ascii_lowercase().as_str() {
        "none" | "n" => Ok(Parity::None),
        "odd" | "o" => Ok(Parity::Odd),
        "even" | "e" => Ok(Parity::Even),
        _ => Err(format!("`{s}` is not a parity: use none, odd or even")),
    }
}

/// `--rmc`: `sim` (the built-in RMC151, kept as an empty address) or HOST[:PORT] (502
/// when none is given).
fn parse_rmc(s: &str) -> Result<String, String> {
    if s.trim().eq_ignore_ascii_case("sim") {
        return Ok(String::new());
    }
    address(s, Some(crate::session::rmc::MODBUS_PORT))
}

/// `--tcp`: HOST:PORT.
fn parse_tcp(s: &str) -> Result<String, String> {
    address(s, None)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parses(args: &[&str]) -> Result<Args, String> {
        try_parse_from(std::iter::once("xsel-pendant").chain(args.iter().copied()))
            .map_err(|e| crate::flags::one_line(&e))
    }

    #[test]
    fn addresses_are_checked_whole_with_the_port_in_range() {
        for (typed, default, want) in [
            ("10.0.0.5", Some(502), "10.0.0.5:502"),
            ("10.0.0.5:1502", Some(502), "10.0.0.5:1502"),
            ("rmc.local", Some(502), "rmc.local:502"),
            ("[::1]", Some(502), "[::1]:502"),
            ("[::1]:5099", None, "[::1]:5099"),
            ("localhost:65535", None, "localhost:65535"),
        ] {
            assert_eq!(address(typed, default).as_deref(), Ok(want), "{typed}");
        }
        for (typed, default, says) in [
            ("127.0.0.1:99999", Some(502), "port 99999 is out of range"),
            ("127.0.0.1:0", None, "port 0 is out of range"),
            ("127.0.0.1:99999:502", Some(502), "not an address"),
            ("127.0.0.1:http", None, "not a port number"),
            ("127.0.0.1:", None, "not a port number"),
            ("127.0.0.1", None, "names no port"),
            ("::1", Some(502), "in brackets"),
            ("[::1", Some(502), "ends with ]"),
            ("[nope]:1", None, "not an IPv6 address"),
            ("a b:1", None, "not an address"),
            (":502", None, "not an address"),
            ("", None, "no address"),
        ] {
            let e = address(typed, default).unwrap_err();
            assert!(e.contains(says), "{typed}: {e}");
        }
    }

    #[test]
    fn a_flag_that_does_nothing_in_the_mode_chosen_is_refused_with_the_reason() {
        let capture = ["--plot-png", "out.png", "--capture", "c.csv"];
        let render = ["--render-png", "out.png"];
        for (mode, extra, flag, says) in [
            (
                &capture[..],
                &["--arm", "left"][..],
                "--arm",
                "for --render-png only",
            ),
            (
                &capture,
                &["--joints", "1,2,3,4"],
                "--joints",
                "for --render-png only",
            ),
            (
                &capture,
                &["--robot", "scara-250"],
                "--robot",
                "names the robot",
            ),
            (
                &capture,
                &["--headless"],
                "--headless",
                "chooses the text mode",
            ),
            (
                &render,
                &["--tcp", "127.0.0.1:5099"],
                "--tcp",
                "X-SEL's line",
            ),
            (&render, &["--rmc", "sim"], "--rmc", "only the window"),
            (
                &["--headless"],
                &["--rmc", "10.0.0.5"],
                "--rmc",
                "only the window",
            ),
            (&["--watch"], &["--no-rmc"], "--no-rmc", "only the window"),
            (
                &["--headless"],
                &["--no-guardian"],
                "--no-guardian",
                "only the window",
            ),
            (
                &["--headless"],
                &["--size", "100x100"],
                "--size",
                "--plot-png only",
            ),
            (
                &["--watch"],
                &["--renderer", "wgpu"],
                "--renderer",
                "window only",
            ),
            (&[], &["--light"], "--light", "--plot-png only"),
            (
                &["--first-contact", "report.txt"],
                &["--rmc", "sim"],
                "--rmc",
                "only the window",
            ),
            (
                &["--first-contact", "report.txt"],
                &["--no-guardian"],
                "--no-guardian",
                "only the window",
            ),
        ] {
            let mut argv = mode.to_vec();
            argv.extend(extra);
            let e = parses(&argv).err().unwrap_or_default();
            assert!(
                e.starts_with(&format!("{flag} does nothing")) && e.contains(says),
                "{argv:?}: {e}"
            );
            assert_eq!(e.lines().count(), 1, "{e}");
        }
        // What a mode uses is taken.
        let dir = std::env::temp_dir();
        let png = dir.join("x.png");
        let png = png.to_str().unwrap();
        for argv in [
            vec![
                "--plot-png",
                png,
                "--capture",
                "c.csv",
                "--size",
                "800x600",
                "--light",
            ],
            vec![
                "--render-png",
                png,
                "--arm",
                "left",
                "--robot",
                "scara-250",
                "--size",
                "64x64",
            ],
            vec![
                "--headless",
                "--tcp",
                "127.0.0.1:5099",
                "--baud",
                "9600",
                "--robot",
                "scara-250",
            ],
            vec![
                "--rmc",
                "sim",
                "--no-guardian",
                "--renderer",
                "wgpu",
                "--sim",
            ],
        ] {
            parses(&argv).unwrap();
        }
    }

    #[test]
    fn an_output_file_in_a_missing_folder_is_refused_naming_it() {
        let missing = std::env::temp_dir()
            .join("xsel-pendant-no-such-folder")
            .join("a.png");
        let missing = missing.to_str().unwrap();
        for argv in [
            vec!["--render-png", missing],
            vec!["--plot-png", missing, "--capture", "c.csv"],
        ] {
            let e = parses(&argv).err().unwrap_or_default();
            assert!(
                e.starts_with(argv[0])
                    && e.contains("xsel-pendant-no-such-folder")
                    && e.contains("does not exist"),
                "{argv:?}: {e}"
            );
        }
        assert!(
            parses(&["--render-png", "here.png"]).is_ok(),
            "the working folder"
        );
    }

    #[test]
    fn line_flags_are_checked_whatever_the_line() {
        for line in [&[][..], &["--tcp", "127.0.0.1:5099"], &["--port", "COM3"]] {
            for (flag, bad, says) in [
                ("--baud", "0", "outside 9600-230400"),
                ("--baud", "99999999", "outside 9600-230400"),
                ("--baud", "fast", "not a number"),
                ("--data-bits", "9", "7 or 8"),
                ("--stop-bits", "3", "1 or 2"),
                ("--parity", "mark", "none, odd or even"),
                ("--station", "099", "exactly 2 hex digits"),
            ] {
                let mut argv = line.to_vec();
                argv.extend([flag, bad]);
                let e = parses(&argv).err().unwrap_or_default();
                assert!(e.contains(flag) && e.contains(says), "{argv:?}: {e}");
                assert_eq!(e.lines().count(), 1, "{e}");
            }
        }
    }

    #[test]
    fn defaults_make_a_valid_line() {
        let args = parses(&[]).unwrap();
        assert_eq!(args.station, Station(0x99));
        assert_eq!(args.renderer, Renderer::Glow);
        assert_eq!(
            parses(&["--renderer", "wgpu"]).unwrap().renderer,
            Renderer::Wgpu
        );
        let argv = |a: &[&str]| a.iter().map(std::ffi::OsString::from).collect::<Vec<_>>();
        assert!(!names_a_connection(argv(&["xsel-pendant"])));
        assert!(!names_a_connection(argv(&[
            "xsel-pendant",
            "--renderer",
            "wgpu"
        ])));
        assert!(!names_a_connection(argv(&[
            "xsel-pendant",
            "--renderer=glow"
        ])));
        assert!(!names_a_connection(argv(&[
            "xsel-pendant",
            "--rmc",
            "10.0.0.5",
            "--no-rmc"
        ])));
        assert!(names_a_connection(argv(&[
            "xsel-pendant",
            "--renderer",
            "wgpu",
            "--sim"
        ])));
        assert!(names_a_connection(argv(&[
            "xsel-pendant",
            "--baud",
            "9600"
        ])));
        assert_eq!(args.line_settings().unwrap(), LineSettings::default());
        let args = parses(&["--station", "0a", "--baud", "9600", "--parity", "E"]).unwrap();
        assert_eq!(args.station, Station(0x0A));
        assert_eq!(args.line_settings().unwrap().to_string(), "9600 8E1");
    }

    #[test]
    fn a_bad_robot_is_refused_even_with_a_port() {
        let args = parses(&["--port", "COM3", "--robot", "no-such-robot.toml"]).unwrap();
        let e = connection(&args).err().map(|e| e.to_string());
        assert!(e.is_some_and(|e| e.starts_with("--robot: `no-such-robot.toml`")));
    }
}
