//! One shape for every piece of file work the window asks for: it runs on a thread of its
//! own, reports progress, can be cancelled, and gives up on a file that does not open in
//! time (a network share or device not answering), so the window keeps painting and STOP
//! keeps working whatever the file does. The window polls it each frame with the time.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::{Duration, Instant};

use crossbeam_channel::{Receiver, TryRecvError, bounded};

/// How long a file may take to open before the job is given up (inferred: a local disk
/// opens in well under a millisecond; a share that has not answered in this long is
/// taken for gone, and the user can try again).
pub const OPEN_LIMIT: Duration = Duration::from_secs(5);

/// What the job and the window share.
#[derive(Debug, Default)]
struct Shared {
    cancelled: AtomicBool,
    opened: AtomicBool,
    done: AtomicU64,
    total: AtomicU64,
}

/// The job's side: it says when its file opened and how far it got, and asks whether it
/// was cancelled.
#[derive(Clone, Debug, Default)]
pub struct Ctl(Arc<Shared>);

impl Ctl {
    /// A control nobody watches (for work done in place: the CLI, tests).
    pub fn detached() -> Self {
        Self::default()
    }

    /// The file is open: the open time limit no longer applies.
    pub fn opened(&self) {
        self.0.opened.store(true, Ordering::Relaxed);
    }

    /// The job's whole size, in whatever unit it counts (bytes, rows).
    pub fn set_total(&self, total: u64) {
        self.0.total.store(total, Ordering::Relaxed);
    }

    /// `n` more units done.
    pub fn advance(&self, n: u64) {
        self.0.done.fetch_add(n, Ordering::Relaxed);
    }

    /// Whether the user cancelled: the job should stop at the next chance.
    pub fn cancelled(&self) -> bool {
        self.0.cancelled.load(Ordering::Relaxed)
    }
}

/// Where a job stands when polled.
#[derive(Debug, PartialEq)]
pub enum JobPoll<T> {
    Running,
    Done(T),
    /// Its file did not open within [`OPEN_LIMIT`]: given up (the thread, stuck in the
    /// OS, is left behind and its result, if any, dropped).
    OpenTimedOut,
    /// The thread ended without a result (it panicked).
    Lost,
}

/// Why a job ended without its result.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
pub enum JobLost {
    #[error(
        "the file did not open within {} s (a network share or device not answering?)",
        OPEN_LIMIT.as_secs()
    )]
    OpenTimedOut,
    #[error("the job stopped unexpectedly")]
    Lost,
}

/// How far a job got: `done` of `total` (`None` while not known).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Progress {
    pub done: u64,
    pub total: Option<u64>,
}

/// A piece of work on its own thread.
#[derive(Debug)]
pub struct Job<T> {
    rx: Receiver<T>,
    ctl: Ctl,
    started: Instant,
    /// Whether the open time limit applies (work that opens no file has none).
    opens_file: bool,
    what: String,
}

