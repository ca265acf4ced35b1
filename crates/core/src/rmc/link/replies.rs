//! What the RMC answered, taken in by the link core: zeros done, the module and the
//! controller's status, an axis's status (and whether its ACK now equals REQ),
//! exceptions; and whether the reply was a good one (the back-off's measure).

use std::time::Instant;

use super::{InFlight, Purpose, RmcCore, RmcEvent, WriteKind};
use crate::rmc::modbus::Response;
use crate::rmc::registers::{AxisId, STATUS_REGISTERS};
use crate::rmc::status::{AxisStatus, ControllerStatus};
use crate::rmc::words::dword_at;

impl RmcCore {
    pub(super) fn complete(&mut self, now: Instant, flight: InFlight, response: Response) {
        self.timeouts_in_row = 0;
        let id = match flight.purpose {
            Purpose::Write { id, .. } => id,
            _ => None,
        };
        // A read answered with another number of registers than it asked for is no
        // answer (a short module read would read as CPU Module ID 0).
        let asked = match flight.purpose {
            Purpose::Module | Purpose::Controller => Some(2),
            Purpose::Status(_) => Some(STATUS_REGISTERS as usize),
            _ => None,
        };
        if let (Some(asked), Response::Registers { words, .. }) = (asked, &response)
            && words.len() != asked
        {
            let what = format!("{} registers where {asked} were asked for", words.len());
            self.events.push_back(RmcEvent::Ignored {
                why: format!("a reply of {what}"),
            });
            return self.bad_reply(now, &what);
        }
        match (flight.purpose, response) {
            (purpose, Response::Exception { function, code }) => {
                self.bad_reply(
                    now,
                    &format!("Modbus exception {:02} ({})", code.0, code.name()),
                );
                if let Purpose::Write { axis, kind, .. } = purpose
                    && let Some(a) = self.axis(axis)
                {
                    // Refused: not run, so REQ is what ACK still is.
                    a.req = !a.req;
                    a.awaiting = None;
                    if kind == WriteKind::Chunk {
                        a.chain = None;
                    }
                }
                if let Purpose::Zeros(axis) = purpose
                    && let Some(a) = self.axis(axis)
                {
                    a.zeroed = true;
                }
                if purpose == Purpose::Module {
                    self.module_read = true;
                }
                self.events
                    .push_back(RmcEvent::Exception { id, function, code });
            }
            (Purpose::Zeros(axis), Response::Written { .. }) => {
                self.good_reply(now);
                if let Some(a) = self.axis(axis) {
                    a.zeroed = true;
                    a.req = false;
                    a.ack = Some(false);
                }
            }
            (Purpose::Module, Response::Registers { words, .. }) => {
                self.good_reply(now);
                self.module_read = true;
                let cpu_id = dword_at(&words, 0).unwrap_or(0);
                self.events.push_back(RmcEvent::Module { cpu_id });
            }
            (Purpose::Controller, Response::Registers { words, .. }) => {
                self.good_reply(now);
                let status = ControllerStatus(dword_at(&words, 0).unwrap_or(0));
                self.events
                    .push_back(RmcEvent::Controller { status, at: now });
            }
            (Purpose::Status(axis), Response::Registers { words, .. }) => {
                match AxisStatus::decode(&words) {
                    Some(status) => {
                        self.good_reply(now);
                        self.on_status(now, axis, status)
                    }
                    None => {
                        self.events.push_back(RmcEvent::Ignored {
                            why: format!(
                                "{axis}'s status came back with {} registers",
                                words.len()
                            ),
                        });
                        self.bad_reply(now, "a status that does not decode");
                    }
                }
            }
            (Purpose::Write { .. }, Response::Written { .. }) => self.good_reply(now),
            (_, other) => {
                self.events.push_back(RmcEvent::Ignored {
                    why: format!("a reply that does not answer its request: {other:?}"),
                });
                self.bad_reply(now, "a reply that does not answer its request");
            }
        }
    }

    pub(super) fn on_status(&mut self, now: Instant, axis: AxisId, status: AxisStatus) {
        let Some(a) = self.axes.get_mut(axis.index()) else {
            return;
        };
        let ack = status.bits.ack();
        a.fresh = true;
        a.read_wanted = false;
        a.ack = Some(ack);
        let mut trusted = true;
        if let Some(w) = a.awaiting {
            if ack == w.req {
                a.awaiting = None;
                self.events.push_back(RmcEvent::Acknowledged {
                    id: w.id,
                    axis,
                    at: now,
                });
            } else if w.timed_out || now >= w.until {
                // Requests are handled in order (RMC.md section 1): a read after the
                // write that still shows the old ACK means the write never arrived. It
                // is not sent again.
                a.req = ack;
                a.awaiting = None;
                // A jog whose move may not have arrived is not carried on: it stops.
                if a.chain.take().is_some() {
                    a.stop_owed = true;
                }
                self.events.push_back(RmcEvent::Unconfirmed {
                    id: w.id,
                    axis,
                    answered: !w.timed_out,
                });
            } else {
                trusted = false;
            }
        }
        if trusted && (status.bits.halted() || status.errors.any()) && a.chain.take().is_some() {
            // A halted axis (a travel limit, a fault) is not pushed on by more moves.
            self.events.push_back(RmcEvent::JogEnded {
                axis,
                why: format!("{axis} halted: {}", status.errors.names().join(", ")),
            });
        }
        if trusted {
            let still = status.bits.tg_done() && status.target_velocity == 0.0;
            if still && a.chain.is_none() {
                a.may_move = false;
            }
            a.last = Some(status);
        }
        self.events.push_back(RmcEvent::Status {
            axis,
            status,
            trusted,
            at: now,
        });
    }
}
