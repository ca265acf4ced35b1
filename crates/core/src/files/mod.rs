//! Files the user names, read with bounds: only a regular file is opened (a FIFO, a
//! device or a directory is refused before `open`, which could block for good), and only
//! up to a size limit checked before reading and again while reading; and operator work
//! saved in files of its own (`saved`). Imports nothing of the project.

pub mod coords_file;
pub mod folders;
pub mod job;
pub mod saved;

use std::io::Read;

use job::Ctl;
use std::path::Path;

/// CSV as the pendant writes it, for Excel as much as for programs: a UTF-8 byte order
/// mark first and CR LF line ends (RFC 4180's, and Excel's own) [I: Excel on Windows takes
/// a CSV without the mark as the system's code page, so `Überführung` would not read back
/// as written]. Every CSV reader of the pendant takes files with or without either.
pub mod csv_style {
    pub const BOM: &str = "\u{feff}";
    pub const EOL: &str = "\r\n";

    /// One CSV field: quoted (quotes doubled) when it holds a separator (`,` or Excel's
    /// `;`), a quote or a line end; as it is otherwise.
    pub fn field(text: &str) -> std::borrow::Cow<'_, str> {
        if text.contains([',', ';', '"', '\n', '\r']) {
            format!("\"{}\"", text.replace('"', "\"\"")).into()
        } else {
            text.into()
        }
    }
}

/// The most a teach list or coordinate-table file may hold (10,000 points are about
/// 1 MB as CSV).
pub const DOCUMENT_LIMIT: u64 = 8 * 1024 * 1024;
/// The most a robot model or simulator coordinate file may hold.
pub const CONFIG_LIMIT: u64 = 1024 * 1024;

/// Reads all of `path` if it is a regular file of at most `limit` bytes; otherwise one
/// sentence that names the file and the reason.
pub fn read_bounded(path: &Path, limit: u64) -> Result<Vec<u8>, String> {
    read_bounded_in(path, limit, &Ctl::detached())
}

/// [`read_bounded`] in a job: says when the file opened, counts the bytes, and stops at
/// a Cancel.
pub fn read_bounded_in(path: &Path, limit: u64, ctl: &Ctl) -> Result<Vec<u8>, String> {
    let shown = path.display();
    let (file, len) = open_regular(path, ctl)?;
    if len > limit {
        return Err(too_big(path, len, limit));
    }
    let mut bytes = Vec::with_capacity(len as usize);
    let mut reader = Watched { inner: file, ctl }.take(limit.saturating_add(1));
    let read = reader.read_to_end(&mut bytes);
    if ctl.cancelled() {
        return Err(format!("reading {shown} was cancelled: nothing changed"));
    }
    read.map_err(|e| format!("cannot read {shown}: {e}"))?;
    if bytes.len() as u64 > limit {
        return Err(too_big(path, bytes.len() as u64, limit));
    }
    Ok(bytes)
}

/// Opens `path` for reading if it is a regular file (checked before `open`, which blocks
/// for good on a FIFO), says so to `ctl` with its size, and returns it with its size.
pub fn open_regular(path: &Path, ctl: &Ctl) -> Result<(std::fs::File, u64), String> {
    let shown = path.display();
    let meta = std::fs::metadata(path).map_err(|e| format!("cannot read {shown}: {e}"))?;
    if meta.is_dir() {
        return Err(format!("{shown} is a folder, not a file"));
    }
    if !meta.is_file() {
        return Err(format!(
            "{shown} is not a regular file (a pipe, device or socket): it is not read"
        ));
    }
    let file = std::fs::File::open(path).map_err(|e| format!("cannot read {shown}: {e}"))?;
    ctl.opened();
    ctl.set_total(meta.len());
    Ok((file, meta.len()))
}

/// A reader that counts its bytes into `ctl` and fails once the job is cancelled.
pub struct Watched<'a, R> {
    pub inner: R,
    pub ctl: &'a Ctl,
}

impl<R: Read> Read for Watched<'_, R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        if self.ctl.cancelled() {
            return Err(std::io::Error::other("cancelled"));
        }
        let n = self.inner.read(buf)?;
        self.ctl.advance(n as u64);
        Ok(n)
    }
}

/// [`read_bounded`] as UTF-8 text.
pub fn read_text_bounded(path: &Path, limit: u64) -> Result<String, String> {
    let bytes = read_bounded(path, limit)?;
    String::from_utf8(bytes).map_err(|e| {
        format!(
            "{} is not UTF-8 text (bad byte at offset {})",
            path.display(),
            e.utf8_error().valid_up_to()
        )
    })
}

/// Writes `bytes` to a file the user named, whole: refused if the name is a folder, a
/// pipe or a device (writing there could block for good), else written as a new file
/// renamed over the old, so a full disk leaves the old file as it was.
pub fn write_whole(path: &Path, bytes: &[u8]) -> Result<(), String> {
    check_target(path)?;
    if path.as_os_str().is_empty() || path.file_name().is_none() {
        return Err(format!("{} names no file", path.display()));
    }
    saved::write_replacing(path, bytes, None)
        .map_err(|e| format!("cannot write {}: {e}", path.display()))
}

/// Whether a save may replace a file that is there.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Overwrite {
    /// Refuse with [`WriteError::Exists`], so the user is asked first.
    Ask,
    Replace,
}

