//! `xsel-sim`: the simulated X-SEL SCARA controller served on a pseudo-terminal or a TCP
//! port, so any Format B client can talk to it.

use std::io::Write;
use std::process::ExitCode;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use clap::Parser;
use xsel_pendant_core::files::{coords_file, read_text_bounded};
use xsel_pendant_core::flags::parse_or_exit;
use xsel_pendant_core::line::{BAUD_RANGE, byte_time_8n1};
use xsel_pendant_core::protocol::Station;
use xsel_pendant_core::robot::RobotModel;
use xsel_pendant_core::sel;
use xsel_pendant_core::sim::console::{self, OperatorAction, parse_code};
use xsel_pendant_core::sim::errors::code_table_text;
use xsel_pendant_core::sim::log_limit::LogLimiter;
use xsel_pendant_core::sim::runner::{RunOptions, SimCore, start_tcp};
use xsel_pendant_core::sim::state::DEFAULT_SERVO_SWITCH_MS;
use xsel_pendant_core::sim::{Controller, FaultSpec, SimSetup};
use xsel_pendant_core::sim::{Mode, SimHandle, SimWatch};

const AFTER_HELP: &str = "\
Every frame in and out is logged to stderr with the time since start, e.g.
  [  1.234567] rx !992120189\\r\\n  command 212H axis status
A frame that gets no reply (also a run without '!' header, logged at its LF) says why:
  [  1.240000] rx !99215FF\\r\\n  ...  [silent: wrong checksum]
Frames answered and replies are logged whole. Under a flood of garbage at most 10
dropped runs a second are logged, each cut at 80 bytes with \"… (N more bytes)\"; one
line counts the rest.
The log is written by a thread of its own: if stderr is closed (e.g. `2>&1 | head`),
the simulator keeps serving with logging off; if nobody reads it (a full pipe), the
simulator keeps serving and counts the log lines it could not write, said once stderr
takes lines again.
A bad option ends it with exit code 2 and one line on stderr naming the option.

One client at a time: on TCP a second client is refused at once (its connection is
closed) with a log line, and served once the first has left. A TCP client that sends
nothing for --idle-timeout seconds (default 60) is dropped with a log line, so one that
vanished without closing (a PC that lost its network) does not lock the port (TCP
keepalive is not set). A pty client that does not read slows the simulator down; no input is ever dropped (a line that fails mid-reply is
logged with what was lost). With --baud, TCP replies go out whole, each when its last
byte would have left a serial line (one segment a reply); a pty gets them byte by byte.

Units: 212H reports SCARA axes 1-4 in each-axis units, joint angles J1, J2 and R (axis
4) in 0.001 deg and Z in 0.001 mm (2A1H/2A3H give base, work or joint positions).
234H/235H move the linear axes 5-6 only; on SCARA axes they answer A04 (use 2D4H/2D5H,
or 236H in the each-axis system). 236H jog and inching in the each-axis system (op
type bits 1-2 = 3) work before homing; Cartesian jogs and 2D4H/2D5H/2D6H answer B02
until 233H has homed. Relative moves turn R the way and distance they name, or are
refused at the R joint's limits (C74), never wrapped by 360 deg. 216H reports the last
refusal or alarm.

Positions: 209H, 21FH, 22DH read the position table (a reply holds what fits the reply
buffer, lowest numbers first); 244H, 245H, 26DH, 290H, 291H write it (checked whole:
a refused write changes nothing; pattern 00 clears a position); 26BH and 2D6H move to
a position. Number 0, above the model's maximum or count 0: A03; an axis the controller
lacks: A04; no data for the axes: B0A. Written positions live until the simulator stops.

Operator console: while running, type on stdin (off with --no-console):
  estop on|off, mode manual|auto, cutoff on|off, alarm CODE [AXIS], alarm clear,
  status, positions [FROM [TO]], positions clear [FROM [TO]], help, quit. --estop, --mode, --drive-cut-off and --alarm set the start state.

