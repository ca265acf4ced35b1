//! The pendant binary. Until the desktop window lands it runs headless: it opens the
//! line (the embedded simulator unless a port is named), polls the controller through
//! the link engine and prints what it reads, then says plainly that the window is next.

use std::sync::Arc;
use std::time::{Duration, Instant};

use clap::{CommandFactory, FromArgMatches, Parser};
use xsel_pendant::link::transport::{SerialTransport, StreamTransport, TcpTransport};
use xsel_pendant::link::{
    Connector, LineSettings, LinkConfig, LinkEvent, Parity, Transport, spawn,
};
use xsel_pendant::pendant::{ConnectionSettings, LineKind, ParityChoice};
use xsel_pendant::ui::{StartOptions, run_window};
use xsel_pendant::protocol::{AxisUnit, HomeState, Reply, ScaraStatus, Station, SystemStatus};
use xsel_pendant::robot::RobotModel;
use xsel_pendant::sim::pipe::PipeEnd;
use xsel_pendant::sim::{EmbeddedOptions, SimHandle, SimSetup, start_embedded};

/// Teach pendant for IAI SCARA robots on X-SEL controllers (serial protocol Format B).
/// With no --port or --tcp it talks to the built-in simulated controller.
#[derive(Parser, Debug)]
#[command(version)]
struct Args {
    /// Serial port of the controller, e.g. /dev/ttyUSB0.
    #[arg(long, conflicts_with = "tcp")]
    port: Option<String>,
    /// A serial-to-Ethernet bridge or `xsel-sim --tcp`, as HOST:PORT.
    #[arg(long, value_name = "ADDR")]
    tcp: Option<String>,
    /// Baud rate (9600-230400).
    #[arg(long, default_value_t = 115_200)]
    baud: u32,
    /// Data bits (7 or 8).
    #[arg(long, default_value_t = 8)]
    data_bits: u8,
    /// Parity: none, odd or even.
    #[arg(long, default_value = "none", value_parser = parse_parity)]
    parity: Parity,
    /// Stop bits (1 or 2).
    #[arg(long, default_value_t = 1)]
    stop_bits: u8,
    /// Station number, 2 hex digits.
    #[arg(long, default_value = "99", value_parser = parse_station)]
    station: Station,
    /// Robot model for the built-in simulator: a TOML file or scara-500 / scara-250.
    #[arg(long, default_value = "scara-500")]
    robot: String,
    /// Keep printing the status every half second until Ctrl-C (text mode).
    #[arg(long)]
    watch: bool,
    /// Text mode: no window; print the controller's state (with --watch, keep polling).
    #[arg(long)]
    headless: bool,
}

/// The connection the command line names, for the window.
fn window_connection(args: &Args) -> ConnectionSettings {
    let mut c = ConnectionSettings {
        baud: args.baud,
        data_bits: args.data_bits,
        parity: ParityChoice::from_link(args.parity),
        stop_bits: args.stop_bits,
        station: args.station.0,
        robot: args.robot.clone(),
        ..ConnectionSettings::default()
    };
    if let Some(port) = &args.port {
        c.kind = LineKind::Serial;
        c.port = port.clone();
    } else if let Some(addr) = &args.tcp {
        c.kind = LineKind::Tcp;
        c.tcp = addr.clone();
    }
    c
}

fn parse_parity(s: &str) -> Result<Parity, String> {
    match s.to_ascii_lowercase().as_str() {
        "none" | "n" => Ok(Parity::None),
        "odd" | "o" => Ok(Parity::Odd),
        "even" | "e" => Ok(Parity::Even),
        _ => Err(format!("`{s}` is not a parity: use none, odd or even")),
    }
}

fn parse_station(s: &str) -> Result<Station, String> {
    u8::from_str_radix(s, 16)
        .map(Station)
        .map_err(|_| format!("`{s}` is not a 2-digit hex station number"))
}

fn load_model(name: &str) -> Result<RobotModel, String> {
    RobotModel::builtin(name)
        .or_else(|_| RobotModel::load(name))
        .map_err(|e| format!("robot model `{name}`: {e}"))
}

/// The line to open, and the simulator behind it when there is no real one.
fn connector(args: &Args, line: LineSettings) -> Result<(Connector, Option<SimHandle>), String> {
    if let Some(port) = args.port.clone() {
        line.validate().map_err(|e| e.to_string())?;
        let open: Connector = Box::new(move || {
            SerialTransport::open(&port, line).map(|t| Box::new(t) as Box<dyn Transport>)
        });
        return Ok((open, None));
    }
    if let Some(addr) = args.tcp.clone() {
        let open: Connector = Box::new(move || {
            TcpTransport::connect(&addr, Duration::from_secs(2))
                .map(|t| Box::new(t) as Box<dyn Transport>)
        });
        return Ok((open, None));
    }
    let mut setup = SimSetup::for_model(load_model(&args.robot)?);
    setup.config.station = args.station.0;
    let (pipe, sim) = start_embedded(EmbeddedOptions {
        setup,
        byte_time: Some(line.byte_time()),
        ..EmbeddedOptions::default()
    });
    let name = format!("built-in simulator ({}, paced at {line})", args.robot);
    let mut pipe = Some(pipe);
    let open: Connector = Box::new(move || {
        pipe.take()
            .map(|p| {
                Box::new(StreamTransport::new(p, &name, PipeEnd::set_read_timeout))
                    as Box<dyn Transport>
            })
            .ok_or_else(|| std::io::Error::other("the built-in simulator has stopped"))
    });
    Ok((open, Some(sim)))
}

