//! The simulated RMC served over Modbus/TCP on std threads: a listener thread and one
//! thread per connection, the controller locked only while a request is answered.
//!
//! A connection silent for [`ServeOptions::idle_timeout`] is dropped (logged), so clients
//! that vanished without a FIN (a PC that lost its network) do not hold the 64 places for
//! ever. TCP keepalive is not set: std offers no setter and `socket2` is not in the tree;
//! the idle timeout covers the same case.

use std::io::{self, Read, Write};
use std::net::{SocketAddr, TcpListener, TcpStream};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex, MutexGuard};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use super::connection::RmcConnection;
use super::controller::{RmcConfig, RmcController};

/// Connections served at once (RMC.md section 1: up to 64); one more is refused (its
/// first request answered with exception 06, Server Device Busy, then closed).
pub const MAX_CONNECTIONS: usize = 64;
/// `rmc-sim`'s idle timeout unless `--idle-timeout` says otherwise.
pub const DEFAULT_IDLE_TIMEOUT: Duration = Duration::from_secs(60);
/// How long a refused client is given to send its first request (to hear why it is
/// refused) before its connection is closed anyway.
const REFUSAL_WAIT: Duration = Duration::from_millis(500);
/// Refused clients waited on at once; beyond these, a refused connection is closed at once
/// (a flood of connects costs no more threads).
const REFUSALS_AT_ONCE: usize = 4;

/// How the server treats its connections.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ServeOptions {
    /// A connection that sends nothing for this long is dropped; `None` (the library's
    /// default, as the pendant's embedded RMC uses it): never. `rmc-sim` sets
    /// [`DEFAULT_IDLE_TIMEOUT`].
    pub idle_timeout: Option<Duration>,
}
/// How often a connection looks for a shutdown (its read timeout), and the listener's
/// pause after a failed accept. (A client that closes is seen at once: its read ends.)
const POLL: Duration = Duration::from_millis(100);
/// A client that takes longer than this to take a reply is dropped.
const WRITE_TIMEOUT: Duration = Duration::from_secs(2);

/// Something that happened to a connection, for a log.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum ServerEvent {
    Opened(SocketAddr),
    /// Refused: [`MAX_CONNECTIONS`] are open already.
    Refused(SocketAddr),
    /// Closed, and why ("closed by the client", "not Modbus/TCP: …", "silent for 60 s:
    /// dropped (the idle timeout)", an IO error).
    Closed(SocketAddr, String),
}

/// Called from the server's threads with each [`ServerEvent`].
pub type EventLog = Arc<dyn Fn(ServerEvent) + Send + Sync>;

/// A running server; dropping it stops accepting (the listener blocks in accept and is
/// woken by a connection of its own), closes every connection and joins the threads
/// (within a poll interval, 100 ms).
pub struct RmcServer {
    addr: SocketAddr,
    stop: Arc<AtomicBool>,
    open: Arc<AtomicUsize>,
    listener: Option<JoinHandle<()>>,
    controller: Arc<Mutex<RmcController>>,
    unplugged: Arc<AtomicBool>,
}

/// What every thread of one server shares.
#[derive(Clone)]
struct Shared {
    stop: Arc<AtomicBool>,
    open: Arc<AtomicUsize>,
    controller: Arc<Mutex<RmcController>>,
    log: Option<EventLog>,
    /// The cable is cut: bytes received are lost, nothing is answered.
    unplugged: Arc<AtomicBool>,
    options: ServeOptions,
    /// Refused clients being told why.
    refusing: Arc<AtomicUsize>,
}

impl Shared {
    fn log(&self, event: ServerEvent) {
        if let Some(log) = &self.log {
            log(event);
        }
    }
}

fn lock(c: &Mutex<RmcController>) -> MutexGuard<'_, RmcController> {
    // A connection thread never panics while holding it; if one did, the state is whole.
    c.lock().unwrap_or_else(|e| e.into_inner())
}

impl RmcServer {
    /// Serves `listener` with a controller of `config`.
    pub fn start(listener: TcpListener, config: RmcConfig) -> io::Result<RmcServer> {
        Self::start_logged(listener, config, None)
    }

    /// As [`start`](Self::start), calling `log` with each connection opened or closed.
    pub fn start_logged(
        listener: TcpListener,
        config: RmcConfig,
        log: Option<EventLog>,
    ) -> io::Result<RmcServer> {
        Self::start_with(listener, config, log, ServeOptions::default())
    }

