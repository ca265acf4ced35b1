//! The link's side of the event stream, kept bounded when the reader falls behind.
//!
//! The channel stays one ordered stream. Its length is the backlog: while it holds
//! [`LinkConfig::event_backlog`](super::LinkConfig::event_backlog) events or more, traffic
//! events (frames, garbage) are left out and counted, and a [`LinkEvent::Dropped`] with
//! the count goes out before the next event once the reader has caught up. Everything
//! else (replies, errors, time-outs, table data, line state) always goes out; to keep
//! those bounded too, the engine pauses its own status polling while the reader is
//! behind (see [`EventOut::behind`]) and sends `Health` only when the reader keeps up.

use std::cell::Cell;

use crossbeam_channel::Sender;

use super::event::LinkEvent;
use super::handle::Repaint;

pub(crate) struct EventOut {
    tx: Sender<LinkEvent>,
    repaint: Repaint,
    limit: usize,
    /// Left out since the last `Dropped` event.
    unreported: Cell<u64>,
    /// Left out over the link's life.
    total: Cell<u64>,
}

impl EventOut {
    pub(crate) fn new(tx: Sender<LinkEvent>, repaint: Repaint, limit: usize) -> Self {
        Self {
            tx,
            repaint,
            limit: limit.max(1),
            unreported: Cell::new(0),
            total: Cell::new(0),
        }
    }

    /// Whether the reader is so far behind that traffic is left out.
    pub(crate) fn behind(&self) -> bool {
        self.tx.len() >= self.limit
    }

    /// Traffic events left out so far.
    pub(crate) fn dropped_total(&self) -> u64 {
        self.total.get()
    }

    /// Sends `event`, or leaves it out and counts it if it is traffic and the reader is
    /// behind. A dropped receiver only means nobody listens any more.
    pub(crate) fn send(&self, event: LinkEvent) {
        if self.behind() {
            if event.is_traffic() {
                self.unreported.set(self.unreported.get() + 1);
                self.total.set(self.total.get() + 1);
                return;
            }
        } else {
            self.report_dropped();
        }
        // Told before it is queued: a UI wakes for it a moment later, when it is there.
        (self.repaint)(&event);
        let _ = self.tx.send(event);
    }

    /// Sends the `Dropped` count still unreported, whatever the backlog (at shutdown).
    pub(crate) fn report_dropped(&self) {
        let frames = self.unreported.replace(0);
        if frames > 0 {
            let _ = self.tx.send(LinkEvent::Dropped { frames });
        }
    }
}