Replies: '#' normal, '&' + 3-hex-digit error code. The simulator's error codes
(also in the README, section \"Simulator\"; `--codes` prints them):
";

/// The simulated X-SEL SCARA controller (Format B slave).
///
/// Serves one client at a time on a pseudo-terminal (--pty: its path is the first line of
/// stdout) or a TCP port (--tcp; a second client is refused at once). The robot starts
/// with servos off and not homed, in AUTO mode: send 232H (servo on), 233H (home), then
/// move. Operator states (E-stop, mode, cut-off, alarms) are typed on stdin.
#[derive(Parser, Debug)]
#[command(name = "xsel-sim", version, after_help = format!("{AFTER_HELP}{}", code_table_text()))]
struct Args {
    /// Create a pseudo-terminal and print its path as the first line of stdout.
    #[arg(long, conflicts_with = "tcp")]
    pty: bool,
    /// Serve TCP on this address (the default when --pty is not given).
    #[arg(long, value_name = "ADDR", default_missing_value = "127.0.0.1:5099", num_args = 0..=1)]
    tcp: Option<String>,
    /// Station number, exactly 2 hex digits.
    #[arg(long, default_value = "99")]
    station: Station,
    /// Robot model TOML file (default: the built-in 500 mm SCARA), or a built-in name
    /// (scara-500, scara-250).
    #[arg(long, value_name = "FILE")]
    robot: Option<String>,
    /// Coordinate-table TOML file (work/tool tables, positions; see
    /// assets/coords/example.toml). Default: that example.
    #[arg(long, value_name = "FILE")]
    coords: Option<String>,
    /// Position table from a coordinate-table TOML file: only its [[position]] entries
    /// load (number, x, y, z, r, axis5, axis6, speed, accel, decel, arm = "right" |
    /// "left"), replacing those of --coords. Default: the --coords file's positions.
    #[arg(long, value_name = "FILE")]
    positions: Option<String>,
    /// SEL programs to serve (213H, 253H-257H) from a text file in the format of the
    /// README's "Programs in the simulator", replacing the demo (program 1, a pick and
    /// place between positions 1 and 2). A program with an error is not loaded (each
    /// error is named by line and column); the others are.
    #[arg(long, value_name = "FILE")]
    programs: Option<String>,
    /// Position numbering of the model: 4 (positions 1-20000, every position message) or
    /// 3 (1-3000; 21FH, 22DH, 26DH, 290H, 291H answer A01).
    #[arg(long, value_name = "3|4", default_value_t = 4, value_parser = clap::value_parser!(u8).range(3..=4))]
    position_digits: u8,
    /// Pace reply bytes at this baud rate (10 bits a character), 9600 to 230400.
    /// Default: no pacing.
    #[arg(long, value_parser = parse_baud)]
    baud: Option<u32>,
    /// Fault injection, e.g. `drop=0.05,corrupt=0.02,seed=7`. Keys: drop, corrupt,
    /// garbage, delay, truncate, stall (probability per reply), seed, delay-ms, stall-ms.
    #[arg(long, value_name = "SPEC")]
    faults: Option<FaultSpec>,
    /// Minimum reply delay in ms (I/O parameter 97 analogue), 0 to 60000.
    #[arg(long, default_value_t = 2, value_parser = clap::value_parser!(u64).range(0..=60_000))]
    delay_ms: u64,
    /// Linear axes 5 and 6 (0, 1 or 2).
    #[arg(long, default_value_t = 0, value_parser = clap::value_parser!(u8).range(0..=2))]
    linear_axes: u8,
    /// Start with servos on and axes homed.
    #[arg(long)]
    ready: bool,
    /// Time a servo takes to switch on or off (232H), ms, 0 to 10000; moves meanwhile
    /// answer B03.
    #[arg(long, value_name = "MS", default_value_t = DEFAULT_SERVO_SWITCH_MS,
          value_parser = clap::value_parser!(u64).range(0..=10_000))]
    servo_on_ms: u64,
    /// Start with the emergency stop pressed (console: `estop off` releases it).
    #[arg(long)]
    estop: bool,
    /// Start with the MODE switch at auto or manual.
    #[arg(long, value_name = "MODE", default_value = "auto", value_parser = ["auto", "manual"])]
    mode: String,
    /// Start with the drive source cut off.
    #[arg(long)]
    drive_cut_off: bool,
    /// Start with this alarm pending, 3 hex digits (e.g. C74); 252H clears it.
    #[arg(long, value_name = "CODE", value_parser = parse_code)]
    alarm: Option<u16>,
    /// No operator console on stdin.
    #[arg(long)]
    no_console: bool,
    /// Reply buffer size: 2048, or 1024 for a J/K/TT model setting (the longest command
    /// received is then 2051 or 1023 bytes).
    #[arg(long, default_value_t = xsel_pendant_core::protocol::REPLY_BUFFER, value_parser = parse_reply_buffer)]
    reply_buffer: usize,
    /// TCP: drop a client that sends nothing for this many seconds (0: never), 0 to
    /// 86400.
    #[arg(long, value_name = "SECONDS", default_value_t = 60,
          value_parser = clap::value_parser!(u64).range(0..=86_400))]
    idle_timeout: u64,
    /// Do not log frames to stderr.
    #[arg(long)]
    quiet: bool,
    /// Print the error code table and exit.
    #[arg(long)]
    codes: bool,
}

