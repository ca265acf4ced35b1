//! Starting the RMC link on the shared driver, and the handle the application talks to it
//! through.

use std::sync::Arc;
use std::sync::atomic::AtomicU64;
use std::time::{Duration, Instant};

use crossbeam_channel::Receiver;

use super::link::{HoldJog, RmcCore, RmcEvent, RmcLinkConfig, RmcRequest};
use super::{AxisId, Command};
use crate::link::core::Input;
use crate::link::driver::{self, DriverHandle};
use crate::link::{Connector, RequestId};

/// Called with each event as it is sent (on the link thread), so a window can wake up.
pub type RmcRepaint = Arc<dyn Fn(&RmcEvent) + Send + Sync>;

/// The application's side of the RMC link. Dropping it closes the link (Stop (6) first
/// to every axis that may be moving).
pub struct RmcHandle {
    driver: DriverHandle<RmcCore>,
    ids: AtomicU64,
}

/// Events the window may leave unread before traffic is left out: a round (two axes and
/// the controller, every 20 ms while anything moves, 250 ms while all stand) brings about
/// 9 events, the frame log's rows among them: about 450 a second, or 36.
pub const EVENT_BACKLOG: usize = 4096;

/// Starts the RMC link thread on `connector` (a TCP connection to the controller, or to
/// the built-in simulator).
pub fn spawn(
    connector: Connector,
    config: RmcLinkConfig,
    repaint: RmcRepaint,
) -> std::io::Result<(RmcHandle, Receiver<RmcEvent>)> {
    let core = RmcCore::new(config, Instant::now());
    let (driver, events) = driver::spawn("rmc-link", core, connector, repaint, EVENT_BACKLOG)?;
    Ok((
        RmcHandle {
            driver,
            ids: AtomicU64::new(1),
        },
        events,
    ))
}

impl RmcHandle {
    fn request(&self, request: RmcRequest) {
        let _ = self.driver.control.send(Input::App(request));
    }

    /// Sends one command to one axis; the events that answer it carry the id.
    pub fn send(&self, axis: AxisId, command: Command) -> RequestId {
        let id = RequestId::next(&self.ids);
        self.request(RmcRequest::Send { id, axis, command });
        id
    }

    /// Starts a held jog: it runs while [`RmcHandle::renew_lease`] is called.
    pub fn hold(&self, axis: AxisId, jog: HoldJog) -> RequestId {
        let id = RequestId::next(&self.ids);
        self.driver.lease.renew();
        self.request(RmcRequest::Hold { id, axis, jog });
        id
    }

    /// Keeps a held jog alive (one atomic store).
    pub fn renew_lease(&self) {
        self.driver.lease.renew();
    }

    /// The held jog's input let go: Stop (6) for that axis, ahead of other requests; and
    /// again in order, so a Hold it overtook on its way ends too.
    pub fn release(&self, axis: AxisId) {
        let _ = self
            .driver
            .stops
            .send(Input::App(RmcRequest::Release { axis }));
        self.request(RmcRequest::StopsInOrder { axis: Some(axis) });
    }

    /// STOP: Stop (6) to every enabled axis, ahead of everything; and again in order, so
    /// a Hold or a move it overtook on its way is not sent.
    pub fn stop_all(&self) {
        let _ = self.driver.stops.send(Input::App(RmcRequest::StopAll));
        self.request(RmcRequest::StopsInOrder { axis: None });
    }

    pub fn reconnect(&self) {
        self.request(RmcRequest::Reconnect);
    }

    pub fn set_poll_interval(&self, interval: Duration) {
        self.request(RmcRequest::SetPollInterval(interval));
    }

    pub fn is_running(&self) -> bool {
        self.driver.is_running()
    }

    /// Closes the link: every Stop (6) owed goes out, then the connection closes.
    pub fn shutdown(mut self) {
        self.driver.close();
    }
}

impl Drop for RmcHandle {
    fn drop(&mut self) {
        self.driver.close();
    }
}
