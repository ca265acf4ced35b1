//! Which request goes on the line next: STOP first, then the user's commands, then status
//! polls when due (never queued, so a stale poll is simply not sent), then table chunks,
//! then spare reads in the line time the polls leave.

use std::collections::VecDeque;
use std::time::{Duration, Instant};

use super::request::{Origin, Pending, Priority, RequestId};
use super::table::{TableJob, TableRequest};
use super::timing::Timing;
use crate::protocol::{AxisPattern, Command, PositionSystem, ScaraStatusQuery};

/// Status polling: the commands of one cycle and how often a cycle starts.
#[derive(Clone, Debug, PartialEq)]
pub struct Polling {
    /// Time from one cycle's start to the next; `None` turns polling off. When the line
    /// cannot keep up, cycles run back to back and the rate falls to what it allows.
    pub interval: Option<Duration>,
    /// Time from one cycle's start to the next once things are steady: no poll has
    /// answered differently and nothing else has gone on the line for [`STEADY_AFTER`].
    /// Any change brings `interval` back at once. `None`, or one shorter than
    /// `interval`: always `interval`.
    pub idle_interval: Option<Duration>,
    /// Sent in order, one per free slot of the line.
    pub commands: Vec<Command>,
}

/// How long after the last change polling keeps its fast interval: a move that has just
/// been sent, or a pause within one, does not slow the polls that follow it.
pub const STEADY_AFTER: Duration = Duration::from_secs(1);

impl Default for Polling {
    fn default() -> Self {
        Self {
            interval: Some(Duration::from_millis(100)),
            idle_interval: None,
            commands: vec![
                Command::ScaraStatus(ScaraStatusQuery {
                    axes: AxisPattern::SCARA_1,
                    system: PositionSystem::Work,
                }),
                Command::SystemStatus,
            ],
        }
    }
}

/// What the link thread should do now.
#[derive(Debug, PartialEq)]
pub enum Next {
    Send(Pending),
    /// Nothing to send before this instant (`None`: until something is submitted).
    Wait(Option<Instant>),
}

/// The share of the line's time spare requests may take from the polls when these leave
/// no slack (a slow line): credit builds up at 1/30 of the time passing, a spare request
/// goes between two cycles when the credit covers its expected line time, and each is
/// charged what it really took. With slack, a spare request goes only when it ends
/// before the next poll is due. The status poll rate stays within 5 % of its rate
/// without them (a request costs a little more than its share: its turnaround and the
/// gap after it).
pub const SPARE_SHARE: u32 = 30;
/// The most line time spare requests may save up while the line has slack.
const SPARE_SAVINGS: Duration = Duration::from_secs(1);
/// A controller's reply delay as spare requests are sized: the real one is a parameter
/// the host cannot read (I/O parameter 97) `[inferred: PROTOCOL.md 1.5]`.
const SPARE_REPLY_DELAY: Duration = Duration::from_millis(3);

/// The queues, the poll clock and the table download in progress.
#[derive(Debug, Default)]
pub struct Scheduler {
    stops: VecDeque<Pending>,
    user: VecDeque<Pending>,
    background: VecDeque<Pending>,
    /// Spare requests with the line time each is expected to take.
    spare: VecDeque<(Pending, Duration)>,
    /// Line time spare requests may take while polls are due (see [`SPARE_SHARE`]).
    spare_credit: Duration,
    /// When the credit last grew.
    credit_at: Option<Instant>,
    /// The spare request on the line: when it went and the time it was expected to take
    /// (the next request can only go once it has ended: its real time is charged then).
    spare_out: Option<(Instant, Duration, bool)>,
    /// The last poll cycle took longer than its interval: the polls leave no slack, and
    /// spare requests go on credit.
    polls_saturated: bool,
    timing: Timing,
    polling: Polling,
    cycle_pos: usize,
    cycle_started: Option<Instant>,
    next_poll_at: Option<Instant>,
    /// After a poll cycle, one background request gets its turn before the next cycle.
    background_turn: bool,
    /// Polls are paused (the event reader is far behind).
    polls_paused: bool,
    /// Polls keep their fast interval until then (see [`Scheduler::activity`]).
    lively_until: Option<Instant>,
    table: Option<TableJob>,
    table_generation: u32,
}

