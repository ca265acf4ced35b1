//! Both links' events taken in oldest first: however long the window slept, the frame
//! log's rows of the two lines interleave as they happened, and neither link's statuses
//! wait behind the other's backlog.

use std::time::Instant;

use crossbeam_channel::Receiver;

use crate::pendant::LinkEvent;
use crate::rmc::RmcEvent;

/// The next event of one link or the other.
#[derive(Debug)]
pub enum Next {
    Xsel(LinkEvent),
    Rmc(RmcEvent),
}

/// The event of each link looked at and not yet taken.
#[derive(Debug, Default)]
pub struct Inbox {
    xsel: Option<LinkEvent>,
    rmc: Option<RmcEvent>,
}

impl Inbox {
    /// Forgets the X-SEL event looked at: its session is gone.
    pub fn forget_xsel(&mut self) {
        self.xsel = None;
    }

    /// Forgets the RMC event looked at: its session is gone.
    pub fn forget_rmc(&mut self) {
        self.rmc = None;
    }

    /// The older of the two links' next events. An event without a time of its own (a
    /// reply, a state change) goes as soon as it is next on its line: it follows the
    /// timed one before it.
    pub fn next(
        &mut self,
        xsel: Option<&Receiver<LinkEvent>>,
        rmc: Option<&Receiver<RmcEvent>>,
    ) -> Option<Next> {
        if self.xsel.is_none() {
            self.xsel = xsel.and_then(|r| r.try_recv().ok());
        }
        if self.rmc.is_none() {
            self.rmc = rmc.and_then(|r| r.try_recv().ok());
        }
        let xsel_first = match (&self.xsel, &self.rmc) {
            (None, None) => return None,
            (Some(_), None) => true,
            (None, Some(_)) => false,
            (Some(x), Some(r)) => older_or_untimed(x.at(), r.at()),
        };
        if xsel_first {
            self.xsel.take().map(Next::Xsel)
        } else {
            self.rmc.take().map(Next::Rmc)
        }
    }
}

/// Whether the event at `a` goes before the one at `b`.
fn older_or_untimed(a: Option<Instant>, b: Option<Instant>) -> bool {
    match (a, b) {
        (None, _) => true,
        (Some(_), None) => false,
        (Some(a), Some(b)) => a <= b,
    }
}

#[cfg(test)]
mod tests {
    use std::time::Duration;

    use super::*;
    use crate::pendant::{Origin, RequestId};
    use crate::protocol::{Command, Reply};

    #[test]
    fn events_of_both_links_come_oldest_first_and_an_untimed_one_follows_its_line() {
        let t0 = Instant::now();
        let ms = |n: u64| t0 + Duration::from_millis(n);
        let (xsel_tx, xsel) = crossbeam_channel::unbounded();
        let (rmc_tx, rmc) = crossbeam_channel::unbounded();
        let sent = |n| LinkEvent::FrameSent {
            id: RequestId(n),
            bytes: b"!99215@@\r\n".to_vec(),
            at: ms(n),
        };
        for event in [
            sent(0),
            sent(20),
            LinkEvent::Reply {
                id: RequestId(20),
                origin: Origin::Poll,
                command: Command::SystemStatus,
                reply: Reply::Ack(Command::SystemStatus.id()),
                round_trip: Duration::from_millis(1),
            },
            sent(40),
        ] {
            xsel_tx.send(event).unwrap();
        }
        for n in [10, 30, 50] {
            rmc_tx
                .send(RmcEvent::FrameSent {
                    bytes: vec![0; 12],
                    at: ms(n),
                })
                .unwrap();
        }
        let mut inbox = Inbox::default();
        let mut order = Vec::new();
        while let Some(next) = inbox.next(Some(&xsel), Some(&rmc)) {
            order.push(match next {
                Next::Xsel(LinkEvent::Reply { .. }) => "reply".to_string(),
                Next::Xsel(e) => format!("x{}", ms_of(e.at(), t0)),
                Next::Rmc(e) => format!("r{}", ms_of(e.at(), t0)),
            });
        }
        assert_eq!(order, ["x0", "r10", "x20", "reply", "r30", "x40", "r50"]);
        // One link alone, or none.
        xsel_tx.send(sent(60)).unwrap();
        assert!(matches!(inbox.next(Some(&xsel), None), Some(Next::Xsel(_))));
        assert!(inbox.next(Some(&xsel), Some(&rmc)).is_none());
        // An event looked at is forgotten with its session.
        rmc_tx.send(RmcEvent::Closed).unwrap();
        xsel_tx.send(sent(70)).unwrap();
        assert!(matches!(
            inbox.next(Some(&xsel), Some(&rmc)),
            Some(Next::Rmc(_))
        ));
        inbox.forget_xsel();
        assert!(inbox.next(Some(&xsel), Some(&rmc)).is_none());
    }

    fn ms_of(at: Option<Instant>, t0: Instant) -> u128 {
        at.map_or(0, |t| t.duration_since(t0).as_millis())
    }
}
