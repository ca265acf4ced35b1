//! A live connection: the link thread on the chosen line, and the embedded simulator when
//! the line is the built-in one. Built from [`ConnectionSettings`]; dropped to close (the
//! link stops any jog or move still running on its way out).

use std::sync::Arc;
use std::time::Duration;

use crossbeam_channel::Receiver;

use crate::link::transport::{SerialTransport, StreamTransport, TcpTransport};
use crate::link::{Connector, LinkConfig, LinkEvent, LinkHandle, Polling, Repaint, Transport};
use crate::pendant::{ConnectionSettings, LineKind, state};
use crate::robot::RobotModel;
use crate::sim::pipe::PipeEnd;
use crate::sim::{EmbeddedOptions, SimHandle, SimSetup, start_embedded};

/// How often a poll cycle starts.
pub const POLL_INTERVAL: Duration = Duration::from_millis(100);

/// The robot model named in the settings: a built-in name or a TOML file.
pub fn load_model(name: &str) -> Result<RobotModel, String> {
    RobotModel::builtin(name)
        .or_else(|_| RobotModel::load(name))
        .map_err(|e| format!("robot model `{name}`: {e}"))
}

/// The link thread and what stands behind the line.
pub struct Session {
    pub link: LinkHandle,
    pub events: Receiver<LinkEvent>,
    /// The embedded simulator, when the line is the built-in one.
    pub sim: Option<SimHandle>,
}

impl Session {
    /// Checks the settings and starts the link; the line itself opens on the link thread
    /// (its success or failure arrives as an event).
    pub fn open(
        settings: &ConnectionSettings,
        model: &RobotModel,
        repaint: Repaint,
    ) -> Result<Session, String> {
        let line = settings.line();
        line.validate().map_err(|e| e.to_string())?;
        let (connector, sim) = connector(settings, model)?;
        let mut config = LinkConfig {
            station: settings.station(),
            polling: Polling {
                interval: Some(POLL_INTERVAL),
                commands: state::poll_commands(),
            },
            ..LinkConfig::default()
        };
        config.timing.line = line;
        let (link, events) = crate::link::spawn(connector, config, repaint)
            .map_err(|e| format!("cannot start the link thread: {e}"))?;
        Ok(Session { link, events, sim })
    }

    /// A session with the repaint hook doing nothing (headless use, tests).
    pub fn open_quiet(settings: &ConnectionSettings, model: &RobotModel) -> Result<Session, String> {
        Self::open(settings, model, Arc::new(|| {}))
    }
}

fn connector(
    settings: &ConnectionSettings,
    model: &RobotModel,
) -> Result<(Connector, Option<SimHandle>), String> {
    let line = settings.line();
    match settings.kind {
        LineKind::Serial => {
            let port = settings.port.trim().to_owned();
            if port.is_empty() {
                return Err("choose a serial port first".into());
            }
            let open: Connector = Box::new(move || {
                SerialTransport::open(&port, line).map(|t| Box::new(t) as Box<dyn Transport>)
            });
            Ok((open, None))
        }
        LineKind::Tcp => {
            let addr = settings.tcp.trim().to_owned();
            if addr.is_empty() {
                return Err("enter the bridge's address as HOST:PORT".into());
            }
            let open: Connector = Box::new(move || {
                TcpTransport::connect(&addr, Duration::from_secs(2))
                    .map(|t| Box::new(t) as Box<dyn Transport>)
            });
            Ok((open, None))
        }
        LineKind::Simulator => {
            let mut setup = SimSetup::for_model(model.clone());
            setup.config.station = settings.station;
            let (pipe, sim) = start_embedded(EmbeddedOptions {
                setup,
                byte_time: Some(line.byte_time()),
                ..EmbeddedOptions::default()
            });
            let name = format!("built-in simulator ({}, paced at {line})", model.name);
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
    }
}
