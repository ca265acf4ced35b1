//! `xsel-pendant --first-contact FILE` against the real `xsel-sim --tcp`: the report
//! written with its summary on stdout, every frame the simulator saw a query; an
//! existing file refused before anything is sent; a silent peer reported as such.

use std::io::{BufRead, BufReader};
use std::net::TcpListener;

use crate::bin_common::*;
use crate::wait::PROCESS;

/// A report path of this test in the temp folder (removed when dropped).
struct Report(std::path::PathBuf);

impl Report {
    fn new(name: &str) -> Report {
        let path = std::env::temp_dir().join(format!(
            "xsel-first-contact-{}-{name}.txt",
            std::process::id()
        ));
        let _ = std::fs::remove_file(&path);
        Report(path)
    }
    fn arg(&self) -> &str {
        self.0.to_str().expect("a UTF-8 temp path")
    }
}

impl Drop for Report {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.0);
    }
}

#[test]
fn the_report_against_xsel_sim_says_what_answered_and_only_queries_reach_it() {
    let sim = TcpSim::start(&["--ready"]);
    let report = Report::new("sim");
    let run = run(
        PENDANT,
        &["--first-contact", report.arg(), "--tcp", &sim.addr],
        PROCESS,
    );
    // The simulator's log of the frames it received, up to the last question (2A2H).
    let mut seen = Vec::new();
    let deadline = std::time::Instant::now() + PROCESS;
    while !seen.iter().any(|l: &String| l.contains("rx !992A2")) {
        let left = deadline.saturating_duration_since(std::time::Instant::now());
        match sim.log.recv_timeout(left) {
            Ok(line) => seen.push(line),
            Err(_) => break,
        }
    }
    drop(sim);
    assert_eq!(run.status.and_then(|s| s.code()), Some(0), "{}", run.stderr);
    assert_no_panic(&run.stderr);
    assert!(
        run.stdout.contains("- 215H: 5 of 5 answered"),
        "{}",
        run.stdout
    );
    assert!(run.stdout.contains("`@@` is accepted"), "{}", run.stdout);
    assert!(run.stdout.contains("report written"), "{}", run.stdout);
    let text = std::fs::read_to_string(&report.0).expect("the report");
    assert!(text.contains("Only queries were sent"));
    assert!(text.contains("Every frame, in order"));
    // Every frame the simulator received is a query.
    let commands: Vec<&String> = seen.iter().filter(|l| l.contains("] rx !99")).collect();
    assert_eq!(
        commands.len(),
        xsel_pendant::first_contact::QUESTIONS.len(),
        "{seen:?}"
    );
    for line in commands {
        let id = &line[line.find("!99").expect("a frame") + 3..][..3];
        assert!(
            [
                "200", "201", "209", "20B", "20E", "20F", "213", "215", "216", "21F", "22D", "2A1",
                "2A2", "2A3"
            ]
            .contains(&id),
            "not a query: {line}"
        );
    }
}

#[test]
fn an_existing_file_is_refused_before_anything_is_sent_and_a_silent_peer_is_said() {
    assert_existing_file_refused("--first-contact", &Report::new("exists").0);

    // A peer that accepts and never answers: three status queries, then the report.
    let listener = TcpListener::bind("127.0.0.1:0").expect("bind");
    let addr = listener.local_addr().expect("addr").to_string();
    let peer = std::thread::spawn(move || {
        let (stream, _) = listener.accept().expect("accept");
        // Reads until the pendant closes its end.
        for _ in BufReader::new(stream).split(b'\n') {}
    });
    let silent = Report::new("silent");
    let run2 = run(
        PENDANT,
        &["--first-contact", silent.arg(), "--tcp", &addr],
        PROCESS,
    );
    assert_eq!(
        run2.status.and_then(|s| s.code()),
        Some(1),
        "{}",
        run2.stderr
    );
    assert!(run2.stderr.contains("did not answer"), "{}", run2.stderr);
    let text = std::fs::read_to_string(&silent.0).expect("the report is written");
    assert!(text.contains("none of 3 answered"), "{text}");
    peer.join().expect("peer");
}
