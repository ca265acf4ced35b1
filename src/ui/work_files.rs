//! The settings and the operator's work in files of their own: the settings, the window's
//! layout, the teach list, the coordinate-table drafts, the position table's draft and
//! names and the signals' watch list, read back at start and written after every
//! change as jobs off the UI thread (see `files::saved`), and flushed at exit; what
//! happens is said in Messages.

use std::path::Path;
use std::time::Instant;

use crate::files::saved::{SaveNews, SavedFile};
use crate::pendant::coords::SavedDrafts;
use crate::pendant::positions::RestoredWork;
use crate::pendant::teach::TeachList;
use crate::pendant::{Level, Pendant, Settings};

/// The coordinate-table drafts.
const DRAFTS_FILE: &str = "coords-drafts.json";
/// The teach list.
const TEACH_FILE: &str = "teach-list.json";
/// The position table's draft and the names beside its numbers.
const POSITIONS_FILE: &str = "positions-work.json";
/// The signals' watch list (and the controller's real encoding).
const SIGNALS_FILE: &str = "signals-watch.json";
/// The panes' arrangement (eframe's own file keeps only the window's place and size).
const LAYOUT_FILE: &str = "layout.json";
/// The settings (connection, jog choices, theme, frame log size).
const SETTINGS_FILE: &str = "settings.json";

/// The files, in one folder (none in a fresh start: tests leave the user's work alone).
#[derive(Debug, Default)]
pub struct WorkFiles {
    drafts: Option<SavedFile>,
    teach: Option<SavedFile>,
    positions: Option<SavedFile>,
    signals: Option<SavedFile>,
    settings: Option<SavedFile>,
    layout: Option<SavedFile>,
}

/// The panes' arrangement as the window keeps it.
pub type Layout = egui_tiles::Tree<super::layout::Tab>;

impl WorkFiles {
    /// The files in `dir`; the settings' file only `with_settings`.
    pub fn in_folder(dir: Option<&Path>, with_settings: bool) -> Self {
        Self {
            drafts: dir.map(|d| SavedFile::new(d.join(DRAFTS_FILE), "coordinate-table drafts")),
            teach: dir.map(|d| SavedFile::new(d.join(TEACH_FILE), "teach list")),
            positions: dir.map(|d| {
                SavedFile::new(d.join(POSITIONS_FILE), "position table's draft and names")
            }),
            signals: dir.map(|d| SavedFile::new(d.join(SIGNALS_FILE), "signals' watch list")),
            settings: dir
                .filter(|_| with_settings)
                .map(|d| SavedFile::new(d.join(SETTINGS_FILE), "settings")),
            layout: dir
                .filter(|_| with_settings)
                .map(|d| SavedFile::new(d.join(LAYOUT_FILE), "window layout")),
        }
    }

    /// The settings saved last time, if their file is there and readable, and what to
    /// say about it (an unreadable file is kept aside, the backup read).
    pub fn restore_settings(&mut self) -> (Option<Settings>, Vec<String>) {
        let Some(file) = &mut self.settings else {
            return (None, Vec::new());
        };
        let restored =
            file.restore(|b| serde_json::from_slice::<Settings>(b).map_err(|e| e.to_string()));
        if let Some(s) = &restored.value {
            file.mark_written(revision_of(s));
        }
        (restored.value, restored.notes)
    }

    /// The layout saved last time, if its file is there and readable, and what to say
    /// about it (an unreadable file is kept aside, the backup read).
    pub fn restore_layout(&mut self) -> (Option<Layout>, Vec<String>) {
        let Some(file) = &mut self.layout else {
            return (None, Vec::new());
        };
        let restored =
            file.restore(|b| serde_json::from_slice::<Layout>(b).map_err(|e| e.to_string()));
        if let Some(l) = &restored.value {
            file.mark_written(revision_of(l));
        }
        (restored.value, restored.notes)
    }

    /// Whether the layout's file holds the layout (eframe's copy may then go).
    pub fn layout_saved(&self) -> bool {
        self.layout.as_ref().is_some_and(SavedFile::is_saved)
    }

    /// Every file is written up to date (the settings and the teach list at least once).
    pub fn all_saved(&self) -> bool {
        [
            &self.settings,
            &self.teach,
            &self.drafts,
            &self.positions,
            &self.signals,
        ]
        .into_iter()
        .flatten()
        .all(SavedFile::is_saved)
    }

