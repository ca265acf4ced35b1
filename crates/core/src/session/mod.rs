//! A connection as the operator names it: the line to open (serial port, TCP bridge or
//! the embedded simulator) and, once started, the link thread on it. The command line and
//! the window both go through here, so a line is prepared one way only. A serial port or
//! TCP bridge may be owned by a guardian process (`guardian/`) that outlives the window.

pub mod closing;
pub mod guardian;
pub mod rmc;

/// What the window's Simulator pane needs of the built-in simulator: its front panel and
/// the operator's actions (the simulator itself stays below the session).
pub mod simulator {
    pub use crate::sim::Mode;
    pub use crate::sim::console::{OperatorAction, parse_code};
    pub use crate::sim::panel::{FrontPanel, PanelState};
}
pub use crate::sim::SimHandle;

/// What the window's wake filter needs of the X-SEL link: how many events its channel
/// holds, and the last answer to each polled command (to tell a change from a repeat).
pub use crate::link::{EVENT_BACKLOG, PollAnswers};

/// Connection auto-detect: a serial port tried at several settings (a probe opens lines,
/// so the window reaches it here).
pub mod probe {
    pub use crate::link::probe::{
        Candidate, Framing, ProbeEnd, ProbeEvent, ProbeHandle, ProbePlan, ProbeReport, spawn_probe,
    };
}

use std::path::PathBuf;
use std::time::Duration;

use crossbeam_channel::Receiver;

use crate::files;
use crate::line::{ConnectionSettings, LineKind, LineSettings};
use crate::link::transport::{SerialTransport, StreamTransport, TcpTransport};
use crate::link::{Connector, LinkConfig, LinkEvent, LinkHandle, Polling, Repaint, Transport};
use crate::link::{Priority, TableRequest};
use crate::protocol::{AxisPattern, Command, CoordKind, ScMode};
use crate::robot::RobotModel;
use crate::sim::panel::{FrontPanel, front_panel};
use crate::sim::pipe::PipeEnd;
use crate::sim::{EmbeddedOptions, SimSetup, start_embedded};

/// How often a poll cycle starts in the window while anything changes.
pub const POLL_INTERVAL: Duration = Duration::from_millis(100);
/// How often a poll cycle starts while things are steady (the arm stands, every poll
/// answers as before, the operator sends nothing): any change brings [`POLL_INTERVAL`]
/// back at once. [I: a move, an alarm or an emergency stop from elsewhere (the
/// controller's own panel, a program) shows within one of these, and the fast polls
/// follow it.]
pub const IDLE_POLL_INTERVAL: Duration = Duration::from_millis(250);

/// A robot model by name: `scara-500`, `scara-250`, or a TOML file (a regular file of at
/// most [`files::CONFIG_LIMIT`] bytes).
pub fn load_model(name: &str) -> Result<RobotModel, String> {
    let builtin = if name.ends_with(".toml") {
        None
    } else {
        RobotModel::builtin(name).ok()
    };
    if let Some(model) = builtin {
        return Ok(model);
    }
    let path = std::path::Path::new(name);
    let text = files::read_text_bounded(path, files::CONFIG_LIMIT)
        .map_err(|e| format!("robot model: {e}"))?;
    RobotModel::from_toml_str(&text).map_err(|e| format!("robot model {name}: {e}"))
}

/// Who owns a serial port or TCP bridge: the window's own link thread, or a guardian
/// process started from this executable that stops the arm when the window dies.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub enum LineOwner {
    #[default]
    InProcess,
    Guardian {
        exe: PathBuf,
    },
}

impl LineOwner {
    /// A guardian from the running executable (falls back to the window's own link when
    /// the executable cannot be found).
    pub fn guardian() -> LineOwner {
        std::env::current_exe().map_or(LineOwner::InProcess, |exe| LineOwner::Guardian { exe })
    }
}

/// The line to open and, for the built-in one, the simulator behind it.
pub struct Connection {
    /// Opens (and re-opens) the line; hand it to `link::spawn`.
    pub connector: Connector,
    /// The embedded simulator, kept alive as long as this is held.
    pub sim: Option<SimHandle>,
    /// The embedded simulator's front panel (operator states), served by its thread.
    pub panel: Option<FrontPanel>,
    pub line: LineSettings,
    /// The robot model (the simulator's, and the one the pendant checks moves with).
    pub model: RobotModel,
    /// What the line is, for messages: "serial port /dev/ttyUSB0", "TCP 10.0.0.5:4001".
    pub target: String,
    /// The port path or HOST:PORT as given (the target's name for the simulator).
    pub address: String,
}

