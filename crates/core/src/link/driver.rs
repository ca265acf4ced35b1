//! The link's IO driver: one thread owns the line and runs a protocol core on it. It knows
//! no protocol: it opens, reads, writes and closes as the core asks, hands in requests
//! (STOPs first), lease renewals, bytes and time-outs, and forwards the core's events on a
//! channel kept bounded. Every rule of the protocol lives in the core.

use std::io;
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use crossbeam_channel::{Receiver, Sender, TryRecvError, select, unbounded};

use super::core::{Input, LineChange, LinkCore, Transmit};
use super::event_out::EventOut;
use super::lease::LeaseClock;
use super::reason::{IoFailure, LineDownReason};
use super::transport::{Transport, is_timeout};
use crate::line::LineSettings;

/// Told of each event as it is sent (on the driver's thread), so a window can wake up.
pub(crate) type Notify<E> = Arc<dyn Fn(&E) + Send + Sync>;

/// Opens (and re-opens) the line with the settings the core asks for.
pub type Connector = Box<dyn FnMut(LineSettings) -> io::Result<Box<dyn Transport>> + Send>;

/// Longest single read while an answer is awaited, so requests are seen promptly.
const READ_SLICE: Duration = Duration::from_millis(20);
/// The last part of a wait for the core's time is slept precisely (a timer wakes some
/// tens of µs late) rather than on the channels.
const ON_TIME: Duration = Duration::from_micros(200);
/// While no answer is awaited, the line is looked at this often (a vanished port shows
/// within a second, stale input is handed in).
pub(super) const IDLE_CHECK: Duration = Duration::from_millis(200);

/// The application's side of a running driver.
pub(crate) struct DriverHandle<C: LinkCore> {
    pub(crate) control: Sender<Input<C::Request>>,
    /// STOPs only: a channel of their own, looked at before any other request, so a STOP
    /// never waits behind a burst of others.
    pub(crate) stops: Sender<Input<C::Request>>,
    pub(crate) lease: Arc<LeaseClock>,
    thread: Option<JoinHandle<C>>,
}

impl<C: LinkCore> DriverHandle<C> {
    /// Whether the thread is still running.
    pub(crate) fn is_running(&self) -> bool {
        self.thread.as_ref().is_some_and(|t| !t.is_finished())
    }

    /// Waits for the thread to end by itself; the core comes back (`None` if the thread
    /// failed or was already joined).
    pub(crate) fn wait(&mut self) -> Option<C> {
        self.thread.take().and_then(|t| t.join().ok())
    }

    /// Asks the core to close and waits for the thread; the core comes back (`None` if
    /// the thread failed or was already joined).
    pub(crate) fn close(&mut self) -> Option<C> {
        let _ = self.control.send(Input::Close);
        self.thread.take().and_then(|t| t.join().ok())
    }
}

/// Starts a driver thread named `name` running `core`; events arrive on the receiver, and
/// `repaint` is told of each as it is sent.
pub(crate) fn spawn<C>(
    name: &str,
    core: C,
    connector: Connector,
    repaint: Notify<C::Event>,
    backlog: usize,
) -> io::Result<(DriverHandle<C>, Receiver<C::Event>)>
where
    C: LinkCore + Send + 'static,
    C::Request: Send + 'static,
    C::Event: Send + 'static,
{
    let (control_tx, control) = unbounded();
    let (stop_tx, stops) = unbounded();
    // Unbounded, but kept short: see `event_out.rs`.
    let (event_tx, event_rx) = unbounded();
    let lease = Arc::new(LeaseClock::new());
    let driver = Driver {
        core,
        connector,
        transport: None,
        control,
        stops,
        handle_gone: false,
        lease: lease.clone(),
        lease_seen: None,
        events: EventOut::new(event_tx, repaint, backlog),
        backlog_told: (false, 0),
        last_line_check: Instant::now(),
        rx_buf: vec![0; 4096],
    };
    let thread = std::thread::Builder::new()
        .name(name.into())
        .spawn(move || driver.run())?;
    let handle = DriverHandle {
        control: control_tx,
        stops: stop_tx,
        lease,
        thread: Some(thread),
    };
    Ok((handle, event_rx))
}

struct Driver<C: LinkCore> {
    core: C,
    connector: Connector,
    transport: Option<Box<dyn Transport>>,
    control: Receiver<Input<C::Request>>,
    stops: Receiver<Input<C::Request>>,
    /// The handle is gone: `Close` was handed in for it.
    handle_gone: bool,
    lease: Arc<LeaseClock>,
    lease_seen: Option<Instant>,
    events: EventOut<C::Event>,
    /// The backlog as last told to the core.
    backlog_told: (bool, u64),
    last_line_check: Instant,
    rx_buf: Vec<u8>,
}

impl<C: LinkCore> Driver<C> {
    fn run(mut self) -> C {
        crate::line::wake_on_time();
        loop {
            self.take_inputs();
            let now = Instant::now();
            if self.core.poll_timeout().is_some_and(|t| t <= now) {
                self.core.handle_timeout(now);
            }
            self.transmit();
            let closed = self.core.is_closed();
            if closed {
                // The count goes out before the core's last events.
                self.events.report_dropped();
            }
            while let Some(event) = self.core.poll_event() {
                self.events.send(event);
            }
            if closed {
                break;
            }
            self.wait();
        }
        self.transport = None;
        self.core
    }

