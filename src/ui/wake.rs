//! When a link event wakes the window: only when it changes what the window shows. A
//! poll that answers what the last one did, traffic while no live frame log is in sight
//! and health figures wait for the next slow wake ([`IDLE_WAKE`]), when they are drawn
//! together; everything else (a changed status, a user's reply, an error, a time-out,
//! the line going up or down) is drawn within [`LINK_REPAINT`].

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use crate::pendant::{LinkEvent, Origin};
use crate::protocol::{Command, Reply};

/// The longest a change waits to be drawn (polls arrive at about 10 Hz; one frame for a
/// burst of them).
pub const LINK_REPAINT: Duration = Duration::from_millis(100);
/// How often a connected, idle window wakes to take in the events that asked for no
/// repaint: health figures are at most this late; the link's 1024-event backlog holds
/// ten times as long. (Statuses are stamped when taken in, so none looks out of date.)
/// A frame of the software renderer at 1280x800 costs about 27 ms of CPU: one every 2 s
/// is about 1.4% of a core.
pub const IDLE_WAKE: Duration = Duration::from_secs(2);

/// Whether an event needs drawing now.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Wake {
    Soon,
    Later,
}

/// Remembers the last answer to each polled command, to tell a change from a repeat.
#[derive(Debug, Default)]
pub struct WakeFilter {
    last_polls: Vec<(Command, Reply)>,
    /// Set by the window while a live frame log is in sight.
    live_log_shown: Arc<AtomicBool>,
}

impl WakeFilter {
    pub fn new(live_log_shown: Arc<AtomicBool>) -> Self {
        Self {
            last_polls: Vec::new(),
            live_log_shown,
        }
    }

    pub fn on_event(&mut self, event: &LinkEvent) -> Wake {
        match event {
            LinkEvent::Reply {
                origin: Origin::Poll,
                command,
                reply,
                ..
            } => self.poll_answered(command, reply),
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
        }
    }

    fn poll_answered(&mut self, command: &Command, reply: &Reply) -> Wake {
        match self.last_polls.iter_mut().find(|(c, _)| c == command) {
            Some((_, last)) if last == reply => Wake::Later,
            Some((_, last)) => {
                *last = reply.clone();
                Wake::Soon
            }
            None => {
                self.last_polls.push((*command, reply.clone()));
                Wake::Soon
            }
        }
    }
}

/// What the window last showed of the RMC, so a poll that reads the same asks for no
/// repaint; Modbus traffic wakes it only while a live frame log is in sight.
#[derive(Debug, Default)]
pub struct RmcWake {
    statuses: Vec<Option<(crate::rmc::AxisStatus, bool)>>,
    controller: Option<crate::rmc::ControllerStatus>,
    live_log_shown: Arc<AtomicBool>,
}

impl RmcWake {
    pub fn new(live_log_shown: Arc<AtomicBool>) -> Self {
        Self {
            live_log_shown,
            ..Self::default()
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
        if changed { Wake::Soon } else { Wake::Later }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pendant::RequestId;
    use crate::protocol::AxisPattern;

    fn answer(origin: Origin, command: Command, reply: Reply) -> LinkEvent {
        LinkEvent::Reply {
            id: RequestId(1),
            origin,
            command,
            reply,
            round_trip: Duration::from_millis(3),
        }
    }

    #[test]
    fn a_poll_that_answers_as_before_waits_and_a_changed_one_wakes() {
        let mut f = WakeFilter::default();
        let status = Command::SystemStatus;
        let axes = Command::AxisStatus {
            axes: AxisPattern::SCARA_1,
        };
        let a = Reply::Ack(status.id());
        let b = Reply::Ack(axes.id());
        assert_eq!(
            f.on_event(&answer(Origin::Poll, status, a.clone())),
            Wake::Soon
        );
        assert_eq!(
            f.on_event(&answer(Origin::Poll, axes, a.clone())),
            Wake::Soon
        );
        assert_eq!(
            f.on_event(&answer(Origin::Poll, status, a.clone())),
            Wake::Later
        );
        assert_eq!(
            f.on_event(&answer(Origin::Poll, axes, a.clone())),
            Wake::Later
        );
        assert_eq!(
            f.on_event(&answer(Origin::Poll, status, b.clone())),
            Wake::Soon
        );
        assert_eq!(
            f.on_event(&answer(Origin::Poll, status, b.clone())),
            Wake::Later
        );
        // What the user asked for is always drawn.
        assert_eq!(f.on_event(&answer(Origin::User, status, b)), Wake::Soon);
    }

    #[test]
    fn traffic_wakes_only_while_a_live_frame_log_is_in_sight() {
        let shown = Arc::new(AtomicBool::new(false));
        let mut f = WakeFilter::new(shown.clone());
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
}
