//! Operator work kept in a file of its own beside the settings (the teach list, the
//! coordinate drafts): written on every change, as a job off the UI thread, as a new file
//! renamed over the old one, the previous good copy kept as `.bak`; a failed write is said
//! once and retried every few seconds; at start the file (or its `.bak`) is read back,
//! and an unreadable file is moved aside, never overwritten.

use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant, SystemTime};

use super::job::Job;
use super::{DOCUMENT_LIMIT, read_bounded};

/// How long after a failed write it is tried again (a full disk, a share gone away).
const RETRY_EVERY: Duration = Duration::from_secs(5);

/// What a save has to tell the operator.
#[derive(Clone, Debug, PartialEq)]
pub enum SaveNews {
    /// The write failed (said once until it works again).
    Failed(String),
    /// A write worked again after failing.
    Recovered(String),
}

/// What was read back at start.
#[derive(Debug)]
pub struct Restored<T> {
    pub value: Option<T>,
    /// Sentences for Messages: read from the backup, set aside, ...
    pub notes: Vec<String>,
}

/// What a write job ends with: how many tries failed before it wrote, or why it stopped.
type WriteResult = Result<u64, String>;

/// One file of operator work and how its writing goes.
#[derive(Debug)]
pub struct SavedFile {
    path: PathBuf,
    /// What it holds, for messages ("teach list").
    what: &'static str,
    /// The revision last written (or read back).
    written: Option<u64>,
    /// The last write failed (said once, until one works again).
    failing: bool,
    /// The write under way: it tries again every [`RETRY_EVERY`] by itself until it
    /// works or a newer revision replaces it, whatever the window is doing.
    writing: Option<Job<WriteResult>>,
    /// The revision the write under way writes.
    writing_revision: u64,
    /// Held by whoever writes the file: a write replaced by a newer one checks, under it,
    /// that it was not cancelled, so it never lands after the newer one.
    lock: Arc<Mutex<()>>,
    /// Why the write under way last failed.
    last_error: Arc<Mutex<String>>,
}

impl SavedFile {
    pub fn new(path: PathBuf, what: &'static str) -> Self {
        Self {
            path,
            what,
            written: None,
            failing: false,
            writing: None,
            writing_revision: 0,
            lock: Arc::default(),
            last_error: Arc::default(),
        }
    }

    pub fn path(&self) -> &Path {
        &self.path
    }

    fn backup(&self) -> PathBuf {
        with_suffix(&self.path, ".bak")
    }

    /// Reads the file back with `parse`; a file that cannot be read or parsed is moved
    /// aside (`<name>.unreadable-<unix seconds>`) and the backup is tried.
    pub fn restore<T>(&self, parse: impl Fn(&[u8]) -> Result<T, String>) -> Restored<T> {
        let mut notes = Vec::new();
        for (path, is_backup) in [(self.path.clone(), false), (self.backup(), true)] {
            if !path.exists() {
                continue;
            }
            let read = read_bounded(&path, DOCUMENT_LIMIT).and_then(|b| parse(&b));
            match read {
                Ok(value) => {
                    if is_backup {
                        notes.push(format!(
                            "the {} was read from its last good copy {}",
                            self.what,
                            path.display()
                        ));
                    }
                    return Restored {
                        value: Some(value),
                        notes,
                    };
                }
                Err(why) => notes.push(self.set_aside(&path, &why)),
            }
        }
        Restored { value: None, notes }
    }

    fn set_aside(&self, path: &Path, why: &str) -> String {
        let secs = SystemTime::now()
            .duration_since(SystemTime::UNIX_EPOCH)
            .map_or(0, |d| d.as_secs());
        let aside = with_suffix(path, &format!(".unreadable-{secs}"));
        match std::fs::rename(path, &aside) {
            Ok(()) => format!(
                "the saved {} could not be read ({why}); it was kept as {}",
                self.what,
                aside.display()
            ),
            Err(e) => format!(
                "the saved {} could not be read ({why}) nor moved aside ({e}); it is left in {}",
                self.what,
                path.display()
            ),
        }
    }

    /// Whether the last change was written (false until the first write or restore, and
    /// while writing fails).
    pub fn is_saved(&self) -> bool {
        self.written.is_some() && !self.failing
    }

    /// The revision now shown came from the file: nothing to write for it.
    pub fn mark_written(&mut self, revision: u64) {
        self.written = Some(revision);
    }