/// The two reply-buffer sizes of the X-SEL family.
fn parse_reply_buffer(s: &str) -> Result<usize, String> {
    use xsel_pendant_core::protocol::{REPLY_BUFFER, SMALL_REPLY_BUFFER};
    match s.trim().parse() {
        Ok(n) if n == REPLY_BUFFER || n == SMALL_REPLY_BUFFER => Ok(n),
        _ => Err(format!(
            "`{s}` is not a reply buffer size: use {SMALL_REPLY_BUFFER} or {REPLY_BUFFER}"
        )),
    }
}

fn parse_baud(s: &str) -> Result<u32, String> {
    let bad = || {
        format!(
            "`{s}` is not a baud rate from {} to {}",
            BAUD_RANGE.start(),
            BAUD_RANGE.end()
        )
    };
    let baud: u32 = s.parse().map_err(|_| bad())?;
    if BAUD_RANGE.contains(&baud) {
        Ok(baud)
    } else {
        Err(bad())
    }
}

fn main() -> ExitCode {
    let args: Args = parse_or_exit("xsel-sim");
    match run(args) {
        Ok(()) => ExitCode::SUCCESS,
        Err(Failure::Flag(e)) => {
            say(&format!("xsel-sim: {e}"));
            ExitCode::from(2)
        }
        Err(Failure::Run(e)) => {
            say(&format!("xsel-sim: {e}"));
            ExitCode::FAILURE
        }
    }
}

/// Why the simulator did not run.
enum Failure {
    /// A file named by an option could not be used (exit code 2, like a bad option).
    Flag(String),
    /// The line could not be served (exit code 1).
    Run(String),
}

/// One line on stderr; false when stderr is closed.
fn say(line: &str) -> bool {
    writeln!(std::io::stderr(), "{line}").is_ok()
}

/// Log lines waiting for stderr; beyond these, lines are counted, not kept.
const LOG_QUEUE: usize = 1024;

/// The traffic log's writer: lines are queued (bounded) for a thread that writes them to
/// stderr, so a stderr nobody reads (a full pipe) never stops the simulator serving;
/// lines that find the queue full are counted and the count is said when stderr takes
/// lines again. A closed stderr turns logging off.
#[derive(Clone)]
struct Logger {
    queue: std::sync::mpsc::SyncSender<String>,
    /// Logging is on (off for --quiet or once stderr is closed).
    on: Arc<AtomicBool>,
    lost: Arc<std::sync::atomic::AtomicU64>,
    done: Arc<std::sync::Mutex<Option<std::sync::mpsc::Receiver<()>>>>,
}

