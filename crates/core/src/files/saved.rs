//! Operator work kept in a file of its own beside the settings (the teach list, the
//! coordinate drafts): written on every change, as a job off the UI thread, as a new file
//! renamed over the old one, the previous good copy kept as `.bak`; a failed write is said
//! once and retried every few seconds; at start the file (or its `.bak`) is read back,
//! and an unreadable file is moved aside, never overwritten.

use std::path::{Path, PathBuf};
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

/// One file of operator work and how its writing goes.
#[derive(Debug)]
pub struct SavedFile {
    path: PathBuf,
    /// What it holds, for messages ("teach list").
    what: &'static str,
    /// The revision last written (or read back).
    written: Option<u64>,
    failing: bool,
    retry_at: Option<Instant>,
    /// The write under way: the revision it writes.
    writing: Option<Job<std::io::Result<()>>>,
    /// The revision the write under way writes.
    writing_revision: u64,
}

impl SavedFile {
    pub fn new(path: PathBuf, what: &'static str) -> Self {
        Self {
            path,
            what,
            written: None,
            failing: false,
            retry_at: None,
            writing: None,
            writing_revision: 0,
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

    /// Starts writing `contents()` when `revision` was not written yet (after a
    /// failure, not before the retry time); one write at a time, off the calling thread.
    /// Says what the operator should hear of the last write.
    pub fn save(
        &mut self,
        revision: u64,
        now: Instant,
        contents: impl FnOnce() -> Vec<u8>,
    ) -> Option<SaveNews> {
        let news = self.poll_write(now);
        if self.writing.is_some()
            || self.written == Some(revision)
            || self.retry_at.is_some_and(|t| now < t)
        {
            return news;
        }
        let path = self.path.clone();
        let bytes = contents();
        let what = format!("save the {} to {}", self.what, path.display());
        match Job::spawn_opening(what, now, move |ctl| {
            let written = write_atomic(&path, &bytes);
            ctl.opened();
            written
        }) {
            Ok(job) => {
                self.writing = Some(job);
                self.writing_revision = revision;
            }
            Err(e) => return news.or(self.failed(&e, now)),
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
        let _ = self.settle(limit, Instant::now());
        if self.written == Some(revision) && !self.failing {
            return None;
        }
        match write_atomic(&self.path, &contents()) {
            Ok(()) => {
                self.written = Some(revision);
                self.failing = false;
                None
            }
            Err(e) => self.failed(&e.to_string(), Instant::now()),
        }
    }

    /// Takes the result of a write that finished.
    fn poll_write(&mut self, now: Instant) -> Option<SaveNews> {
        let done = Job::take(&mut self.writing, now)?;
        let result = match done {
            Ok(written) => written.map_err(|e| e.to_string()),
            Err(lost) => Err(lost.to_string()),
        };
        self.finish(self.writing_revision, result, now)
    }

    /// Waits at most `limit` for the write under way and takes its result (at exit; in
    /// tests).
    pub fn settle(&mut self, limit: std::time::Duration, now: Instant) -> Option<SaveNews> {
        let job = self.writing.take()?;
        let revision = self.writing_revision;
        let result = job
            .wait(limit)
            .unwrap_or_else(|| Err(std::io::Error::other("not done in time")))
            .map_err(|e| e.to_string());
        self.finish(revision, result, now)
    }

    fn finish(
        &mut self,
        revision: u64,
        result: Result<(), String>,
        now: Instant,
    ) -> Option<SaveNews> {
        match result {
            Ok(()) => {
                self.written = Some(revision);
                self.retry_at = None;
                std::mem::take(&mut self.failing).then(|| {
                    SaveNews::Recovered(format!(
                        "the {} is saved again to {}",
                        self.what,
                        self.path.display()
                    ))
                })
            }
            Err(e) => self.failed(&e, now),
        }
    }

    fn failed(&mut self, why: &str, now: Instant) -> Option<SaveNews> {
        self.retry_at = Some(now + RETRY_EVERY);
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

    #[test]
    fn a_failed_write_is_said_once_retried_later_and_its_recovery_said() {
        let d = dir("fail");
        std::fs::create_dir_all(&d).unwrap();
        // A folder where the new file should go: every write fails, as on a full disk.
        let path = d.join("drafts.json");
        std::fs::create_dir_all(with_suffix(&path, ".new")).unwrap();
        let mut f = SavedFile::new(path.clone(), "drafts");
        let t0 = Instant::now();
        assert!(matches!(
            saved(&mut f, 1, t0, || b"ok".to_vec()),
            Some(SaveNews::Failed(_))
        ));
        assert!(!f.is_saved());
        assert_eq!(
            saved(&mut f, 2, t0 + Duration::from_secs(1), || panic!("not yet")),
            None
        );
        assert_eq!(
            saved(&mut f, 2, t0 + RETRY_EVERY, || b"ok".to_vec()),
            None,
            "said twice"
        );
        std::fs::remove_dir(with_suffix(&path, ".new")).unwrap();
        let later = t0 + RETRY_EVERY * 2;
        assert!(matches!(
            saved(&mut f, 2, later, || b"ok 2".to_vec()),
            Some(SaveNews::Recovered(_))
        ));
        assert_eq!(std::fs::read(&path).unwrap(), b"ok 2");
    }
}