    /// Starts writing `contents()` when `revision` was not written yet; one write at a
    /// time, off the calling thread (a failing write of an older revision is replaced).
    /// Says what the operator should hear of the last write.
    pub fn save(
        &mut self,
        revision: u64,
        now: Instant,
        contents: impl FnOnce() -> Vec<u8>,
    ) -> Option<SaveNews> {
        let news = self.poll_write(now);
        if self.written == Some(revision) {
            return news;
        }
        if let Some(job) = &self.writing {
            if self.writing_revision == revision || !self.failing {
                // It writes this revision, or an older one that will soon be done.
                return news;
            }
            // An older revision that keeps failing: this one takes its place.
            job.cancel();
            self.writing = None;
        }
        let bytes = contents();
        let what = format!("save the {} to {}", self.what, self.path.display());
        let (path, lock, last_error) = (
            self.path.clone(),
            self.lock.clone(),
            self.last_error.clone(),
        );
        match Job::spawn_opening(what, now, move |ctl| {
            ctl.opened();
            write_retrying(&path, &bytes, &lock, ctl, &last_error)
        }) {
            Ok(job) => {
                self.writing = Some(job);
                self.writing_revision = revision;
            }
            Err(e) => return news.or(self.failed(&e)),
        }
        news
    }

    /// Waits at most `limit` for the write under way, then writes `contents()` here
    /// if `revision` is still not written (at exit: nothing the operator did is left
    /// in memory only).
    pub fn flush(
        &mut self,
        revision: u64,
        limit: std::time::Duration,
        contents: impl FnOnce() -> Vec<u8>,
    ) -> Option<SaveNews> {
        if self.failing
            && let Some(job) = &self.writing
        {
            // It is waiting to try again: this write goes now instead.
            job.cancel();
        }
        let _ = self.settle(limit, Instant::now());
        if self.written == Some(revision) && !self.failing {
            return None;
        }
        let written = {
            let _held = self.lock.lock().unwrap_or_else(|e| e.into_inner());
            write_atomic(&self.path, &contents())
        };
        match written {
            Ok(()) => {
                self.written = Some(revision);
                self.failing = false;
                None
            }
            Err(e) => self.failed(&e.to_string()),
        }
    }

    /// Takes the result of a write that finished, or notices that the one under way
    /// has failed (it goes on trying by itself).
    fn poll_write(&mut self, now: Instant) -> Option<SaveNews> {
        if let Some(job) = &self.writing
            && job.progress().done > 0
            && !self.failing
        {
            let why = self
                .last_error
                .lock()
                .map(|e| e.clone())
                .unwrap_or_default();
            return self.failed(&why);
        }
        let done = Job::take(&mut self.writing, now)?;
        let result = match done {
            Ok(written) => written,
            Err(lost) => Err(lost.to_string()),
        };
        self.finish(self.writing_revision, result)
    }

    /// Waits at most `limit` for the write under way and takes its result (at exit; in
    /// tests).
    pub fn settle(&mut self, limit: std::time::Duration, now: Instant) -> Option<SaveNews> {
        let job = self.writing.take()?;
        let revision = self.writing_revision;
        let result = job
            .wait(limit)
            .unwrap_or_else(|| Err("not done in time".to_owned()));
        let _ = now;
        self.finish(revision, result)
    }

    fn finish(&mut self, revision: u64, result: WriteResult) -> Option<SaveNews> {
        match result {
            Ok(failures) => {
                self.written = Some(revision);
                let was_failing = std::mem::take(&mut self.failing);
                (was_failing || failures > 0).then(|| {
                    SaveNews::Recovered(format!(
                        "the {} is saved again to {}",
                        self.what,
                        self.path.display()
                    ))
                })
            }
            Err(e) if e == SUPERSEDED => None,
            Err(e) => self.failed(&e),
        }
    }

    fn failed(&mut self, why: &str) -> Option<SaveNews> {
        let first = !std::mem::replace(&mut self.failing, true);
        first.then(|| {
            SaveNews::Failed(format!(
                "the {} could not be saved to {} ({why}); the last saved copy is kept, \
                 and saving is tried again every {} s",
                self.what,
                self.path.display(),
                RETRY_EVERY.as_secs()
            ))
        })
    }

    /// Whether a write is under way.
    pub fn is_writing(&self) -> bool {
        self.writing.is_some()
    }
}

/// Why a write job stopped when a newer one (or the flush at exit) took its place.
const SUPERSEDED: &str = "replaced by a newer write";

