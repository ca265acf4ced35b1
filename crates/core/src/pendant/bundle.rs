//! A support bundle: one folder holding what a support request needs (the versions, the
//! latest snapshot, the alarm history, the last frames as JSON Lines, Messages and the
//! settings), gathered from the model in one call and written whole off the UI thread.

use std::path::Path;
use std::time::{Instant, SystemTime};

use super::Pendant;
use super::connection::LineState;

/// The frames at the end of the log that go into the bundle.
pub const LAST_FRAMES: u64 = 5000;

/// One file of the bundle.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct BundleFile {
    pub name: &'static str,
    pub bytes: Vec<u8>,
}

/// The bundle's files, as the model holds things now.
pub fn gather(p: &Pendant, now: Instant, wall: SystemTime) -> Vec<BundleFile> {
    let mut files = Vec::new();
    let mut about = format!(
        "xsel-pendant {} support bundle, {}\n",
        env!("CARGO_PKG_VERSION"),
        humantime::format_rfc3339_seconds(wall)
    );
    let line = match &p.line {
        LineState::Up { line, .. } => format!("connected: {line}"),
        LineState::Down { reason, .. } => format!("down: {reason}"),
        LineState::Opening => "opening".to_owned(),
        LineState::Closed => "not connected".to_owned(),
    };
    about.push_str(&format!("line: {line}\n"));
    match &p.controller.version {
        Some(v) => about.push_str(&format!(
            "controller (201H unit 0): model {:02X}, unit code {:02X}, version {:04X}, \
             built {:04}-{:02}-{:02}\n",
            v.model, v.unit_code, v.version, v.year, v.month, v.day
        )),
        None => about.push_str("controller version: not read\n"),
    }
    match &p.snapshots.latest {
        Some(s) => {
            about.push_str(&format!("snapshot.json: {}\n", s.summary()));
            files.push(BundleFile {
                name: "snapshot.json",
                bytes: s.to_json(),
            });
        }
        None => about.push_str("no snapshot taken (Alarms view, Take snapshot)\n"),
    }
    about.push_str(&format!(
        "alarms.csv: {} record(s) as last read; frames.jsonl: the last {} frames at most; \
         messages.txt; settings.json\n",
        p.alarms.records().len(),
        LAST_FRAMES
    ));
    files.insert(
        0,
        BundleFile {
            name: "README.txt",
            bytes: about.into_bytes(),
        },
    );
    files.push(BundleFile {
        name: "alarms.csv",
        bytes: super::alarms::to_csv(p.alarms.records()).into_bytes(),
    });
    let log = &p.frame_log;
    let first = log.end().saturating_sub(LAST_FRAMES);
    let mut frames = Vec::new();
    let rows = (first..log.end()).filter_map(|seq| log.row(seq));
    // Writing into memory cannot fail.
    let _ = super::frame_log::file::write_jsonl(&mut frames, log.origin_wall(), rows);
    files.push(BundleFile {
        name: "frames.jsonl",
        bytes: frames,
    });
    let mut messages = String::new();
    for m in &p.messages {
        let ago = now.saturating_duration_since(m.at).as_secs_f64();
        messages.push_str(&format!("{ago:>10.3} s ago  {:?}  {}\n", m.level, m.text));
    }
    files.push(BundleFile {
        name: "messages.txt",
        bytes: messages.into_bytes(),
    });
    files.push(BundleFile {
        name: "settings.json",
        bytes: serde_json::to_vec_pretty(&p.settings).unwrap_or_default(),
    });
    files
}

/// Writes the files into a new folder `folder` (refused if it exists: nothing is
/// replaced); the bytes written.
pub fn write(folder: &Path, files: &[BundleFile]) -> Result<u64, String> {
    if folder.exists() {
        return Err(format!(
            "{} already exists: nothing was written there",
            folder.display()
        ));
    }
    std::fs::create_dir_all(folder)
        .map_err(|e| format!("cannot make the folder {}: {e}", folder.display()))?;
    let mut total = 0;
    for f in files {
        crate::files::write_whole(&folder.join(f.name), &f.bytes)?;
        total += f.bytes.len() as u64;
    }
    Ok(total)
}

/// The bundle folder's name for a time: `xsel-pendant-support-20261205-075158`.
pub fn folder_name(wall: SystemTime) -> String {
    let t = humantime::format_rfc3339_seconds(wall).to_string();
    let digits: String = t.chars().filter(char::is_ascii_digit).collect();
    let (date, time) = digits.split_at(digits.len().min(8));
    format!("xsel-pendant-support-{date}-{time}")
}

#[cfg(test)]
mod tests {
    use std::time::Duration;

    use super::*;
    use crate::pendant::sim_bench::{Bench, Fault};

    #[test]
    fn a_bundle_holds_every_part_and_never_replaces_a_folder() {
        let mut b = Bench::new(crate::sim::SimSetup::default());
        b.sim.raise_alarm(0xC74, Some(1), "for the bundle");
        b.poll();
        b.pump(|_| Fault::Pass);
        // The line's traffic, as the link reports it: 20 frames each way.
        for _ in 0..20 {
            let at = b.now();
            b.p.handle_event(
                at,
                crate::link::LinkEvent::FrameSent {
                    id: crate::link::RequestId(9),
                    bytes: b"!99215C0\r\n".to_vec(),
                    at,
                },
            );
            b.p.handle_event(
                at,
                crate::link::LinkEvent::FrameReceived {
                    bytes: b"#9921510000000000060004\r\n".to_vec(),
                    first_byte: at,
                    last_byte: at,
                },
            );
        }
        let wall = SystemTime::UNIX_EPOCH + Duration::from_secs(1_796_000_000);
        let files = gather(&b.p, b.now(), wall);
        let names: Vec<&str> = files.iter().map(|f| f.name).collect();
        assert_eq!(
            names,
            [
                "README.txt",
                "alarms.csv",
                "frames.jsonl",
                "messages.txt",
                "settings.json"
            ]
        );
        let text = |name: &str| {
            String::from_utf8(files.iter().find(|f| f.name == name).unwrap().bytes.clone()).unwrap()
        };
        assert!(
            text("README.txt").contains("version 0107"),
            "{}",
            text("README.txt")
        );
        assert!(text("README.txt").contains("no snapshot taken"));
        assert!(text("README.txt").contains("line: connected: bench"));
        assert!(
            text("alarms.csv").contains(",C74,"),
            "{}",
            text("alarms.csv")
        );
        let frames = text("frames.jsonl");
        assert_eq!(frames.lines().count(), 41, "a header and 40 frames");
        assert!(frames.contains("\"hex\""));
        assert!(text("messages.txt").contains("connected"));
        assert!(text("settings.json").starts_with('{'));
        let name = folder_name(wall);
        assert_eq!(name, "xsel-pendant-support-20261130-005320");
        let dir = std::env::temp_dir().join(format!("{name}-{}", std::process::id()));
        let written = write(&dir, &files).unwrap();
        assert_eq!(
            written,
            files.iter().map(|f| f.bytes.len() as u64).sum::<u64>()
        );
        assert_eq!(
            std::fs::read(dir.join("alarms.csv")).unwrap(),
            files[1].bytes
        );
        let again = write(&dir, &files).unwrap_err();
        assert!(again.contains("already exists"), "{again}");
        let _ = std::fs::remove_dir_all(&dir);
    }
}
