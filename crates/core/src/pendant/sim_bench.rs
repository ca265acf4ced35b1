//! A pendant wired to the simulator's controller, sans-IO, on a virtual clock, for the
//! sub-models' tests: every command the pendant asks for is answered (or not) by the
//! simulator or by a fault the test injects.

use std::time::{Duration, Instant};

use crate::link::{LinkEvent, Origin, RequestId};
use crate::pendant::{Intent, Pendant, Request, Settings};
use crate::protocol::{Command, ErrorCode, Frame, Reply, ScMode, Station};
use crate::robot::RobotModel;
use crate::sim::{Controller, SimSetup};

/// What the line does with one command.
#[derive(Clone, Debug)]
pub(crate) enum Fault {
    /// The simulator answers.
    Pass,
    /// `&` with this code instead.
    Error(u16),
    /// No valid reply, retries exhausted.
    Timeout,
    /// Never sent (STOP came first, the line was lost...).
    NotSent(crate::link::NotSentReason),
}

pub(crate) struct Bench {
    pub p: Pendant,
    pub sim: Controller,
    pub t: Duration,
    pub start: Instant,
    pub sent: Vec<Command>,
}

impl Bench {
    pub(crate) fn new(setup: SimSetup) -> Bench {
        let start = Instant::now();
        let mut setup = setup;
        setup.config.start_ready = true;
        let mut b = Bench {
            p: Pendant::new(Settings::default(), RobotModel::default_model()),
            sim: Controller::new(setup),
            t: Duration::ZERO,
            start,
            sent: Vec::new(),
        };
        b.p.handle_event(
            start,
            LinkEvent::Connected {
                line: "bench".into(),
            },
        );
        b.pump(|_| Fault::Pass);
        // Work 0 and tool 0 are selected on the simulator: the base frame and the flange.
        for kind in [
            crate::protocol::CoordKind::Work,
            crate::protocol::CoordKind::Tool,
        ] {
            b.p.handle_event(
                start,
                LinkEvent::TableDone {
                    kind,
                    axes: crate::protocol::AxisPattern::SCARA_1,
                    first: 0,
                    records: vec![Some(crate::protocol::PerAxis::new()); 4],
                    missing: vec![],
                },
            );
        }
        b.poll();
        // The tables' requests (read by hand above) and the version query are answered.
        b.pump(|_| Fault::Pass);
        b
    }

    pub(crate) fn now(&self) -> Instant {
        self.start + self.t
    }

    /// One command through the simulator (or the fault), its event to the pendant.
    pub(crate) fn exchange(&mut self, command: Command, origin: Origin, fault: Fault) {
        self.t += Duration::from_millis(5);
        let now = self.now();
        self.sent.push(command.clone());
        let id = RequestId(1);
        let event = match fault {
            Fault::Pass => {
                let frame = command
                    .to_bytes(Station::DEFAULT, ScMode::Computed)
                    .unwrap();
                let bytes = self
                    .sim
                    .handle(&frame, self.t)
                    .expect("the simulator answers");
                let reply = Reply::decode(&Frame::parse(&bytes).unwrap()).unwrap();
                match reply {
                    Reply::Error(code) => LinkEvent::ErrorReply {
                        id,
                        origin,
                        command,
                        code,
                    },
                    reply => LinkEvent::Reply {
                        id,
                        origin,
                        command,
                        reply,
                        round_trip: Duration::from_millis(5),
                    },
                }
            }
            Fault::Error(code) => LinkEvent::ErrorReply {
                id,
                origin,
                command,
                code: ErrorCode(code),
            },
            Fault::Timeout => LinkEvent::Timeout {
                id,
                origin,
                command,
                retrying: false,
                recheck: None,
                at: now,
            },
            Fault::NotSent(reason) => LinkEvent::NotSent {
                id,
                command,
                reason,
            },
        };
        self.p.handle_event(now, event);
    }

    /// Runs the pendant's requests until none are left; `fault` decides each command's
    /// fate.
    pub(crate) fn pump(&mut self, mut fault: impl FnMut(&Command) -> Fault) {
        for _ in 0..100_000 {
            let requests = self.p.take_requests();
            if requests.is_empty() {
                return;
            }
            for r in requests {
                match r {
                    Request::Submit(c) | Request::Background(c) | Request::Spare(c) => {
                        let f = fault(&c);
                        self.exchange(c, Origin::User, f);
                    }
                    Request::Stop => {
                        let stop = Command::Stop(crate::link::format_b::safety::stop_all());
                        self.exchange(stop, Origin::User, Fault::Pass);
                    }
                    _ => {}
                }
            }
        }
        panic!("the pendant never stopped asking");
    }

    /// One status poll cycle through the simulator.
    pub(crate) fn poll(&mut self) {
        for c in crate::pendant::controller::poll_commands() {
            self.exchange(c, Origin::Poll, Fault::Pass);
        }
    }

    pub(crate) fn apply(&mut self, intent: impl Into<Intent>) {
        let now = self.now();
        self.p.apply(intent.into(), now);
    }

    /// Lets the simulated arm finish its move, polling.
    pub(crate) fn settle(&mut self) {
        for _ in 0..2000 {
            self.t += Duration::from_millis(20);
            self.sim.advance(self.t);
            self.poll();
            if self.sim.at_rest() && self.p.jog.followed.is_none() {
                return;
            }
            if self.sim.at_rest() {
                // The pendant follows the profile; the polls say the move is over.
                self.t += Duration::from_millis(200);
                self.sim.advance(self.t);
                self.poll();
                return;
            }
        }
        panic!("the arm never came to rest");
    }
}
