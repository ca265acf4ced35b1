//! `xsel-pendant --snapshot FILE` against the real `xsel-sim --tcp`: a snapshot with
//! every part read, written as a new JSON file the window can open; an existing file
//! refused before anything is sent; a line that cannot be opened said at once.

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
    let sim = TcpSim::start(&["--ready", "--quiet"]);
    let path = temp("sim");
    let file = path.to_str().expect("UTF-8");
    // About 10 s on an idle machine (every position number is read at 115200 baud):
    // the bound only ends a run that hangs.
    let run = run(
        PENDANT,
        &["--snapshot", file, "--tcp", &sim.addr],
        PROCESS * 6,
    );
    drop(sim);
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
    // The simulator's example coordinate file defines two zones.
    assert_eq!(snapshot.zones.len(), 2, "{:?}", snapshot.zones);
    let _ = std::fs::remove_file(&path);
}

#[test]
fn an_existing_file_and_a_refused_line_end_it_at_once() {
    assert_existing_file_refused("--snapshot", &temp("exists"));

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
