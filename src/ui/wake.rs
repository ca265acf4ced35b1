//! When a link event wakes the window: only when it changes what the window shows. A
//! poll that answers what the last one did, traffic while no live frame log is in sight
//! and health figures wait until something else wakes the window, until half a link's
//! backlog is unread, or at the latest [`IDLE_WAKE`], and are then taken in together;
//! everything else (a changed status, a user's reply, an error, a time-out, the line
//! going up or down) is drawn within [`LINK_REPAINT`].

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::time::Duration;

use crate::pendant::{LinkEvent, Origin};
use crate::session::PollAnswers;

/// The longest a change waits to be drawn (polls arrive at about 10 Hz; one frame for a
/// burst of them).
pub const LINK_REPAINT: Duration = Duration::from_millis(100);
/// How often a connected window with nothing to draw wakes all the same, to show the
/// health figures' counts (a fault among them wakes it at once: a time-out or an error
/// reply is an event of its own; any other frame, a moved mouse say, shows them too).
/// Taking in half a link's backlog (see [`Unread`]) usually comes first: about every
/// 25 s while both links poll a standing machine. A frame of the software renderer at
/// 1280x800 after such a pause costs 60-150 ms of CPU on the development machine
/// (`benches/window_idle.sh`), which is why the window paints this seldom.
pub const IDLE_WAKE: Duration = Duration::from_secs(30);

/// Whether an event needs drawing now.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Wake {
    Soon,
    Later,
}

/// Counts the events left for later since the window last took every event in (shared
/// by both links' filters; the window sets it back to 0): once half a link's backlog
/// waits, the window wakes to take them in, so a window with nothing to draw never falls
/// behind its links (which would leave traffic out of the frame log and pause the polls).
#[derive(Debug)]
struct Unread {
    count: Arc<AtomicUsize>,
    limit: usize,
}

impl Unread {
    fn new(count: Arc<AtomicUsize>, backlog: usize) -> Self {
        Self {
            count,
            limit: (backlog / 2).max(1),
        }
    }

    /// `wake`, or `Soon` when this event fills half the backlog.
    fn pass(&self, wake: Wake) -> Wake {
        if wake == Wake::Later && self.count.fetch_add(1, Ordering::Relaxed) + 1 < self.limit {
            return Wake::Later;
        }
        Wake::Soon
    }
}

/// Decides for the X-SEL link's events: remembers the last answer to each polled
/// command, to tell a change from a repeat.
#[derive(Debug)]
pub struct WakeFilter {
    polls: PollAnswers,
    unread: Unread,
    /// Set by the window while a live frame log is in sight.
    live_log_shown: Arc<AtomicBool>,
}

impl WakeFilter {
    /// A filter for a link that holds `backlog` unread events; `unread` counts the
    /// events left for later (see [`Unread`]).
    pub fn new(live_log_shown: Arc<AtomicBool>, unread: Arc<AtomicUsize>, backlog: usize) -> Self {
        Self {
            polls: PollAnswers::default(),
            unread: Unread::new(unread, backlog),
            live_log_shown,
        }
    }

    pub fn on_event(&mut self, event: &LinkEvent) -> Wake {
        let wake = match event {
            LinkEvent::Reply {
                origin: Origin::Poll,
                command,
                reply,
                ..
            } => {
                if self.polls.changed(command, reply) {
                    Wake::Soon
                } else {
                    Wake::Later
                }
            }
            LinkEvent::FrameSent { .. }
            | LinkEvent::FrameReceived { .. }
            | LinkEvent::Garbage { .. }
            | LinkEvent::Dropped { .. } => {
                if self.live_log_shown.load(Ordering::Relaxed) {
                    Wake::Soon
                } else {
                    Wake::Later
                }
            }
            LinkEvent::Health(_) => Wake::Later,
            _ => Wake::Soon,
        };
        self.unread.pass(wake)
    }
}

/// What the window last showed of the RMC, so a poll that reads the same asks for no
/// repaint; Modbus traffic wakes it only while a live frame log is in sight.
#[derive(Debug)]
pub struct RmcWake {
    statuses: Vec<Option<(crate::rmc::AxisStatus, bool)>>,
    controller: Option<crate::rmc::ControllerStatus>,
    unread: Unread,
    live_log_shown: Arc<AtomicBool>,
}

impl RmcWake {
    /// A filter for a link that holds `backlog` unread events; `unread` counts the
    /// events left for later (see [`Unread`]).
    pub fn new(live_log_shown: Arc<AtomicBool>, unread: Arc<AtomicUsize>, backlog: usize) -> Self {
        Self {
            statuses: Vec::new(),
            controller: None,
            unread: Unread::new(unread, backlog),
            live_log_shown,
        }
    }

