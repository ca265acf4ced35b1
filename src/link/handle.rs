//! Starting the link thread, and the handle the application talks to it through.

use std::io;
use std::sync::Arc;
use std::sync::atomic::AtomicU64;
use std::thread::JoinHandle;
use std::time::Duration;

use crossbeam_channel::{Receiver, Sender, unbounded};

use super::engine::Engine;
use super::event::LinkEvent;
use super::request::{Origin, Pending, Priority, RequestId};
use super::schedule::Polling;
use super::table::TableRequest;
use super::timing::Timing;
use super::transport::Transport;
use crate::protocol::{AxisPattern, Command, ScMode, Station, Stop};

/// Opens (and re-opens) the line.
pub type Connector = Box<dyn FnMut() -> io::Result<Box<dyn Transport>> + Send>;
/// Called after events were sent, so a UI can wake up and draw them.
pub type Repaint = Arc<dyn Fn() + Send + Sync>;

/// How the link behaves.
#[derive(Clone, Debug, PartialEq)]
pub struct LinkConfig {
    pub station: Station,
    /// Computed checksums (default) or `@@` in commands (a debug setting, DESIGN.md).
    pub sc_mode: ScMode,
    pub timing: Timing,
    /// How many times a query (never motion) is sent again after a time-out.
    pub query_retries: u8,
    pub polling: Polling,
    /// Try to reopen a lost line by itself.
    pub auto_reconnect: bool,
    pub reconnect_interval: Duration,
    /// What is read after a motion command timed out, instead of re-sending it.
    pub recheck: Command,
}

impl Default for LinkConfig {
    fn default() -> Self {
        let polling = Polling::default();
        let recheck = polling
            .commands
            .first()
            .copied()
            .unwrap_or(Command::SystemStatus);
        Self {
            station: Station::DEFAULT,
            sc_mode: ScMode::Computed,
            timing: Timing::default(),
            query_retries: 2,
            polling,
            auto_reconnect: true,
            reconnect_interval: Duration::from_millis(500),
            recheck,
        }
    }
}

/// Messages from the handle to the thread.
pub(crate) enum Control {
    Submit(Pending),
    SetPolling(Polling),
    DownloadTable(TableRequest),
    CancelTable,
    Reconnect,
    SetAutoReconnect(bool),
    Shutdown,
}

/// The application's side of the link. Dropping it stops the thread and closes the line.
pub struct LinkHandle {
    control: Sender<Control>,
    ids: Arc<AtomicU64>,
    thread: Option<JoinHandle<()>>,
}

/// Starts the link thread. Events arrive on the returned receiver; `repaint` is called
/// whenever some were sent.
pub fn spawn(
    connector: Connector,
    config: LinkConfig,
    repaint: Repaint,
) -> std::io::Result<(LinkHandle, Receiver<LinkEvent>)> {
    let (control_tx, control_rx) = unbounded();
    let (event_tx, event_rx) = unbounded();
    let ids = Arc::new(AtomicU64::new(1));
    let engine = Engine::new(
        connector,
        config,
        control_rx,
        event_tx,
        repaint,
        ids.clone(),
    );
    let thread = std::thread::Builder::new()
        .name("xsel-link".into())
        .spawn(move || engine.run())?;
    let handle = LinkHandle {
        control: control_tx,
        ids,
        thread: Some(thread),
    };
    Ok((handle, event_rx))
}

impl LinkHandle {
    /// Queues a command; the events that answer it carry the returned id. 238H STOP
    /// always goes to the head of the queue.
    pub fn submit(&self, command: Command, priority: Priority) -> RequestId {
        let id = RequestId::next(&self.ids);
        let pending = Pending::new(id, command, Origin::User, priority);
        let _ = self.control.send(Control::Submit(pending));
        id
    }

    /// 238H for all axes, at the head of the queue.
    pub fn stop_all(&self) -> RequestId {
        self.submit(
            Command::Stop(Stop {
                axes: AxisPattern::ALL,
                cancel_held_outputs: false,
            }),
            Priority::Stop,
        )
    }

    pub fn set_polling(&self, polling: Polling) {
        let _ = self.control.send(Control::SetPolling(polling));
    }

    pub fn download_table(&self, request: TableRequest) {
        let _ = self.control.send(Control::DownloadTable(request));
    }

    pub fn cancel_table(&self) {
        let _ = self.control.send(Control::CancelTable);
    }

    /// Closes and reopens the line now (or opens it, if it is down).
    pub fn reconnect(&self) {
        let _ = self.control.send(Control::Reconnect);
    }

    pub fn set_auto_reconnect(&self, on: bool) {
        let _ = self.control.send(Control::SetAutoReconnect(on));
    }

    /// Whether the thread is still running.
    pub fn is_running(&self) -> bool {
        self.thread.as_ref().is_some_and(|t| !t.is_finished())
    }
}

impl Drop for LinkHandle {
    fn drop(&mut self) {
        let _ = self.control.send(Control::Shutdown);
        if let Some(thread) = self.thread.take() {
            let _ = thread.join();
        }
    }
}
