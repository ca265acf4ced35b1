//! Work the frame log pane runs off the UI thread as jobs (`files::job`): filtering a
//! whole log, saving and opening files. The pane polls each job every frame.

use std::io::BufReader;
use std::path::PathBuf;
use std::time::Instant;

use crate::files::job::{Ctl, Job};
use crate::files::{Overwrite, Watched, WriteError, open_regular, write_file};
use crate::pendant::frame_log::file::{read_jsonl, write_jsonl, write_text};
use crate::pendant::frame_log::filter::Matcher;
use crate::pendant::frame_log::{FrameLog, Snapshot};

/// The rows of a snapshot that pass a filter, and where the scan ended.
pub struct Filtered {
    pub seqs: Vec<u64>,
    pub end: u64,
}

/// Filters a snapshot on another thread.
pub fn filter(snapshot: Snapshot, matcher: Matcher, now: Instant) -> Result<Job<Filtered>, String> {
    Job::spawn("filter the frame log", now, move |_| {
        filter_now(&snapshot, &matcher)
    })
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

/// A finished save: the path, and how many rows were written or why none were.
pub struct Saved {
    pub path: PathBuf,
    pub format: Format,
    pub result: Result<u64, WriteError>,
}

/// Saves rows (all of the snapshot, or only `only`) to `path`, whole (a new file renamed
/// into place: a full disk leaves the old file as it was), asking first before replacing.
pub fn save(
    snapshot: Snapshot,
    only: Option<Vec<u64>>,
    format: Format,
    path: PathBuf,
    overwrite: Overwrite,
    now: Instant,
) -> Result<Job<Saved>, String> {
    let what = format!("saving {}", path.display());
    Job::spawn_opening(what, now, move |ctl| {
        let result = save_now(&snapshot, only.as_deref(), format, &path, overwrite, ctl);
        Saved {
            path,
            format,
            result,
        }
    })
}

fn save_now(
    snapshot: &Snapshot,
    only: Option<&[u64]>,
    format: Format,
    path: &std::path::Path,
    overwrite: Overwrite,
    ctl: &Ctl,
) -> Result<u64, WriteError> {
    let rows: Box<dyn Iterator<Item = _>> = match only {
        Some(seqs) => Box::new(seqs.iter().filter_map(|&s| snapshot.row(s))),
        None => Box::new(snapshot.rows()),
    };
    // The log is bounded by its cap: it is put together in memory, then written whole.
    let mut bytes = Vec::new();
    let written = match format {
        Format::Text => write_text(&mut bytes, snapshot.origin_wall, rows),
        Format::JsonLines => write_jsonl(&mut bytes, snapshot.origin_wall, rows),
    }
    .map_err(|e| WriteError::Failed(format!("cannot write {}: {e}", path.display())))?;
    write_file(path, &bytes, overwrite, ctl)?;
    Ok(written)
}

/// An opened log, or why it could not be read, with its path.
pub type Opened = (PathBuf, Result<FrameLog, String>);

/// Opens a JSON Lines log (a regular file only, read with a bound per line and the
/// log's cap), with progress and Cancel.
pub fn open(path: PathBuf, cap: usize, now: Instant) -> Result<Job<Opened>, String> {
    let what = format!("reading {}", path.display());
    Job::spawn_opening(what, now, move |ctl| {
        let read = open_regular(&path, ctl).and_then(|(file, _)| {
            let read = read_jsonl(BufReader::new(Watched { inner: file, ctl }), cap);
            if ctl.cancelled() {
                return Err(format!(
                    "reading {} was cancelled: nothing changed",
                    path.display()
                ));
            }
            read.map_err(|e| format!("{}: {e}", path.display()))
        });
        (path, read)
    })
}
