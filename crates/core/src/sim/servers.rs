//! The standalone simulator's lines: a pseudo-terminal (Unix) and a TCP port serving one
//! client at a time (a second one is refused at once, with a log line; one silent for
//! [`RunOptions::idle_timeout`] is dropped, with a log line, so a client that vanished
//! without a FIN does not lock the port).
//!
//! TCP keepalive is not set on accepted sockets: std has no setter for it and `socket2`
//! is not in the dependency tree; the idle timeout covers the vanished client instead.

use std::io::{self, Write};
use std::net::{SocketAddr, TcpListener, TcpStream};
#[cfg(unix)]
use std::sync::atomic::AtomicBool;
use std::sync::atomic::Ordering;
use std::time::Duration;
use std::time::Instant;

use super::runner::{RunOptions, ServeEnd, SimCore, SimHandle, lock, serve};
use crate::line::Line;

#[cfg(unix)]
/// How long one blocked write waits before the input is read and the stop flag checked.
const WRITE_SLICE: Duration = Duration::from_millis(5);
#[cfg(unix)]
/// Input kept while a reply waits for room: a controller's UART keeps receiving whatever
/// it does with its replies. 1 MiB `[inferred]`: the X-SEL's receive buffer size is not
/// documented; the simulator's is generous so that hosts that pipeline are served, and
/// what does not fit is dropped, counted and logged.
const INPUT_KEEP: usize = 1 << 20;
#[cfg(unix)]
/// A line that accepts no byte for this long is reported (once per reply).
const FULL_REPORT: Duration = Duration::from_secs(1);

/// A pseudo-terminal served by the simulator: clients open [`PtyServer::path`].
#[cfg(unix)]
pub struct PtyServer {
    pub path: String,
    pub handle: SimHandle,
}

/// The master side of the simulator's pseudo-terminal. A full pty (the client does not
/// read) slows the simulator down: a write waits for room, never gives up on a reply,
/// and keeps receiving meanwhile into a bounded buffer, so a host that writes everything
/// before it reads is served. Only the stop flag ends the wait.
#[cfg(unix)]
struct PtyMaster<'a> {
    port: &'a mut serialport::TTYPort,
    stop: &'a AtomicBool,
    shared: &'a std::sync::Mutex<SimCore>,
    opts_notice: Option<super::runner::NoticeFn>,
    /// Input received while a reply waited for room, not yet served.
    received: std::collections::VecDeque<u8>,
    /// Input was dropped since the buffer was last empty (said once per such spell).
    dropping: bool,
}

#[cfg(unix)]
impl PtyMaster<'_> {
    /// Reads what input is there (without waiting) into the buffer; what does not fit
    /// is dropped, counted and logged.
    fn keep_receiving(&mut self) -> io::Result<()> {
        use serialport::SerialPort;
        use std::io::Read;
        let mut buf = [0u8; 4096];
        self.port.set_timeout(Duration::from_micros(100))?;
        loop {
            let n = match self.port.read(&mut buf) {
                Ok(n) => n,
                Err(e) if crate::line::is_timeout(&e) || e.raw_os_error() == Some(5) => 0,
                Err(e) => return Err(e),
            };
            if n == 0 {
                return self.port.set_timeout(WRITE_SLICE).map_err(io::Error::other);
            }
            let room = INPUT_KEEP.saturating_sub(self.received.len());
            let kept = n.min(room);
            self.received.extend(buf.iter().take(kept));
            let dropped = n - kept;
            if dropped > 0 {
                lock(self.shared).controller.note_lost(0, dropped as u64);
                if !std::mem::replace(&mut self.dropping, true)
                    && let Some(notice) = &self.opts_notice
                {
                    notice(&format!(
                        "input buffer full ({INPUT_KEEP} bytes) while a reply waits for \
                         room: bytes of input dropped until it has room (counted)"
                    ));
                }
            }
        }
    }
}