impl Scheduler {
    pub fn new(polling: Polling, now: Instant) -> Self {
        let mut s = Self::default();
        s.set_polling(polling, now);
        s
    }

    pub fn polling(&self) -> &Polling {
        &self.polling
    }

    pub fn set_polling(&mut self, polling: Polling, now: Instant) {
        // An interval with nothing to send is no polling at all.
        self.next_poll_at = polling
            .interval
            .filter(|_| !polling.commands.is_empty())
            .map(|_| now);
        self.cycle_pos = 0;
        self.cycle_started = None;
        self.lively_until = Some(super::driver::later(now, STEADY_AFTER));
        self.polling = polling;
    }

    /// Something changed at `now` (a poll answered differently, a request of the
    /// application's went out, a reply failed): polls keep their fast interval for
    /// [`STEADY_AFTER`], and a cycle waiting out the idle interval starts when the fast
    /// one would have.
    pub fn activity(&mut self, now: Instant) {
        self.lively_until = Some(super::driver::later(now, STEADY_AFTER));
        if let (0, Some(start), Some(at), Some(interval)) = (
            self.cycle_pos,
            self.cycle_started,
            self.next_poll_at,
            self.polling.interval,
        ) {
            self.next_poll_at = Some(at.min(super::driver::later(start, interval).max(now)));
        }
    }

    /// The time from this cycle's start to the next one's.
    fn cycle_interval(&self, now: Instant, interval: Duration) -> Duration {
        let steady = self.lively_until.is_none_or(|t| now >= t);
        match self.polling.idle_interval {
            Some(idle) if steady => idle.max(interval),
            _ => interval,
        }
    }

    /// Pauses or resumes polling; on resuming, a cycle is due at once.
    pub fn pause_polls(&mut self, paused: bool, now: Instant) {
        if self.polls_paused && !paused {
            self.set_polling(self.polling.clone(), now);
        }
        self.polls_paused = paused;
    }

    /// The line's timing, which sizes spare requests.
    pub fn set_timing(&mut self, timing: Timing) {
        self.timing = timing;
    }

    /// The line time one transaction of `command` is expected to take (its longest reply).
    fn line_time(&self, command: &Command) -> Duration {
        let sent = command
            .to_bytes(
                crate::protocol::Station::DEFAULT,
                crate::protocol::ScMode::Computed,
            )
            .map_or(crate::protocol::MIN_FRAME_LEN, |b| b.len());
        self.timing
            .wire_transaction_time(sent, command.max_reply_len(), SPARE_REPLY_DELAY)
    }

    /// Queues a request behind the others of its priority.
    pub fn push(&mut self, pending: Pending) {
        if pending.priority == Priority::Spare {
            let t = self.line_time(&pending.command);
            return self.spare.push_back((pending, t));
        }
        self.queue(pending.priority).push_back(pending);
    }

    /// Puts a request at the head of its queue (a retry, a recheck, a waiting move).
    pub fn push_front(&mut self, pending: Pending) {
        if pending.priority == Priority::Spare {
            let t = self.line_time(&pending.command);
            return self.spare.push_front((pending, t));
        }
        self.queue(pending.priority).push_front(pending);
    }

    /// Whether a STOP is already waiting.
    pub fn stop_queued(&self) -> bool {
        !self.stops.is_empty()
    }

    fn queue(&mut self, priority: Priority) -> &mut VecDeque<Pending> {
        match priority {
            Priority::Stop => &mut self.stops,
            Priority::User => &mut self.user,
            // Spare requests have their own queue (with their line time); a retry of one
            // waits with the background work.
            Priority::Background | Priority::Spare => &mut self.background,
        }
    }

    /// Starts a table download, replacing one in progress (returned so it can be reported).
    pub fn start_table(&mut self, request: TableRequest) -> Option<TableJob> {
        self.background
            .retain(|p| !matches!(p.origin, Origin::Table { .. }));
        self.table_generation = self.table_generation.wrapping_add(1);
        self.table
            .replace(TableJob::new(request, self.table_generation))
    }