    /// As [`start_logged`](Self::start_logged), with `options` (the idle timeout).
    pub fn start_with(
        listener: TcpListener,
        config: RmcConfig,
        log: Option<EventLog>,
        options: ServeOptions,
    ) -> io::Result<RmcServer> {
        let addr = listener.local_addr()?;
        listener.set_nonblocking(false)?;
        let shared = Shared {
            stop: Arc::new(AtomicBool::new(false)),
            open: Arc::new(AtomicUsize::new(0)),
            controller: Arc::new(Mutex::new(RmcController::new(config, Instant::now()))),
            log,
            unplugged: Arc::new(AtomicBool::new(false)),
            options,
            refusing: Arc::new(AtomicUsize::new(0)),
        };
        let unplugged = shared.unplugged.clone();
        let (stop, open, controller) = (
            shared.stop.clone(),
            shared.open.clone(),
            shared.controller.clone(),
        );
        let thread = std::thread::Builder::new()
            .name("rmc-listener".into())
            .spawn(move || accept_loop(&listener, &shared))?;
        Ok(RmcServer {
            addr,
            stop,
            open,
            listener: Some(thread),
            controller,
            unplugged,
        })
    }

    pub fn local_addr(&self) -> SocketAddr {
        self.addr
    }

    /// Connections open now.
    pub fn connections(&self) -> usize {
        self.open.load(Ordering::SeqCst)
    }

    /// Cuts (or mends) the cable: while cut, connections stay open but every byte sent to
    /// the controller is lost and nothing is answered, as when an Ethernet cable is pulled
    /// (the axes run on: the RMC has no host watchdog, RMC.md section 6).
    pub fn unplug(&self, cut: bool) {
        self.unplugged.store(cut, Ordering::SeqCst);
    }

    /// The controller, for a caller that looks inside (lock it briefly).
    pub fn controller(&self) -> Arc<Mutex<RmcController>> {
        self.controller.clone()
    }
}

impl Drop for RmcServer {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::SeqCst);
        if let Some(thread) = self.listener.take() {
            // Wakes the listener from accept: it sees the flag and ends. (A listener on
            // every address is reached on loopback.)
            let mut wake = self.addr;
            if wake.ip().is_unspecified() {
                wake.set_ip(match wake {
                    SocketAddr::V4(_) => std::net::Ipv4Addr::LOCALHOST.into(),
                    SocketAddr::V6(_) => std::net::Ipv6Addr::LOCALHOST.into(),
                });
            }
            let _ = std::net::TcpStream::connect_timeout(&wake, Duration::from_secs(1));
            let _ = thread.join();
        }
    }
}

/// Accepts until the stop flag is set, then joins every connection thread.
fn accept_loop(listener: &TcpListener, shared: &Shared) {
    let mut threads: Vec<JoinHandle<()>> = Vec::new();
    while !shared.stop.load(Ordering::SeqCst) {
        match listener.accept() {
            Ok(_) if shared.stop.load(Ordering::SeqCst) => break,
            Ok((stream, peer)) => {
                threads.retain(|t| !t.is_finished());
                if shared.open.load(Ordering::SeqCst) >= MAX_CONNECTIONS {
                    shared.log(ServerEvent::Refused(peer));
                    refuse(stream, shared);
                    continue;
                }
                shared.open.fetch_add(1, Ordering::SeqCst);
                shared.log(ServerEvent::Opened(peer));
                let conn = shared.clone();
                let spawned = std::thread::Builder::new()
                    .name(format!("rmc-{peer}"))
                    .spawn(move || {
                        let why = serve(stream, &conn);
                        conn.open.fetch_sub(1, Ordering::SeqCst);
                        conn.log(ServerEvent::Closed(peer, why));
                    });
                match spawned {
                    Ok(t) => threads.push(t),
                    Err(e) => {
                        shared.open.fetch_sub(1, Ordering::SeqCst);
                        shared.log(ServerEvent::Closed(peer, format!("no thread: {e}")));
                    }
                }
            }
            // A connection that failed before it was accepted (or no descriptor is
            // free): go on after a pause.
            Err(_) => std::thread::sleep(POLL),
        }
    }
    for t in threads {
        let _ = t.join();
    }
}

