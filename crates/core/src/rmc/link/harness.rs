//! The RMC link core against the simulated RMC151 in one thread on a virtual clock: a
//! stand-in for the driver that can lose replies, drop writes, cut the line and answer
//! badly.

use std::collections::VecDeque;
use std::time::{Duration, Instant};

use super::{RmcCore, RmcEvent, RmcLinkConfig, RmcRequest};
use crate::link::RequestId;
use crate::link::core::{Input, LineChange, LinkCore, Transmit};
use crate::link::reason::LineDownReason;
use crate::rmc::modbus::{Request, decode_request};
use crate::rmc::{AxisId, AxisStatus, Command};
use crate::sim::rmc::{RmcConfig, RmcConnection, RmcController};

/// One way of going wrong on the line, for the next request that matches.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Fault {
    /// The controller runs the next write but its reply is lost.
    LoseNextWriteReply,
    /// The next write never reaches the controller (nor does a reply come).
    LoseNextWrite,
    /// The next status reply after a write shows ACK as it was before (a controller
    /// whose loop has not yet taken the command).
    AckLate,
    /// Every status reply shows ACK as it was before the last write (a controller that
    /// never takes commands from this host).
    AckNever,
}

/// A device that keeps answering badly, every request until healed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Sick {
    /// Every request answered with exception 04 (Server Device Failure).
    Exceptions,
    /// Every read answered with one register fewer than asked (writes run as usual).
    ShortReads,
}

pub struct Bench {
    pub core: RmcCore,
    pub sim: RmcController,
    conn: Option<RmcConnection>,
    pub now: Instant,
    pub start: Instant,
    /// Replies on their way, with when they arrive.
    inbound: VecDeque<(Instant, Vec<u8>)>,
    /// Every request written, as the controller would read it, with its time.
    pub wire: Vec<(Instant, Request)>,
    pub events: Vec<(Instant, RmcEvent)>,
    pub faults: Vec<Fault>,
    /// The line refuses to open while cut.
    pub cut: bool,
    /// The device answers badly while set.
    pub sick: Option<Sick>,
    ids: u64,
    latency: Duration,
    /// A write went out since the last status read answered.
    wrote_since_status: bool,
}

/// A status reply with its ACK bit (Status Bits bit 31: the high word's top bit) flipped.
fn flip_ack(reply: &[u8]) -> Vec<u8> {
    use crate::rmc::modbus::{Response, decode_response, encode_response};
    match decode_response(reply) {
        Ok((
            h,
            Response::Registers {
                function,
                mut words,
            },
        )) => {
            words[1] ^= 0x8000;
            encode_response(h, &Response::Registers { function, words })
        }
        _ => reply.to_vec(),
    }
}

pub fn axis(index: usize) -> AxisId {
    AxisId::new(index).unwrap()
}

impl Bench {
    pub fn new(config: RmcLinkConfig) -> Self {
        let start = Instant::now();
        Self {
            core: RmcCore::new(config, start),
            sim: RmcController::new(RmcConfig::default(), start),
            conn: None,
            now: start,
            start,
            inbound: VecDeque::new(),
            wire: Vec::new(),
            events: Vec::new(),
            faults: Vec::new(),
            cut: false,
            sick: None,
            ids: 0,
            wrote_since_status: false,
            latency: Duration::from_micros(500),
        }
    }

    /// Connected, polled once, axis 0 enabled and acknowledged.
    pub fn enabled() -> Self {
        let mut b = Self::new(RmcLinkConfig::default());
        b.send(axis(0), Command::Enable(true));
        b.run_until(Duration::from_secs(1), |b| {
            b.core
                .last_status(axis(0))
                .is_some_and(|s| s.bits.enabled())
        });
        b
    }

    /// The link's time between status rounds.
    pub fn core_poll_interval(&self) -> Duration {
        self.core.config.poll_interval
    }

    /// The time between status rounds while every axis stands.
    pub fn core_idle_poll_interval(&self) -> Duration {
        self.core.config.idle_poll_interval
    }

    pub fn request(&mut self, request: RmcRequest) {
        self.core.handle_request(self.now, Input::App(request));
        self.pump();
    }

    pub fn next_id(&mut self) -> RequestId {
        self.ids += 1;
        RequestId(self.ids)
    }

    pub fn send(&mut self, axis: AxisId, command: Command) -> RequestId {
        let id = self.next_id();
        self.request(RmcRequest::Send { id, axis, command });
        id
    }

    pub fn renew(&mut self) {
        self.core
            .handle_request(self.now, Input::LeaseRenewed(self.now));
    }

    /// Cuts the line now (the driver saw the socket fail).
    pub fn lose_line(&mut self) {
        self.conn = None;
        self.inbound.clear();
        self.core
            .handle_line(self.now, LineChange::Lost(LineDownReason::Closed));
        self.pump();
    }

