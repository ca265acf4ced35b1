//! Work the frame log pane runs off the UI thread: filtering a whole log, saving and
//! opening files. Each job reports once over a channel; the pane polls it every frame.

use std::fs::File;
use std::io::{BufReader, BufWriter};
use std::path::PathBuf;
use std::thread;

use crossbeam_channel::{Receiver, bounded};

use crate::pendant::frame_log::file::{read_jsonl, write_jsonl, write_text};
use crate::pendant::frame_log::filter::Matcher;
use crate::pendant::frame_log::{FrameLog, Snapshot};

/// A job running on its own thread.
pub struct Job<T> {
    rx: Receiver<T>,
}

impl<T: Send + 'static> Job<T> {
    fn spawn(name: &str, work: impl FnOnce() -> T + Send + 'static) -> Result<Job<T>, String> {
        let (tx, rx) = bounded(1);
        thread::Builder::new()
            .name(name.into())
            .spawn(move || {
                let _ = tx.send(work());
            })
            .map_err(|e| format!("cannot start the {name} thread: {e}"))?;
        Ok(Job { rx })
    }

    /// The result, once there is one.
    pub fn poll(&self) -> Option<T> {
        self.rx.try_recv().ok()
    }
}

/// The rows of a snapshot that pass a filter, and where the scan ended.
pub struct Filtered {
    pub seqs: Vec<u64>,
    pub end: u64,
}

/// Filters a snapshot on another thread.
pub fn filter(snapshot: Snapshot, matcher: Matcher) -> Result<Job<Filtered>, String> {
    Job::spawn("frame-log filter", move || filter_now(&snapshot, &matcher))
}

/// Filters a snapshot here (the thread's work; benches time it).
pub fn filter_now(snapshot: &Snapshot, matcher: &Matcher) -> Filtered {
    let seqs = snapshot
        .rows()
        .filter(|r| matcher.matches(r))
        .map(|r| r.seq())
        .collect();
    Filtered {
        seqs,
        end: snapshot.end(),
    }
}

/// Which format to save.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    Text,
    JsonLines,
}

/// Saves rows (all of the snapshot, or only `only`) to `path`; says how many.
pub fn save(
    snapshot: Snapshot,
    only: Option<Vec<u64>>,
    format: Format,
    path: PathBuf,
) -> Result<Job<Result<String, String>>, String> {
    // A pipe or a device would block the job for good: refused before it starts.
    crate::files::check_target(&path)?;
    Job::spawn("frame-log save", move || {
        let file =
            File::create(&path).map_err(|e| format!("cannot create {}: {e}", path.display()))?;
        let mut out = BufWriter::new(file);
        let rows: Box<dyn Iterator<Item = _>> = match &only {
            Some(seqs) => Box::new(seqs.iter().filter_map(|&s| snapshot.row(s))),
            None => Box::new(snapshot.rows()),
        };
        let written = match format {
            Format::Text => write_text(&mut out, snapshot.origin_wall, rows),
            Format::JsonLines => write_jsonl(&mut out, snapshot.origin_wall, rows),
        }
        .map_err(|e| format!("cannot write {}: {e}", path.display()))?;
        Ok(format!("saved {written} rows to {}", path.display()))
    })
}

/// Opens a JSON Lines log.
pub fn open(path: PathBuf, cap: usize) -> Result<Job<Result<FrameLog, String>>, String> {
    // A pipe or a device would block the open, or never end: refused before the job.
    let meta =
        std::fs::metadata(&path).map_err(|e| format!("cannot open {}: {e}", path.display()))?;
    if !meta.is_file() {
        return Err(format!(
            "{} is not a regular file (a folder, pipe or device): it is not read",
            path.display()
        ));
    }
    Job::spawn("frame-log open", move || {
        let file = File::open(&path).map_err(|e| format!("cannot open {}: {e}", path.display()))?;
        read_jsonl(BufReader::new(file), cap).map_err(|e| format!("{}: {e}", path.display()))
    })
}
