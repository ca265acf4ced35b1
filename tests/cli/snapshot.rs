//! `xsel-pendant --snapshot FILE` against the real `xsel-sim --tcp`: a snapshot with
//! every part read, written as a new JSON file the window can open; an existing file
//! refused before anything is sent; a line that cannot be opened said at once.

use std::process::{Command, Stdio};

use xsel_pendant::pendant::snapshot::Snapshot;

use crate::bin_common::*;
use crate::wait::PROCESS;

fn temp(name: &str) -> std::path::PathBuf {
    let path =
        std::env::temp_dir().join(format!("xsel-snapshot-{}-{name}.json", std::process::id()));
    let _ = std::fs::remove_file(&path);
    path
}

#[test]
fn a_snapshot_of_xsel_sim_is_written_whole_and_reads_back() {
    let mut sim = Command::new(SIM)
        .args(["--tcp", "127.0.0.1:0", "--ready", "--quiet"])
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .expect("xsel-sim starts");
    let out = lines_of(sim.stdout.take().expect("stdout"));
    let addr = out.recv_timeout(PROCESS).expect("the address on stdout");
    let path = temp("sim");
    let file = path.to_str().expect("UTF-8");
    // About 10 s on an idle machine (every position number is read at 115200 baud):
    // the bound only ends a run that hangs.
    let run = run(
        PENDANT,
        &["--snapshot", file, "--tcp", addr.trim()],
        PROCESS * 6,
    );
    let _ = sim.kill();
    let _ = sim.wait();
    assert_eq!(run.status.and_then(|s| s.code()), Some(0), "{}", run.stderr);
    assert!(run.stdout.contains("snapshot written"), "{}", run.stdout);
    assert!(
        run.stderr.contains("reading position table"),
        "{}",
        run.stderr
    );
    let snapshot = Snapshot::from_json(&std::fs::read(&path).expect("the file")).expect("reads");
    assert!(snapshot.missing.is_empty(), "{:?}", snapshot.missing);
    assert_eq!(snapshot.versions.len(), 4);
    assert!(!snapshot.positions.is_empty());
    assert_eq!(snapshot.work.len(), 32);
    let _ = std::fs::remove_file(&path);
}

#[test]
fn an_existing_file_and_a_refused_line_end_it_at_once() {
    let path = temp("exists");
    std::fs::write(&path, "keep me").expect("write");
    let file = path.to_str().expect("UTF-8");
    let run1 = run(PENDANT, &["--snapshot", file], PROCESS);
    assert_eq!(
        run1.status.and_then(|s| s.code()),
        Some(2),
        "{}",
        run1.stderr
    );
    assert!(run1.stderr.contains("the file exists"), "{}", run1.stderr);
    assert_eq!(std::fs::read_to_string(&path).expect("kept"), "keep me");
    let _ = std::fs::remove_file(&path);

    let fresh = temp("refused");
    let tcp = refused_addr();
    let run2 = run(
        PENDANT,
        &["--snapshot", fresh.to_str().expect("UTF-8"), "--tcp", &tcp],
        PROCESS,
    );
    assert_eq!(
        run2.status.and_then(|s| s.code()),
        Some(1),
        "{}",
        run2.stderr
    );
    assert_no_panic(&run2.stderr);
    assert!(!fresh.exists());
}