impl Logger {
    fn start() -> Logger {
        let (queue, lines) = std::sync::mpsc::sync_channel::<String>(LOG_QUEUE);
        let (done_tx, done) = std::sync::mpsc::channel();
        let on = Arc::new(AtomicBool::new(true));
        let lost = Arc::new(std::sync::atomic::AtomicU64::new(0));
        let (writer_on, writer_lost) = (on.clone(), lost.clone());
        let spawned = std::thread::Builder::new()
            .name("xsel-sim-log".into())
            .spawn(move || {
                use std::sync::mpsc::RecvTimeoutError;
                loop {
                    // A pause in the traffic says the count too, not only the next line.
                    let line = match lines.recv_timeout(Duration::from_millis(500)) {
                        Ok(line) => Some(line),
                        Err(RecvTimeoutError::Timeout) => None,
                        Err(RecvTimeoutError::Disconnected) => break,
                    };
                    let missed = writer_lost.swap(0, Ordering::Relaxed);
                    let ok = (missed == 0
                        || say(&format!(
                            "xsel-sim: {missed} log lines not written: stderr was not being \
                             read (the simulator kept serving)"
                        )))
                        && line.is_none_or(|l| say(&l));
                    if !ok {
                        writer_on.store(false, Ordering::Relaxed);
                    }
                }
                let _ = done_tx.send(());
            });
        if spawned.is_err() {
            on.store(false, Ordering::Relaxed);
        }
        Logger {
            queue,
            on,
            lost,
            done: Arc::new(std::sync::Mutex::new(Some(done))),
        }
    }

    /// Queues one line; counts it when the queue is full.
    fn line(&self, line: String) {
        if !self.on.load(Ordering::Relaxed) {
            return;
        }
        if let Err(std::sync::mpsc::TrySendError::Full(_)) = self.queue.try_send(line) {
            self.lost.fetch_add(1, Ordering::Relaxed);
        }
    }

    /// Lets the writer empty the queue (at most a second: stderr may never take it).
    fn finish(self) {
        let done = self.done.lock().ok().and_then(|mut d| d.take());
        drop(self);
        if let Some(done) = done {
            let _ = done.recv_timeout(Duration::from_secs(1));
        }
    }
}

