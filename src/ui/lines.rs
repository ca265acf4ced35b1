//! The window's two lines (the X-SEL's session and the RMC151's): opened and closed as
//! the pendant asks, the old one closing on a thread of its own, their events taken in
//! oldest first within a time budget, and the pendant's requests forwarded in its order.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering};
use std::time::{Duration, Instant};

use super::inbox::{Inbox, Next};
use super::wake::{LINK_REPAINT, RmcWake, Wake, WakeFilter};
use crate::pendant::axes::AxisCall;
use crate::pendant::{Pendant, Request};
use crate::session::closing::Closing;
use crate::session::rmc::RmcSession;
use crate::session::simulator::FrontPanel;
use crate::session::{LineOwner, Session, SimHandle, load_model};

/// Most time spent applying link events in one frame (about 5 us each: one frame takes
/// in what 25 s of idle polling of both links brings).
const EVENT_BUDGET: Duration = Duration::from_millis(16);
/// The simulator's thread answers the front panel within a tick (20 ms); the window looks
/// again after this.
pub const PANEL_ANSWER: Duration = Duration::from_millis(60);

/// The two devices' connections.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Device {
    Xsel,
    Rmc,
}

/// Both lines and what closes behind them.
pub struct Lines {
    session: Option<Session>,
    /// The RMC151's connection, apart from the robot's line: motion on one never waits
    /// for the other.
    rmc: Option<RmcSession>,
    /// The links' events, taken in oldest first.
    inbox: Inbox,
    /// Sessions closing on threads of their own (the window draws, STOP reaches them).
    closing: Vec<(Device, Closing)>,
    /// A line asked for while its old one still closes: opened once it has.
    open_when_closed: Vec<Device>,
    owner: LineOwner,
    /// Whether a live frame log was drawn in the last frame (its rows are worth a wake).
    pub live_log_shown: Arc<AtomicBool>,
    /// Link events that woke the window so far.
    link_wakes: Arc<AtomicU64>,
    /// Link events left for later since the window last took every event in (see
    /// `wake`).
    unread: Arc<AtomicUsize>,
}

impl Lines {
    /// No line open yet; serial ports and bridges go to `owner`.
    pub fn new(owner: LineOwner) -> Self {
        Self {
            session: None,
            rmc: None,
            inbox: Inbox::default(),
            closing: Vec::new(),
            open_when_closed: Vec::new(),
            owner,
            live_log_shown: Default::default(),
            link_wakes: Default::default(),
            unread: Default::default(),
        }
    }

    /// Whether the X-SEL's line is open (or opening).
    pub fn has_session(&self) -> bool {
        self.session.is_some()
    }

    /// How many link events so far changed what the window shows (and so woke it).
    pub fn link_wakes(&self) -> u64 {
        self.link_wakes.load(Ordering::Relaxed)
    }

    /// How many old connections are still closing (on threads of their own).
    pub fn closing(&self) -> usize {
        self.closing.len()
    }

    /// The RMC151's session (tests reach its built-in simulator).
    pub fn rmc(&self) -> Option<&RmcSession> {
        self.rmc.as_ref()
    }

    /// The embedded simulator, when the line is the built-in one.
    pub fn sim(&self) -> Option<&SimHandle> {
        self.session.as_ref().and_then(|s| s.sim.as_ref())
    }

    /// The built-in simulator's front panel, when the line is the built-in one.
    pub fn panel(&self) -> Option<&FrontPanel> {
        self.session.as_ref().and_then(|s| s.panel.as_ref())
    }

    /// What the simulator's front panel did since the last call.
    pub fn take_sim_news(&mut self) -> Vec<String> {
        self.session
            .as_mut()
            .and_then(|s| s.panel.as_mut())
            .map(|p| p.take_news())
            .unwrap_or_default()
    }

    /// STOP to both links now (the window closing), whatever the pendant queued.
    pub fn stop_all(&self) {
        if let Some(s) = &self.session {
            s.link.stop_all();
        }
        if let Some(r) = &self.rmc {
            r.link.stop_all();
        }
    }