    /// Hands in the lease, the reader's backlog and every request waiting (STOPs first,
    /// and again between any two other requests).
    fn take_inputs(&mut self) {
        let now = Instant::now();
        let renewed = self.lease.renewed_at();
        if renewed.is_some() && renewed != self.lease_seen {
            self.lease_seen = renewed;
            if let Some(at) = renewed {
                self.core.handle_request(now, Input::LeaseRenewed(at));
            }
        }
        let backlog = (self.events.behind(), self.events.dropped_total());
        if backlog != self.backlog_told {
            self.backlog_told = backlog;
            let (behind, dropped) = backlog;
            self.core
                .handle_request(now, Input::Backlog { behind, dropped });
        }
        if let Some(why) = self.transport.as_mut().map(|t| t.take_guardian_stops()) {
            for why in why {
                self.core.handle_line(now, LineChange::GuardianStopped(why));
            }
        }
        self.take_stops(now);
        loop {
            match self.control.try_recv() {
                Ok(input) => self.core.handle_request(now, input),
                Err(TryRecvError::Empty) => break,
                Err(TryRecvError::Disconnected) => {
                    self.handle_dropped(now);
                    break;
                }
            }
            self.take_stops(now);
        }
    }

    fn take_stops(&mut self, now: Instant) {
        while let Ok(stop) = self.stops.try_recv() {
            self.core.handle_request(now, stop);
        }
    }

    /// The handle was dropped without a word: close all the same.
    fn handle_dropped(&mut self, now: Instant) {
        if !std::mem::replace(&mut self.handle_gone, true) {
            self.core.handle_request(now, Input::Close);
        }
    }

    /// Does what the core asks on the line until it asks for nothing more.
    fn transmit(&mut self) {
        loop {
            if !self.core.awaits_bytes() {
                self.hand_in_waiting_input();
            }
            let Some(transmit) = self.core.poll_transmit(Instant::now()) else {
                return;
            };
            match transmit {
                Transmit::Open(settings) => {
                    self.transport = None;
                    let change = match (self.connector)(settings) {
                        Ok(transport) => {
                            let name = transport.describe();
                            self.transport = Some(transport);
                            self.last_line_check = Instant::now();
                            LineChange::Opened { name }
                        }
                        Err(e) => LineChange::OpenFailed(IoFailure::from(&e)),
                    };
                    self.core.handle_line(Instant::now(), change);
                }
                Transmit::Write(bytes) => {
                    let written = match self.transport.as_mut() {
                        Some(t) => t
                            .write_all_bytes(&bytes)
                            .map_err(|e| LineDownReason::WriteFailed(IoFailure::from(&e))),
                        None => Err(LineDownReason::Closed),
                    };
                    if let Err(reason) = written {
                        self.lost(reason);
                    }
                }
                Transmit::Close => self.transport = None,
            }
        }
    }

    /// Hands in what waits on the line (stale input: no answer is awaited).
    fn hand_in_waiting_input(&mut self) {
        let Some(transport) = self.transport.as_mut() else {
            return;
        };
        match transport.discard_input() {
            Ok(stale) if !stale.is_empty() => self.core.handle_bytes(Instant::now(), &stale),
            Ok(_) => {}
            Err(e) => self.lost(LineDownReason::ReadFailed(IoFailure::from(&e))),
        }
    }

    fn lost(&mut self, reason: LineDownReason) {
        self.transport = None;
        self.core
            .handle_line(Instant::now(), LineChange::Lost(reason));
    }

    /// Waits for the line while an answer is awaited, else for a request, the core's
    /// next time-out or the next look at the line.
    fn wait(&mut self) {
        let now = Instant::now();
        let due = self.core.poll_timeout();
        let until = |t: Option<Instant>, most: Duration| {
            t.map_or(most, |t| t.saturating_duration_since(now))
                .min(most)
        };
        if self.transport.is_some() && self.core.awaits_bytes() {
            self.read(until(due, READ_SLICE));
            return;
        }
        let look = self
            .transport
            .as_ref()
            .map(|_| self.last_line_check + IDLE_CHECK);
        let wait = until([due, look].into_iter().flatten().min(), IDLE_CHECK);
        if self.handle_gone {
            // No request can come any more (the channels would answer at once): only time.
            std::thread::sleep(wait);
        } else if !wait.is_zero() {
            let now = Instant::now();
            select! {
                recv(self.stops) -> stop => match stop {
                    Ok(stop) => self.core.handle_request(now, stop),
                    Err(_) => self.handle_dropped(now),
                },
                recv(self.control) -> input => match input {
                    Ok(input) => self.core.handle_request(now, input),
                    Err(_) => self.handle_dropped(now),
                },
                default(wait.saturating_sub(ON_TIME)) => {
                    // The core's time (a line gap) is kept to the microsecond.
                    if let Some(due) = due.filter(|t| t.saturating_duration_since(now) <= wait) {
                        crate::line::sleep_until(due);
                    }
                }
            }
        }
        if self.transport.is_some() && self.last_line_check.elapsed() >= IDLE_CHECK {
            self.read(Duration::ZERO);
        }
    }

    /// One read of at most `wait`; what came, or the loss of the line, is handed in.
    fn read(&mut self, wait: Duration) {
        self.last_line_check = Instant::now();
        let Some(transport) = self.transport.as_mut() else {
            return;
        };
        match transport.read_timeout(&mut self.rx_buf, wait) {
            Ok(0) => self.lost(LineDownReason::Closed),
            Ok(n) => {
                let at = Instant::now();
                let bytes = self.rx_buf.get(..n).unwrap_or_default();
                self.core.handle_bytes(at, bytes);
            }
            Err(e) if is_timeout(&e) => {}
            Err(e) => self.lost(LineDownReason::ReadFailed(IoFailure::from(&e))),
        }
    }
}

/// `at + d`, or a time far enough ahead when a huge setting would overflow.
pub(crate) fn later(at: Instant, d: Duration) -> Instant {
    at.checked_add(d)
        .or_else(|| at.checked_add(Duration::from_secs(24 * 3600)))
        .unwrap_or(at)
}