fn run(args: Args) -> Result<(), Failure> {
    if args.codes {
        // A closed stdout (`--codes | head`) is not an error.
        let _ = write!(std::io::stdout(), "{}", code_table_text());
        return Ok(());
    }
    let model = match &args.robot {
        None => RobotModel::default_model(),
        Some(r) if !r.ends_with(".toml") && RobotModel::builtin(r).is_ok() => {
            RobotModel::builtin(r).map_err(|e| Failure::Flag(format!("--robot: {e}")))?
        }
        Some(path) => load_model_file(path).map_err(|e| Failure::Flag(format!("--robot: {e}")))?,
    };
    let mut setup = SimSetup::for_model(model);
    if let Some(path) = &args.coords {
        let file = coords_file::load(path, &setup.model)
            .map_err(|e| Failure::Flag(format!("--coords: {e}")))?;
        setup.coords = file.tables;
        setup.positions = file.positions;
        setup.zones = file.zones;
    }
    if let Some(path) = &args.positions {
        let file = coords_file::load(path, &setup.model)
            .map_err(|e| Failure::Flag(format!("--positions: {e}")))?;
        setup.positions = file.positions;
    }
    if let Some(path) = &args.programs {
        let text = read_text_bounded(std::path::Path::new(path), sel::MAX_FILE_BYTES)
            .map_err(|e| Failure::Flag(format!("--programs: {e}")))?;
        let parsed = sel::parse(&text);
        for line in parsed.report() {
            say(&format!("xsel-sim: --programs {path}: {line}"));
        }
        setup.programs = parsed.runnable().cloned().collect();
    }
    setup.config.position_digits = args.position_digits;
    setup.config.station = args.station.0;
    setup.config.reply_delay = Duration::from_millis(args.delay_ms);
    setup.config.linear_axes = args.linear_axes;
    setup.config.start_ready = args.ready;
    setup.config.reply_buffer = args.reply_buffer;
    setup.config.servo_switch_time = Duration::from_millis(args.servo_on_ms);
    let mut controller = Controller::new(setup);
    for action in start_state(&args) {
        action.apply(&mut controller);
    }
    let core = SimCore::new(controller, args.faults.clone().unwrap_or_default());
    // The serving thread never writes stderr itself: a pipe nobody reads would stop it.
    let logger = Logger::start();
    let logging = logger.on.clone();
    if args.quiet {
        logging.store(false, Ordering::Relaxed);
    }
    let opts = RunOptions {
        pacing: args.baud.map(byte_time_8n1),
        log: Some(Box::new({
            // Garbage floods are cut and counted, as in the pendant's frame log.
            let mut limiter = LogLimiter::default();
            let logger = logger.clone();
            move |entry| {
                if logger.on.load(Ordering::Relaxed) {
                    limiter
                        .lines(entry)
                        .into_iter()
                        .for_each(|l| logger.line(l));
                }
            }
        })),
        notice: Some(Arc::new({
            let logger = logger.clone();
            move |line: &str| logger.line(format!("xsel-sim: {line}"))
        })),
        idle_timeout: (args.idle_timeout > 0).then(|| Duration::from_secs(args.idle_timeout)),
        ..RunOptions::default()
    };
    let stop = Arc::new(AtomicBool::new(false));
    {
        let stop = stop.clone();
        ctrlc::set_handler(move || stop.store(true, Ordering::Relaxed))
            .map_err(|e| Failure::Run(format!("cannot catch Ctrl-C: {e}")))?;
    }
    let handle = if args.pty {
        serve_pty(core, opts).map_err(Failure::Run)?
    } else {
        let addr = args.tcp.as_deref().unwrap_or("127.0.0.1:5099");
        // An address that names nothing is a bad flag (exit 2), like every other one.
        std::net::ToSocketAddrs::to_socket_addrs(addr).map_err(|e| {
            Failure::Flag(format!("--tcp {addr}: not an address to listen on ({e})"))
        })?;
        let server = start_tcp(core, addr, opts)
            .map_err(|e| Failure::Run(format!("cannot listen on {addr}: {e}")))?;
        let mut out = std::io::stdout();
        let _ = writeln!(out, "{}", server.addr);
        let _ = out.flush();
        server.handle
    };
    let status = format!(
        "xsel-sim: station {}, faults: {}, servo switch {} ms; {}Ctrl-C to stop",
        args.station,
        args.faults.map_or("none".to_owned(), |f| f.to_string()),
        args.servo_on_ms,
        if args.no_console {
            ""
        } else {
            "console on stdin (`help`); "
        }
    );
    if !args.no_console {
        let (watch, stop) = (handle.watch(), stop.clone());
        std::thread::spawn(move || console_loop(&watch, &stop));
    }
    if !say(&status) {
        logging.store(false, Ordering::Relaxed);
    }
    while !stop.load(Ordering::Relaxed) && handle.is_running() {
        std::thread::sleep(Duration::from_millis(50));
    }
    let counters = handle.counters();
    let faults = handle.fault_counts();
    handle.join();
    logger.finish();
    say(&format!(
        "xsel-sim: stopped; {} frames, {} replies, {} errors, {} silent; motion {} received / {} started; faults injected {}",
        counters.frames,
        counters.replies,
        counters.errors,
        counters.silent(),
        counters.motion_received,
        counters.motion_started,
        faults.total()
    ));
    Ok(())
}