/// Writes `bytes` to `path`, and after a failure (a full disk, a share gone away) tries
/// again every [`RETRY_EVERY`] until it works or the job is cancelled; each failure is
/// counted in the job's progress and its reason kept in `last_error`.
fn write_retrying(
    path: &Path,
    bytes: &[u8],
    lock: &Mutex<()>,
    ctl: &super::job::Ctl,
    last_error: &Mutex<String>,
) -> WriteResult {
    let mut failures = 0;
    loop {
        let written = {
            let _held = lock.lock().unwrap_or_else(|e| e.into_inner());
            if ctl.cancelled() {
                return Err(SUPERSEDED.to_owned());
            }
            write_atomic(path, bytes)
        };
        match written {
            Ok(()) => return Ok(failures),
            Err(e) => {
                if let Ok(mut last) = last_error.lock() {
                    *last = e.to_string();
                }
                failures += 1;
                ctl.advance(1);
            }
        }
        // Waits out the retry time, in slices, so a cancel ends it at once.
        let until = Instant::now() + RETRY_EVERY;
        while Instant::now() < until {
            if ctl.cancelled() {
                return Err(SUPERSEDED.to_owned());
            }
            std::thread::sleep(Duration::from_millis(50));
        }
    }
}

fn with_suffix(path: &Path, suffix: &str) -> PathBuf {
    let mut name = path.as_os_str().to_owned();
    name.push(suffix);
    PathBuf::from(name)
}

/// `bytes` into `path` so that a crash or a full disk at any moment leaves the old file
/// or the new one whole: a new file written and flushed, the old one renamed to `.bak`,
/// the new one renamed into place.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    write_replacing(path, bytes, Some(&with_suffix(path, ".bak")))
}

