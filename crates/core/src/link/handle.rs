//! Starting the link thread, and the handle the application talks to it through.

use std::sync::Arc;
use std::sync::atomic::AtomicU64;
use std::time::{Duration, Instant};

use crossbeam_channel::Receiver;

use super::core::Input;
use super::driver::{self, Connector, DriverHandle};
use super::event::LinkEvent;
use super::format_b::{Control, FormatB, ShutdownReport};
use super::request::{Origin, Pending, Priority, RequestId};
use super::schedule::Polling;
use super::table::TableRequest;
use super::timing::Timing;
use crate::protocol::{AxisPattern, Command, ScMode, Station, Stop};

/// Called with each event as it is sent (on the link thread), so a UI can wake up and
/// draw what changed; it should return at once.
pub type Repaint = Arc<dyn Fn(&LinkEvent) + Send + Sync>;

/// Events the reader may leave unread by default (see [`LinkConfig::event_backlog`]).
/// A poll brings three (the frame sent, the frame received, the reply): about 120 a
/// second while polls are fast, 50 while steady.
pub const EVENT_BACKLOG: usize = 4096;

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
    /// A continuous jog (236H, distance 0) is stopped when its lease is not renewed
    /// ([`LinkHandle::renew_jog_lease`]) for this long; one not yet sent is dropped.
    pub jog_lease: Duration,
    /// Events the reader may leave unread before traffic events are left out (counted
    /// in `LinkEvent::Dropped`) and status polling pauses.
    pub event_backlog: usize,
}

impl Default for LinkConfig {
    fn default() -> Self {
        let polling = Polling::default();
        let recheck = polling
            .commands
            .first()
            .cloned()
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
            jog_lease: super::lease::JOG_LEASE,
            event_backlog: EVENT_BACKLOG,
        }
    }
}

/// The application's side of the link. Dropping it does what [`LinkHandle::shutdown`]
/// does (the report then arrives as the last event, if anyone still listens).
pub struct LinkHandle {
    driver: DriverHandle<FormatB>,
    ids: Arc<AtomicU64>,
}

/// Starts the link thread. Events arrive on the returned receiver; `repaint` is called
/// whenever some were sent.
pub fn spawn(
    connector: Connector,
    config: LinkConfig,
    repaint: Repaint,
) -> std::io::Result<(LinkHandle, Receiver<LinkEvent>)> {
    let ids = Arc::new(AtomicU64::new(1));
    let backlog = config.event_backlog;
    let core = FormatB::new(config, ids.clone(), Instant::now());
    let (driver, events) = driver::spawn("xsel-link", core, connector, repaint, backlog)?;
    Ok((LinkHandle { driver, ids }, events))
}

impl LinkHandle {
    /// Queues a command; the events that answer it carry the returned id. 238H STOP
    /// always goes to the head of the queue. Submitting a continuous jog renews its
    /// lease (see [`LinkHandle::renew_jog_lease`]).
    pub fn submit(&self, command: Command, priority: Priority) -> RequestId {
        let id = RequestId::next(&self.ids);
        let (stop, continuous) = (command.is_stop(), command.is_continuous_jog());
        let pending = Pending::new(id, command, Origin::User, priority);
        let input = Input::App(Control::Submit(pending));
        if stop {
            let _ = self.driver.stops.send(input);
        } else {
            if continuous {
                self.driver.lease.renew();
            }
            let _ = self.driver.control.send(input);
        }
        id
    }

    /// Keeps a continuous jog alive: call it at least every `LinkConfig::jog_lease`
    /// (the window: every frame while the jog button or key is held). When renewals
    /// stop, the link sends 238H by itself, so a frozen, minimised or crashed window
    /// cannot leave the arm jogging. Cheap: one atomic store, no message.
    pub fn renew_jog_lease(&self) {
        self.driver.lease.renew();
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

    /// A sender of STOPs for all axes that works while the handle itself is busy
    /// closing on another thread (the window's STOP button during a disconnect).
    pub fn stopper(&self) -> StopSender {
        StopSender {
            stops: self.driver.stops.clone(),
            ids: self.ids.clone(),
        }
    }

    fn control(&self, control: Control) {
        let _ = self.driver.control.send(Input::App(control));
    }

    pub fn set_polling(&self, polling: Polling) {
        self.control(Control::SetPolling(polling));
    }

    pub fn download_table(&self, request: TableRequest) {
        self.control(Control::DownloadTable(request));
    }

    pub fn cancel_table(&self) {
        self.control(Control::CancelTable);
    }

    /// Closes and reopens the line now (or opens it, if it is down).
    pub fn reconnect(&self) {
        self.control(Control::Reconnect);
    }

    pub fn set_auto_reconnect(&self, on: bool) {
        self.control(Control::SetAutoReconnect(on));
    }

    /// Whether the thread is still running.
    pub fn is_running(&self) -> bool {
        self.driver.is_running()
    }

    /// Shuts the link down and says what was done: the transaction in flight ends
    /// (bounded by its reply timeout), every queued STOP goes out, plus a 238H of the
    /// link's own if a jog or move may still be running, each tried once and bounded by
    /// its reply timeout; then the line is closed. Other queued requests are not sent.
    pub fn shutdown(mut self) -> ShutdownReport {
        self.finish()
    }

    fn finish(&mut self) -> ShutdownReport {
        self.driver
            .close()
            .map_or_else(ShutdownReport::thread_failed, |core| core.shutdown_report())
    }
}

/// STOPs for all axes into a link, from anywhere (see [`LinkHandle::stopper`]); a link
/// that has closed takes them no more, and they are then dropped.
#[derive(Clone)]
pub struct StopSender {
    stops: crossbeam_channel::Sender<Input<Control>>,
    ids: Arc<AtomicU64>,
}

impl StopSender {
    /// 238H for all axes, ahead of anything queued (a closing link still sends it).
    pub fn stop_all(&self) {
        let pending = Pending::new(
            RequestId::next(&self.ids),
            Command::Stop(Stop {
                axes: AxisPattern::ALL,
                cancel_held_outputs: false,
            }),
            Origin::User,
            Priority::Stop,
        );
        let _ = self.stops.send(Input::App(Control::Submit(pending)));
    }
}

impl Drop for LinkHandle {
    fn drop(&mut self) {
        // The report also went out as the last event (`LinkEvent::ShutDown`).
        let _ = self.finish();
    }
}
