//! The Format B core wired to the simulator's sans-IO controller on a virtual clock, in
//! one thread: what a driver and a line would do, with every byte's time computed, so a
//! test of the link's rules runs in milliseconds and the same way every time.

use std::collections::VecDeque;
use std::sync::Arc;
use std::sync::atomic::AtomicU64;
use std::time::{Duration, Instant};

use super::{Control, FormatB};
use crate::link::core::{Input, LineChange, LinkCore, Transmit};
use crate::link::event::LinkEvent;
use crate::link::handle::LinkConfig;
use crate::link::reason::{IoFailure, LineDownReason};
use crate::link::request::{Origin, Pending, Priority, RequestId};
use crate::link::schedule::Polling;
use crate::protocol::{
    ArmPolicy, Axis, AxisPattern, CentiG, Command, Direction, Jog, JogFrame, JogMotion, Milli,
    MmPerSec, PerAxis, Percent, ScaraMotion, ScaraMove, Stop,
};
use crate::sim::faults::{FaultInjector, FaultSpec};
use crate::sim::framing::{Assembler, Received, max_command};
use crate::sim::{Controller, SimSetup};

/// The far end of the line: the simulated controller, its faults and the wire's timing.
pub(crate) struct SimEnd {
    pub(crate) controller: Controller,
    pub(crate) faults: FaultInjector,
    assembler: Assembler,
    /// Wire time of one byte (zero: bytes arrive at once).
    byte_time: Duration,
    /// The controller answers one frame at a time: a frame that arrives while a reply is
    /// still going out (delayed, stalled) is handled once it is out, as the simulator's
    /// IO thread does.
    busy_until: Instant,
    /// When the host's last byte reaches the controller (bytes queue on the wire).
    wire_free: Instant,
    /// Bytes on their way to the host, each chunk with the instant it arrives.
    inbound: VecDeque<(Instant, Vec<u8>)>,
    /// Every command frame the controller received, with when.
    pub(crate) received: Vec<(Instant, Vec<u8>)>,
    t0: Instant,
}

impl SimEnd {
    fn new(setup: SimSetup, faults: FaultSpec, byte_time: Duration, t0: Instant) -> Self {
        let limit = max_command(setup.config.reply_buffer);
        Self {
            controller: Controller::new(setup),
            faults: FaultInjector::new(faults),
            assembler: Assembler::with_limit(limit),
            byte_time,
            wire_free: t0,
            busy_until: t0,
            inbound: VecDeque::new(),
            received: Vec::new(),
            t0,
        }
    }

    fn wire(&self, bytes: usize) -> Duration {
        self.byte_time.saturating_mul(bytes as u32)
    }

    /// The host wrote `bytes` at `now`: frames the controller completes are answered,
    /// their replies put on the wire back with the reply delay and any fault.
    fn host_wrote(&mut self, now: Instant, bytes: &[u8]) {
        let mut at = self.wire_free.max(now);
        for &byte in bytes {
            at += self.byte_time;
            let Some(Received::Frame(frame)) = self.assembler.push(byte) else {
                continue;
            };
            let frame = frame.to_vec();
            self.received.push((at, frame.clone()));
            let handled = at.max(self.busy_until);
            let mut reply = Vec::new();
            let since = handled.saturating_duration_since(self.t0);
            if self.controller.answer(&frame, since, &mut reply).is_err() {
                continue;
            }
            let delivery = self.faults.plan(&reply);
            let mut start = handled + self.controller.reply_delay();
            for piece in delivery.pieces {
                start += piece.pause + self.wire(piece.bytes.len());
                self.inbound.push_back((start, piece.bytes));
            }
            self.busy_until = start;
        }
        self.wire_free = at;
    }

    fn next_arrival(&self) -> Option<Instant> {
        self.inbound.iter().map(|(t, _)| *t).min()
    }

    /// The chunk due first at or before `now`.
    fn take_due(&mut self, now: Instant) -> Option<Vec<u8>> {
        let (i, _) = self
            .inbound
            .iter()
            .enumerate()
            .filter(|(_, (t, _))| *t <= now)
            .min_by_key(|(_, (t, _))| *t)?;
        self.inbound.remove(i).map(|(_, bytes)| bytes)
    }