impl Connection {
    /// Prepares the line of `settings` for this process's link.
    pub fn prepare_in_process(settings: &ConnectionSettings, model: RobotModel) -> Connection {
        Self::prepare(settings, model, &LineOwner::InProcess)
    }

    /// Prepares the line of `settings`; only the simulator starts now, a port or socket
    /// opens (or its guardian starts) when the connector is called. The built-in
    /// simulator is always the window's own.
    pub fn prepare(
        settings: &ConnectionSettings,
        model: RobotModel,
        owner: &LineOwner,
    ) -> Connection {
        let line = settings.line();
        match settings.kind {
            LineKind::Serial | LineKind::Tcp => {
                let (target, address) = match settings.kind {
                    LineKind::Serial => (
                        format!("serial port {}", settings.port.trim()),
                        settings.port.trim(),
                    ),
                    _ => (format!("TCP {}", settings.tcp.trim()), settings.tcp.trim()),
                };
                let address = address.to_owned();
                let connector = match owner {
                    LineOwner::Guardian { exe } => guardian_connector(settings, exe.clone()),
                    LineOwner::InProcess => direct_connector(settings.kind, address.clone()),
                };
                Connection {
                    connector,
                    sim: None,
                    panel: None,
                    line,
                    model,
                    target,
                    address,
                }
            }
            LineKind::Simulator => {
                let mut setup = SimSetup::for_model(model.clone());
                setup.config.station = settings.station;
                let (panel, desk) = front_panel();
                let (pipe, sim) = start_embedded(EmbeddedOptions {
                    setup,
                    byte_time: Some(line.byte_time()),
                    panel: Some(desk),
                    ..EmbeddedOptions::default()
                });
                let target = format!("built-in simulator ({}, paced at {line})", settings.robot);
                let name = target.clone();
                let mut pipe = Some(pipe);
                let connector: Connector = Box::new(move |_paced_by_the_simulator| {
                    pipe.take()
                        .map(|p| {
                            Box::new(StreamTransport::new(p, &name, PipeEnd::set_read_timeout))
                                as Box<dyn Transport>
                        })
                        .ok_or_else(|| std::io::Error::other("the built-in simulator has stopped"))
                });
                Connection {
                    connector,
                    sim: Some(sim),
                    panel: Some(panel),
                    line,
                    model,
                    address: target.clone(),
                    target,
                }
            }
        }
    }

    /// Opens the line now, so a missing port or a refused connection is reported at once
    /// (the message names the line); the connector then hands out that open line first
    /// and re-opens as before.
    pub fn open_now(&mut self) -> Result<(), String> {
        let mut connector: Connector = Box::new(|_| Err(std::io::Error::other("moved")));
        std::mem::swap(&mut connector, &mut self.connector);
        match connector(self.line) {
            Ok(line) => {
                let mut first = Some(line);
                self.connector = Box::new(move |line| match first.take() {
                    Some(t) => Ok(t),
                    None => connector(line),
                });
                Ok(())
            }
            Err(e) => {
                self.connector = connector;
                Err(self.open_error(&e))
            }
        }
    }

    /// A message for an error from the connector, naming the line once.
    pub fn open_error(&self, e: &std::io::Error) -> String {
        let text = e.to_string();
        if !text.contains(&self.address) {
            format!("cannot open {}: {text}", self.target)
        } else if text.starts_with("cannot open") {
            text
        } else {
            format!("cannot open {text}")
        }
    }
}

/// Opens a serial port or a TCP bridge in this process.
fn direct_connector(kind: LineKind, address: String) -> Connector {
    match kind {
        LineKind::Serial => Box::new(move |line| {
            SerialTransport::open(&address, line).map(|t| Box::new(t) as Box<dyn Transport>)
        }),
        _ => Box::new(move |_settings_are_the_bridges| {
            TcpTransport::connect(&address, Duration::from_secs(2))
                .map(|t| Box::new(t) as Box<dyn Transport>)
        }),
    }
}

