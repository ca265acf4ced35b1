//! What the RMC link core sends next, in order: zeros on a new connection, every STOP
//! owed, the CPU Module ID, ACK reads, the queue, a held jog's next move, the status round.

use std::time::Instant;

use super::axis::Awaiting;
use super::{ACK_WAIT, Purpose, RmcCore, RmcEvent, WriteKind};
use crate::rmc::command::{Command, MoveRelative, ZEROS_REGISTERS};
use crate::rmc::modbus::Request;
use crate::rmc::registers::{CONTROLLER_STATUS, CPU_MODULE_ID, STATUS_REGISTERS};
use crate::robot::RelativeTo;

impl RmcCore {
    /// What goes out next on an open line with nothing in flight.
    pub(super) fn next_purpose(&mut self, now: Instant) -> Option<Purpose> {
        // Zeros first on a new connection (ACK to 0), then every STOP owed.
        if let Some(a) = self.axes.iter().find(|a| !a.zeroed) {
            return Some(Purpose::Zeros(a.id));
        }
        if let Some(a) = self.axes.iter().find(|a| a.stop_owed) {
            let command = Command::Stop {
                decel: self.config.stop_decel,
            };
            return Some(Purpose::Write {
                axis: a.id,
                id: None,
                command,
                kind: WriteKind::Stop,
            });
        }
        if self.closing.is_some() {
            return None;
        }
        if !self.module_read {
            return Some(Purpose::Module);
        }
        if let Some(a) = self
            .axes
            .iter()
            .find(|a| a.read_wanted || a.awaiting.is_some())
        {
            return Some(Purpose::Status(a.id));
        }
        if let Some(&(id, axis, command)) = self.queue.front() {
            let a = self.axes.get(axis.index())?;
            if command.moves() && !a.fresh {
                return Some(Purpose::Status(axis));
            }
            self.queue.pop_front();
            return Some(Purpose::Write {
                axis,
                id: Some(id),
                command,
                kind: WriteKind::User,
            });
        }
        if let Some(a) = self.axes.iter().find(|a| {
            a.chain
                .is_some_and(|c| c.due(a.last.as_ref().filter(|_| a.fresh)))
        }) {
            if !a.fresh {
                return Some(Purpose::Status(a.id));
            }
            let chain = a.chain?;
            let command = Command::MoveRelative(MoveRelative {
                distance: chain.jog.direction * chain.chunk,
                speed: chain.jog.speed,
                accel: chain.jog.accel,
                decel: chain.jog.decel,
                relative_to: RelativeTo::Target,
            });
            return Some(Purpose::Write {
                axis: a.id,
                id: (!chain.started).then_some(chain.id),
                command,
                kind: WriteKind::Chunk,
            });
        }
        self.next_poll(now)
    }

    /// The next read of the status round, when it is due.
    pub(super) fn next_poll(&mut self, now: Instant) -> Option<Purpose> {
        if self.reader_behind || now < self.next_round {
            return None;
        }
        let purpose = match self.axes.get(self.round_at) {
            Some(a) => Purpose::Status(a.id),
            None => Purpose::Controller,
        };
        self.round_at += 1;
        if self.round_at > self.axes.len() {
            self.round_at = 0;
            self.next_round = now + self.round_interval();
        }
        Some(purpose)
    }

    /// The time to the next status round: the fast one while anything moves, is owed or
    /// awaited (or no status is known), the idle one else.
    fn round_interval(&self) -> std::time::Duration {
        let moving = |s: &crate::rmc::AxisStatus| {
            !s.bits.tg_done() || s.target_velocity != 0.0 || s.actual_velocity != 0.0
        };
        let busy = !self.queue.is_empty()
            || self.axes.iter().any(|a| {
                a.chain.is_some()
                    || a.awaiting.is_some()
                    || a.may_move
                    || a.stop_owed
                    || a.last.as_ref().is_none_or(moving)
            });
        if busy {
            self.config.poll_interval
        } else {
            self.config
                .idle_poll_interval
                .max(self.config.poll_interval)
        }
    }

    pub(super) fn request_of(&mut self, purpose: Purpose) -> Request {
        match purpose {
            Purpose::Zeros(axis) => Request::Write {
                address: axis.command_block(),
                words: vec![0; ZEROS_REGISTERS],
            },
            Purpose::Module => Request::Read {
                address: CPU_MODULE_ID,
                count: 2,
            },
            Purpose::Controller => Request::Read {
                address: CONTROLLER_STATUS,
                count: 2,
            },
            Purpose::Status(axis) => Request::Read {
                address: axis.status_block(),
                count: STATUS_REGISTERS,
            },
            Purpose::Write { axis, command, .. } => {
                let req = self.axis(axis).map(|a| !a.req).unwrap_or(true);
                Request::Write {
                    address: axis.command_block(),
                    words: command.block(req),
                }
            }
        }
    }

    /// A write goes out: REQ toggled, its ACK awaited.
    pub(super) fn wrote(&mut self, now: Instant, purpose: Purpose) {
        let Purpose::Write {
            axis,
            id,
            command,
            kind,
        } = purpose
        else {
            return;
        };
        // Its ACK is read within a fast round, however still the axes stood.
        self.next_round = self.next_round.min(now + self.config.poll_interval);
        let Some(a) = self.axis(axis) else {
            return;
        };
        a.req = !a.req;
        let req = a.req;
        a.awaiting = Some(Awaiting {
            id,
            req,
            timed_out: false,
            until: now + ACK_WAIT,
        });
        match kind {
            WriteKind::Stop => a.stop_owed = false,
            WriteKind::Chunk => {
                if let Some(c) = a.chain.as_mut() {
                    c.started = true;
                }
                a.may_move = true;
            }
            WriteKind::User => a.may_move |= command.moves(),
        }
        self.events.push_back(RmcEvent::Sent {
            id,
            axis,
            command,
            req,
            at: now,
        });
    }
}