    /// The message IDs of the command frames received, in order ("236", "238"...).
    pub(crate) fn ids_received(&self) -> Vec<String> {
        self.received
            .iter()
            .filter_map(|(_, f)| std::str::from_utf8(f.get(3..6)?).ok().map(str::to_owned))
            .collect()
    }
}

/// How the line behaves when the core opens it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Plug {
    /// Opens.
    In,
    /// Every open fails (a port that vanished).
    Out,
}

/// The core and the simulator on one virtual clock.
pub(crate) struct Bench {
    pub(crate) core: FormatB,
    pub(crate) sim: SimEnd,
    pub(crate) now: Instant,
    pub(crate) t0: Instant,
    /// Every event, in order.
    pub(crate) events: Vec<LinkEvent>,
    /// Every frame written, with when.
    pub(crate) written: Vec<(Instant, Vec<u8>)>,
    pub(crate) plug: Plug,
    line_open: bool,
    /// Events before this were looked at by `run_until`.
    cursor: usize,
    /// Steps taken without the clock moving (a core that keeps asking would spin).
    same_instant: u32,
    ids: Arc<AtomicU64>,
}

/// A simulator that starts homed with servos on, answering after `reply_delay`.
pub(crate) fn ready_setup(reply_delay: Duration) -> SimSetup {
    let mut setup = SimSetup::default();
    setup.config.start_ready = true;
    setup.config.reply_delay = reply_delay;
    setup
}

/// A configuration without polling (tests that count frames).
pub(crate) fn quiet_config() -> LinkConfig {
    LinkConfig {
        polling: Polling {
            interval: None,
            idle_interval: None,
            commands: Vec::new(),
        },
        ..LinkConfig::default()
    }
}

impl Bench {
    pub(crate) fn new(setup: SimSetup, faults: FaultSpec, config: LinkConfig) -> Self {
        let t0 = Instant::now();
        let ids = Arc::new(AtomicU64::new(1));
        let byte_time = config.timing.line.byte_time();
        Self {
            core: FormatB::new(config, ids.clone(), t0),
            sim: SimEnd::new(setup, faults, byte_time, t0),
            now: t0,
            t0,
            events: Vec::new(),
            written: Vec::new(),
            plug: Plug::In,
            line_open: false,
            same_instant: 0,
            cursor: 0,
            ids,
        }
    }

    /// A ready simulator answering after 1 ms, no faults, no polling; the line opened.
    pub(crate) fn quiet() -> Self {
        let mut bench = Self::new(
            ready_setup(Duration::from_millis(1)),
            FaultSpec::none(),
            quiet_config(),
        );
        bench.settle();
        bench
    }

    /// Milliseconds since the start, for messages.
    pub(crate) fn ms(&self, at: Instant) -> f64 {
        at.saturating_duration_since(self.t0).as_secs_f64() * 1e3
    }

    /// Submits as the handle does: a continuous jog renews the lease.
    pub(crate) fn submit(&mut self, command: Command) -> RequestId {
        if command.is_continuous_jog() {
            self.renew_lease();
        }
        let id = RequestId::next(&self.ids);
        let pending = Pending::new(id, command, Origin::User, Priority::User);
        self.core
            .handle_request(self.now, Input::App(Control::Submit(pending)));
        self.pump();
        id
    }

    /// Numbers a submission now (as the handle does) without handing it to the core yet:
    /// [`Bench::deliver`] hands it over later, as a command that waited in the driver's
    /// channel while a STOP overtook it in its own.
    pub(crate) fn number(&mut self, command: Command) -> Pending {
        Pending::new(
            RequestId::next(&self.ids),
            command,
            Origin::User,
            Priority::User,
        )
    }