#[cfg(unix)]
impl Line for PtyMaster<'_> {
    fn read_timeout(&mut self, buf: &mut [u8], timeout: Duration) -> io::Result<usize> {
        use serialport::SerialPort;
        use std::io::Read;
        if !self.received.is_empty() {
            let n = buf.len().min(self.received.len());
            for (slot, byte) in buf.iter_mut().zip(self.received.drain(..n)) {
                *slot = byte;
            }
            self.dropping &= !self.received.is_empty();
            return Ok(n);
        }
        self.port
            .set_timeout(timeout.max(Duration::from_micros(100)))?;
        match self.port.read(buf) {
            // A pty master reads EIO while no client has the slave open on some systems;
            // treat it as "nothing yet".
            Err(e) if e.raw_os_error() == Some(5) => {
                std::thread::sleep(timeout);
                Err(io::Error::new(io::ErrorKind::TimedOut, "no client"))
            }
            other => other,
        }
    }

    fn write_all_bytes(&mut self, bytes: &[u8]) -> io::Result<()> {
        use serialport::SerialPort;
        self.port.set_timeout(WRITE_SLICE)?;
        let started = Instant::now();
        let mut reported = false;
        let mut sent = 0;
        while sent < bytes.len() {
            match self.port.write(&bytes[sent..]) {
                Ok(0) => return Err(io::ErrorKind::WriteZero.into()),
                Ok(n) => sent += n,
                Err(e) if crate::line::is_timeout(&e) => {
                    if self.stop.load(Ordering::Relaxed) {
                        return Err(io::Error::new(io::ErrorKind::Interrupted, "stopping"));
                    }
                    self.keep_receiving()?;
                    if !reported && started.elapsed() >= FULL_REPORT {
                        reported = true;
                        if let Some(n) = &self.opts_notice {
                            n("pty full for 1 s: the client is not reading; waiting for \
                               room (input is kept meanwhile)");
                        }
                    }
                }
                Err(e) => return Err(e),
            }
        }
        if reported && let Some(n) = &self.opts_notice {
            n("pty has room again: serving");
        }
        self.port.flush()
    }
}

/// Creates a pseudo-terminal and serves it on a new thread (Unix only; TCP works
/// everywhere).
#[cfg(unix)]
pub fn start_pty(core: SimCore, mut opts: RunOptions) -> io::Result<PtyServer> {
    use serialport::SerialPort;
    let (mut master, slave) = serialport::TTYPort::pair().map_err(io::Error::other)?;
    let path = slave
        .name()
        .ok_or_else(|| io::Error::other("the pseudo-terminal has no name"))?;
    let handle = SimHandle::spawn(core, move |shared, stop| {
        // The slave stays open here so the path stays valid and the master never sees a
        // hang-up between clients.
        let _slave = slave;
        let mut line = PtyMaster {
            port: &mut master,
            stop,
            shared,
            opts_notice: opts.notice.clone(),
            received: std::collections::VecDeque::new(),
            dropping: false,
        };
        while !stop.load(Ordering::Relaxed) {
            match serve(&mut line, shared, stop, &mut opts) {
                ServeEnd::Stopped => break,
                ServeEnd::Closed | ServeEnd::Failed(_) => {
                    std::thread::sleep(Duration::from_millis(20))
                }
            }
        }
    });
    Ok(PtyServer { path, handle })
}

/// A TCP port served by the simulator, one client at a time.
pub struct TcpServer {
    pub addr: SocketAddr,
    pub handle: SimHandle,
}

/// The client being served; a client that connects meanwhile is refused at once (its
/// connection closed, one notice line), as a serial port has one user.
struct TcpClient<'a> {
    stream: TcpStream,
    peer: SocketAddr,
    listener: &'a TcpListener,
    opts_notice: Option<super::runner::NoticeFn>,
    /// The last byte received from the client or sent to it.
    heard: Instant,
    /// Drop the client after this long without a byte from it.
    idle: Option<Duration>,
    /// It was dropped for its silence.
    dropped_idle: bool,
}

