//! The driver's side of the event stream, kept bounded when the reader falls behind.
//!
//! The channel stays one ordered stream. Its length is the backlog: while it holds
//! [`LinkConfig::event_backlog`](super::LinkConfig::event_backlog) events or more, traffic
//! events (frames, garbage) are left out and counted, and the core's "dropped" event with
//! the count goes out before the next event once the reader has caught up. Everything
//! else (replies, errors, time-outs, table data, line state) always goes out; to keep
//! those bounded too, the core is told the reader is behind (and the Format B core pauses
//! its own status polling, and sends health only when the reader keeps up).

use crossbeam_channel::Sender;

use super::core::CoreEvent;
use super::driver::Notify;

pub(crate) struct EventOut<E> {
    tx: Sender<E>,
    repaint: Notify<E>,
    limit: usize,
    /// Left out since the last "dropped" event.
    unreported: u64,
    /// Left out over the link's life.
    total: u64,
}

impl<E: CoreEvent> EventOut<E> {
    pub(crate) fn new(tx: Sender<E>, repaint: Notify<E>, limit: usize) -> Self {
        Self {
            tx,
            repaint,
            limit: limit.max(1),
            unreported: 0,
            total: 0,
        }
    }

    /// Whether the reader is so far behind that traffic is left out.
    pub(crate) fn behind(&self) -> bool {
        self.tx.len() >= self.limit
    }

    /// Traffic events left out so far.
    pub(crate) fn dropped_total(&self) -> u64 {
        self.total
    }

    /// Sends `event`, or leaves it out and counts it if it is traffic and the reader is
    /// behind. A dropped receiver only means nobody listens any more.
    pub(crate) fn send(&mut self, event: E) {
        if self.behind() {
            if event.is_traffic() {
                self.unreported += 1;
                self.total += 1;
                return;
            }
        } else {
            self.report_dropped();
        }
        // Told before it is queued: a UI wakes for it a moment later, when it is there.
        (self.repaint)(&event);
        let _ = self.tx.send(event);
    }

    /// Sends the count still unreported, whatever the backlog (at the end).
    pub(crate) fn report_dropped(&mut self) {
        let frames = std::mem::take(&mut self.unreported);
        if frames > 0
            && let Some(event) = E::dropped(frames)
        {
            let _ = self.tx.send(event);
        }
    }
}