    pub fn on_event(&mut self, event: &crate::rmc::RmcEvent) -> Wake {
        use crate::rmc::RmcEvent;
        let changed = match event {
            RmcEvent::Status {
                axis,
                status,
                trusted,
                ..
            } => {
                let i = axis.index();
                if self.statuses.len() <= i {
                    self.statuses.resize(i + 1, None);
                }
                let new = Some((*status, *trusted));
                std::mem::replace(&mut self.statuses[i], new) != new
            }
            RmcEvent::Controller { status, .. } => {
                self.controller.replace(*status) != Some(*status)
            }
            RmcEvent::FrameSent { .. }
            | RmcEvent::FrameReceived { .. }
            | RmcEvent::Garbage { .. }
            | RmcEvent::Dropped(_) => self.live_log_shown.load(Ordering::Relaxed),
            RmcEvent::Ignored { .. } => false,
            _ => true,
        };
        self.unread
            .pass(if changed { Wake::Soon } else { Wake::Later })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pendant::RequestId;
    use crate::protocol::{AxisPattern, Command, Reply};

    fn answer(origin: Origin, command: &Command, reply: Reply) -> LinkEvent {
        LinkEvent::Reply {
            id: RequestId(1),
            origin,
            command: command.clone(),
            reply,
            round_trip: Duration::from_millis(3),
        }
    }

    #[test]
    fn a_poll_that_answers_as_before_waits_and_a_changed_one_wakes() {
        let mut f = WakeFilter::new(Arc::default(), Arc::default(), 1024);
        let status = Command::SystemStatus;
        let axes = Command::AxisStatus {
            axes: AxisPattern::SCARA_1,
        };
        let a = Reply::Ack(status.id());
        let b = Reply::Ack(axes.id());
        assert_eq!(
            f.on_event(&answer(Origin::Poll, &status, a.clone())),
            Wake::Soon
        );
        assert_eq!(
            f.on_event(&answer(Origin::Poll, &axes, a.clone())),
            Wake::Soon
        );
        assert_eq!(
            f.on_event(&answer(Origin::Poll, &status, a.clone())),
            Wake::Later
        );
        assert_eq!(
            f.on_event(&answer(Origin::Poll, &axes, a.clone())),
            Wake::Later
        );
        assert_eq!(
            f.on_event(&answer(Origin::Poll, &status, b.clone())),
            Wake::Soon
        );
        assert_eq!(
            f.on_event(&answer(Origin::Poll, &status, b.clone())),
            Wake::Later
        );
        // What the user asked for is always drawn.
        assert_eq!(f.on_event(&answer(Origin::User, &status, b)), Wake::Soon);
    }

    #[test]
    fn traffic_wakes_only_while_a_live_frame_log_is_in_sight() {
        let shown = Arc::new(AtomicBool::new(false));
        let mut f = WakeFilter::new(shown.clone(), Arc::default(), 1024);
        let sent = LinkEvent::FrameSent {
            id: RequestId(2),
            bytes: b"!99215@@\r\n".to_vec(),
            at: std::time::Instant::now(),
        };
        assert_eq!(f.on_event(&sent), Wake::Later);
        shown.store(true, Ordering::Relaxed);
        assert_eq!(f.on_event(&sent), Wake::Soon);
        let down = LinkEvent::Disconnected {
            reason: crate::pendant::LineDownReason::Closed,
        };
        assert_eq!(f.on_event(&down), Wake::Soon);
    }

    #[test]
    fn events_left_for_later_wake_the_window_once_half_a_backlog_waits() {
        use Wake::{Later, Soon};
        let unread = Arc::new(AtomicUsize::new(0));
        let mut f = WakeFilter::new(Arc::default(), unread.clone(), 8);
        let sent = LinkEvent::FrameSent {
            id: RequestId(2),
            bytes: b"!99215@@\r\n".to_vec(),
            at: std::time::Instant::now(),
        };
        let wakes: Vec<Wake> = (0..5).map(|_| f.on_event(&sent)).collect();
        assert_eq!(wakes, [Later, Later, Later, Soon, Soon]);
        // The window took everything in: the count starts again.
        unread.store(0, Ordering::Relaxed);
        let wakes: Vec<Wake> = (0..4).map(|_| f.on_event(&sent)).collect();
        assert_eq!(wakes, [Later, Later, Later, Soon]);
        // The RMC's filter counts into the same count, against its own backlog.
        unread.store(0, Ordering::Relaxed);
        let mut r = RmcWake::new(Arc::default(), unread.clone(), 4);
        let ignored = crate::rmc::RmcEvent::Ignored { why: String::new() };
        assert_eq!(f.on_event(&sent), Later);
        assert_eq!(r.on_event(&ignored), Soon, "two events wait: half of 4");
    }
}