    /// The download a chunk of `generation` belongs to, if it is still the current one.
    pub fn table_for(&mut self, generation: u32) -> Option<&mut TableJob> {
        self.table
            .as_mut()
            .filter(|job| job.generation == generation)
    }

    /// The finished download, once every chunk is answered or given up.
    pub fn take_finished_table(&mut self) -> Option<TableJob> {
        let chunk_waiting = self
            .background
            .iter()
            .any(|p| matches!(p.origin, Origin::Table { .. }));
        if self.table.as_ref()?.is_finished() && !chunk_waiting {
            return self.table.take();
        }
        None
    }

    /// Everything queued, emptied (when the line is lost: none of it may go out later).
    pub fn drain_queued(&mut self) -> Vec<Pending> {
        let mut all: Vec<Pending> = self.stops.drain(..).collect();
        all.extend(self.user.drain(..));
        all.extend(self.background.drain(..));
        all.extend(self.spare.drain(..).map(|(p, _)| p));
        all
    }

    /// The queued user requests `ended` picks out, taken from the queue in order (a STOP
    /// of all axes takes the motion still waiting behind a poll).
    pub fn take_user(&mut self, mut ended: impl FnMut(&Pending) -> bool) -> Vec<Pending> {
        let mut taken = Vec::new();
        self.user.retain(|p| {
            let end = ended(p);
            if end {
                taken.push(p.clone());
            }
            !end
        });
        taken
    }

    /// Abandons the table download in progress.
    pub fn abort_table(&mut self) -> Option<TableJob> {
        self.background
            .retain(|p| !matches!(p.origin, Origin::Table { .. }));
        self.table.take()
    }

    /// The next request at `now`; `new_id` numbers polls and table chunks.
    pub fn next(&mut self, now: Instant, new_id: &mut impl FnMut() -> RequestId) -> Next {
        self.settle_spare(now);
        if let Some(p) = self.stops.pop_front().or_else(|| self.user.pop_front()) {
            return Next::Send(p);
        }
        let poll_due = self.poll_due(now);
        if (!poll_due || self.background_turn)
            && let Some(p) = self.next_background(new_id)
        {
            self.background_turn = false;
            return Next::Send(p);
        }
        if let Some(p) = self.next_spare(now, poll_due) {
            return Next::Send(p);
        }
        if poll_due && let Some(p) = self.next_poll(now, new_id) {
            return Next::Send(p);
        }
        Next::Wait(
            self.next_poll_at
                .filter(|_| !self.polling.commands.is_empty() && !self.polls_paused),
        )
    }

    fn poll_due(&self, now: Instant) -> bool {
        !self.polls_paused
            && !self.polling.commands.is_empty()
            && (self.cycle_pos > 0 || self.next_poll_at.is_some_and(|at| now >= at))
    }

    fn next_poll(
        &mut self,
        now: Instant,
        new_id: &mut impl FnMut() -> RequestId,
    ) -> Option<Pending> {
        let interval = self.polling.interval?;
        let command = self.polling.commands.get(self.cycle_pos)?.clone();
        if self.cycle_pos == 0 {
            self.cycle_started = Some(now);
        }
        self.cycle_pos += 1;
        if self.cycle_pos >= self.polling.commands.len() {
            self.cycle_pos = 0;
            let start = self.cycle_started.unwrap_or(now);
            let gap = self.cycle_interval(now, interval);
            let due = super::driver::later(start, gap);
            self.polls_saturated = due <= now;
            self.next_poll_at = Some(due.max(now));
            self.background_turn = true;
        }
        Some(Pending::new(
            new_id(),
            command,
            Origin::Poll,
            Priority::User,
        ))
    }

