//! The simulator's programs as a third-party host sees them (PROTOCOL.md 3.44-3.45): the
//! real `xsel-sim` binary with `--programs FILE` over TCP, the section's example frames
//! sent as raw bytes and their replies checked byte for byte; a file with errors named by
//! line and column, the rest loaded; a file that cannot be read.

use std::io::{BufRead, BufReader};
use std::path::PathBuf;
use std::process::{Command, Stdio};
use std::sync::mpsc::channel;
use std::time::Instant;

use crate::signals::{Sim, err, with_sc};
use crate::wait::{LONG, PROCESS, until};

/// A program file of this test (removed when dropped).
struct File(PathBuf);

impl File {
    fn new(name: &str, text: &str) -> File {
        let path = std::env::temp_dir().join(format!(
            "xsel-sim-programs-{name}-{}.sel",
            std::process::id()
        ));
        std::fs::write(&path, text).expect("the program file is written");
        File(path)
    }

    fn path(&self) -> &str {
        self.0.to_str().expect("a UTF-8 temporary path")
    }
}

impl Drop for File {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.0);
    }
}

/// Eleven steps that take no time, a wait for input 16 at step 12, an output at 13.
const TWELVE: &str = "PROGRAM 1 twelve\n\
                      LET 1 1\nLET 1 2\nLET 1 3\nLET 1 4\nLET 1 5\nLET 1 6\n\
                      LET 1 7\nLET 1 8\nLET 1 9\nLET 1 10\nLET 1 11\n\
                      WTON 16\n\
                      BTON 300\n\
                      EXIT\n";

/// 215H byte 2 bit 5: "program running".
fn program_running(sim: &mut Sim) -> bool {
    sim.status_byte_2() & 0x20 != 0
}

#[test]
fn the_section_3_45_examples_run_pause_step_resume_and_end_a_program_from_a_file() {
    let file = File::new("twelve", TWELVE);
    let mut sim = Sim::with(&["--programs", file.path()]);
    assert!(!program_running(&mut sim));
    assert_eq!(sim.exact("!99253018E"), "#992532F", "run 1");
    // 3.44's example reply: program 1 started, at step 12 (waiting for input 16).
    until("program 1 at step 12", LONG, || {
        sim.exact("!99213018A") == "#99213011000C0000000E0"
    });
    assert!(program_running(&mut sim));
    // Pause takes hold between steps: once input 16 ends step 12, before step 13.
    assert_eq!(sim.exact("!992550190"), "#9925531", "pause 1");
    sim.type_line("in 16 on", "input 16 on");
    let paused_at_13 = with_sc("#99213011000D0000000");
    until("paused before step 13", LONG, || {
        sim.exact("!99213018A") == paused_at_13
    });
    // One step: BTON 300 alone, then paused before step 14.
    assert_eq!(sim.exact("!992560191"), "#9925632", "one step 1");
    let paused_at_14 = with_sc("#99213011000E0000000");
    until("paused before step 14", LONG, || {
        sim.exact("!99213018A") == paused_at_14
    });
    assert_eq!(
        sim.exact("!9920C012C0008D6"),
        "#9920C012C00080139",
        "output 300 on"
    );
    assert_eq!(sim.exact("!992560191"), "#9925632", "a second step: EXIT");
    let ended = with_sc("#9921301000000000000");
    until("program 1 ended", LONG, || sim.exact("!99213018A") == ended);
    assert!(!program_running(&mut sim));
    // Resume and end (all) on nothing started: resume is refused, end all is not.
    assert_eq!(sim.exact("!992570192"), err("B0C"), "resume 1, not started");
    assert_eq!(sim.exact("!99254008E"), "#9925430", "end all");
    // Run again, then end all while it waits: 213H says not started, no error.
    sim.type_line("in 16 off", "input 16 off");
    assert_eq!(sim.exact("!99253018E"), "#992532F");
    until("program 1 started", LONG, || program_running(&mut sim));
    assert_eq!(sim.exact("!99254008E"), "#9925430");
    assert_eq!(sim.exact("!99213018A"), ended);
}

#[test]
fn the_demo_is_served_by_default_and_refusals_get_their_codes() {
    let mut sim = Sim::with(&["--ready"]);
    assert_eq!(sim.exact("!99253018E"), "#992532F", "the demo runs");
    until("the demo at a step", LONG, || {
        let r = sim.ask("!9921301");
        r.len() == 22 && &r[..9] == "#99213011"
    });
    for (body, code) in [
        ("!9925300", "A03"), // run 00
        ("!9925600", "A03"), // one step 00
        ("!9925341", "A03"), // program 65
        ("!9925302", "B0B"), // no program 2
        ("!9925301", "B0C"), // already started
        ("!9925601", "B0C"), // one step while running
        ("!9921300", "A03"), // 213H for 00
    ] {
        assert_eq!(sim.ask(body), err(code), "{body}");
    }
    // The program holds the arm: the host's SCARA move is refused.
    assert_eq!(sim.ask("!992D5040000000000000200001388"), err("B03"));
    assert_eq!(sim.exact("!99254008E"), "#9925430");
}

#[test]
fn a_file_with_errors_names_them_by_line_and_column_and_loads_the_rest() {
    let file = File::new(
        "errors",
        "PROGRAM 1 fine\nTIMW 0.1\nEXIT\nPROGRAM 2 broken\nVEL 100\nMOVP 1.5\nFROB 3\n",
    );
    let mut child = Command::new(env!("CARGO_BIN_EXE_xsel-sim"))
        .args([
            "--tcp",
            "127.0.0.1:0",
            "--quiet",
            "--no-console",
            "--programs",
        ])
        .arg(file.path())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("xsel-sim starts");
    let stderr = BufReader::new(child.stderr.take().expect("stderr"));
    let (tx, rx) = channel();
    std::thread::spawn(move || {
        for line in stderr.lines().map_while(Result::ok) {
            if tx.send(line).is_err() {
                break;
            }
        }
    });
    let mut said = Vec::new();
    let deadline = Instant::now() + PROCESS;
    while !said.iter().any(|l: &String| l.contains("Ctrl-C")) {
        let left = deadline.saturating_duration_since(Instant::now());
        match rx.recv_timeout(left) {
            Ok(line) => said.push(line),
            Err(_) => panic!("no start line on stderr: {said:?}"),
        }
    }
    let _ = child.kill();
    let _ = child.wait();
    let has = |want: &str| said.iter().any(|l| l.contains(want));
    assert!(has("program(s) loaded: 1 (fine)"), "{said:?}");
    assert!(
        has("program 2 (broken) not loaded: 2 line(s) with errors"),
        "{said:?}"
    );
    assert!(
        has("line 6, column 6: 1.5: a whole number is needed"),
        "{said:?}"
    );
    assert!(has("line 7, column 1: unknown command FROB"), "{said:?}");
}

#[test]
fn a_file_that_cannot_be_read_is_a_bad_flag() {
    let missing = std::env::temp_dir().join(format!("no-such-programs-{}.sel", std::process::id()));
    let out = Command::new(env!("CARGO_BIN_EXE_xsel-sim"))
        .args(["--tcp", "127.0.0.1:0", "--no-console", "--programs"])
        .arg(&missing)
        .stdin(Stdio::null())
        .output()
        .expect("xsel-sim runs");
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("--programs"), "{stderr}");
}
