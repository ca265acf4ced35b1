//! Shared set-up for the link tests: a link joined to a simulator, and event waiting.
#![allow(dead_code)]

use std::time::{Duration, Instant};

use crossbeam_channel::Receiver;
use xsel_pendant::link::transport::StreamTransport;
use xsel_pendant::link::{Connector, LinkConfig, LinkEvent, LinkHandle, Polling, spawn};
use xsel_pendant::protocol::{
    ArmPolicy, Axis, AxisPattern, Command, Milli, PerAxis, Percent, ScaraMotion, ScaraMove,
};
use xsel_pendant::sim::pipe::PipeEnd;
use xsel_pendant::sim::{EmbeddedOptions, FaultSpec, SimHandle, SimSetup, start_embedded};

/// A simulator that starts homed with servos on, so moves are accepted at once.
pub fn ready_setup(reply_delay: Duration) -> SimSetup {
    let mut setup = SimSetup::default();
    setup.config.start_ready = true;
    setup.config.reply_delay = reply_delay;
    setup
}

/// A connector that hands out the one pipe end once; later attempts fail like a
/// missing port.
pub fn pipe_connector(pipe: PipeEnd) -> Connector {
    let mut pipe = Some(pipe);
    Box::new(move |_| match pipe.take() {
        Some(p) => Ok(Box::new(StreamTransport::new(
            p,
            "embedded simulator",
            PipeEnd::set_read_timeout,
        ))),
        None => Err(std::io::Error::new(
            std::io::ErrorKind::NotFound,
            "the simulator is gone",
        )),
    })
}

/// Link + embedded simulator.
pub fn embedded_link(
    setup: SimSetup,
    faults: FaultSpec,
    byte_time: Option<Duration>,
    config: LinkConfig,
) -> (LinkHandle, Receiver<LinkEvent>, SimHandle) {
    let (pipe, sim) = start_embedded(EmbeddedOptions {
        setup,
        byte_time,
        read_timeout: Duration::from_millis(20),
        faults,
        ..EmbeddedOptions::default()
    });
    let (link, events) =
        spawn(pipe_connector(pipe), config, std::sync::Arc::new(|_| {})).expect("link thread");
    (link, events, sim)
}

/// A link configuration without polling (tests that count frames).
pub fn quiet_config() -> LinkConfig {
    LinkConfig {
        polling: Polling {
            interval: None,
            idle_interval: None,
            commands: Vec::new(),
        },
        ..LinkConfig::default()
    }
}

/// Link over a serial port (or pty) path that can be reopened.
#[cfg(unix)]
pub fn serial_link(path: &str, config: LinkConfig) -> (LinkHandle, Receiver<LinkEvent>) {
    let path = path.to_owned();
    let connector: Connector = Box::new(move |line| {
        xsel_pendant::link::SerialTransport::open(&path, line)
            .map(|t| Box::new(t) as Box<dyn xsel_pendant::link::Transport>)
    });
    spawn(connector, config, std::sync::Arc::new(|_| {})).expect("link thread")
}

/// A simulator serving a pseudo-terminal (its path in `.path`; Unix only).
#[cfg(unix)]
pub fn pty_server(setup: SimSetup) -> xsel_pendant::sim::runner::PtyServer {
    use xsel_pendant::sim::Controller;
    use xsel_pendant::sim::runner::{RunOptions, SimCore, start_pty};
    start_pty(
        SimCore::new(Controller::new(setup), FaultSpec::none()),
        RunOptions::default(),
    )
    .expect("pty")
}

/// Matches the event that settles request `id`: its reply, error reply or refusal.
pub fn answered(id: xsel_pendant::link::RequestId) -> impl FnMut(&LinkEvent) -> bool {
    move |e| match e {
        LinkEvent::Reply { id: r, .. }
        | LinkEvent::ErrorReply { id: r, .. }
        | LinkEvent::NotSent { id: r, .. } => *r == id,
        _ => false,
    }
}

/// Waits for the first event matching `pred`; every event seen is kept in `seen`.
pub fn wait_for(
    events: &Receiver<LinkEvent>,
    timeout: Duration,
    seen: &mut Vec<LinkEvent>,
    mut pred: impl FnMut(&LinkEvent) -> bool,
) -> Option<LinkEvent> {
    let deadline = Instant::now() + timeout;
    loop {
        let left = deadline.saturating_duration_since(Instant::now());
        let event = events.recv_timeout(left).ok()?;
        seen.push(event.clone());
        if pred(&event) {
            return Some(event);
        }
    }
}

/// 2D5H relative PTP move of axis 1 (X in the work frame) by `micrometres`.
pub fn step_x(micrometres: i32) -> Command {
    Command::ScaraMoveRelative(ScaraMove {
        motion: ScaraMotion::Ptp {
            acc: Percent(50),
            dec: Percent(50),
            speed: Percent(30),
            arm: ArmPolicy::KeepNoSwitch,
        },
        targets: PerAxis::new().with(Axis::A1, Milli(micrometres)),
    })
}

pub const SCARA: AxisPattern = AxisPattern::SCARA_1;

/// The events as one line each, for failure messages.
pub fn story(seen: &[LinkEvent]) -> String {
    seen.iter()
        .filter(|e| !matches!(e, LinkEvent::Health(_)))
        .map(|e| match e {
            LinkEvent::Reply { id, origin, .. }
            | LinkEvent::ErrorReply { id, origin, .. }
            | LinkEvent::Timeout { id, origin, .. } => {
                format!("  {} [{id} {origin:?}]", e.summary())
            }
            LinkEvent::FrameSent { id, .. } => format!("  {} [{id}]", e.summary()),
            _ => format!("  {}", e.summary()),
        })
        .collect::<Vec<_>>()
        .join("\n")
}

/// 236H continuous jog (distance 0) of axis 1 in the work frame: runs until stopped.
pub fn jog_x() -> Command {
    use xsel_pendant::protocol::{CentiG, Direction, Jog, JogFrame, JogMotion, MmPerSec};
    Command::Jog(Jog {
        axes: AxisPattern::single(Axis::A1),
        direction: Direction::Negative,
        distance: Milli(0),
        motion: JogMotion::Cartesian {
            frame: JogFrame::Work,
            acc: CentiG(10),
            dec: CentiG(10),
            speed: MmPerSec(5),
        },
    })
}

/// The message IDs of the frames the simulator received, in order ("236", "238"...).
pub fn ids_received(sim: &SimHandle) -> Vec<String> {
    use xsel_pendant::sim::runner::Dir;
    sim.traffic()
        .into_iter()
        .filter(|t| t.dir == Dir::In && t.bytes.first() == Some(&b'!'))
        .filter_map(|t| {
            std::str::from_utf8(t.bytes.get(3..6)?)
                .ok()
                .map(str::to_owned)
        })
        .collect()
}

/// Whether a 238H STOP follows the last 236H jog among the frames received.
pub fn stop_follows_last_jog(sim: &SimHandle) -> bool {
    let ids = ids_received(sim);
    match ids.iter().rposition(|id| id == "236") {
        Some(jog) => ids[jog..].iter().any(|id| id == "238"),
        None => false,
    }
}
