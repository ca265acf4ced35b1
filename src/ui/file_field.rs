//! A file the user names and the job working on it: the name typed (kept for scripts and
//! tests) or chosen in the platform's file dialog (rfd, on a job thread so the window keeps
//! painting), taken relative to the last folder used; a save over a file that is there is
//! asked first; a running job shows its progress and a Cancel.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use egui::{Button, RichText, TextEdit, Ui};

use super::widgets::AMBER;
use crate::files::Overwrite;
use crate::files::folders::resolve;
use crate::files::job::{Job, JobPoll};

/// A dialog that ends sooner than this was never shown.
const NO_DIALOG_WITHIN: Duration = Duration::from_millis(400);
const NO_DIALOG: &str = if cfg!(any(target_os = "windows", target_os = "macos")) {
    "no file dialog could be shown: type the file's path instead"
} else {
    "no file dialog could be shown (this desktop has neither xdg-desktop-portal nor \
     zenity): type the file's path instead"
};

/// Which dialog a way of browsing opens.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Purpose {
    Open,
    Save,
}

/// One way to browse: the menu entry, what the panel does with the file chosen.
pub struct Browse<A> {
    pub label: &'static str,
    pub action: A,
    pub purpose: Purpose,
}

/// File kinds the dialog offers: a name and its extensions.
pub type Filters = &'static [(&'static str, &'static [&'static str])];

/// How a panel's file field looks and browses.
pub struct FieldSpec<A: 'static> {
    pub label: &'static str,
    pub hint: &'static str,
    pub width: f32,
    pub browse: &'static [Browse<A>],
    pub filters: Filters,
}

/// What the panel is asked to do: `action` on `path`, replacing a file there or not.
#[derive(Clone, Debug, PartialEq)]
pub struct FileAsk<A> {
    pub action: A,
    pub path: PathBuf,
    pub overwrite: Overwrite,
}

/// The typed name, the dialog while it is open, and a save waiting for "Replace".
pub struct FileField<A: 'static> {
    spec: &'static FieldSpec<A>,
    pub typed: String,
    dialog: Option<(Job<Option<PathBuf>>, A, Purpose)>,
    confirm: Option<(A, PathBuf, String)>,
    asked: Option<Result<FileAsk<A>, String>>,
}

