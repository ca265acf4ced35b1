//! `rmc-sim`: a simulated Delta RMC151E motion controller served over Modbus/TCP, so any
//! Modbus client (the pendant's RMC link among them) can drive its axes.

use std::io::{BufRead, Write};
use std::net::TcpListener;
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use clap::Parser;
use xsel_pendant_core::flags::parse_or_exit;
use xsel_pendant_core::rmc::AxisId;
use xsel_pendant_core::sim::rmc::{
    DEFAULT_IDLE_TIMEOUT, RmcAction, RmcConfig, RmcController, RmcServer, ServeOptions, ServerEvent,
};

const AFTER_HELP: &str = "\
Modbus/TCP, function codes 3, 4, 6, 8, 16 and 23, any unit ID (echoed). FC4 reads
the same map as FC3; reads take up to 125 registers, any address and count (each
16-bit register is its half of a 32-bit one); FC6 writes one half of Position Scale,
Offset or In Position Tolerance (the Command Area takes whole FC16 blocks only:
exception 02); FC8 sub-function 0 echoes the request. Per axis n (0-based): status
file at 4096 + 512n (elements 0-57, Status Bits through Command Velocity, modelled;
the rest of the file reads 0), Command Area at 20480 + 20n (and its low copy at
1024 + 20n), Position Scale at 12288 + 512n, In Position Tolerance at 12400 + 512n;
CPU Module ID (17) at 3588, Controller Status Bits at 22542. Commands: 0 No-op,
1 Closed Loop Halt, 4 Clear Faults, 5 Hold Current Position, 6 Stop (Closed Loop),
21 Move Relative, 97 Enable/Disable Axis; +256 sets REQ, echoed in ACK (Status Bits
bit 31) on the same connection. Axes start disabled at position 0, soft travel limits
-1000 to 1000 pu.

The first line of stdout is `listening on ADDR` (the bound address, so --tcp
127.0.0.1:0 picks a free port). Connections opened and closed are logged on stderr.
Up to 64 connections; a connection that sends nothing for --idle-timeout seconds is
dropped (logged), so clients that vanished do not hold the places. One more client
while 64 are open is refused: its first request gets exception 06 (Server Device
Busy), then it is closed (logged).
Runs until Ctrl-C (or `quit` on the console). A bad option ends it with exit code 2
and one line on stderr.

Operator console: while running, type on stdin (off with --no-console):
  fault AXIS on|off   the axis's Fault Input (Error Bit 3, an Auto Stop: Halted)
  ferror AXIS         a following error (Error Bit 0, an Auto Stop)
  program | run       PROGRAM mode (motion commands refused, Last Error 103) or RUN
  status              each axis's positions and bits
  help, quit
Axes are numbered from 1 on the console.";

/// A simulated Delta RMC151E motion controller on Modbus/TCP.
#[derive(Parser, Debug)]
#[command(name = "rmc-sim", version, after_help = AFTER_HELP)]
struct Args {
    /// Serve Modbus/TCP on this address. The RMC itself listens on port 502 [inferred],
    /// which needs privileges on Unix; the default port 5020 does not.
    #[arg(long, value_name = "ADDR", default_value = "127.0.0.1:5020")]
    tcp: String,
    /// Axes, 1 to 8.
    #[arg(long, value_name = "N", default_value_t = 2, value_parser = clap::value_parser!(u8).range(1..=8))]
    axes: u8,
    /// Drop a connection that sends nothing for this many seconds (0: never), 0 to
    /// 86400.
    #[arg(long, value_name = "SECONDS", default_value_t = DEFAULT_IDLE_TIMEOUT.as_secs(),
          value_parser = clap::value_parser!(u64).range(0..=86_400))]
    idle_timeout: u64,
    /// No operator console on stdin.
    #[arg(long)]
    no_console: bool,
}

fn say(line: &str) {
    let _ = writeln!(std::io::stderr(), "{line}");
}

