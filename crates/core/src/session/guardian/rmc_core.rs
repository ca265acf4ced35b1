//! The guardian's rules for an RMC151 (sans-IO, time passed in): it relays the window's
//! Modbus/TCP requests and the controller's replies, notes which axes were sent motion
//! and the REQ last written to each, and when the window's process closes or falls silent
//! longer than the lease while an axis may move, writes Stop (Closed Loop) (6) to each
//! such axis with REQ toggled (RMC.md sections 4-6: the RMC has no host watchdog). Its
//! own requests are pipelined behind the window's (the RMC answers in order, RMC.md
//! section 1) and carry transaction numbers of their own; their replies are not relayed.

use std::collections::VecDeque;
use std::time::{Duration, Instant};

use super::guard::Guard;
use super::wire::FromGuardian;
use crate::rmc::modbus::{self, FrameBuffer, Header, Request};
use crate::rmc::{AxisId, Command, MAX_AXES};

/// The guardian's transaction numbers: the top of the range (the window's link counts up
/// from 1 and would take hours of polling to reach them; a clash is only a reply dropped).
const OWN_TRANSACTIONS: u16 = 0xFF00;
/// How long the guardian waits for the replies to its Stops before it gives up.
const REPLY_WAIT: Duration = Duration::from_millis(500);

/// What the guardian knows of an RMC and owes it.
#[derive(Debug)]
pub struct RmcGuardianCore {
    unit: u8,
    lease: Duration,
    stop_decel: f32,
    from_window: FrameBuffer,
    from_line: FrameBuffer,
    to_line: VecDeque<Vec<u8>>,
    to_window: VecDeque<FromGuardian>,
    log: VecDeque<String>,
    /// The REQ the window last wrote to each axis.
    req: [bool; MAX_AXES],
    /// Motion was written to the axis and no Stop (6) since.
    may_move: [bool; MAX_AXES],
    /// The guardian's own Stops not yet answered, and when it gives up on them.
    own_out: Vec<(u16, AxisId)>,
    own_deadline: Option<Instant>,
    transaction: u16,
    last_heard: Instant,
    /// This silence already cost a STOP.
    silence_stopped: bool,
    window_closed: bool,
}

impl RmcGuardianCore {
    pub fn new(now: Instant, unit: u8, lease: Duration, stop_decel: f32) -> Self {
        Self {
            unit,
            lease,
            stop_decel,
            from_window: FrameBuffer::default(),
            from_line: FrameBuffer::default(),
            to_line: VecDeque::new(),
            to_window: VecDeque::new(),
            log: VecDeque::new(),
            req: [false; MAX_AXES],
            may_move: [false; MAX_AXES],
            own_out: Vec::new(),
            own_deadline: None,
            transaction: OWN_TRANSACTIONS,
            last_heard: now,
            silence_stopped: false,
            window_closed: false,
        }
    }

    /// Whether an axis may be moving on the window's commands.
    pub fn motion_may_run(&self) -> bool {
        self.may_move.iter().any(|m| *m)
    }

    /// Notes what a whole request of the window does to an axis.
    fn note_request(&mut self, frame: &[u8]) {
        let Ok((_, Request::Write { address, words })) = modbus::decode_request(frame) else {
            return;
        };
        let Some(axis) = AxisId::first(MAX_AXES).find(|a| a.command_block() == address) else {
            return;
        };
        let Ok((command, req)) = Command::from_block(&words) else {
            return;
        };
        let i = axis.index();
        // Zeros (a No-op without REQ) reset ACK to 0: the window's REQ is 0 again.
        self.req[i] = req;
        if command.moves() {
            self.may_move[i] = true;
        } else if matches!(command, Command::Stop { .. } | Command::Enable(false)) {
            self.may_move[i] = false;
        }
    }