    /// The next spare request: when it ends before the next poll is due, or from the
    /// line time saved up while polls are due.
    fn next_spare(&mut self, now: Instant, poll_due: bool) -> Option<Pending> {
        let &(_, time) = self.spare.front()?;
        let polling = !self.polls_paused && !self.polling.commands.is_empty();
        let ends_in_time = !poll_due
            && self
                .next_poll_at
                .is_none_or(|at| super::driver::later(now, time) <= at);
        let from_credit = polling && !ends_in_time;
        if from_credit && (!self.polls_saturated || self.cycle_pos != 0 || self.spare_credit < time)
        {
            return None;
        }
        self.spare_out = Some((now, time, from_credit));
        self.spare.pop_front().map(|(p, _)| p)
    }

    /// Grows the credit with the time passed, and charges the spare request that has
    /// ended: all of its time when it was sent on credit, what it overran its expected
    /// time by when it was sent into the polls' slack (it may have delayed a poll).
    fn settle_spare(&mut self, now: Instant) {
        let polling = !self.polls_paused && !self.polling.commands.is_empty();
        if let Some(at) = self.credit_at.filter(|_| polling) {
            let grown = now.saturating_duration_since(at) / SPARE_SHARE;
            self.spare_credit = (self.spare_credit + grown).min(SPARE_SAVINGS);
        }
        self.credit_at = Some(now);
        if let Some((sent, expected, from_credit)) = self.spare_out.take() {
            let took = now.saturating_duration_since(sent);
            let charge = if from_credit {
                took
            } else {
                took.saturating_sub(expected)
            };
            self.spare_credit = self.spare_credit.saturating_sub(charge);
        }
    }