    /// Numbers a submission at `priority` as the handle does (a STOP at
    /// [`Priority::Stop`]) without handing it over: a test can then deliver a frame's
    /// requests in the order a driver takes them (its STOPs first) or as they were made.
    pub(crate) fn number_at(&mut self, command: Command, priority: Priority) -> Pending {
        Pending::new(RequestId::next(&self.ids), command, Origin::User, priority)
    }

    pub(crate) fn deliver(&mut self, pending: Pending) {
        self.core
            .handle_request(self.now, Input::App(Control::Submit(pending)));
        self.pump();
    }

    pub(crate) fn stop_all(&mut self) -> RequestId {
        self.submit(Command::Stop(Stop {
            axes: AxisPattern::ALL,
            cancel_held_outputs: false,
        }))
    }

    pub(crate) fn control(&mut self, control: Control) {
        self.core.handle_request(self.now, Input::App(control));
        self.pump();
    }

    pub(crate) fn renew_lease(&mut self) {
        self.core
            .handle_request(self.now, Input::LeaseRenewed(self.now));
    }

    pub(crate) fn close(&mut self) {
        self.core.handle_request(self.now, Input::Close);
        self.pump();
    }

    /// The line is pulled: what was on its way is lost, and reopening fails until
    /// [`Bench::plug_in`].
    pub(crate) fn pull_line(&mut self) {
        self.plug = Plug::Out;
        self.sim.inbound.clear();
        if std::mem::take(&mut self.line_open) {
            self.core
                .handle_line(self.now, LineChange::Lost(LineDownReason::Closed));
        }
        self.pump();
    }

    /// The driver's write of the last frame failed: the line is gone with it.
    pub(crate) fn write_failed(&mut self) {
        self.sim.inbound.clear();
        self.line_open = false;
        self.core.handle_line(
            self.now,
            LineChange::Lost(LineDownReason::WriteFailed(IoFailure {
                kind: std::io::ErrorKind::BrokenPipe,
                detail: "broken pipe".into(),
            })),
        );
        self.pump();
    }

    pub(crate) fn plug_in(&mut self) {
        self.plug = Plug::In;
    }

    /// Does what the core asks now, and collects its events.
    fn pump(&mut self) {
        for _ in 0..1000 {
            let Some(transmit) = self.core.poll_transmit(self.now) else {
                break;
            };
            match transmit {
                Transmit::Open(_) => {
                    let change = match self.plug {
                        Plug::In => {
                            self.line_open = true;
                            LineChange::Opened {
                                name: "virtual line".into(),
                            }
                        }
                        Plug::Out => LineChange::OpenFailed(IoFailure {
                            kind: std::io::ErrorKind::NotFound,
                            detail: "no such port".into(),
                        }),
                    };
                    self.core.handle_line(self.now, change);
                }
                Transmit::Write(bytes) => {
                    self.written.push((self.now, bytes.clone()));
                    self.sim.host_wrote(self.now, &bytes);
                }
                Transmit::Close => {
                    self.line_open = false;
                    self.sim.inbound.clear();
                }
            }
        }
        while let Some(event) = self.core.poll_event() {
            self.events.push(event);
        }
    }

    /// Advances to the next thing that happens (a byte arriving or the core's time-out)
    /// if it is before `limit`; false when nothing is due before it.
    pub(crate) fn step(&mut self, limit: Instant) -> bool {
        // What the core does at this instant first (events looked at before time moves).
        let before = (self.events.len(), self.written.len());
        self.pump();
        if (self.events.len(), self.written.len()) != before {
            return true;
        }
        let arrival = self.sim.next_arrival().filter(|_| self.line_open);
        let next = [arrival, self.core.poll_timeout()]
            .into_iter()
            .flatten()
            .min();
        let Some(next) = next.filter(|t| *t <= limit) else {
            self.now = self.now.max(limit);
            self.sim.controller.advance(self.now - self.t0);
            self.pump();
            return false;
        };
        // A timer may have passed while it did not count (a lease while the line was
        // down); one that is not consumed when handled would spin the driver.
        if next <= self.now {
            self.same_instant += 1;
            assert!(
                self.same_instant < 100,
                "the core keeps asking to be woken at {} ms: it would spin the driver",
                self.ms(next)
            );
        } else {
            self.same_instant = 0;
            self.now = next;
        }
        while let Some(bytes) = self.sim.take_due(self.now) {
            self.core.handle_bytes(self.now, &bytes);
        }
        if self.core.poll_timeout().is_some_and(|t| t <= self.now) {
            self.core.handle_timeout(self.now);
        }
        self.pump();
        true
    }