/// The operator states asked for on the command line, in the order they apply.
fn start_state(args: &Args) -> Vec<OperatorAction> {
    let mut actions = Vec::new();
    if args.mode == "manual" {
        actions.push(OperatorAction::Mode(Mode::Manual));
    }
    if args.estop {
        actions.push(OperatorAction::EmergencyStop(true));
    }
    if args.drive_cut_off {
        actions.push(OperatorAction::DriveCutOff(true));
    }
    if let Some(code) = args.alarm {
        actions.push(OperatorAction::Alarm { code, axis: None });
    }
    actions
}

/// Reads operator commands from stdin until it closes (or `quit`); answers on stdout.
fn console_loop(watch: &SimWatch, stop: &AtomicBool) {
    use std::io::BufRead;
    for line in std::io::stdin().lock().lines() {
        let Ok(line) = line else { break };
        if line.trim().is_empty() {
            continue;
        }
        let (text, quit) = watch.with(|c| console::run_line(&line, c));
        let mut out = std::io::stdout();
        let _ = writeln!(out, "{text}");
        let _ = out.flush();
        if quit {
            stop.store(true, Ordering::Relaxed);
            break;
        }
    }
}

/// Serves a pseudo-terminal and prints its path.
#[cfg(unix)]
fn serve_pty(core: SimCore, opts: RunOptions) -> Result<SimHandle, String> {
    let server = xsel_pendant_core::sim::runner::start_pty(core, opts)
        .map_err(|e| format!("cannot create a pseudo-terminal: {e}"))?;
    let mut out = std::io::stdout();
    let _ = writeln!(out, "{}", server.path);
    let _ = out.flush();
    Ok(server.handle)
}

/// Pseudo-terminals exist on Unix only.
#[cfg(not(unix))]
fn serve_pty(_: SimCore, _: RunOptions) -> Result<SimHandle, String> {
    Err("--pty is Unix-only (Linux, macOS); use --tcp HOST:PORT, which works everywhere".into())
}

/// A robot model file, read with the same bounds as the pendant's (a regular file of at
/// most 1 MB: a FIFO or `/dev/zero` is refused, not read).
fn load_model_file(path: &str) -> Result<RobotModel, String> {
    let text = xsel_pendant_core::files::read_text_bounded(
        std::path::Path::new(path),
        xsel_pendant_core::files::CONFIG_LIMIT,
    )?;
    RobotModel::from_toml_str(&text).map_err(|e| format!("{path}: {e}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parses(args: &[&str]) -> Result<Args, String> {
        Args::try_parse_from(std::iter::once("xsel-sim").chain(args.iter().copied()))
            .map_err(|e| e.to_string())
    }

    #[test]
    fn baud_is_a_real_line_rate() {
        for bad in ["0", "1200", "9599", "230401", "-5", "fast"] {
            let e = parses(&[&format!("--baud={bad}")])
                .err()
                .unwrap_or_default();
            assert!(e.contains("9600 to 230400"), "--baud {bad}: {e}");
        }
        for good in ["9600", "115200", "230400"] {
            assert!(parses(&["--baud", good]).is_ok(), "--baud {good}");
        }
    }

    #[test]
    fn delay_and_reply_buffer_are_bounded() {
        for (flag, bad) in [
            ("--delay-ms", "60001"),
            ("--delay-ms", "many"),
            ("--reply-buffer", "1000"),
            ("--reply-buffer", "0"),
        ] {
            let e = parses(&[flag, bad]).err().unwrap_or_default();
            assert!(e.contains(flag), "{flag} {bad}: {e}");
        }
        assert_eq!(
            parses(&["--reply-buffer", "1024"]).unwrap().reply_buffer,
            1024
        );
    }

    #[test]
    fn station_is_exactly_two_hex_digits() {
        for bad in ["9", "+9", "099", "", "9G", " 9"] {
            let e = parses(&["--station", bad]).err().unwrap_or_default();
            assert!(e.contains("exactly 2 hex digits"), "--station {bad:?}: {e}");
        }
        assert_eq!(parses(&["--station", "0a"]).unwrap().station, Station(0x0A));
        assert_eq!(parses(&[]).unwrap().station, Station(0x99));
    }
}