/// Tells a refused client why, on a thread of its own: its first request (if it comes
/// within [`REFUSAL_WAIT`]) is answered with exception 06, Server Device Busy, then the
/// connection is closed. With [`REFUSALS_AT_ONCE`] such threads running, it is closed at
/// once.
fn refuse(stream: TcpStream, shared: &Shared) {
    if shared.refusing.fetch_add(1, Ordering::SeqCst) >= REFUSALS_AT_ONCE {
        shared.refusing.fetch_sub(1, Ordering::SeqCst);
        return;
    }
    let refusing = shared.refusing.clone();
    let spawned = std::thread::Builder::new()
        .name("rmc-refuse".into())
        .spawn(move || {
            busy_reply(stream);
            refusing.fetch_sub(1, Ordering::SeqCst);
        });
    if spawned.is_err() {
        shared.refusing.fetch_sub(1, Ordering::SeqCst);
    }
}

/// Answers the first whole request on `stream` with exception 06 (Server Device Busy).
fn busy_reply(mut stream: TcpStream) {
    let deadline = Instant::now() + REFUSAL_WAIT;
    let _ = stream.set_nonblocking(false);
    let mut frames = crate::rmc::modbus::FrameBuffer::default();
    let mut buf = [0u8; 260];
    while let Some(left) = deadline.checked_duration_since(Instant::now()) {
        if left.is_zero() || stream.set_read_timeout(Some(left)).is_err() {
            break;
        }
        let n = match stream.read(&mut buf) {
            Ok(0) | Err(_) => break,
            Ok(n) => n,
        };
        frames.push(buf.get(..n).unwrap_or_default());
        match frames.next_frame() {
            None => continue,
            Some(Ok(frame)) => {
                let (head, function) = (frame.get(..4), frame.get(6..8));
                if let (Some(head), Some(&[unit, function])) = (head, function) {
                    let mut out = head.to_vec();
                    out.extend([0, 3, unit, function | 0x80, 6]);
                    let _ = stream.set_write_timeout(Some(REFUSAL_WAIT));
                    let _ = stream.write_all(&out);
                }
                break;
            }
            Some(Err(_)) => break,
        }
    }
    let _ = stream.shutdown(std::net::Shutdown::Both);
}

/// Serves one connection until it closes, it sends bytes that are not Modbus/TCP, it is
/// silent for the idle timeout, or the server stops; returns why it ended.
fn serve(mut stream: TcpStream, shared: &Shared) -> String {
    // Accepted sockets inherit non-blocking mode on some platforms (Windows).
    let setup = stream
        .set_nonblocking(false)
        .and_then(|()| stream.set_read_timeout(Some(POLL)))
        .and_then(|()| stream.set_write_timeout(Some(WRITE_TIMEOUT)));
    if let Err(e) = setup {
        return e.to_string();
    }
    let _ = stream.set_nodelay(true);
    let _ = crate::line::keepalive(&stream);
    let mut connection = RmcConnection::new();
    let mut buf = [0u8; 1024];
    let mut heard = Instant::now();
    loop {
        if shared.stop.load(Ordering::SeqCst) {
            return "the server stopped".into();
        }
        if let Some(idle) = shared.options.idle_timeout
            && heard.elapsed() >= idle
        {
            let _ = stream.shutdown(std::net::Shutdown::Both);
            return format!(
                "silent for {} s: dropped (the idle timeout)",
                idle.as_secs_f64()
            );
        }
        let n = match stream.read(&mut buf) {
            Ok(0) => return "closed by the client".into(),
            Ok(n) => n,
            Err(e) if is_timeout(&e) => continue,
            Err(e) => return e.to_string(),
        };
        heard = Instant::now();
        if shared.unplugged.load(Ordering::SeqCst) {
            continue;
        }
        let reply = {
            let mut controller = lock(&shared.controller);
            connection.handle_bytes(
                &mut controller,
                Instant::now(),
                buf.get(..n).unwrap_or_default(),
            )
        };
        match reply {
            Ok(bytes) if bytes.is_empty() => {}
            Ok(bytes) => {
                if let Err(e) = stream.write_all(&bytes) {
                    return e.to_string();
                }
            }
            Err(e) => {
                let _ = stream.shutdown(std::net::Shutdown::Both);
                return format!("not Modbus/TCP: {e}");
            }
        }
    }
}

fn is_timeout(e: &io::Error) -> bool {
    matches!(
        e.kind(),
        io::ErrorKind::WouldBlock | io::ErrorKind::TimedOut | io::ErrorKind::Interrupted
    )
}