    /// Stop (6) to every axis that may move, REQ toggled, and why.
    fn stop(&mut self, now: Instant, why: &str) {
        let axes: Vec<AxisId> = AxisId::first(MAX_AXES)
            .filter(|a| self.may_move[a.index()])
            .collect();
        if axes.is_empty() {
            return;
        }
        let mut names = Vec::new();
        for axis in axes {
            let i = axis.index();
            self.req[i] = !self.req[i];
            self.may_move[i] = false;
            self.transaction = self.transaction.wrapping_add(1).max(OWN_TRANSACTIONS);
            let header = Header {
                transaction: self.transaction,
                unit: self.unit,
            };
            let block = Command::Stop {
                decel: self.stop_decel,
            }
            .block(self.req[i]);
            self.to_line.push_back(modbus::encode_request(
                header,
                &Request::Write {
                    address: axis.command_block(),
                    words: block,
                },
            ));
            self.own_out.push((self.transaction, axis));
            names.push(axis.to_string());
        }
        self.own_deadline = Some(now + REPLY_WAIT);
        let text = format!("Stop (6) to {}: {why}", names.join(", "));
        self.log.push_back(text.clone());
        self.to_window.push_back(FromGuardian::Stopped(text));
    }
}

impl Guard for RmcGuardianCore {
    fn handle_heartbeat(&mut self, now: Instant) {
        self.last_heard = now;
        self.silence_stopped = false;
    }

    fn handle_window_bytes(&mut self, now: Instant, bytes: &[u8]) {
        self.handle_heartbeat(now);
        self.from_window.push(bytes);
        while let Some(frame) = self.from_window.next_frame() {
            match frame {
                Ok(frame) => {
                    self.note_request(&frame);
                    self.to_line.push_back(frame);
                }
                // Not Modbus: relayed as it is (the controller closes the connection).
                Err(_) => self.to_line.push_back(bytes.to_vec()),
            }
        }
    }

    fn handle_window_closed(&mut self, now: Instant) {
        if !self.window_closed {
            self.window_closed = true;
            self.stop(now, "the window's process ended");
        }
    }

    fn handle_line_bytes(&mut self, bytes: &[u8]) {
        self.from_line.push(bytes);
        while let Some(frame) = self.from_line.next_frame() {
            let Ok(frame) = frame else {
                self.to_window
                    .push_back(FromGuardian::Bytes(bytes.to_vec()));
                continue;
            };
            let transaction = u16::from_be_bytes([frame[0], frame[1]]);
            if let Some(at) = self.own_out.iter().position(|(t, _)| *t == transaction) {
                let (_, axis) = self.own_out.remove(at);
                // Byte 7 is the function code; its top bit marks an exception reply.
                let how = match frame.get(7) {
                    Some(f) if f & 0x80 != 0 => "refused (a Modbus exception)",
                    _ => "answered",
                };
                self.log.push_back(format!(
                    "the RMC {how} the guardian's Stop (6) to {axis} (Modbus transaction {transaction})"
                ));
            } else {
                self.to_window.push_back(FromGuardian::Bytes(frame));
            }
        }
    }

    fn handle_timeout(&mut self, now: Instant) {
        let silent = now.saturating_duration_since(self.last_heard) > self.lease;
        if !self.window_closed && silent && !self.silence_stopped && self.motion_may_run() {
            self.silence_stopped = true;
            self.stop(now, "the window fell silent");
        }
        if self.own_deadline.is_some_and(|t| now >= t) && !self.own_out.is_empty() {
            self.log
                .push_back("no reply to the guardian's Stop in time".to_string());
            self.own_out.clear();
        }
    }

    fn poll_transmit(&mut self, _now: Instant) -> Option<Vec<u8>> {
        self.to_line.pop_front()
    }

    fn poll_to_window(&mut self) -> Option<FromGuardian> {
        self.to_window.pop_front()
    }

    fn poll_log(&mut self) -> Option<String> {
        self.log.pop_front()
    }

    fn poll_timeout(&self) -> Option<Instant> {
        let silence = (!self.window_closed && self.motion_may_run() && !self.silence_stopped)
            .then(|| self.last_heard + self.lease);
        let replies = self.own_deadline.filter(|_| !self.own_out.is_empty());
        silence.into_iter().chain(replies).min()
    }