    /// Closes both lines as the window does on exit: each link sends its STOPs; waits
    /// for both and for any close already under way.
    pub fn close(&mut self) {
        self.open_when_closed.clear();
        self.close_session();
        self.close_rmc();
        for (_, closing) in self.closing.drain(..) {
            drop(closing.finish());
        }
    }

    /// Closes the X-SEL's line on a thread of its own (its link sends the STOPs owed
    /// first); the window goes on drawing.
    fn close_session(&mut self) {
        if let Some(session) = self.session.take() {
            self.closing
                .push((Device::Xsel, session.close_in_background()));
        }
        self.inbox.forget_xsel();
    }

    /// Closes the RMC151's connection on a thread of its own (its link stops what may
    /// move first).
    fn close_rmc(&mut self) {
        if let Some(rmc) = self.rmc.take() {
            let closing = Closing::start("the RMC151's connection", rmc, None, |rmc| {
                drop(rmc);
                None
            });
            self.closing.push((Device::Rmc, closing));
        }
        self.inbox.forget_rmc();
    }

    /// Opens `device`'s line once its old one has closed (once, however often asked).
    fn open_later(&mut self, device: Device) {
        if !self.open_when_closed.contains(&device) {
            self.open_when_closed.push(device);
        }
    }

    /// Whether `device`'s old connection is still closing.
    fn still_closing(&self, device: Device) -> bool {
        self.closing.iter().any(|(d, _)| *d == device)
    }

    /// Takes in the closes that ended (a problem goes to Messages) and opens the lines
    /// that waited for them; true while any close runs.
    pub fn closes_done(
        &mut self,
        ctx: &egui::Context,
        pendant: &mut Pendant,
        now: Instant,
    ) -> bool {
        let mut i = 0;
        while i < self.closing.len() {
            if self.closing[i].1.is_done() {
                let (_, closing) = self.closing.remove(i);
                if let Some(problem) = closing.finish() {
                    pendant.say(crate::pendant::Level::Warning, problem, now);
                }
            } else {
                i += 1;
            }
        }
        for device in std::mem::take(&mut self.open_when_closed) {
            match device {
                Device::Xsel => self.open_session(ctx, pendant, now),
                Device::Rmc => self.open_rmc(ctx, pendant, now),
            }
        }
        !self.closing.is_empty()
    }

    /// Takes in the links' events, both lines' oldest first, for at most
    /// [`EVENT_BUDGET`]; true when some are left for the next frame (otherwise the
    /// count of events left for later starts again).
    pub fn drain_events(&mut self, pendant: &mut Pendant, now: Instant) -> bool {
        let deadline = now + EVENT_BUDGET;
        let xsel = self.session.as_ref().map(|s| &s.events);
        let rmc = self.rmc.as_ref().map(|r| &r.events);
        while let Some(next) = self.inbox.next(xsel, rmc) {
            match next {
                Next::Xsel(event) => pendant.handle_event(Instant::now(), event),
                Next::Rmc(event) => pendant.handle_axes_event(Instant::now(), event),
            }
            if Instant::now() >= deadline {
                return true;
            }
        }
        self.unread.store(0, Ordering::Relaxed);
        false
    }

    /// Forwards the pendant's requests to the lines, in the model's order: a STOP
    /// already ended what was asked before it (and the link's STOP channel overtakes the
    /// rest), so nothing here reorders.
    pub fn run_requests(&mut self, ctx: &egui::Context, pendant: &mut Pendant, now: Instant) {
        for request in pendant.take_requests() {
            match request {
                Request::Stop => {
                    if let Some(s) = &self.session {
                        s.stop_all();
                    }
                    if let Some(r) = &self.rmc {
                        r.link.stop_all();
                    }
                    for (_, closing) in &self.closing {
                        closing.stop_all();
                    }
                }
                Request::Submit(_)
                | Request::Background(_)
                | Request::Spare(_)
                | Request::RenewJogLease
                | Request::ReadTable(_)
                | Request::ReadRecords(..)
                | Request::CancelTableRead => {
                    if let Some(s) = &self.session {
                        crate::driven::forward(s, request, |kind| pendant.table_records(kind));
                    }
                }
                Request::SimulatorTables(tables) => match self.panel() {
                    Some(panel) => panel.try_tables(tables),
                    None => pendant.note(
                        "no built-in simulator on this line: the draft was not given",
                        now,
                    ),
                },
                Request::Connect => self.open_session(ctx, pendant, now),
                Request::Disconnect => {
                    self.open_when_closed.retain(|d| *d != Device::Xsel);
                    self.close_session();
                }
                Request::Axes(call) => self.axes_call(ctx, pendant, call, now),
            }
        }
    }

