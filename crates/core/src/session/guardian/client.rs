//! The window's side of a guardian: starts `xsel-pendant --guardian` as a child process
//! that owns the port, and is the link's [`Transport`] through it. A heartbeat thread
//! tells the guardian the window's process is alive; when the process dies or stops,
//! the guardian hears nothing more and stops the arm by itself.

use std::io::{self, BufReader};
use std::path::Path;
use std::process::{Child, ChildStdin, Command as Process, Stdio};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use crossbeam_channel::{Receiver, RecvTimeoutError, unbounded};

use super::wire::{self, FromGuardian, OpenLine, RmcLine, ToGuardian};
use super::{GUARDIAN_FLAG, HEARTBEAT};
use crate::line::ConnectionSettings;
use crate::link::Transport;

/// Longest wait for the guardian to say the line is open (a TCP connect gives up
/// after 2 s; a process start on a loaded PC takes a moment).
const OPEN_TIMEOUT: Duration = Duration::from_secs(6);
/// Longest wait for the guardian to exit after its pipe closed (it may owe a STOP,
/// bounded by the reply timeout, twice) before it is killed.
const EXIT_TIMEOUT: Duration = Duration::from_secs(3);

/// What the stdout reader hands the transport: a message, or how the pipe ended.
type Heard = Result<FromGuardian, String>;

/// The line, through its guardian process.
pub struct GuardianLine {
    child: Child,
    pid: u32,
    stdin: Arc<Mutex<Option<ChildStdin>>>,
    heard: Receiver<Heard>,
    /// Bytes delivered but not yet read.
    pending: Vec<u8>,
    line: String,
    /// The guardian's own STOPs not yet handed to the link.
    stops: Vec<String>,
    beating: Arc<AtomicBool>,
}

impl GuardianLine {
    /// Starts the guardian (`exe --guardian`), has it open the line of `settings`, and
    /// waits until it says the line is open or why not.
    pub fn open(exe: &Path, settings: &ConnectionSettings, lease: Duration) -> io::Result<Self> {
        Self::start(
            exe,
            OpenLine {
                connection: settings.clone(),
                lease_ms: u64::try_from(lease.as_millis()).unwrap_or(u64::MAX),
                rmc: None,
            },
        )
    }

    /// Starts a guardian that owns the connection to the RMC151 `rmc` and stops its
    /// moving axes when the window dies or falls silent longer than `lease`.
    pub fn open_rmc(exe: &Path, rmc: RmcLine, lease: Duration) -> io::Result<Self> {
        Self::start(
            exe,
            OpenLine {
                connection: ConnectionSettings::default(),
                lease_ms: u64::try_from(lease.as_millis()).unwrap_or(u64::MAX),
                rmc: Some(rmc),
            },
        )
    }

    fn start(exe: &Path, open: OpenLine) -> io::Result<Self> {
        let mut process = Process::new(exe);
        process
            .arg(GUARDIAN_FLAG)
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::inherit());
        own_process_group(&mut process);
        let mut child = process
            .spawn()
            .map_err(|e| io::Error::other(format!("cannot start the guardian process: {e}")))?;
        let pid = child.id();
        let (Some(mut stdin), Some(stdout)) = (child.stdin.take(), child.stdout.take()) else {
            let _ = child.kill();
            let _ = child.wait();
            return Err(io::Error::other("the guardian process has no pipes"));
        };
        let open = ToGuardian::Open(open);
        if let Err(e) = wire::send(&mut stdin, &open) {
            let _ = child.kill();
            let _ = child.wait();
            return Err(io::Error::other(format!(
                "the guardian process ended at once: {e}"
            )));
        }
        let heard = listen(stdout);
        let mut line = GuardianLine {
            child,
            pid,
            stdin: Arc::new(Mutex::new(Some(stdin))),
            heard,
            pending: Vec::new(),
            line: String::new(),
            stops: Vec::new(),
            beating: Arc::new(AtomicBool::new(true)),
        };
        line.line = line.wait_opened()?;
        line.start_heartbeat();
        Ok(line)
    }

    /// The guardian's process id.
    pub fn pid(&self) -> u32 {
        self.pid
    }

    fn wait_opened(&mut self) -> io::Result<String> {
        let deadline = Instant::now() + OPEN_TIMEOUT;
        loop {
            let left = deadline.saturating_duration_since(Instant::now());
            match self.heard.recv_timeout(left) {
                Ok(Ok(FromGuardian::Opened { line, .. })) => return Ok(line),
                Ok(Ok(FromGuardian::Failed(why))) => return Err(io::Error::other(why)),
                Ok(Ok(_)) => {}
                Ok(Err(why)) => return Err(io::Error::other(why)),
                Err(_) => {
                    return Err(io::Error::new(
                        io::ErrorKind::TimedOut,
                        "the guardian process did not open the line in time",
                    ));
                }
            }
        }
    }

    fn start_heartbeat(&self) {
        let stdin = self.stdin.clone();
        let beating = self.beating.clone();
        let spawned = std::thread::Builder::new()
            .name("guardian-heartbeat".into())
            .spawn(move || {
                while beating.load(Ordering::Relaxed) {
                    std::thread::sleep(HEARTBEAT);
                    let mut pipe = stdin.lock().unwrap_or_else(|p| p.into_inner());
                    let Some(pipe) = pipe.as_mut() else { return };
                    if wire::send(pipe, &ToGuardian::Heartbeat).is_err() {
                        return;
                    }
                }
            });
        // Without heartbeats the guardian stops any motion after its lease: safe.
        drop(spawned);
    }

    /// Why the guardian's output ended: its exit status when it has one.
    fn ended(&mut self, why: String) -> io::Error {
        let status = match self.child.try_wait() {
            Ok(Some(s)) => format!(" ({s})"),
            _ => String::new(),
        };
        io::Error::new(
            io::ErrorKind::BrokenPipe,
            format!("the guardian process ended{status}: {why}"),
        )
    }
}

