//! The face a protocol core shows the link driver (DESIGN.md "The link", quinn-proto's
//! shape): input is handed in with the time, what to do on the line is polled out. A core
//! touches no port, clock or thread, so every rule it keeps is tested on a virtual clock.

use std::time::Instant;

use super::reason::{IoFailure, LineDownReason};
use crate::line::LineSettings;

/// What the driver is asked to do on the line.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Transmit {
    /// Open the line with these settings (a TCP bridge or the simulator's pipe takes them
    /// as they come). The driver answers with [`LineChange::Opened`] or
    /// [`LineChange::OpenFailed`] before it asks for anything else.
    Open(LineSettings),
    /// Write these bytes. Whatever input was waiting before this was polled has been
    /// handed in already (see [`LinkCore::awaits_bytes`]), so it is never taken for the
    /// answer to these bytes.
    Write(Vec<u8>),
    /// Close the line; the core counts it as closed from now on.
    Close,
}

/// What happened to the line, as the driver saw it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum LineChange {
    /// The line is open; `name` is how it describes itself.
    Opened { name: String },
    /// It could not be opened.
    OpenFailed(IoFailure),
    /// It is gone (end of file, a failed read or write); the driver has dropped it.
    Lost(LineDownReason),
    /// A guardian process that owns the line sent 238H of its own, and why.
    GuardianStopped(String),
}

/// What the driver hands a core through [`LinkCore::handle_request`]: the protocol's own
/// requests from the application, and the few things every driver knows.
#[derive(Clone, Debug, PartialEq)]
pub enum Input<R> {
    /// A request from the application (submit, STOP, table read...).
    App(R),
    /// The jog lease was last renewed at this instant (the driver reads the lease clock).
    LeaseRenewed(Instant),
    /// Whether the event reader is far behind, and how many traffic events were left out
    /// over the link's life.
    Backlog { behind: bool, dropped: u64 },
    /// Finish what is owed (every STOP), close the line, and end.
    Close,
}

/// Events a driver forwards: traffic may be left out while the reader is behind.
pub trait CoreEvent: Sized {
    /// Whether this event may be left out (and counted) while the reader is behind.
    fn is_traffic(&self) -> bool;
    /// The event that says `frames` traffic events were left out, if the core has one.
    fn dropped(frames: u64) -> Option<Self>;
}

/// A protocol as a state machine. The driver calls the `handle_*` methods as things
/// happen, then drains `poll_transmit` and `poll_event`, and sleeps until
/// `poll_timeout` or the next input.
pub trait LinkCore {
    /// The application's requests.
    type Request;
    /// What the core reports.
    type Event: CoreEvent;

    fn handle_request(&mut self, now: Instant, input: Input<Self::Request>);
    fn handle_line(&mut self, now: Instant, change: LineChange);
    /// Bytes read from the line at `now`.
    fn handle_bytes(&mut self, now: Instant, bytes: &[u8]);
    /// Called once `now` has reached [`LinkCore::poll_timeout`].
    fn handle_timeout(&mut self, now: Instant);
    /// The next thing to do on the line, if any.
    fn poll_transmit(&mut self, now: Instant) -> Option<Transmit>;
    fn poll_event(&mut self) -> Option<Self::Event>;
    /// When [`LinkCore::handle_timeout`] is next due.
    fn poll_timeout(&self) -> Option<Instant>;
    /// Whether an answer is awaited: the driver then reads the line at once. Otherwise it
    /// waits on its channels, looks at the line now and then, and hands in what waits on
    /// the line before each [`LinkCore::poll_transmit`]; bytes that arrive while no answer
    /// is awaited are stale.
    fn awaits_bytes(&self) -> bool;
    /// The core has finished; the driver ends.
    fn is_closed(&self) -> bool;
}
