//! A pane's file row: the name field, the job on its file, and the last word said of them.

use std::fmt::Display;
use std::path::{Path, PathBuf};
use std::time::Instant;

use egui::{Button, Response, Ui};

use super::file_field::{FieldSpec, FileAsk, FileField, job_line, take_done};
use super::widgets::{GREEN, RED, clock_utc, reserved_line};
use crate::files::job::Job;
use crate::files::{WriteError, read_bounded_in, write_file};
use crate::pendant::Intent;

/// A finished read or write of a pane's file.
pub enum Done<R> {
    Read {
        path: PathBuf,
        read: Result<R, String>,
    },
    Written {
        path: PathBuf,
        rows: usize,
        result: Result<(), WriteError>,
    },
}

/// A button of the file row: its label, its hover text, what it asks for.
pub type FileButton<A> = (&'static str, Option<&'static str>, A);

/// The file field (`A`: what it is asked to do), the job working on its file (finishing
/// as `D`) and the last word said of them.
pub struct FileWork<A: 'static, D> {
    file: FileField<A>,
    job: Option<Job<D>>,
    /// The last word: done well or not, and its sentence. A pane whose result line is the
    /// pendant's takes it and hands it on.
    pub message: Option<(bool, String)>,
}

impl<A: Copy + Send + 'static, D: Send + 'static> FileWork<A, D> {
    pub fn new(spec: &'static FieldSpec<A>) -> Self {
        Self {
            file: FileField::new(spec, ""),
            job: None,
            message: None,
        }
    }

    /// No job runs: the field and the buttons can be used.
    pub fn idle(&self) -> bool {
        self.job.is_none()
    }

    /// The name field and Browse..., greyed while a job runs.
    pub fn field(&mut self, ui: &mut Ui, folder: &Path, now: Instant) -> Response {
        let idle = self.idle();
        ui.add_enabled_ui(idle, |ui| self.file.show(ui, folder, now))
            .response
    }

    /// A button asking for `action` on the typed name, greyed while a job runs or unless
    /// `enabled`.
    pub fn button(
        &mut self,
        ui: &mut Ui,
        (label, hover, action): FileButton<A>,
        enabled: bool,
        folder: &Path,
    ) {
        let b = ui.add_enabled(enabled && self.idle(), Button::new(label));
        let b = match hover {
            Some(hover) => b.on_hover_text(hover),
            None => b,
        };
        if b.clicked() {
            self.file.ask(action, folder);
        }
    }

    /// The action asked for this frame (a button, the dialog, Replace), the last word
    /// forgotten; or none, and why not said.
    pub fn take_ask(&mut self) -> Option<FileAsk<A>> {
        match self.file.take()? {
            Ok(ask) => {
                self.message = None;
                Some(ask)
            }
            Err(why) => {
                self.message = Some((false, why));
                None
            }
        }
    }

    /// The job an action started, or why none could be.
    pub fn started(&mut self, job: Result<Job<D>, String>) {
        match job {
            Ok(job) => self.job = Some(job),
            Err(e) => self.message = Some((false, e)),
        }
    }

    /// The action asked for this frame, started by `start`.
    pub fn start(&mut self, start: impl FnOnce(FileAsk<A>) -> Result<Job<D>, String>) {
        if let Some(ask) = self.take_ask() {
            let job = start(ask);
            self.started(job);
        }
    }

    /// "Replace it?" while a save waits for the answer, and a running job's line (its
    /// Cancel said).
    pub fn lines(&mut self, ui: &mut Ui) {
        self.file.confirm_line(ui);
        if let Some(said) = job_line(ui, &mut self.job) {
            self.message = Some((false, said));
        }
    }

    /// The last word in a line that is always there: green when done well, red when not.
    pub fn message_line(&self, ui: &mut Ui) {
        let said = self
            .message
            .as_ref()
            .map(|(ok, t)| (if *ok { GREEN } else { RED }, t.as_str()));
        reserved_line(ui, said, said.map(|(_, t)| t));
    }