    /// Takes back what the last run saved. A teach list still in old settings (and no
    /// file yet) stays in the pendant and is written to its file at the first save.
    pub fn restore(&mut self, pendant: &mut Pendant, now: Instant) {
        if let Some(file) = &mut self.drafts {
            let restored = file.restore(|b| {
                let saved: SavedDrafts = serde_json::from_slice(b).map_err(|e| e.to_string())?;
                Ok(saved)
            });
            say_all(pendant, restored.notes, now);
            if let Some(saved) = restored.value {
                if pendant.coords.restore(&saved) {
                    pendant.note("coordinate-table drafts restored from the last run", now);
                } else {
                    let text = format!(
                        "the drafts in {} are of another format and were not restored",
                        file.path().display()
                    );
                    pendant.say(Level::Warning, text, now);
                }
            }
            file.mark_written(pendant.coords.revision());
        }
        if let Some(file) = &mut self.positions {
            // A file that does not read is set aside (its last good copy read), never
            // overwritten by the empty draft of this run.
            let restored = file.restore(RestoredWork::parse);
            say_all(pendant, restored.notes, now);
            if let Some(work) = restored.value {
                let (rows, names) = pendant.positions.restore(work);
                if rows + names > 0 {
                    let count =
                        |n: usize, one: &str| format!("{n} {one}{}", if n == 1 { "" } else { "s" });
                    let text = format!(
                        "position table's draft restored: {}, {} of numbers not in it",
                        count(rows, "row"),
                        count(names, "name")
                    );
                    pendant.note(text, now);
                }
            }
            file.mark_written(pendant.positions.work_revision());
        }
        if let Some(file) = &mut self.signals {
            let restored = file
                .restore(|b| crate::pendant::signals::file::parse(b).map_err(|e| e.to_string()));
            say_all(pendant, restored.notes, now);
            if let Some((rows, encoding)) = restored.value {
                pendant.signals.restore(rows, encoding);
            }
            file.mark_written(pendant.signals.revision());
        }
        if let Some(file) = &mut self.teach {
            let restored =
                file.restore(|b| TeachList::from_json_bytes(b).map_err(|e| e.to_string()));
            say_all(pendant, restored.notes, now);
            match restored.value {
                Some(list) => {
                    let n = list.len();
                    pendant.teach.set(list);
                    file.mark_written(pendant.teach.revision());
                    let points = if n == 1 {
                        "1 point".to_owned()
                    } else {
                        format!("{n} points")
                    };
                    pendant.note(format!("teach list restored: {points}"), now);
                }
                None if !pendant.teach.list().is_empty() => {
                    let text = format!(
                        "the teach list ({} points) moves from the settings into {}",
                        pendant.teach.list().len(),
                        file.path().display()
                    );
                    pendant.note(text, now);
                }
                None => file.mark_written(pendant.teach.revision()),
            }
        }
    }

    /// Writes what changed since it was last written (a failed write tries again by
    /// itself).
    pub fn autosave(&mut self, pendant: &mut Pendant, layout: &Layout, now: Instant) {
        let mut news = Vec::new();
        for (file, revision, contents) in self.with_contents(pendant, layout) {
            news.extend(file.save(revision, now, contents));
        }
        for n in news {
            match n {
                SaveNews::Failed(text) => pendant.say(Level::Error, text, now),
                SaveNews::Recovered(text) => pendant.note(text, now),
            }
        }
    }

    /// At exit: waits a moment for writes under way and writes what is still unsaved,
    /// so nothing the operator did is left in memory only.
    pub fn flush(&mut self, pendant: &Pendant, layout: &Layout) {
        const LIMIT: std::time::Duration = std::time::Duration::from_secs(2);
        for (file, revision, contents) in self.with_contents(pendant, layout) {
            file.flush(revision, LIMIT, contents);
        }
    }

    /// Each file with the revision it should hold and how to write that revision.
    fn with_contents<'a>(
        &'a mut self,
        pendant: &'a Pendant,
        layout: &'a Layout,
    ) -> impl Iterator<Item = (&'a mut SavedFile, u64, Contents<'a>)> {
        let coords = &pendant.coords;
        let teach = &pendant.teach;
        let positions = &pendant.positions;
        let signals = &pendant.signals;
        let settings = &pendant.settings;
        let drafts: Contents<'a> =
            Box::new(move || serde_json::to_vec(&coords.saved()).unwrap_or_default());
        let list: Contents<'a> = Box::new(move || teach.list().to_json().into_bytes());
        let work: Contents<'a> = Box::new(move || positions.saved());
        let watch: Contents<'a> = Box::new(move || signals.saved());
        let prefs: Contents<'a> =
            Box::new(move || serde_json::to_vec_pretty(settings).unwrap_or_default());
        let panes: Contents<'a> = Box::new(move || serde_json::to_vec(layout).unwrap_or_default());
        [
            self.drafts.as_mut().map(|f| (f, coords.revision(), drafts)),
            self.teach.as_mut().map(|f| (f, teach.revision(), list)),
            self.positions
                .as_mut()
                .map(|f| (f, positions.work_revision(), work)),
            self.signals
                .as_mut()
                .map(|f| (f, signals.revision(), watch)),
            self.settings
                .as_mut()
                .map(|f| (f, revision_of(settings), prefs)),
            self.layout
                .as_mut()
                .map(|f| (f, revision_of(layout), panes)),
        ]
        .into_iter()
        .flatten()
    }
}

/// How to put a file's contents together (only when it is to be written).
type Contents<'a> = Box<dyn FnOnce() -> Vec<u8> + 'a>;

/// The revision of something small kept whole (the settings, the layout): a hash of its
/// saved form (a change of any field changes it).
fn revision_of(value: &impl serde::Serialize) -> u64 {
    use std::hash::{Hash, Hasher};
    let bytes = serde_json::to_vec(value).unwrap_or_default();
    let mut h = std::collections::hash_map::DefaultHasher::new();
    bytes.hash(&mut h);
    h.finish()
}

fn say_all(pendant: &mut Pendant, notes: Vec<String>, now: Instant) {
    for text in notes {
        pendant.say(Level::Warning, text, now);
    }
}