    fn next_background(&mut self, new_id: &mut impl FnMut() -> RequestId) -> Option<Pending> {
        if let Some(p) = self.background.pop_front() {
            return Some(p);
        }
        let job = self.table.as_mut()?;
        let generation = job.generation;
        let command = job.next_query()?;
        let Command::CoordQuery2(q) = command else {
            return None;
        };
        let origin = Origin::Table {
            kind: q.kind,
            first: q.first,
            count: q.count,
            generation,
        };
        Some(Pending::new(
            new_id(),
            command,
            origin,
            Priority::Background,
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::protocol::{CoordKind, Stop};

    fn ids() -> impl FnMut() -> RequestId {
        let mut n = 1000;
        move || {
            n += 1;
            RequestId(n)
        }
    }

    fn user(id: u64, command: Command, priority: Priority) -> Pending {
        Pending::new(RequestId(id), command, Origin::User, priority)
    }

    fn stop() -> Command {
        Command::Stop(Stop {
            axes: AxisPattern::ALL,
            cancel_held_outputs: false,
        })
    }

    #[test]
    fn stop_overtakes_queued_user_commands_whatever_priority_it_was_given() {
        let now = Instant::now();
        let mut s = Scheduler::new(Polling::default(), now);
        let mut new_id = ids();
        s.push(user(1, Command::AlarmReset, Priority::User));
        s.push(user(2, stop(), Priority::Background));
        assert!(matches!(s.next(now, &mut new_id), Next::Send(p) if p.id == RequestId(2)));
        assert!(matches!(s.next(now, &mut new_id), Next::Send(p) if p.id == RequestId(1)));
    }

    #[test]
    fn polls_are_made_when_due_and_never_queue_up() {
        let t0 = Instant::now();
        let mut s = Scheduler::new(Polling::default(), t0);
        let mut new_id = ids();
        // One cycle: 2A1H then 215H, then nothing until the interval has passed.
        let Next::Send(a) = s.next(t0, &mut new_id) else {
            panic!("poll expected")
        };
        let Next::Send(b) = s.next(t0, &mut new_id) else {
            panic!("poll expected")
        };
        assert_eq!((a.origin, b.origin), (Origin::Poll, Origin::Poll));
        assert_eq!(b.command, Command::SystemStatus);
        assert_eq!(
            s.next(t0, &mut new_id),
            Next::Wait(Some(t0 + Duration::from_millis(100)))
        );
        // Three intervals pass with the line busy: only one cycle is due, not three.
        let late = t0 + Duration::from_millis(350);
        assert!(matches!(s.next(late, &mut new_id), Next::Send(_)));
        assert!(matches!(s.next(late, &mut new_id), Next::Send(_)));
        assert_eq!(
            s.next(late, &mut new_id),
            Next::Wait(Some(late + Duration::from_millis(100)))
        );
    }

    #[test]
    fn steady_polls_slow_to_the_idle_interval_and_a_change_brings_the_fast_one_back_at_once() {
        let ms = Duration::from_millis;
        let t0 = Instant::now();
        let polling = Polling {
            interval: Some(ms(100)),
            idle_interval: Some(ms(250)),
            commands: vec![Command::SystemStatus],
        };
        let mut s = Scheduler::new(polling, t0);
        let mut new_id = ids();
        let mut now = t0;
        let mut run_until = |s: &mut Scheduler, end: Instant, now: &mut Instant| {
            let mut starts = Vec::new();
            while *now < end {
                match s.next(*now, &mut new_id) {
                    Next::Send(p) => {
                        assert_eq!(p.origin, Origin::Poll);
                        starts.push(now.duration_since(t0).as_millis());
                    }
                    Next::Wait(Some(at)) => *now = at,
                    Next::Wait(None) => panic!("polling stopped"),
                }
            }
            starts
        };
        // Nothing changes: the fast interval for STEADY_AFTER, then the idle one.
        let starts = run_until(&mut s, t0 + ms(2100), &mut now);
        assert_eq!(
            starts,
            [
                0, 100, 200, 300, 400, 500, 600, 700, 800, 900, 1000, 1250, 1500, 1750, 2000
            ]
        );
        assert_eq!(now, t0 + ms(2250), "waiting out the idle interval");
        // A change while an idle wait runs: the next cycle goes when the fast one would
        // have (at once here: 100 ms after the last cycle have passed), then fast again.
        s.activity(t0 + ms(2150));
        now = t0 + ms(2150);
        let starts = run_until(&mut s, t0 + ms(2500), &mut now);
        assert_eq!(starts, [2150, 2250, 2350, 2450]);
        // A change soon after a cycle started: the next one comes 100 ms after it.
        let mut s = Scheduler::new(
            Polling {
                interval: Some(ms(100)),
                idle_interval: Some(ms(250)),
                commands: vec![Command::SystemStatus],
            },
            t0,
        );
        let mut now = t0 + ms(5000);
        assert!(matches!(s.next(now, &mut new_id), Next::Send(_)));
        assert_eq!(s.next(now, &mut new_id), Next::Wait(Some(now + ms(250))));
        s.activity(now + ms(10));
        assert_eq!(
            s.next(now + ms(10), &mut new_id),
            Next::Wait(Some(now + ms(100)))
        );
        now += ms(100);
        assert!(matches!(s.next(now, &mut new_id), Next::Send(_)));
    }

    #[test]
    fn user_commands_wait_behind_no_more_than_the_poll_in_flight() {
        let t0 = Instant::now();
        let mut s = Scheduler::new(Polling::default(), t0);
        let mut new_id = ids();
        let Next::Send(_poll) = s.next(t0, &mut new_id) else {
            panic!()
        };
        s.push(user(7, Command::AlarmReset, Priority::User));
        assert!(matches!(s.next(t0, &mut new_id), Next::Send(p) if p.id == RequestId(7)));
    }

    #[test]
    fn paused_polls_are_not_made_and_resume_at_once() {
        let t0 = Instant::now();
        let mut s = Scheduler::new(Polling::default(), t0);
        let mut new_id = ids();
        s.pause_polls(true, t0);
        let later = t0 + Duration::from_secs(1);
        assert_eq!(s.next(later, &mut new_id), Next::Wait(None));
        s.pause_polls(false, later);
        assert!(matches!(s.next(later, &mut new_id), Next::Send(p) if p.origin == Origin::Poll));
    }

    #[test]
    fn an_interval_with_no_commands_waits_for_submissions_instead_of_spinning() {
        let t0 = Instant::now();
        let polling = Polling {
            interval: Some(Duration::from_millis(10)),
            idle_interval: None,
            commands: Vec::new(),
        };
        let mut s = Scheduler::new(polling, t0);
        let mut new_id = ids();
        let later = t0 + Duration::from_secs(1);
        assert_eq!(s.next(later, &mut new_id), Next::Wait(None));
    }

    #[test]
    fn table_chunks_interleave_with_polls() {
        let t0 = Instant::now();
        let polling = Polling {
            interval: Some(Duration::ZERO),
            idle_interval: None,
            commands: vec![Command::SystemStatus],
        };
        let mut s = Scheduler::new(polling, t0);
        let mut new_id = ids();
        s.start_table(TableRequest {
            kind: CoordKind::Work,
            axes: AxisPattern::SCARA_1,
            first: 0,
            records: 32,
            reply_buffer: 2048,
        });
        let mut kinds = Vec::new();
        for _ in 0..4 {
            let Next::Send(p) = s.next(t0, &mut new_id) else {
                panic!()
            };
            kinds.push(matches!(p.origin, Origin::Table { .. }));
        }
        assert_eq!(
            kinds,
            [false, true, false, false],
            "poll, chunk, then polls (32 records = 1 chunk)"
        );
    }

    fn spare(id: u64) -> Pending {
        use crate::protocol::{BitQuery, BitSpace};
        let q = BitQuery {
            space: BitSpace::Input,
            program: 0,
            start: 0,
            count: 64,
        };
        Pending::new(
            RequestId(id),
            Command::BitQuery(q),
            Origin::User,
            Priority::Spare,
        )
    }

    /// Sends `n` requests, each taking `took` on the line; which were spare.
    fn run_line(s: &mut Scheduler, t0: Instant, took: Duration, n: usize) -> Vec<bool> {
        let mut new_id = ids();
        let mut now = t0;
        let mut sent = Vec::new();
        while sent.len() < n {
            match s.next(now, &mut new_id) {
                Next::Send(p) => {
                    sent.push(p.priority == Priority::Spare);
                    now += took;
                }
                Next::Wait(Some(at)) => now = at.max(now + Duration::from_micros(1)),
                Next::Wait(None) => break,
            }
        }
        sent
    }

    #[test]
    fn spare_reads_go_in_the_time_the_polls_leave() {
        let t0 = Instant::now();
        let polling = Polling {
            interval: Some(Duration::from_millis(100)),
            idle_interval: None,
            commands: vec![Command::SystemStatus],
        };
        let mut s = Scheduler::new(polling, t0);
        for i in 0..3 {
            s.push(spare(i));
        }
        // A poll takes 5 ms; a spare read at 115200 baud ends long before the next poll.
        let sent = run_line(&mut s, t0, Duration::from_millis(5), 5);
        assert_eq!(sent, [false, true, true, true, false]);
    }

    #[test]
    fn on_a_saturated_line_spare_reads_take_only_their_share() {
        let t0 = Instant::now();
        let polling = Polling {
            interval: Some(Duration::from_millis(10)),
            idle_interval: None,
            commands: vec![Command::SystemStatus, Command::SystemStatus],
        };
        let mut s = Scheduler::new(polling, t0);
        let mut slow = Timing::default();
        slow.line.baud = 9_600;
        s.set_timing(slow);
        for i in 0..100 {
            s.push(spare(i));
        }
        // Each transaction takes 20 ms: polls run back to back and are always due.
        let sent = run_line(&mut s, t0, Duration::from_millis(20), 2_000);
        let spares = sent.iter().filter(|&&x| x).count();
        let cycles = (sent.len() - spares) / 2;
        // Each transaction took 20 ms: the spare reads' share of all the line's time.
        let took = Duration::from_millis(20);
        let spare_time = took * spares as u32;
        let all_time = took * sent.len() as u32;
        assert!(spares > 0, "spare reads are not starved");
        assert!(
            spare_time <= all_time / SPARE_SHARE + took,
            "{spares} spare reads in {cycles} cycles"
        );
        // Never inside a cycle.
        let mut pos = 0;
        for x in sent {
            if x {
                assert_eq!(pos % 2, 0);
            } else {
                pos += 1;
            }
        }
    }
}