    /// Runs the virtual clock on by `d`.
    pub(crate) fn run_for(&mut self, d: Duration) {
        let limit = self.now + d;
        while self.step(limit) {}
    }

    /// Runs until an event after the last one a `run_until` matched matches `pred` (its
    /// index, as a threaded test waits on the event channel), or `d` of virtual time
    /// has passed.
    pub(crate) fn run_until(
        &mut self,
        d: Duration,
        mut pred: impl FnMut(&LinkEvent) -> bool,
    ) -> Option<usize> {
        let limit = self.now + d;
        loop {
            let from = self.cursor;
            if let Some(i) = self.events[from..].iter().position(&mut pred) {
                self.cursor = from + i + 1;
                return Some(from + i);
            }
            self.cursor = self.events.len();
            if !self.step(limit) {
                let from = self.cursor;
                let found = self.events[from..].iter().position(&mut pred)?;
                self.cursor = from + found + 1;
                return Some(from + found);
            }
        }
    }

    /// Runs until nothing more is due (polling off) or for at most 10 s.
    pub(crate) fn settle(&mut self) {
        let limit = self.now + Duration::from_secs(10);
        while self.core.poll_timeout().is_some_and(|t| t <= limit)
            || self.sim.next_arrival().is_some()
        {
            let health_only = self.core.outstanding.is_none()
                && self.sim.next_arrival().is_none()
                && self.core.poll_timeout() == Some(self.core.next_health);
            if health_only || !self.step(limit) {
                break;
            }
        }
    }

    /// The events that settle request `id`: its reply, error reply, refusal or time-out.
    pub(crate) fn answer_to(&self, id: RequestId) -> Option<&LinkEvent> {
        self.events.iter().find(|e| match e {
            LinkEvent::Reply { id: r, .. }
            | LinkEvent::ErrorReply { id: r, .. }
            | LinkEvent::NotSent { id: r, .. }
            | LinkEvent::Interrupted { id: r, .. } => *r == id,
            LinkEvent::Timeout {
                id: r, retrying, ..
            } => *r == id && !retrying,
            _ => false,
        })
    }

    /// The message IDs of the frames written, in order.
    pub(crate) fn ids_written(&self) -> Vec<String> {
        self.written
            .iter()
            .filter_map(|(_, f)| std::str::from_utf8(f.get(3..6)?).ok().map(str::to_owned))
            .collect()
    }

    /// The events as one line each, for failure messages.
    pub(crate) fn story(&self) -> String {
        self.events
            .iter()
            .filter(|e| !matches!(e, LinkEvent::Health(_)))
            .map(|e| format!("  {}", e.summary()))
            .collect::<Vec<_>>()
            .join("\n")
    }
}

/// 2D5H relative PTP move of axis 1 (X in the work frame) by `micrometres`.
pub(crate) fn step_x(micrometres: i32) -> Command {
    Command::ScaraMoveRelative(ScaraMove {
        motion: ScaraMotion::Ptp {
            acc: Percent(50),
            dec: Percent(50),
            speed: Percent(30),
            arm: ArmPolicy::KeepNoSwitch,
        },
        targets: PerAxis::new().with(Axis::A1, Milli(micrometres)),
    })
}

/// 236H continuous jog (distance 0) of axis 1 in the work frame: runs until stopped.
pub(crate) fn jog_x() -> Command {
    Command::Jog(Jog {
        axes: AxisPattern::single(Axis::A1),
        direction: Direction::Negative,
        distance: Milli(0),
        motion: JogMotion::Cartesian {
            frame: JogFrame::Work,
            acc: CentiG(10),
            dec: CentiG(10),
            speed: MmPerSec(5),
        },
    })
}