    /// The whole row: the field and `buttons` on one line, the action asked for started
    /// by `start`, the Replace and job lines, and the last word.
    pub fn row(
        &mut self,
        ui: &mut Ui,
        folder: &Path,
        now: Instant,
        buttons: &[FileButton<A>],
        start: impl FnOnce(FileAsk<A>) -> Result<Job<D>, String>,
    ) {
        ui.horizontal_wrapped(|ui| {
            self.field(ui, folder, now);
            for &button in buttons {
                self.button(ui, button, true, folder);
            }
        });
        self.start(start);
        self.lines(ui);
        self.message_line(ui);
    }

    /// A finished job's result, taken; a job lost is said.
    pub fn finished(&mut self, now: Instant) -> Option<D> {
        match take_done(&mut self.job, now)? {
            Ok(done) => Some(done),
            Err(why) => {
                self.message = Some((false, why));
                None
            }
        }
    }

    /// A save found a file at `path` (`what` it is): ask before replacing it, `again`
    /// asked on "Replace".
    pub fn exists(&mut self, again: A, path: PathBuf, what: String) {
        self.file.exists(again, path, what);
    }
}

impl<A: Copy + Send + 'static, R: Send + 'static> FileWork<A, Done<R>> {
    /// A finished job. A read is handed back (and its file, when read, pushed to `out` as
    /// used). A write is said: `words` of its rows, then "to PATH at TIME", and its file
    /// pushed as used; or, where a file was there, asked to replace (`again` of the path
    /// asked on "Replace"); or why not.
    pub fn poll(
        &mut self,
        now: Instant,
        out: &mut Vec<Intent>,
        words: impl FnOnce(usize) -> String,
        again: impl FnOnce(&Path) -> A,
    ) -> Option<(PathBuf, Result<R, String>)> {
        match self.finished(now)? {
            Done::Read { path, read } => {
                if read.is_ok() {
                    out.push(Intent::FileUsed(path.clone()));
                }
                Some((path, read))
            }
            Done::Written { path, rows, result } => {
                match result {
                    Ok(()) => {
                        let said =
                            format!("{} to {} at {}", words(rows), path.display(), clock_utc());
                        self.message = Some((true, said));
                        out.push(Intent::FileUsed(path));
                    }
                    Err(WriteError::Exists(what)) => self.exists(again(&path), path, what),
                    Err(e) => self.message = Some((false, e.sentence(&path))),
                }
                None
            }
        }
    }
}

/// A job reading `path` (at most `limit` bytes) and parsing it with `parse` (given the
/// path and the bytes), off the UI thread; a parse error names the file.
pub fn read_job<R: Send + 'static, E: Display>(
    path: PathBuf,
    limit: u64,
    now: Instant,
    parse: impl FnOnce(&Path, &[u8]) -> Result<R, E> + Send + 'static,
) -> Result<Job<Done<R>>, String> {
    let shown = path.display().to_string();
    Job::spawn_opening(format!("reading {shown}"), now, move |ctl| {
        let read = read_bounded_in(&path, limit, ctl)
            .and_then(|bytes| parse(&path, &bytes).map_err(|e| format!("{}: {e}", path.display())));
        Done::Read { path, read }
    })
}

/// A job ("`verb` PATH") writing `rows` rows, as `text` makes them (CSV or JSON: see
/// [`is_json`]), to the file `ask` names, off the UI thread; a file there is replaced
/// only as `ask` says.
pub fn write_job<A, R: Send + 'static>(
    verb: &str,
    ask: FileAsk<A>,
    rows: usize,
    now: Instant,
    text: impl FnOnce() -> String + Send + 'static,
) -> Result<Job<Done<R>>, String> {
    let FileAsk {
        path, overwrite, ..
    } = ask;
    let shown = path.display().to_string();
    Job::spawn_opening(format!("{verb} {shown}"), now, move |ctl| {
        let result = write_file(&path, text().as_bytes(), overwrite, ctl);
        Done::Written { path, rows, result }
    })
}

/// A name ending in `.json` (any case) is JSON; any other, CSV.
pub fn is_json(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("json"))
}
