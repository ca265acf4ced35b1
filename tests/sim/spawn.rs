//! A simulator binary started for a test: killed when the test ends, its first stdout
//! line (where it listens) read, its stderr handed over or collected line by line.

use std::io::{BufRead, BufReader};
use std::process::{Child, ChildStderr, Command, Stdio};
use std::sync::{Arc, Mutex};

/// Kills the simulator when the test ends, passed or not.
pub struct Guard(Child);

impl Drop for Guard {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// Starts `bin` with `args`, no stdin; its guard, its first stdout line (trimmed) and
/// its stderr.
pub fn start(bin: &str, args: &[&str]) -> (Guard, String, ChildStderr) {
    let mut child = Command::new(bin)
        .args(args)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap_or_else(|e| panic!("{bin} starts: {e}"));
    let stdout = child.stdout.take().expect("stdout is piped");
    let stderr = child.stderr.take().expect("stderr is piped");
    let guard = Guard(child);
    let mut line = String::new();
    BufReader::new(stdout)
        .read_line(&mut line)
        .unwrap_or_else(|e| panic!("{bin} prints where it listens: {e}"));
    (guard, line.trim().to_owned(), stderr)
}

/// The address of `rmc-sim`'s first line, `listening on ADDR`.
pub fn rmc_address(first_line: &str) -> String {
    first_line
        .strip_prefix("listening on ")
        .unwrap_or_else(|| panic!("first line: {first_line:?}"))
        .to_owned()
}

/// Collects stderr's lines on a thread.
pub fn collect(stderr: ChildStderr) -> Arc<Mutex<Vec<String>>> {
    let lines = Arc::new(Mutex::new(Vec::new()));
    let sink = lines.clone();
    std::thread::spawn(move || {
        for line in BufReader::new(stderr).lines().map_while(Result::ok) {
            sink.lock().unwrap().push(line);
        }
    });
    lines
}