/// Why a save did not happen.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum WriteError {
    /// The file is there and was kept: what it is, to ask the user ("3.2 kB").
    Exists(String),
    /// Anything else, as one sentence naming the file.
    Failed(String),
}

impl WriteError {
    /// The sentence to show for it.
    pub fn sentence(&self, path: &Path) -> String {
        match self {
            Self::Exists(what) => format!("{} already exists ({what})", path.display()),
            Self::Failed(why) => why.clone(),
        }
    }
}

/// [`write_whole`] in a job, asking first before replacing a file that is there.
pub fn write_file(
    path: &Path,
    bytes: &[u8],
    overwrite: Overwrite,
    ctl: &Ctl,
) -> Result<(), WriteError> {
    if overwrite == Overwrite::Ask
        && let Ok(meta) = std::fs::metadata(path)
        && meta.is_file()
    {
        ctl.opened();
        return Err(WriteError::Exists(kilobytes(meta.len())));
    }
    let written = write_whole(path, bytes).map_err(WriteError::Failed);
    ctl.opened();
    written
}

fn kilobytes(bytes: u64) -> String {
    if bytes < 1_000_000 {
        format!("{:.1} kB", bytes as f64 / 1e3)
    } else {
        megabytes(bytes)
    }
}

/// Refuses a target that exists and is not a regular file.
pub fn check_target(path: &Path) -> Result<(), String> {
    match std::fs::metadata(path) {
        Ok(meta) if !meta.is_file() => Err(format!(
            "{} is not a regular file (a folder, pipe or device): nothing is written there",
            path.display()
        )),
        _ => Ok(()),
    }
}

fn too_big(path: &Path, size: u64, limit: u64) -> String {
    format!(
        "{} is {} and more than this kind of file may hold ({}): it is not read",
        path.display(),
        megabytes(size),
        megabytes(limit)
    )
}

fn megabytes(bytes: u64) -> String {
    format!("{:.1} MB", bytes as f64 / 1e6)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn temp(name: &str) -> std::path::PathBuf {
        let dir = std::env::temp_dir().join(format!("xsel-files-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        dir.join(name)
    }

    #[test]
    fn a_file_within_the_limit_is_read_whole() {
        let path = temp("small.csv");
        std::fs::write(&path, b"name,x\nP1,1\n").unwrap();
        assert_eq!(read_bounded(&path, 100).unwrap(), b"name,x\nP1,1\n");
    }

    #[test]
    fn a_huge_file_a_folder_or_a_missing_one_is_refused_with_its_name() {
        let path = temp("big.csv");
        std::fs::write(&path, vec![b','; 5000]).unwrap();
        let e = read_bounded(&path, 1000).unwrap_err();
        assert!(e.contains("big.csv") && e.contains("not read"), "{e}");
        let dir = temp("");
        let e = read_bounded(&dir, 1000).unwrap_err();
        assert!(e.contains("folder"), "{e}");
        let e = read_bounded(&temp("missing.csv"), 1000).unwrap_err();
        assert!(
            e.starts_with("cannot read") && e.contains("missing.csv"),
            "{e}"
        );
    }

    #[cfg(unix)]
    #[test]
    fn a_fifo_is_refused_without_blocking() {
        let path = temp("fifo");
        let _ = std::fs::remove_file(&path);
        let made = std::process::Command::new("mkfifo").arg(&path).status();
        assert!(made.is_ok_and(|s| s.success()), "mkfifo failed");
        let e = read_bounded(&path, 1000).unwrap_err();
        assert!(e.contains("not a regular file"), "{e}");
    }

    #[test]
    fn a_file_that_is_there_is_kept_until_the_user_says_replace() {
        let path = temp("kept.csv");
        std::fs::write(&path, b"the operator's points").unwrap();
        let ctl = Ctl::detached();
        let e = write_file(&path, b"new", Overwrite::Ask, &ctl).unwrap_err();
        assert!(
            e.sentence(&path).contains("already exists (0.0 kB)"),
            "{e:?}"
        );
        assert_eq!(std::fs::read(&path).unwrap(), b"the operator's points");
        write_file(&path, b"new", Overwrite::Replace, &ctl).unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"new");
    }

    #[test]
    fn a_cancelled_read_stops_and_changes_nothing() {
        let path = temp("cancelled.csv");
        std::fs::write(&path, vec![b'x'; 1 << 20]).unwrap();
        let (go, gate) = crossbeam_channel::bounded::<()>(0);
        let reading = path.clone();
        let job = job::Job::spawn_opening("read", std::time::Instant::now(), move |ctl| {
            let _ = gate.recv();
            read_bounded_in(&reading, u64::MAX, ctl)
        })
        .unwrap();
        job.cancel();
        drop(go);
        let e = job
            .wait(std::time::Duration::from_secs(10))
            .unwrap()
            .unwrap_err();
        assert!(e.contains("cancelled"), "{e}");
    }

    #[cfg(target_os = "linux")]
    #[test]
    fn an_endless_device_is_refused_not_read() {
        let e = read_bounded(Path::new("/dev/zero"), 1000).unwrap_err();
        assert!(e.contains("not a regular file"), "{e}");
    }
}