fn main() -> ExitCode {
    let args: Args = parse_or_exit("rmc-sim");
    // An address that names nothing is a bad flag (exit 2), like every other one.
    if let Err(e) = std::net::ToSocketAddrs::to_socket_addrs(args.tcp.as_str()) {
        say(&format!(
            "rmc-sim: --tcp {}: not an address to listen on ({e})",
            args.tcp
        ));
        return ExitCode::from(2);
    }
    let listener = match TcpListener::bind(args.tcp.as_str()) {
        Ok(l) => l,
        Err(e) => {
            say(&format!("rmc-sim: cannot listen on {}: {e}", args.tcp));
            return ExitCode::FAILURE;
        }
    };
    let config = RmcConfig {
        axes: usize::from(args.axes),
        ..RmcConfig::default()
    };
    let idle = if args.idle_timeout == 0 {
        "idle ones are kept: --idle-timeout 0".to_owned()
    } else {
        format!("idle ones are dropped after {} s", args.idle_timeout)
    };
    let options = ServeOptions {
        idle_timeout: (args.idle_timeout > 0).then(|| Duration::from_secs(args.idle_timeout)),
    };
    let log = Arc::new(move |event: ServerEvent| match event {
        ServerEvent::Opened(peer) => say(&format!("rmc-sim: {peer} connected")),
        ServerEvent::Refused(peer) => say(&format!(
            "rmc-sim: {peer} refused: {} connections are open ({idle}); its first request \
             is answered with exception 06 (Server Device Busy)",
            xsel_pendant_core::sim::rmc::MAX_CONNECTIONS,
        )),
        ServerEvent::Closed(peer, why) => say(&format!("rmc-sim: {peer} closed: {why}")),
    });
    let server = match RmcServer::start_with(listener, config, Some(log), options) {
        Ok(s) => s,
        Err(e) => {
            say(&format!("rmc-sim: cannot serve {}: {e}", args.tcp));
            return ExitCode::FAILURE;
        }
    };
    let mut out = std::io::stdout();
    let _ = writeln!(out, "listening on {}", server.local_addr());
    let _ = out.flush();
    let stop = Arc::new(AtomicBool::new(false));
    {
        let stop = stop.clone();
        if let Err(e) = ctrlc::set_handler(move || stop.store(true, Ordering::SeqCst)) {
            say(&format!("rmc-sim: cannot catch Ctrl-C: {e}"));
        }
    }
    say(&format!(
        "rmc-sim: RMC151E with {} axes; Ctrl-C to stop",
        args.axes
    ));
    if !args.no_console {
        console(server.controller(), stop.clone());
    }
    while !stop.load(Ordering::SeqCst) {
        std::thread::sleep(Duration::from_millis(50));
    }
    drop(server);
    say("rmc-sim: stopped");
    ExitCode::SUCCESS
}

/// Reads operator lines from stdin on a thread of its own: `quit` stops the simulator;
/// the end of stdin (a closed pipe) ends only the console.
fn console(controller: Arc<Mutex<RmcController>>, stop: Arc<AtomicBool>) {
    let spawned = std::thread::Builder::new()
        .name("rmc-console".into())
        .spawn(move || {
            for line in std::io::stdin().lock().lines().map_while(Result::ok) {
                let line = line.trim();
                let mut c = controller.lock().unwrap_or_else(|e| e.into_inner());
                c.advance(Instant::now());
                match line {
                    "" => {}
                    "quit" => {
                        stop.store(true, Ordering::SeqCst);
                        return;
                    }
                    "help" => say(CONSOLE_HELP),
                    "status" => {
                        for axis in AxisId::first(c.axis_count()) {
                            if let Some(s) = c.status(axis) {
                                say(&format!(
                                    "{axis}: command {:.3} target {:.3} actual {:.3}; {}; errors: {}",
                                    s.command_position,
                                    s.target_position,
                                    s.actual_position,
                                    s.bits.names().join(", "),
                                    s.errors.names().join(", ")
                                ));
                            }
                        }
                        let mode = if c.controller_status() & 1 != 0 { "RUN" } else { "PROGRAM" };
                        say(&format!("controller: {mode}"));
                    }
                    other => match RmcAction::parse(other) {
                        Ok(action) if c.operate(action) => say(&format!("rmc-sim: {other}: done")),
                        Ok(_) => say(&format!("rmc-sim: {other}: no such axis here")),
                        Err(e) => say(&format!("rmc-sim: {e}")),
                    },
                }
            }
        });
    if let Err(e) = spawned {
        say(&format!("rmc-sim: no console: {e}"));
    }
}

const CONSOLE_HELP: &str = "fault AXIS on|off, ferror AXIS, program, run, status, help, quit";