    /// What the driver does after any input: time-outs, transmits, replies due.
    pub fn pump(&mut self) {
        for _ in 0..1000 {
            let mut busy = false;
            if self.core.poll_timeout().is_some_and(|t| t <= self.now) {
                self.core.handle_timeout(self.now);
            }
            while let Some(t) = self.core.poll_transmit(self.now) {
                busy = true;
                self.transmit(t);
            }
            while self.inbound.front().is_some_and(|(at, _)| *at <= self.now) {
                if let Some((_, bytes)) = self.inbound.pop_front() {
                    self.core.handle_bytes(self.now, &bytes);
                    busy = true;
                }
            }
            while let Some(e) = self.core.poll_event() {
                self.events.push((self.now, e));
            }
            if !busy {
                return;
            }
        }
    }

    fn transmit(&mut self, t: Transmit) {
        match t {
            Transmit::Open(_) => {
                let change = if self.cut {
                    LineChange::OpenFailed(crate::link::IoFailure {
                        kind: std::io::ErrorKind::ConnectionRefused,
                        detail: "refused".into(),
                    })
                } else {
                    self.conn = Some(RmcConnection::new());
                    LineChange::Opened { name: "sim".into() }
                };
                self.core.handle_line(self.now, change);
            }
            Transmit::Write(bytes) => {
                let request = decode_request(&bytes).map(|(_, r)| r);
                let is_write = matches!(request, Ok(Request::Write { .. }));
                let is_status = matches!(request, Ok(Request::Read { count: 116, .. }));
                if let Ok(r) = request {
                    self.wire.push((self.now, r));
                }
                let fault = self.faults.first().copied().filter(|f| match f {
                    Fault::AckLate | Fault::AckNever => is_status && self.wrote_since_status,
                    _ => is_write,
                });
                if fault.is_some_and(|f| f != Fault::AckNever) {
                    self.faults.remove(0);
                }
                if is_write {
                    self.wrote_since_status = true;
                }
                if is_status && fault.is_none() {
                    self.wrote_since_status = false;
                }
                if fault == Some(Fault::LoseNextWrite) {
                    return;
                }
                if let Some(reply) = self.sick_reply(&bytes) {
                    self.inbound.push_back((self.now + self.latency, reply));
                    return;
                }
                let Some(conn) = self.conn.as_mut() else {
                    return;
                };
                let reply = conn.handle_bytes(&mut self.sim, self.now, &bytes);
                if fault == Some(Fault::LoseNextWriteReply) {
                    return;
                }
                if let Ok(mut reply) = reply {
                    if matches!(fault, Some(Fault::AckLate | Fault::AckNever)) {
                        reply = flip_ack(&reply);
                    }
                    self.inbound.push_back((self.now + self.latency, reply));
                }
            }
            Transmit::Close => {
                self.conn = None;
                self.inbound.clear();
            }
        }
    }

    /// What a sick device answers to `request`, if it answers badly.
    fn sick_reply(&self, request: &[u8]) -> Option<Vec<u8>> {
        use crate::rmc::modbus::{ExceptionCode, Response, encode_response};
        let (header, request) = decode_request(request).ok()?;
        let response = match (self.sick?, request) {
            (Sick::Exceptions, r) => Response::Exception {
                function: r.function(),
                code: ExceptionCode(4),
            },
            (Sick::ShortReads, Request::Read { count, .. }) => Response::Registers {
                function: 3,
                words: vec![0; usize::from(count.saturating_sub(1))],
            },
            (Sick::ShortReads, _) => return None,
        };
        Some(encode_response(header, &response))
    }

    /// Runs the virtual clock in 0.5 ms ticks until `done` or `limit` passes; whether
    /// `done` came true.
    pub fn run_until(&mut self, limit: Duration, mut done: impl FnMut(&Self) -> bool) -> bool {
        let end = self.now + limit;
        self.pump();
        while self.now < end {
            if done(self) {
                return true;
            }
            self.now += Duration::from_micros(500);
            self.sim.advance(self.now);
            self.pump();
        }
        done(self)
    }

    /// Runs the clock for `d`, renewing the lease every `renew` if given.
    pub fn run_for(&mut self, d: Duration, renew: Option<Duration>) {
        let end = self.now + d;
        let mut next_renew = self.now;
        while self.now < end {
            if let Some(every) = renew
                && self.now >= next_renew
            {
                self.renew();
                next_renew = self.now + every;
            }
            self.now += Duration::from_micros(500);
            self.sim.advance(self.now);
            self.pump();
        }
    }

    /// The commands written to `axis`'s block, in order, with their REQ.
    pub fn commands_to(&self, axis: AxisId) -> Vec<(Command, bool)> {
        self.wire
            .iter()
            .filter_map(|(_, r)| match r {
                Request::Write { address, words } if *address == axis.command_block() => {
                    Command::from_block(words).ok()
                }
                _ => None,
            })
            .collect()
    }

    /// Whether any event so far is one `f` picks.
    pub fn saw(&self, f: impl Fn(&RmcEvent) -> bool) -> bool {
        self.events.iter().any(|(_, e)| f(e))
    }

    /// How many motion commands were written to `axis`'s block.
    pub fn moves_to(&self, axis: AxisId) -> usize {
        self.commands_to(axis)
            .iter()
            .filter(|(c, _)| c.moves())
            .count()
    }

    /// The simulator's own view of an axis (ACK clear).
    pub fn truth(&self, axis: AxisId) -> AxisStatus {
        self.sim.status(axis).unwrap_or_default()
    }
}