/// A thread that reads the guardian's messages until its stdout closes.
fn listen(stdout: std::process::ChildStdout) -> Receiver<Heard> {
    let (tx, rx) = unbounded();
    let spawned = std::thread::Builder::new()
        .name("guardian-stdout".into())
        .spawn(move || {
            let mut input = BufReader::new(stdout);
            loop {
                let next = match wire::receive::<FromGuardian>(&mut input) {
                    Ok(Some(m)) => Ok(m),
                    Ok(None) => Err("its output closed".to_owned()),
                    Err(e) => Err(e.to_string()),
                };
                let last = next.is_err();
                if tx.send(next).is_err() || last {
                    return;
                }
            }
        });
    if spawned.is_err() {
        let (tx, rx) = unbounded();
        let _ = tx.send(Err("no thread to read it".to_owned()));
        return rx;
    }
    rx
}

/// A guardian of its own process group: Ctrl-C in the terminal reaches the window, which
/// stops the arm and closes the pipe, and never kills the guardian first.
#[cfg(unix)]
fn own_process_group(process: &mut Process) {
    use std::os::unix::process::CommandExt;
    process.process_group(0);
}

#[cfg(windows)]
fn own_process_group(process: &mut Process) {
    use std::os::windows::process::CommandExt;
    /// `CREATE_NEW_PROCESS_GROUP`: Ctrl-C in the console does not reach the guardian.
    const CREATE_NEW_PROCESS_GROUP: u32 = 0x0000_0200;
    process.creation_flags(CREATE_NEW_PROCESS_GROUP);
}

#[cfg(not(any(unix, windows)))]
fn own_process_group(_process: &mut Process) {}

impl Transport for GuardianLine {
    fn read_timeout(&mut self, buf: &mut [u8], timeout: Duration) -> io::Result<usize> {
        let deadline = Instant::now() + timeout;
        while self.pending.is_empty() {
            let left = deadline.saturating_duration_since(Instant::now());
            match self.heard.recv_timeout(left) {
                Ok(Ok(FromGuardian::Bytes(b))) => self.pending = b,
                Ok(Ok(FromGuardian::Stopped(why))) => {
                    self.stops.push(why);
                }
                Ok(Ok(FromGuardian::Failed(why))) => return Err(self.ended(why)),
                Ok(Ok(FromGuardian::Opened { .. })) => {}
                Ok(Err(why)) => return Err(self.ended(why)),
                Err(RecvTimeoutError::Timeout) => {
                    return Err(io::Error::new(io::ErrorKind::TimedOut, "no bytes yet"));
                }
                Err(RecvTimeoutError::Disconnected) => {
                    return Err(self.ended("its reader stopped".into()));
                }
            }
        }
        let n = self.pending.len().min(buf.len());
        buf[..n].copy_from_slice(&self.pending[..n]);
        self.pending.drain(..n);
        Ok(n)
    }

    fn write_all_bytes(&mut self, bytes: &[u8]) -> io::Result<()> {
        let mut pipe = self.stdin.lock().unwrap_or_else(|p| p.into_inner());
        let Some(pipe) = pipe.as_mut() else {
            return Err(io::Error::new(
                io::ErrorKind::BrokenPipe,
                "the guardian's pipe is closed",
            ));
        };
        wire::send(pipe, &ToGuardian::Bytes(bytes.to_vec())).map_err(|e| {
            io::Error::new(
                io::ErrorKind::BrokenPipe,
                format!("the guardian process is gone: {e}"),
            )
        })
    }

    fn discard_input(&mut self) -> io::Result<Vec<u8>> {
        let mut dropped = std::mem::take(&mut self.pending);
        while let Ok(heard) = self.heard.try_recv() {
            match heard {
                Ok(FromGuardian::Bytes(b)) => dropped.extend_from_slice(&b),
                Ok(FromGuardian::Stopped(why)) => {
                    self.stops.push(why);
                }
                Ok(FromGuardian::Failed(why)) | Err(why) => return Err(self.ended(why)),
                Ok(FromGuardian::Opened { .. }) => {}
            }
        }
        Ok(dropped)
    }

    fn describe(&self) -> String {
        crate::link::transport::guardian_line_name(&self.line, self.pid)
    }

    fn take_guardian_stops(&mut self) -> Vec<String> {
        std::mem::take(&mut self.stops)
    }
}

impl Drop for GuardianLine {
    /// Says the window lets go of the line (its process runs on: the guardian's log says
    /// so), closes the pipe and waits for the guardian to exit (it STOPs first if motion
    /// may run), so the port is free when this returns; one that hangs is killed.
    fn drop(&mut self) {
        self.beating.store(false, Ordering::Relaxed);
        if let Some(mut pipe) = self.stdin.lock().unwrap_or_else(|p| p.into_inner()).take() {
            let _ = wire::send(&mut pipe, &ToGuardian::LetGo);
        }
        let deadline = Instant::now() + EXIT_TIMEOUT;
        while Instant::now() < deadline {
            match self.child.try_wait() {
                Ok(Some(_)) | Err(_) => return,
                Ok(None) => std::thread::sleep(Duration::from_millis(5)),
            }
        }
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}