impl<A: Copy + Send + 'static> FileField<A> {
    pub fn new(spec: &'static FieldSpec<A>, typed: &str) -> Self {
        Self {
            spec,
            typed: typed.into(),
            dialog: None,
            confirm: None,
            asked: None,
        }
    }

    /// The name field and Browse... (a menu when there are several ways to browse).
    pub fn show(&mut self, ui: &mut Ui, folder: &Path, now: Instant) {
        self.poll_dialog(ui, now);
        let spec = self.spec;
        let shown = ui.label(spec.label);
        ui.add(
            TextEdit::singleline(&mut self.typed)
                .desired_width(spec.width)
                .hint_text(spec.hint),
        )
        .labelled_by(shown.id)
        .on_hover_text(format!(
            "A name without a folder is in {} (the last folder used)",
            folder.display()
        ));
        let open = self.dialog.is_none();
        let mut chosen = None;
        match spec.browse {
            [] => {}
            [only] => {
                // Never wrapped letter by letter at the end of a short row.
                if ui
                    .add_enabled(
                        open,
                        Button::new("Browse...").wrap_mode(egui::TextWrapMode::Extend),
                    )
                    .on_hover_text("Choose the file in the system's file dialog")
                    .clicked()
                {
                    chosen = Some(only);
                }
            }
            several => {
                ui.add_enabled_ui(open, |ui| {
                    ui.style_mut().wrap_mode = Some(egui::TextWrapMode::Extend);
                    ui.menu_button("Browse...", |ui| {
                        for way in several {
                            if ui.button(way.label).clicked() {
                                chosen = Some(way);
                                ui.close();
                            }
                        }
                    });
                });
            }
        }
        if let Some(way) = chosen {
            self.open_dialog(way, spec.filters, folder, now);
        }
    }

    fn open_dialog(&mut self, way: &Browse<A>, filters: Filters, folder: &Path, now: Instant) {
        let mut dialog = rfd::FileDialog::new().set_directory(folder);
        for (name, extensions) in filters {
            dialog = dialog.add_filter(*name, extensions);
        }
        if let Some(name) = Path::new(self.typed.trim()).file_name() {
            dialog = dialog.set_file_name(name.to_string_lossy());
        }
        let purpose = way.purpose;
        // rfd runs dialogs from any thread of a windowed app (its documentation); on this
        // one the window keeps painting while the dialog is open.
        let job = Job::spawn("choose a file", now, move |_| match purpose {
            Purpose::Open => dialog.pick_file(),
            Purpose::Save => dialog.save_file(),
        });
        match job {
            Ok(job) => self.dialog = Some((job, way.action, purpose)),
            Err(e) => self.asked = Some(Err(e)),
        }
    }

    fn poll_dialog(&mut self, ui: &Ui, now: Instant) {
        let Some((job, action, purpose)) = &self.dialog else {
            return;
        };
        match job.poll(now) {
            JobPoll::Running | JobPoll::OpenTimedOut => {
                ui.ctx().request_repaint_after(Duration::from_millis(100));
            }
            JobPoll::Done(Some(path)) => {
                self.typed = path.display().to_string();
                // The platform's save dialog asks before replacing a file itself.
                let overwrite = match purpose {
                    Purpose::Save => Overwrite::Replace,
                    Purpose::Open => Overwrite::Ask,
                };
                self.asked = Some(Ok(FileAsk {
                    action: *action,
                    path,
                    overwrite,
                }));
                self.dialog = None;
            }
            JobPoll::Done(None) => {
                // Inferred: no person cancels a dialog this fast; rfd answers "nothing
                // chosen" at once where the desktop has no file dialog service.
                if job.elapsed(now) < NO_DIALOG_WITHIN {
                    self.asked = Some(Err(NO_DIALOG.into()));
                }
                self.dialog = None;
            }
            JobPoll::Lost => {
                self.asked = Some(Err(
                    "the file dialog could not be shown: type the file's path instead".into(),
                ));
                self.dialog = None;
            }
        }
    }

    /// A button of the panel asks for `action` on the typed name.
    pub fn ask(&mut self, action: A, folder: &Path) {
        self.confirm = None;
        self.asked = Some(resolve(&self.typed, folder).map(|path| FileAsk {
            action,
            path,
            overwrite: Overwrite::Ask,
        }));
    }

    /// A save found a file at `path` (`what` it is): ask before replacing it.
    pub fn exists(&mut self, action: A, path: PathBuf, what: String) {
        self.confirm = Some((action, path, what));
    }

    /// What to do now: an action on a full path, or why there is none.
    pub fn take(&mut self) -> Option<Result<FileAsk<A>, String>> {
        self.asked.take()
    }

    /// "X exists: Replace / Keep it" while a save waits for the answer.
    pub fn confirm_line(&mut self, ui: &mut Ui) {
        let Some((action, path, what)) = self.confirm.take() else {
            return;
        };
        let mut keep = true;
        ui.horizontal_wrapped(|ui| {
            ui.label(
                RichText::new(format!(
                    "{} already exists ({what}). Replace it?",
                    path.display()
                ))
                .color(AMBER),
            );
            if ui.button("Replace").clicked() {
                self.asked = Some(Ok(FileAsk {
                    action,
                    path: path.clone(),
                    overwrite: Overwrite::Replace,
                }));
                keep = false;
            } else if ui.button("Keep it").clicked() {
                keep = false;
            }
        });
        if keep {
            self.confirm = Some((action, path, what));
        }
    }
}

/// The folder names are taken in, looked up again only when the last folder used
/// changes (looking means asking the file system).
#[derive(Default)]
pub struct FolderCache {
    key: Option<Option<PathBuf>>,
    folder: PathBuf,
}

impl FolderCache {
    pub fn get(&mut self, last: Option<&Path>) -> &Path {
        if self.key.as_ref().is_none_or(|k| k.as_deref() != last) {
            self.folder = crate::files::folders::default_folder(last);
            self.key = Some(last.map(Path::to_path_buf));
        }
        &self.folder
    }
}

/// A running job's line: what it does, how far, and Cancel. A cancelled job is taken
/// out of `slot`, and the sentence to say is returned.
pub fn job_line<T: Send + 'static>(ui: &mut Ui, slot: &mut Option<Job<T>>) -> Option<String> {
    let job = slot.as_ref()?;
    ui.ctx().request_repaint_after(Duration::from_millis(100));
    let mut cancel = false;
    ui.horizontal_wrapped(|ui| {
        ui.spinner();
        let p = job.progress();
        let how_far = match (job.is_open(), p.total) {
            (false, _) => " (opening...)".to_owned(),
            (true, Some(total)) => format!(" ({:.0} %)", p.done as f64 * 100.0 / total as f64),
            (true, None) if p.done > 0 => format!(" ({} done)", p.done),
            (true, None) => String::new(),
        };
        ui.label(format!("{}{how_far}", job.what()));
        cancel = ui.button("Cancel").clicked();
    });
    if !cancel {
        return None;
    }
    job.cancel();
    let said = format!("cancelled: {}; nothing changed", job.what());
    *slot = None;
    Some(said)
}

/// A finished job's result, taken out of `slot` (which is then empty): `None` while it
/// runs, else the result or the sentence saying why there is none.
pub fn take_done<T: Send + 'static>(
    slot: &mut Option<Job<T>>,
    now: Instant,
) -> Option<Result<T, String>> {
    let what = slot.as_ref()?.what().to_owned();
    Job::take(slot, now)
        .map(|done| done.map_err(|lost| format!("{what}: {lost}; given up, nothing changed")))
}