    fn axes_call(
        &mut self,
        ctx: &egui::Context,
        pendant: &mut Pendant,
        call: AxisCall,
        now: Instant,
    ) {
        if let AxisCall::Connect = call {
            return self.open_rmc(ctx, pendant, now);
        }
        if let AxisCall::Disconnect = call {
            self.open_when_closed.retain(|d| *d != Device::Rmc);
            return self.close_rmc();
        }
        let Some(rmc) = &self.rmc else {
            return;
        };
        match call {
            // The model records what the link says went out under each id (its Sent
            // events), never what was asked for.
            AxisCall::Send(axis, command) => {
                rmc.link.send(axis, command);
            }
            AxisCall::Hold(axis, jog) => {
                rmc.link.hold(axis, jog);
            }
            AxisCall::Release(axis) => rmc.link.release(axis),
            AxisCall::RenewLease => rmc.link.renew_lease(),
            AxisCall::Connect | AxisCall::Disconnect => {}
        }
    }

    /// Opens the RMC151's connection in the settings (closing the current one).
    fn open_rmc(&mut self, ctx: &egui::Context, pendant: &mut Pendant, now: Instant) {
        self.close_rmc();
        if self.still_closing(Device::Rmc) {
            // The old connection closes first (its STOP); this one opens after it.
            return self.open_later(Device::Rmc);
        }
        let repaint_ctx = ctx.clone();
        let wakes = self.link_wakes.clone();
        let last = std::sync::Mutex::new(RmcWake::new(
            self.live_log_shown.clone(),
            self.unread.clone(),
            crate::rmc::EVENT_BACKLOG,
        ));
        let repaint = Arc::new(move |event: &crate::rmc::RmcEvent| {
            // A poll that reads what is already shown wakes nobody.
            if last.lock().map_or(Wake::Soon, |mut l| l.on_event(event)) == Wake::Soon {
                wakes.fetch_add(1, Ordering::Relaxed);
                repaint_ctx.request_repaint_after(LINK_REPAINT);
            }
        });
        match RmcSession::open(&pendant.settings.rmc, repaint, &self.owner) {
            Ok(session) => self.rmc = Some(session),
            Err(e) => pendant.rmc_connect_failed(e, now),
        }
    }

    fn open_session(&mut self, ctx: &egui::Context, pendant: &mut Pendant, now: Instant) {
        // The old link shuts down first (stopping any motion), then the new one opens:
        // the same port cannot be opened twice.
        self.close_session();
        if self.still_closing(Device::Xsel) {
            return self.open_later(Device::Xsel);
        }
        let settings = pendant.settings.connection.clone();
        let model = match load_model(&settings.robot) {
            Ok(m) => m,
            Err(e) => return pendant.connect_failed(e, now),
        };
        pendant.set_model(model.clone());
        // A link event wakes the window only when it changes what is shown, and then at
        // most every LINK_REPAINT: polls alone bring ~40 events a second, and a repaint
        // each would keep a software renderer busy (see `wake`).
        let repaint_ctx = ctx.clone();
        let filter = std::sync::Mutex::new(WakeFilter::new(
            self.live_log_shown.clone(),
            self.unread.clone(),
            crate::session::EVENT_BACKLOG,
        ));
        let wakes = self.link_wakes.clone();
        let repaint = Arc::new(move |event: &crate::pendant::LinkEvent| {
            let wake = filter.lock().map_or(Wake::Soon, |mut f| f.on_event(event));
            if wake == Wake::Soon {
                wakes.fetch_add(1, Ordering::Relaxed);
                repaint_ctx.request_repaint_after(LINK_REPAINT);
            }
        });
        let polls = crate::pendant::controller::poll_commands();
        match Session::open(&settings, &model, polls, repaint, &self.owner) {
            Ok(session) => self.session = Some(session),
            Err(e) => pendant.connect_failed(e, now),
        }
    }
}