/// Opens a serial port or TCP bridge through a guardian process, a new one each time
/// the link (re)connects.
fn guardian_connector(settings: &ConnectionSettings, exe: PathBuf) -> Connector {
    let settings = settings.clone();
    let lease = crate::link::JOG_LEASE;
    Box::new(move |_settings_go_to_the_guardian| {
        guardian::GuardianLine::open(&exe, &settings, lease)
            .map(|t| Box::new(t) as Box<dyn Transport>)
    })
}

/// The link thread on a line, and the simulator behind it when there is one.
pub struct Session {
    pub link: LinkHandle,
    pub events: Receiver<LinkEvent>,
    /// The embedded simulator, when the line is the built-in one.
    pub sim: Option<SimHandle>,
    /// Its front panel: the window's Simulator pane talks to it through this, never
    /// through a lock of the simulator.
    pub panel: Option<FrontPanel>,
}

impl Session {
    /// Checks the settings, prepares the line and starts the link polling `polls` every
    /// [`POLL_INTERVAL`] ([`IDLE_POLL_INTERVAL`] while steady); the line opens on the link thread (success or failure arrives
    /// as an event).
    pub fn open(
        settings: &ConnectionSettings,
        model: &RobotModel,
        polls: Vec<Command>,
        repaint: Repaint,
        owner: &LineOwner,
    ) -> Result<Session, String> {
        settings.line().validate().map_err(|e| e.to_string())?;
        match settings.kind {
            LineKind::Serial if settings.port.trim().is_empty() => {
                return Err("choose a serial port first".into());
            }
            LineKind::Tcp if settings.tcp.trim().is_empty() => {
                return Err("enter the bridge's address as HOST:PORT".into());
            }
            _ => {}
        }
        let connection = Connection::prepare(settings, model.clone(), owner);
        let mut config = LinkConfig {
            station: crate::protocol::Station(settings.station),
            sc_mode: if settings.send_at_at {
                ScMode::AtAt
            } else {
                ScMode::Computed
            },
            polling: Polling {
                interval: Some(POLL_INTERVAL),
                idle_interval: Some(IDLE_POLL_INTERVAL),
                commands: polls,
            },
            ..LinkConfig::default()
        };
        config.timing.line = connection.line;
        let (link, events) = crate::link::spawn(connection.connector, config, repaint)
            .map_err(|e| format!("cannot start the link thread: {e}"))?;
        Ok(Session {
            link,
            events,
            sim: connection.sim,
            panel: connection.panel,
        })
    }

    /// Closes on a thread of its own (see [`closing`]): the link ends its transaction,
    /// sends the STOPs it owes and closes the line while the caller goes on; STOP still
    /// reaches it meanwhile.
    pub fn close_in_background(self) -> closing::Closing {
        let stopper = self.link.stopper();
        closing::Closing::start(
            "the X-SEL's line",
            self,
            Some(Box::new(move || stopper.stop_all())),
            |session| {
                let Session { link, sim, .. } = session;
                let report = link.shutdown();
                drop(sim);
                (!report.is_clean()).then(|| report.to_string())
            },
        )
    }

    /// Sends a command at the user's priority (238H at the head of the queue).
    pub fn submit(&self, command: Command) {
        self.link.submit(command, Priority::User);
    }

    /// Sends a command that gives way to the status polls (a position table read).
    pub fn submit_background(&self, command: Command) {
        self.link.submit(command, Priority::Background);
    }

    /// Sends a query in the line time the status polls leave (a signal read).
    pub fn submit_spare(&self, command: Command) {
        self.link.submit(command, Priority::Spare);
    }

    /// 238H for all axes, ahead of anything queued.
    pub fn stop_all(&self) {
        self.link.stop_all();
    }

    /// Keeps a held jog alive (see [`LinkHandle::renew_jog_lease`]).
    pub fn renew_jog_lease(&self) {
        self.link.renew_jog_lease();
    }

    /// Reads `records` of a coordinate table with 2A4H, in chunks that fit the reply
    /// buffer.
    pub fn read_table(&self, kind: CoordKind, records: std::ops::Range<u16>) {
        self.link.download_table(TableRequest {
            kind,
            axes: AxisPattern::SCARA_1,
            first: records.start,
            records: records.end.saturating_sub(records.start),
            reply_buffer: crate::protocol::REPLY_BUFFER,
        });
    }

    /// Stops the table read in progress.
    pub fn cancel_table_read(&self) {
        self.link.cancel_table();
    }
}
