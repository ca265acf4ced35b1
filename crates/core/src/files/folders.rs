//! Where a file the user names lives: a name typed without a folder goes into the last
//! folder used, else the user's documents (else home), never the working directory the
//! app happened to start in.

use std::path::{Path, PathBuf};

/// The folder a typed name is taken relative to: `last` while it is still a folder,
/// else the documents folder, else home, else (nothing known) the working directory.
pub fn default_folder(last: Option<&Path>) -> PathBuf {
    last.filter(|p| p.is_dir())
        .map(Path::to_path_buf)
        .or_else(documents)
        .or_else(home)
        .unwrap_or_else(|| PathBuf::from("."))
}

/// The full path of what the user typed: absolute as typed, `~/` (and on Windows `~\`)
/// from home, else in `folder`.
pub fn resolve(typed: &str, folder: &Path) -> Result<PathBuf, String> {
    let typed = typed.trim();
    if typed.is_empty() {
        return Err("type a file name or choose one with Browse...".into());
    }
    // `~/` from home; on Windows `~\` too.
    let rest = typed
        .strip_prefix("~/")
        .or_else(|| typed.strip_prefix("~\\").filter(|_| cfg!(windows)));
    let path = match rest.zip(home()) {
        Some((rest, home)) => home.join(rest),
        None => folder.join(typed),
    };
    if path.file_name().is_none() || typed.ends_with(['/', '\\']) {
        return Err(format!(
            "{} is a folder name; add a file name",
            path.display()
        ));
    }
    Ok(path)
}

fn home() -> Option<PathBuf> {
    let var = if cfg!(windows) { "USERPROFILE" } else { "HOME" };
    std::env::var_os(var)
        .map(PathBuf::from)
        .filter(|p| p.is_dir())
}

/// The user's documents folder. Windows: `%USERPROFILE%\Documents` (inferred: the default
/// place; a Documents folder moved elsewhere is not followed). Elsewhere: XDG's
/// `XDG_DOCUMENTS_DIR` from `user-dirs.dirs`, else `~/Documents`, if it is a folder.
fn documents() -> Option<PathBuf> {
    let home = home()?;
    let xdg = (!cfg!(windows)).then(|| xdg_documents(&home)).flatten();
    xdg.or_else(|| Some(home.join("Documents")))
        .filter(|p| p.is_dir())
}

fn xdg_documents(home: &Path) -> Option<PathBuf> {
    let config = std::env::var_os("XDG_CONFIG_HOME")
        .map(PathBuf::from)
        .unwrap_or_else(|| home.join(".config"));
    let text = super::read_text_bounded(&config.join("user-dirs.dirs"), 64 * 1024).ok()?;
    let value = text
        .lines()
        .find_map(|l| l.trim().strip_prefix("XDG_DOCUMENTS_DIR="))?
        .trim()
        .trim_matches('"');
    let path = match value.strip_prefix("$HOME") {
        Some(rest) => home.join(rest.trim_start_matches('/')),
        None => PathBuf::from(value),
    };
    // "$HOME/" alone means "no documents folder" in XDG's convention.
    (path != home).then_some(path)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_bare_name_goes_into_the_folder_and_a_full_path_stays() {
        let folder = std::env::temp_dir();
        assert_eq!(
            resolve(" points.csv ", &folder).unwrap(),
            folder.join("points.csv")
        );
        let full = folder.join("x").join("t.json");
        assert_eq!(
            resolve(&full.to_string_lossy(), Path::new("/elsewhere")).unwrap(),
            full
        );
    }

    #[test]
    fn nothing_or_a_folder_typed_is_refused_with_what_to_do() {
        let folder = std::env::temp_dir();
        assert!(resolve("  ", &folder).unwrap_err().contains("Browse"));
        assert!(resolve("sub/", &folder).unwrap_err().contains("folder"));
    }

    #[test]
    fn the_last_folder_wins_while_it_exists_and_never_the_working_directory_when_home_is_known() {
        let tmp = std::env::temp_dir();
        assert_eq!(default_folder(Some(&tmp)), tmp);
        let gone = tmp.join("xsel-no-such-folder-at-all");
        let fallback = default_folder(Some(&gone));
        assert_ne!(fallback, gone);
        if home().is_some() {
            assert_ne!(fallback, PathBuf::from("."));
        }
    }
}