fn system_line(s: &SystemStatus) -> String {
    format!(
        "controller: {} mode, {}, E-stop {}, drive source {}, errors: critical {} latest {}",
        s.mode.name().unwrap_or("unknown"),
        if s.status3.ready() {
            "ready"
        } else {
            "not ready"
        },
        if s.status1.emergency_stop() {
            "ACTIVE"
        } else {
            "off"
        },
        if s.status3.drive_cut_off() {
            "CUT OFF"
        } else {
            "on"
        },
        s.critical_error,
        s.latest_error,
    )
}

fn scara_line(s: &ScaraStatus) -> String {
    let names = ["X", "Y", "Z", "R"];
    let mut text = format!(
        "SCARA: work #{} tool #{}, arm {:?}, {:?} coordinates:",
        s.work, s.tool, s.common.arm, s.common.system
    );
    for (i, (axis, state)) in s.axes.iter().enumerate() {
        let unit = if axis.is_scara_r() {
            AxisUnit::Deg
        } else {
            AxisUnit::Mm
        };
        let home = match state.status.home_state() {
            HomeState::Done => "homed",
            HomeState::Homing => "homing",
            _ => "not homed",
        };
        let servo = if state.status.servo_on() {
            "servo on"
        } else {
            "servo off"
        };
        text.push_str(&format!(
            "\n  {} {:>12}  {servo}, {home}",
            names.get(i).copied().unwrap_or("?"),
            state.position.with_unit(unit).to_string()
        ));
    }
    text
}

fn main() {
    let matches = Args::command().get_matches();
    let args = Args::from_arg_matches(&matches).unwrap_or_else(|e| e.exit());
    if !args.headless && !args.watch {
        // Line flags on the command line replace the saved connection; without them the
        // window opens on the built-in simulator with the saved line settings kept.
        let named = [
            "port", "tcp", "baud", "data_bits", "parity", "stop_bits", "station", "robot",
        ]
        .iter()
        .any(|id| matches.value_source(id) == Some(clap::parser::ValueSource::CommandLine));
        let options = StartOptions {
            connection: named.then(|| window_connection(&args)),
            fresh: false,
        };
        if let Err(e) = run_window(options) {
            eprintln!("xsel-pendant: {e}");
            std::process::exit(2);
        }
        return;
    }
    let line = LineSettings {
        baud: args.baud,
        data_bits: args.data_bits,
        parity: args.parity,
        stop_bits: args.stop_bits,
    };
    let (open, _sim) = match connector(&args, line) {
        Ok(c) => c,
        Err(e) => {
            eprintln!("xsel-pendant: {e}");
            std::process::exit(2);
        }
    };
    let mut config = LinkConfig {
        station: args.station,
        auto_reconnect: args.watch,
        ..LinkConfig::default()
    };
    config.timing.line = line;
    let (_link, events) = match spawn(open, config, Arc::new(|| {})) {
        Ok(link) => link,
        Err(e) => {
            eprintln!("xsel-pendant: cannot start the link thread: {e}");
            std::process::exit(2);
        }
    };
    println!("xsel-pendant {}", env!("CARGO_PKG_VERSION"));
    let run_for = if args.watch {
        Duration::MAX
    } else {
        Duration::from_secs(2)
    };
    let start = Instant::now();
    let (mut system, mut scara, mut health) = (None, None, None);
    let mut last_print = Instant::now();
    while start.elapsed() < run_for {
        match events.recv_timeout(Duration::from_millis(100)) {
            Ok(LinkEvent::Reply {
                reply: Reply::SystemStatus(s),
                ..
            }) => system = Some(s),
            Ok(LinkEvent::Reply {
                reply: Reply::ScaraStatus(s),
                ..
            }) => scara = Some(s),
            Ok(LinkEvent::Health(h)) => health = Some(h),
            Ok(
                e @ (LinkEvent::Connected { .. }
                | LinkEvent::Disconnected { .. }
                | LinkEvent::Reconnected { .. }
                | LinkEvent::Timeout { .. }
                | LinkEvent::ErrorReply { .. }
                | LinkEvent::Garbage { .. }),
            ) => println!("link: {}", e.summary()),
            _ => {}
        }
        if args.watch && last_print.elapsed() >= Duration::from_millis(500) {
            last_print = Instant::now();
            if let Some(s) = &scara {
                println!("{}", scara_line(s));
            }
        }
    }
    match (&system, &scara) {
        (Some(sys), Some(sc)) => println!("{}\n{}", system_line(sys), scara_line(sc)),
        _ => println!("no status was read from the controller in {run_for:?}"),
    }
    if let Some(h) = health {
        println!(
            "link: {} transactions, {} timeouts, {:.0} polls/s, median round trip {}",
            h.transactions,
            h.timeouts,
            h.polls_per_second,
            h.median_round_trip
                .map_or("-".into(), |d| format!("{:.1} ms", d.as_secs_f64() * 1e3))
        );
    }
    println!(
        "\nThe desktop window (jog, coordinate tables, arm view, frame log) is not built yet;\n\
         this run shows the link and the controller (or simulator) working headless.\n\
         `--watch` keeps polling; `cargo run --bin xsel-sim -- --help` serves the simulator."
    );
    if system.is_none() {
        std::process::exit(1);
    }
}