impl TcpClient<'_> {
    /// The client being served has closed its end (its FIN is waiting to be read).
    fn client_gone(&self) -> bool {
        let mut b = [0u8; 1];
        if self.stream.set_nonblocking(true).is_err() {
            return false;
        }
        let gone = match self.stream.peek(&mut b) {
            Ok(0) => true,
            Ok(_) => false,
            Err(e) => !crate::line::is_timeout(&e),
        };
        let _ = self.stream.set_nonblocking(false);
        gone
    }

    fn refuse_newcomers(&self) {
        // A client that connects just after the served one left is served next, not
        // refused: the next read ends this one.
        if self.client_gone() {
            return;
        }
        while let Ok((other, addr)) = self.listener.accept() {
            let _ = other.shutdown(std::net::Shutdown::Both);
            drop(other);
            if let Some(n) = &self.opts_notice {
                n(&format!(
                    "refused a second client from {addr}: one client at a time, serving {}",
                    self.peer
                ));
            }
        }
    }
}

impl Line for TcpClient<'_> {
    fn read_timeout(&mut self, buf: &mut [u8], timeout: Duration) -> io::Result<usize> {
        // Read first: a client that has just left is seen gone (its FIN came before the
        // next client's connect) before anyone waiting is refused.
        let got = Line::read_timeout(&mut self.stream, buf, timeout);
        match &got {
            Ok(0) => {}
            Ok(_) => {
                self.heard = Instant::now();
                self.refuse_newcomers();
            }
            Err(e) if crate::line::is_timeout(e) => {
                if let Some(idle) = self.idle
                    && self.heard.elapsed() >= idle
                {
                    self.dropped_idle = true;
                    let _ = self.stream.shutdown(std::net::Shutdown::Both);
                    return Err(io::Error::other(format!(
                        "silent for {} s (the idle timeout)",
                        idle.as_secs_f64()
                    )));
                }
                self.refuse_newcomers();
            }
            Err(_) => {}
        }
        got
    }

    fn write_all_bytes(&mut self, bytes: &[u8]) -> io::Result<()> {
        self.stream.write_all(bytes)?;
        self.heard = Instant::now();
        Ok(())
    }
}

/// Binds `addr` and serves one client at a time on a new thread; clients that connect
/// while one is served are refused at once. Paced replies are written whole, each when
/// its last byte is due (one segment a reply).
pub fn start_tcp(core: SimCore, addr: &str, mut opts: RunOptions) -> io::Result<TcpServer> {
    let listener = TcpListener::bind(addr)?;
    listener.set_nonblocking(true)?;
    let local = listener.local_addr()?;
    opts.coalesce = true;
    let handle = SimHandle::spawn(core, move |shared, stop| {
        while !stop.load(Ordering::Relaxed) {
            match listener.accept() {
                Ok((stream, peer)) => {
                    let _ = stream.set_nonblocking(false);
                    let _ = stream.set_nodelay(true);
                    let _ = crate::line::keepalive(&stream);
                    opts.notify(&format!("client {peer} connected"));
                    let mut client = TcpClient {
                        stream,
                        peer,
                        listener: &listener,
                        opts_notice: opts.notice.clone(),
                        heard: Instant::now(),
                        idle: opts.idle_timeout,
                        dropped_idle: false,
                    };
                    let end = serve(&mut client, shared, stop, &mut opts);
                    match end {
                        ServeEnd::Failed(e) if client.dropped_idle => {
                            opts.notify(&format!(
                                "client {peer} dropped: {e}; serving the next client"
                            ));
                        }
                        ServeEnd::Failed(e) => {
                            opts.notify(&format!("client {peer} lost: {e}"));
                        }
                        ServeEnd::Closed | ServeEnd::Stopped => {
                            opts.notify(&format!("client {peer} left"));
                        }
                    }
                }
                Err(_) => {
                    let mut core = lock(shared);
                    let now = core.now();
                    core.controller.advance(now);
                    drop(core);
                    std::thread::sleep(Duration::from_millis(10));
                }
            }
        }
    });
    Ok(TcpServer {
        addr: local,
        handle,
    })
}

#[cfg(test)]
mod tests {
    use std::sync::atomic::AtomicBool;
    use std::sync::{Arc, Mutex};