/// `bytes` into `path` through a new file renamed into place; the old file, if any, is
/// renamed to `backup` first (or simply replaced).
pub fn write_replacing(path: &Path, bytes: &[u8], backup: Option<&Path>) -> std::io::Result<()> {
    use std::io::Write;
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir)?;
    }
    let new = with_suffix(path, ".new");
    let written = std::fs::File::create(&new).and_then(|mut f| {
        f.write_all(bytes)?;
        f.sync_all()
    });
    if let Err(e) = written {
        let _ = std::fs::remove_file(&new);
        return Err(e);
    }
    if let Some(backup) = backup
        && path.exists()
    {
        std::fs::rename(path, backup)?;
    }
    std::fs::rename(&new, path)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dir(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("xsel-saved-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        d
    }

    fn text(b: &[u8]) -> Result<String, String> {
        let s = String::from_utf8(b.to_vec()).map_err(|e| e.to_string())?;
        if s.starts_with("ok") {
            Ok(s)
        } else {
            Err("not ok".into())
        }
    }

    const LIMIT: Duration = Duration::from_secs(10);

    /// A save and the wait for its job: what the operator is told.
    fn saved(
        f: &mut SavedFile,
        revision: u64,
        now: Instant,
        contents: impl FnOnce() -> Vec<u8>,
    ) -> Option<SaveNews> {
        let started = f.save(revision, now, contents);
        started.or(f.settle(LIMIT, now))
    }

    #[test]
    fn every_change_is_written_whole_and_the_last_good_copy_kept() {
        let d = dir("write");
        let mut f = SavedFile::new(d.join("teach.json"), "teach list");
        let now = Instant::now();
        assert_eq!(saved(&mut f, 1, now, || b"ok 1".to_vec()), None);
        assert_eq!(saved(&mut f, 1, now, || panic!("written twice")), None);
        assert_eq!(saved(&mut f, 2, now, || b"ok 2".to_vec()), None);
        assert_eq!(std::fs::read(f.path()).unwrap(), b"ok 2");
        assert_eq!(std::fs::read(d.join("teach.json.bak")).unwrap(), b"ok 1");
        assert!(!d.join("teach.json.new").exists(), "a stray new file");
        assert_eq!(f.restore(text).value.as_deref(), Some("ok 2"));
    }

    #[test]
    fn a_change_while_a_write_runs_is_written_after_it_and_a_flush_leaves_nothing_unsaved() {
        let d = dir("busy");
        let mut f = SavedFile::new(d.join("teach.json"), "teach list");
        let now = Instant::now();
        f.save(1, now, || b"ok 1".to_vec());
        // A second change while the first write may still run: written after it, or now.
        f.save(2, now, || b"ok 2".to_vec());
        assert_eq!(f.flush(3, LIMIT, || b"ok 3".to_vec()), None);
        assert!(f.is_saved() && !f.is_writing());
        assert_eq!(std::fs::read(f.path()).unwrap(), b"ok 3");
    }

    #[test]
    fn an_unreadable_file_is_set_aside_and_the_backup_read() {
        let d = dir("aside");
        let mut f = SavedFile::new(d.join("teach.json"), "teach list");
        let now = Instant::now();
        saved(&mut f, 1, now, || b"ok first".to_vec());
        saved(&mut f, 2, now, || b"ok second".to_vec());
        std::fs::write(f.path(), b"garbage").unwrap();
        let r = f.restore(text);
        assert_eq!(r.value.as_deref(), Some("ok first"));
        assert!(
            r.notes.iter().any(|n| n.contains("kept as")),
            "{:?}",
            r.notes
        );
        assert!(
            r.notes.iter().any(|n| n.contains("last good copy")),
            "{:?}",
            r.notes
        );
        let aside = std::fs::read_dir(&d)
            .unwrap()
            .flatten()
            .find(|e| e.file_name().to_string_lossy().contains("unreadable"))
            .expect("the unreadable file kept");
        assert_eq!(std::fs::read(aside.path()).unwrap(), b"garbage");
    }

    /// A failed write (a folder where its new file should go, as a full disk) is said
    /// once, and the job writes by itself within [`RETRY_EVERY`] of the way clearing,
    /// however seldom the window calls (no frame between).
    #[test]
    fn a_failed_write_reaches_the_disk_within_the_retry_time_of_space_coming_back() {
        let d = dir("fail");
        std::fs::create_dir_all(&d).unwrap();
        let path = d.join("drafts.json");
        let blocker = with_suffix(&path, ".new");
        std::fs::create_dir_all(&blocker).unwrap();
        let mut f = SavedFile::new(path.clone(), "drafts");
        let t0 = Instant::now();
        assert_eq!(f.save(1, t0, || b"ok".to_vec()), None);
        let deadline = Instant::now() + LIMIT;
        let news = loop {
            if let Some(n) = f.save(1, Instant::now(), || panic!("written twice")) {
                break n;
            }
            assert!(Instant::now() < deadline, "the failure is never said");
            std::thread::sleep(Duration::from_millis(10));
        };
        assert!(matches!(news, SaveNews::Failed(_)), "{news:?}");
        assert!(!f.is_saved());
        // Said once, however often asked.
        assert_eq!(f.save(1, Instant::now(), || panic!("written twice")), None);
        std::fs::remove_dir(&blocker).unwrap();
        let cleared = Instant::now();
        let deadline = cleared + RETRY_EVERY + LIMIT;
        while std::fs::read(&path).ok().as_deref() != Some(&b"ok"[..]) {
            assert!(Instant::now() < deadline, "never written");
            std::thread::sleep(Duration::from_millis(10));
        }
        let took = cleared.elapsed();
        assert!(took <= RETRY_EVERY + Duration::from_secs(1), "{took:?}");
        let news = f.settle(LIMIT, Instant::now());
        assert!(matches!(news, Some(SaveNews::Recovered(_))), "{news:?}");
        assert!(f.is_saved());
    }

    /// A newer change replaces a write that keeps failing; the old bytes never land
    /// after the new ones.
    #[test]
    fn a_newer_change_replaces_a_failing_write() {
        let d = dir("newer");
        std::fs::create_dir_all(&d).unwrap();
        let path = d.join("teach.json");
        let blocker = with_suffix(&path, ".new");
        std::fs::create_dir_all(&blocker).unwrap();
        let mut f = SavedFile::new(path.clone(), "teach list");
        f.save(1, Instant::now(), || b"ok old".to_vec());
        let deadline = Instant::now() + LIMIT;
        while f.save(1, Instant::now(), Vec::new).is_none() {
            assert!(Instant::now() < deadline, "the failure is never said");
            std::thread::sleep(Duration::from_millis(10));
        }
        std::fs::remove_dir(&blocker).unwrap();
        assert_eq!(f.flush(2, LIMIT, || b"ok new".to_vec()), None);
        assert_eq!(std::fs::read(&path).unwrap(), b"ok new");
        assert!(f.is_saved() && !f.is_writing());
    }
}
