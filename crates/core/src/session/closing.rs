//! A session closing on a thread of its own, so the window goes on drawing and its STOP
//! still reaches the closing link while the link ends its transaction, delivers the STOPs
//! it owes and closes the line (up to a reply time-out each, and a reconnect's wait).

use std::thread::JoinHandle;

/// Sends a STOP of every axis into a link that is closing.
pub type Stopper = Box<dyn Fn() + Send>;

/// One session on its way out.
pub struct Closing {
    /// Which line, for messages: "the X-SEL's line".
    pub what: &'static str,
    stop: Option<Stopper>,
    /// Closes the session; its answer is a problem to report, if any.
    thread: Option<JoinHandle<Option<String>>>,
}

impl Closing {
    /// Closes `session` with `close` on a new thread; `stop`, when given, reaches the
    /// link while it closes.
    pub fn start<T: Send + 'static>(
        what: &'static str,
        session: T,
        stop: Option<Stopper>,
        close: impl FnOnce(T) -> Option<String> + Send + 'static,
    ) -> Closing {
        let thread = std::thread::Builder::new()
            .name("session-close".into())
            .spawn(move || close(session));
        match thread {
            Ok(thread) => Closing {
                what,
                stop,
                thread: Some(thread),
            },
            // No thread to be had: close here, as before (the window waits).
            Err(e) => {
                let _ = e;
                Closing {
                    what,
                    stop: None,
                    thread: None,
                }
            }
        }
    }

    /// STOP for all axes into the closing link (it still sends STOPs).
    pub fn stop_all(&self) {
        if let Some(stop) = &self.stop {
            stop();
        }
    }

    /// Whether the close has ended.
    pub fn is_done(&self) -> bool {
        self.thread.as_ref().is_none_or(JoinHandle::is_finished)
    }

    /// Waits for the close to end; a problem it met, for Messages.
    pub fn finish(mut self) -> Option<String> {
        let thread = self.thread.take()?;
        match thread.join() {
            Ok(problem) => problem.map(|p| format!("{} closed: {p}", self.what)),
            Err(_) => Some(format!("{}: its close failed", self.what)),
        }
    }
}

impl Drop for Closing {
    /// Never left behind: dropping one waits for its close (the window's exit).
    fn drop(&mut self) {
        if let Some(thread) = self.thread.take() {
            let _ = thread.join();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::{AtomicUsize, Ordering};
    use std::sync::{Arc, mpsc};
    use std::time::Duration;

    #[test]
    fn a_close_runs_on_its_own_thread_and_takes_stops_meanwhile() {
        let (release, wait) = mpsc::channel::<()>();
        let stops = Arc::new(AtomicUsize::new(0));
        let counted = stops.clone();
        let closing = Closing::start(
            "the test line",
            wait,
            Some(Box::new(move || {
                counted.fetch_add(1, Ordering::SeqCst);
            })),
            |wait| {
                let _ = wait.recv();
                Some("a STOP could not be sent".into())
            },
        );
        // The close is blocked: the caller is not.
        assert!(!closing.is_done());
        closing.stop_all();
        assert_eq!(stops.load(Ordering::SeqCst), 1);
        release.send(()).unwrap();
        let deadline = std::time::Instant::now() + Duration::from_secs(10);
        while !closing.is_done() {
            assert!(std::time::Instant::now() < deadline, "the close ends");
            std::thread::yield_now();
        }
        assert_eq!(
            closing.finish().as_deref(),
            Some("the test line closed: a STOP could not be sent")
        );
    }
}