impl<T: Send + 'static> Job<T> {
    /// Runs `work` that opens no file (filtering, painting): no time limit.
    pub fn spawn(
        what: impl Into<String>,
        now: Instant,
        work: impl FnOnce(&Ctl) -> T + Send + 'static,
    ) -> Result<Self, String> {
        Self::start(what.into(), now, false, work)
    }

    /// Runs `work` that opens a file and calls [`Ctl::opened`] once it has.
    pub fn spawn_opening(
        what: impl Into<String>,
        now: Instant,
        work: impl FnOnce(&Ctl) -> T + Send + 'static,
    ) -> Result<Self, String> {
        Self::start(what.into(), now, true, work)
    }

    fn start(
        what: String,
        now: Instant,
        opens_file: bool,
        work: impl FnOnce(&Ctl) -> T + Send + 'static,
    ) -> Result<Self, String> {
        let (tx, rx) = bounded(1);
        let ctl = Ctl::default();
        let theirs = ctl.clone();
        std::thread::Builder::new()
            .name(format!("job: {what}"))
            .spawn(move || {
                let _ = tx.send(work(&theirs));
            })
            .map_err(|e| format!("cannot start a thread to {what}: {e}"))?;
        Ok(Self {
            rx,
            ctl,
            started: now,
            opens_file,
            what,
        })
    }

    /// Where the job stands at `now`.
    pub fn poll(&self, now: Instant) -> JobPoll<T> {
        match self.rx.try_recv() {
            Ok(done) => JobPoll::Done(done),
            Err(TryRecvError::Disconnected) => JobPoll::Lost,
            Err(TryRecvError::Empty) => {
                let opened = self.ctl.0.opened.load(Ordering::Relaxed);
                if self.opens_file && !opened && now.duration_since(self.started) >= OPEN_LIMIT {
                    self.cancel();
                    JobPoll::OpenTimedOut
                } else {
                    JobPoll::Running
                }
            }
        }
    }

    /// A finished job's result taken out of `slot` (which is then empty): `None` while
    /// it runs (or there is none), else the result or why there is none.
    pub fn take(slot: &mut Option<Self>, now: Instant) -> Option<Result<T, JobLost>> {
        let done = match slot.as_ref()?.poll(now) {
            JobPoll::Running => return None,
            JobPoll::Done(done) => Ok(done),
            JobPoll::OpenTimedOut => Err(JobLost::OpenTimedOut),
            JobPoll::Lost => Err(JobLost::Lost),
        };
        *slot = None;
        Some(done)
    }

    /// Waits at most `limit` for the result (at exit, and in tests).
    pub fn wait(&self, limit: Duration) -> Option<T> {
        self.rx.recv_timeout(limit).ok()
    }

    /// Asks the job to stop; the window drops it and says so.
    pub fn cancel(&self) {
        self.ctl.0.cancelled.store(true, Ordering::Relaxed);
    }

    pub fn progress(&self) -> Progress {
        let total = self.ctl.0.total.load(Ordering::Relaxed);
        Progress {
            done: self.ctl.0.done.load(Ordering::Relaxed),
            total: (total > 0).then_some(total),
        }
    }

    /// How long it has run at `now`.
    pub fn elapsed(&self, now: Instant) -> Duration {
        now.saturating_duration_since(self.started)
    }

    /// What it does, for the window ("read /home/op/points.csv").
    pub fn what(&self) -> &str {
        &self.what
    }

    /// Whether its file has opened (false until then for a job that opens one).
    pub fn is_open(&self) -> bool {
        !self.opens_file || self.ctl.0.opened.load(Ordering::Relaxed)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_result_is_polled_once_it_is_there_and_progress_is_seen() {
        let t0 = Instant::now();
        let job = Job::spawn("count", t0, |ctl| {
            ctl.set_total(10);
            ctl.advance(4);
            7
        })
        .unwrap();
        assert_eq!(job.wait(Duration::from_secs(10)), Some(7));
        assert_eq!(
            job.progress(),
            Progress {
                done: 4,
                total: Some(10)
            }
        );
    }

    #[test]
    fn a_file_that_never_opens_is_given_up_at_the_limit_on_the_virtual_clock() {
        let (release, stuck) = bounded::<()>(0);
        let t0 = Instant::now();
        let job = Job::spawn_opening("open a dead share", t0, move |ctl| {
            let _ = stuck.recv();
            ctl.cancelled()
        })
        .unwrap();
        assert_eq!(job.poll(t0 + OPEN_LIMIT / 2), JobPoll::Running);
        assert!(!job.is_open());
        assert_eq!(job.poll(t0 + OPEN_LIMIT), JobPoll::OpenTimedOut);
        // The stuck thread, once the OS lets it go, sees that it was given up.
        drop(release);
        assert_eq!(job.wait(Duration::from_secs(10)), Some(true));
    }

    #[test]
    fn an_opened_file_has_no_limit_and_a_cancel_reaches_the_work() {
        let (go, wait) = bounded::<()>(0);
        let t0 = Instant::now();
        let job = Job::spawn_opening("read", t0, move |ctl| {
            ctl.opened();
            let _ = wait.recv();
            ctl.cancelled()
        })
        .unwrap();
        let deadline = Instant::now() + Duration::from_secs(10);
        while !job.is_open() && Instant::now() < deadline {
            std::thread::yield_now();
        }
        assert_eq!(job.poll(t0 + OPEN_LIMIT * 10), JobPoll::Running);
        job.cancel();
        drop(go);
        assert_eq!(job.wait(Duration::from_secs(10)), Some(true));
    }

    #[test]
    fn a_job_that_panics_is_lost_not_waited_for() {
        let job: Job<u8> = Job::spawn("panic", Instant::now(), |_| panic!("boom")).unwrap();
        assert_eq!(job.wait(Duration::from_secs(10)), None);
        assert_eq!(job.poll(Instant::now()), JobPoll::Lost);
    }
}