    fn is_done(&self) -> bool {
        self.window_closed && self.to_line.is_empty() && self.own_out.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rmc::MoveRelative;
    use crate::rmc::modbus::{Response, decode_request, encode_request, encode_response};
    use crate::robot::RelativeTo;

    fn axis(i: usize) -> AxisId {
        AxisId::new(i).unwrap()
    }

    fn write(transaction: u16, axis: AxisId, command: Command, req: bool) -> Vec<u8> {
        encode_request(
            Header {
                transaction,
                unit: 1,
            },
            &Request::Write {
                address: axis.command_block(),
                words: command.block(req),
            },
        )
    }

    fn step() -> Command {
        Command::MoveRelative(MoveRelative {
            distance: 100.0,
            speed: 10.0,
            accel: 100.0,
            decel: 100.0,
            relative_to: RelativeTo::Command,
        })
    }

    fn drain(core: &mut RmcGuardianCore, now: Instant) -> Vec<(AxisId, Command, bool, u16)> {
        let mut out = Vec::new();
        while let Some(bytes) = core.poll_transmit(now) {
            if let Ok((h, Request::Write { address, words })) = decode_request(&bytes) {
                let a = AxisId::first(MAX_AXES)
                    .find(|a| a.command_block() == address)
                    .unwrap();
                let (c, req) = Command::from_block(&words).unwrap();
                out.push((a, c, req, h.transaction));
            }
        }
        out
    }

    #[test]
    fn a_window_that_ends_after_a_move_gets_stop_6_with_req_toggled() {
        let now = Instant::now();
        let lease = Duration::from_millis(250);
        let mut g = RmcGuardianCore::new(now, 1, lease, 1000.0);
        g.handle_window_bytes(now, &write(1, axis(0), Command::NoOp, false));
        g.handle_window_bytes(now, &write(2, axis(1), Command::Enable(true), true));
        g.handle_window_bytes(now, &write(3, axis(1), step(), false));
        let relayed = drain(&mut g, now);
        assert_eq!(relayed.len(), 3, "the window's requests go through");
        g.handle_window_closed(now);
        let own = drain(&mut g, now);
        assert_eq!(own.len(), 1, "only the axis sent motion: {own:?}");
        let (a, c, req, t) = own[0];
        assert_eq!(
            (a, c, req),
            (axis(1), Command::Stop { decel: 1000.0 }, true)
        );
        assert!(matches!(g.poll_to_window(), Some(FromGuardian::Stopped(_))));
        assert!(!g.is_done(), "it waits for the reply");
        // The reply to its own Stop is not relayed; then it is done.
        let reply = encode_response(
            Header {
                transaction: t,
                unit: 1,
            },
            &Response::Written {
                address: axis(1).command_block(),
                count: 12,
            },
        );
        g.handle_line_bytes(&reply);
        assert!(g.poll_to_window().is_none());
        assert!(g.is_done());
    }

    #[test]
    fn a_silent_window_costs_one_stop_and_replies_still_reach_it() {
        let now = Instant::now();
        let lease = Duration::from_millis(250);
        let mut g = RmcGuardianCore::new(now, 1, lease, 500.0);
        g.handle_window_bytes(now, &write(9, axis(0), step(), true));
        drain(&mut g, now);
        let answer = encode_response(
            Header {
                transaction: 9,
                unit: 1,
            },
            &Response::Written {
                address: axis(0).command_block(),
                count: 12,
            },
        );
        g.handle_line_bytes(&answer);
        assert_eq!(g.poll_to_window(), Some(FromGuardian::Bytes(answer)));
        assert_eq!(g.poll_timeout(), Some(now + lease));
        let later = now + lease + Duration::from_millis(1);
        g.handle_timeout(later);
        let own = drain(&mut g, later);
        assert_eq!(own.len(), 1);
        assert_eq!(
            (own[0].1, own[0].2),
            (Command::Stop { decel: 500.0 }, false)
        );
        g.handle_timeout(later + lease * 4);
        assert!(drain(&mut g, later).is_empty(), "one STOP per silence");
        // No motion: a silence costs nothing.
        let mut g = RmcGuardianCore::new(now, 1, lease, 500.0);
        g.handle_window_bytes(now, &write(1, axis(0), Command::Enable(true), true));
        drain(&mut g, now);
        g.handle_timeout(later);
        assert!(drain(&mut g, later).is_empty());
        g.handle_window_closed(later);
        assert!(drain(&mut g, later).is_empty());
        assert!(g.is_done());
    }
}
