//! The teach list as the operator's work: the list, a revision the autosave follows, a
//! loaded file waiting for the operator's yes before it replaces the list, and the list a
//! load replaced (Undo load).

use super::TeachList;
use crate::pendant::Level;

/// A file's points read and checked, waiting for "Replace".
#[derive(Clone, Debug, PartialEq)]
pub struct PendingLoad {
    pub path: String,
    pub list: TeachList,
}

/// The list and what may replace it.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TeachBook {
    list: TeachList,
    /// Moves on every change: the autosave writes when it differs from what it wrote.
    revision: u64,
    pending: Option<PendingLoad>,
    /// The list the last load replaced, and the file it came from.
    before_load: Option<(String, TeachList)>,
    /// The last word on a file (loaded, refused, undone).
    feedback: Option<(Level, String)>,
    /// A Go (point index, list revision) that flips the arm or enters a zone, waiting for
    /// a second press until then; any change of the list takes it back.
    pub(crate) go_confirm: Option<((usize, u64), std::time::Instant)>,
}

impl TeachBook {
    pub fn new(list: TeachList) -> Self {
        Self {
            list,
            ..Self::default()
        }
    }

    pub fn list(&self) -> &TeachList {
        &self.list
    }

    pub fn revision(&self) -> u64 {
        self.revision
    }

    /// A loaded file waiting for the operator's answer.
    pub fn pending(&self) -> Option<&PendingLoad> {
        self.pending.as_ref()
    }

    /// The file whose load Undo load takes back, and how many points come back.
    pub fn undoable_load(&self) -> Option<(&str, usize)> {
        self.before_load
            .as_ref()
            .map(|(p, l)| (p.as_str(), l.len()))
    }

    /// Any change of the list (an edit, a recorded point, a restore).
    pub fn set(&mut self, list: TeachList) {
        if list != self.list {
            self.list = list;
            self.revision += 1;
        }
    }

    /// Changes the list in place (a recorded point).
    pub fn edit<R>(&mut self, f: impl FnOnce(&mut TeachList) -> R) -> R {
        self.revision += 1;
        f(&mut self.list)
    }
}

/// What a teach-file action says: the operator's word, also kept beside the list.
type Said = Option<(Level, String)>;

impl TeachBook {
    /// The pane's last word on a file (loaded, refused, undone).
    pub fn feedback(&self) -> Option<&(Level, String)> {
        self.feedback.as_ref()
    }

    /// A teach file was read: its points wait for "Replace", or the reason it is refused
    /// is said. A file with no points never replaces the list.
    pub fn loaded(&mut self, path: &str, read: Result<TeachList, String>) -> Said {
        let list = match read {
            Ok(list) if list.is_empty() => {
                let text = format!("{path}: the file has no points; the list is unchanged");
                return self.says(Level::Warning, text);
            }
            Ok(list) => list,
            Err(e) => return self.says(Level::Warning, format!("{e} (nothing changed)")),
        };
        self.pending = Some(PendingLoad {
            path: path.to_owned(),
            list,
        });
        if self.list.is_empty() {
            // Nothing to lose: replaced at once (and still undoable).
            return self.confirm_load();
        }
        None
    }

    /// "Replace": the waiting file's points become the list; Undo load brings it back.
    pub fn confirm_load(&mut self) -> Said {
        let PendingLoad { path, list } = self.pending.take()?;
        let (n, old) = (list.len(), self.list.len());
        let before = std::mem::replace(&mut self.list, list);
        self.revision += 1;
        self.before_load = Some((path.clone(), before));
        let text =
            format!("loaded {n} points from {path}, replacing {old} (Undo load brings them back)");
        self.says(Level::Info, text)
    }

    /// "Cancel": the waiting file is forgotten; the list stays.
    pub fn cancel_load(&mut self) {
        self.pending = None;
    }

    /// "Undo load": the list as it was before the last load.
    pub fn undo_load(&mut self) -> Said {
        let (path, before) = self.before_load.take()?;
        let n = before.len();
        self.list = before;
        self.revision += 1;
        self.says(
            Level::Info,
            format!("load of {path} undone: {n} points back"),
        )
    }

    fn says(&mut self, level: Level, text: String) -> Said {
        self.feedback = Some((level, text.clone()));
        Some((level, text))
    }
}

#[cfg(test)]
mod tests {
    use std::time::Instant;

    use super::*;
    use crate::pendant::teach::TaughtPose;
    use crate::pendant::{Intent, Pendant, Settings};
    use crate::protocol::ArmSystem;
    use crate::robot::RobotModel;

    fn loaded(path: &str, read: Result<TeachList, String>) -> Intent {
        Intent::TeachLoaded {
            path: path.into(),
            read,
        }
    }

    fn list(names: &[&str]) -> TeachList {
        let mut l = TeachList::new();
        for n in names {
            let at = TaughtPose {
                pose: [250_000, 0, 0, 0],
                arm: ArmSystem::Right,
                work: 0,
                tool: 0,
            };
            l.record(n, at).unwrap();
        }
        l
    }

    #[test]
    fn a_load_waits_for_replace_and_undo_load_brings_the_old_list_back() {
        let now = Instant::now();
        let mut p = Pendant::new(Settings::default(), RobotModel::default_model());
        p.teach.set(list(&["A", "B"]));
        let before = p.teach.revision();
        p.apply(loaded("new.json", Ok(list(&["X", "Y", "Z"]))), now);
        assert_eq!(
            p.teach.list().len(),
            2,
            "replaced before the operator said yes"
        );
        assert_eq!(p.teach.pending().map(|l| l.list.len()), Some(3));
        p.apply(Intent::TeachConfirmLoad, now);
        assert_eq!(p.teach.list().len(), 3);
        assert!(p.teach.revision() > before, "the autosave would not see it");
        assert_eq!(p.teach.undoable_load(), Some(("new.json", 2)));
        p.apply(Intent::TeachUndoLoad, now);
        assert_eq!(p.teach.list(), &list(&["A", "B"]));
        p.apply(loaded("other.csv", Ok(list(&["Q"]))), now);
        p.apply(Intent::TeachCancelLoad, now);
        assert_eq!(
            p.teach.list(),
            &list(&["A", "B"]),
            "cancel changed the list"
        );
    }

    #[test]
    fn a_file_with_no_points_or_an_error_never_replaces_the_list() {
        let now = Instant::now();
        let mut p = Pendant::new(Settings::default(), RobotModel::default_model());
        p.teach.set(list(&["A"]));
        p.apply(loaded("empty.json", Ok(TeachList::new())), now);
        p.apply(
            loaded("bad.json", Err("bad.json: line 3: expected a name".into())),
            now,
        );
        assert_eq!(p.teach.pending(), None);
        assert_eq!(p.teach.list(), &list(&["A"]));
        let said: Vec<&str> = p.messages.iter().map(|m| m.text.as_str()).collect();
        assert!(said.iter().any(|t| t.contains("no points")), "{said:?}");
        assert!(
            said.iter().any(|t| t.contains("nothing changed")),
            "{said:?}"
        );
    }
}