    use super::*;
    use crate::sim::{Controller, FaultSpec, SimSetup};

    /// A line that delivers one burst of input, then fails every write.
    struct FailingWrites(Option<Vec<u8>>);

    impl Line for FailingWrites {
        fn read_timeout(&mut self, buf: &mut [u8], _: Duration) -> io::Result<usize> {
            match self.0.take() {
                Some(v) => {
                    buf[..v.len()].copy_from_slice(&v);
                    Ok(v.len())
                }
                None => Ok(0),
            }
        }
        fn write_all_bytes(&mut self, _: &[u8]) -> io::Result<()> {
            Err(io::ErrorKind::BrokenPipe.into())
        }
    }

    /// While a reply waits for room, input is kept up to the bound; the rest is dropped,
    /// counted and logged, and the writer is never blocked.
    #[cfg(unix)]
    #[test]
    fn input_beyond_the_bound_is_dropped_counted_and_logged() {
        use std::io::Write;
        let (mut master, mut slave) = serialport::TTYPort::pair().expect("pty");
        let shared = Mutex::new(SimCore::new(
            Controller::new(SimSetup::default()),
            FaultSpec::none(),
        ));
        let seen = Arc::new(Mutex::new(Vec::<String>::new()));
        let sink = seen.clone();
        let stop = AtomicBool::new(false);
        let mut line = PtyMaster {
            port: &mut master,
            stop: &stop,
            shared: &shared,
            opts_notice: Some(Arc::new(move |l: &str| {
                sink.lock().unwrap().push(l.to_owned())
            })),
            received: std::collections::VecDeque::new(),
            dropping: false,
        };
        const SENT: usize = INPUT_KEEP + 300_000;
        let writer = std::thread::spawn(move || {
            let chunk = [b'x'; 4096];
            let mut sent = 0;
            while sent < SENT {
                let n = (SENT - sent).min(chunk.len());
                slave
                    .write_all(&chunk[..n])
                    .expect("the simulator keeps reading");
                sent += n;
            }
            slave
        });
        let deadline = std::time::Instant::now() + Duration::from_secs(30);
        let mut lost = 0;
        while line.received.len() + lost < SENT {
            assert!(
                std::time::Instant::now() < deadline,
                "the writer was blocked"
            );
            line.keep_receiving().expect("reads");
            lost = lock(&shared).controller.counters().input_lost_bytes as usize;
        }
        let _slave = writer.join().expect("writer");
        assert_eq!(line.received.len(), INPUT_KEEP);
        assert_eq!(lost, SENT - INPUT_KEEP);
        let notices = seen.lock().unwrap();
        let drops = notices
            .iter()
            .filter(|l| l.contains("bytes of input dropped"))
            .count();
        assert_eq!(drops, 1, "the drop is logged once: {notices:?}");
    }

    #[test]
    fn a_line_that_fails_mid_reply_logs_and_counts_what_is_lost() {
        let mut setup = SimSetup::default();
        setup.config.reply_delay = Duration::ZERO;
        let shared = Mutex::new(SimCore::new(Controller::new(setup), FaultSpec::none()));
        let seen = Arc::new(Mutex::new(Vec::<String>::new()));
        let sink = seen.clone();
        let mut opts = RunOptions {
            notice: Some(Arc::new(move |l: &str| {
                sink.lock().unwrap().push(l.to_owned())
            })),
            ..RunOptions::default()
        };
        // Two whole frames and the start of a third: the first reply fails.
        let mut line = FailingWrites(Some(b"!99215@@\r\n!99215@@\r\n!992".to_vec()));
        let end = serve(&mut line, &shared, &AtomicBool::new(false), &mut opts);
        assert!(matches!(end, ServeEnd::Failed(_)), "{end:?}");
        let n = *lock(&shared).controller.counters();
        assert_eq!((n.lost_replies, n.input_lost_bytes), (1, 14));
        let seen = seen.lock().unwrap();
        assert!(
            seen.iter().any(|l| l.contains("14 bytes of input")),
            "{seen:?}"
        );
    }
}
