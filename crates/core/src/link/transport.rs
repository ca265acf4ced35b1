//! The byte lines the link can own: a serial port, a TCP socket (serial-to-Ethernet
//! bridge) or any `Read + Write` stream such as the embedded simulator's pipe.

use std::io::{self, Read, Write};
use std::net::{TcpStream, ToSocketAddrs};
use std::time::Duration;

use crate::line::{Line, LineSettings, Parity};
// The link's code reads `transport::is_timeout`; it lives with the line trait.
pub use crate::line::is_timeout;

/// What the link thread needs of a line. Implementations answer a read with nothing to
/// deliver by `ErrorKind::TimedOut` (or `WouldBlock`) after at most `timeout`, with
/// `Ok(0)` or another error when the line is gone.
pub trait Transport: Send {
    /// Reads what has arrived, waiting at most `timeout` for the first byte.
    fn read_timeout(&mut self, buf: &mut [u8], timeout: Duration) -> io::Result<usize>;
    /// Writes every byte (and pushes them out).
    fn write_all_bytes(&mut self, bytes: &[u8]) -> io::Result<()>;
    /// Drops whatever input is waiting; returns the bytes dropped when it can tell.
    fn discard_input(&mut self) -> io::Result<Vec<u8>>;
    /// A short name for logs and the connection panel ("/dev/ttyUSB0 115200 8N1").
    fn describe(&self) -> String;
    /// The STOPs a guardian process owning the line sent of its own since the last
    /// call, each with why; the link hands each on as
    /// [`super::LinkEvent::GuardianStopped`].
    fn take_guardian_stops(&mut self) -> Vec<String> {
        Vec::new()
    }
    /// A second handle that writes to the same line, so one thread can block reading
    /// while another writes at once (the guardian); `None` where the line has no such
    /// handle.
    fn try_clone_writer(&self) -> Option<Box<dyn Write + Send>> {
        None
    }
}

/// How a line owned by a guardian process names itself: `<line> (guardian process <pid>)`.
const GUARDIAN_NAME: &str = " (guardian process ";

/// The name of a line owned by the guardian process `pid`.
pub fn guardian_line_name(line: &str, pid: u32) -> String {
    format!("{line}{GUARDIAN_NAME}{pid})")
}

/// The guardian's process id in a line's name, if a guardian owns it.
pub fn guardian_of(name: &str) -> Option<u32> {
    let (_, rest) = name.rsplit_once(GUARDIAN_NAME)?;
    rest.strip_suffix(')')?.parse().ok()
}

/// Longest time spent dropping input before a command: a line that never falls silent
/// (wrong baud rate, a floating receive wire) must not hold a STOP back.
const DRAIN_LIMIT: Duration = Duration::from_millis(5);

/// Reads what is waiting, within a short timeout, until nothing more comes (or the
/// time or size limit is reached).
fn drain(line: &mut dyn Line) -> io::Result<Vec<u8>> {
    let started = std::time::Instant::now();
    let mut dropped = Vec::new();
    let mut buf = [0u8; 512];
    loop {
        match line.read_timeout(&mut buf, Duration::ZERO) {
            Ok(0) => return Ok(dropped),
            Ok(n) => dropped.extend_from_slice(&buf[..n]),
            Err(e) if is_timeout(&e) => return Ok(dropped),
            Err(e) => return Err(e),
        }
        if dropped.len() > 1 << 16 || started.elapsed() > DRAIN_LIMIT {
            return Ok(dropped);
        }
    }
}

/// A serial port opened exclusively (where the platform can tell) with the given line
/// settings. Windows opens COM ports exclusively by nature; on Unix the port is locked
/// with `TIOCEXCL`.
pub struct SerialTransport {
    port: Box<dyn serialport::SerialPort>,
    name: String,
    settings: LineSettings,
}

impl SerialTransport {
    /// Opens `path`; the error names the port and the reason (busy, missing, denied).
    pub fn open(path: &str, settings: LineSettings) -> io::Result<Self> {
        settings
            .validate()
            .map_err(|e| io::Error::new(io::ErrorKind::InvalidInput, e))?;
        let builder = serialport::new(path, settings.baud)
            .data_bits(match settings.data_bits {
                7 => serialport::DataBits::Seven,
                _ => serialport::DataBits::Eight,
            })
            .parity(match settings.parity {
                Parity::None => serialport::Parity::None,
                Parity::Odd => serialport::Parity::Odd,
                Parity::Even => serialport::Parity::Even,
            })
            .stop_bits(match settings.stop_bits {
                2 => serialport::StopBits::Two,
                _ => serialport::StopBits::One,
            })
            .flow_control(serialport::FlowControl::None)
            .timeout(Duration::from_millis(10));
        let port = open_exclusive(builder)
            .map_err(|e| io::Error::other(format!("cannot open {path}: {e}")))?;
        Ok(Self::from_port(port, path, settings))
    }

    /// Wraps an already open port (for example one end of `TTYPort::pair()`, boxed).
    pub fn from_port(
        port: Box<dyn serialport::SerialPort>,
        name: &str,
        settings: LineSettings,
    ) -> Self {
        Self {
            port,
            name: name.to_owned(),
            settings,
        }
    }
}

/// Opens the port and locks it for this program where the platform has such a lock.
#[cfg(unix)]
fn open_exclusive(
    builder: serialport::SerialPortBuilder,
) -> io::Result<Box<dyn serialport::SerialPort>> {
    let mut port = builder.open_native().map_err(io::Error::other)?;
    port.set_exclusive(true)
        .map_err(|e| io::Error::other(format!("cannot lock it for this program: {e}")))?;
    Ok(Box::new(port))
}

/// Opens the port; COM ports are exclusive by nature.
#[cfg(not(unix))]
fn open_exclusive(
    builder: serialport::SerialPortBuilder,
) -> io::Result<Box<dyn serialport::SerialPort>> {
    builder.open().map_err(io::Error::other)
}

impl Transport for SerialTransport {
    fn read_timeout(&mut self, buf: &mut [u8], timeout: Duration) -> io::Result<usize> {
        self.port.read_timeout(buf, timeout)
    }

    fn write_all_bytes(&mut self, bytes: &[u8]) -> io::Result<()> {
        self.port.write_all_bytes(bytes)
    }

    fn discard_input(&mut self) -> io::Result<Vec<u8>> {
        drain(&mut self.port)
    }

    fn describe(&self) -> String {
        format!("{} {}", self.name, self.settings)
    }

    fn try_clone_writer(&self) -> Option<Box<dyn Write + Send>> {
        self.port
            .try_clone()
            .ok()
            .map(|p| Box::new(p) as Box<dyn Write + Send>)
    }
}

/// A TCP connection to a serial-to-Ethernet bridge or to `xsel-sim --tcp`.
pub struct TcpTransport {
    stream: TcpStream,
    peer: String,
}

impl TcpTransport {
    /// Connects within `timeout`; Nagle is off so single frames go out at once.
    pub fn connect(addr: &str, timeout: Duration) -> io::Result<Self> {
        let mut last_err = io::Error::new(io::ErrorKind::NotFound, format!("{addr}: no address"));
        let addrs = addr
            .to_socket_addrs()
            .map_err(|e| io::Error::new(e.kind(), format!("{addr}: {e}")))?;
        for candidate in addrs {
            match TcpStream::connect_timeout(&candidate, timeout) {
                Ok(stream) => {
                    stream.set_nodelay(true)?;
                    return Ok(Self {
                        stream,
                        peer: addr.to_owned(),
                    });
                }
                Err(e) => last_err = io::Error::new(e.kind(), format!("{addr}: {e}")),
            }
        }
        Err(last_err)
    }
}

impl Transport for TcpTransport {
    fn read_timeout(&mut self, buf: &mut [u8], timeout: Duration) -> io::Result<usize> {
        Line::read_timeout(&mut self.stream, buf, timeout)
    }

    fn write_all_bytes(&mut self, bytes: &[u8]) -> io::Result<()> {
        self.stream.write_all_bytes(bytes)
    }

    fn discard_input(&mut self) -> io::Result<Vec<u8>> {
        drain(&mut self.stream)
    }

    fn describe(&self) -> String {
        format!("tcp {}", self.peer)
    }

    fn try_clone_writer(&self) -> Option<Box<dyn Write + Send>> {
        self.stream
            .try_clone()
            .ok()
            .map(|s| Box::new(s) as Box<dyn Write + Send>)
    }
}

/// Any byte stream whose reads time out by themselves (the embedded simulator's pipe):
/// `set_timeout` is called before each read.
pub struct StreamTransport<S> {
    stream: S,
    name: String,
    set_timeout: fn(&mut S, Duration),
}

impl<S: Read + Write + Send> StreamTransport<S> {
    pub fn new(stream: S, name: &str, set_timeout: fn(&mut S, Duration)) -> Self {
        Self {
            stream,
            name: name.to_owned(),
            set_timeout,
        }
    }
}

impl<S: Read + Write + Send> Line for StreamTransport<S> {
    fn read_timeout(&mut self, buf: &mut [u8], timeout: Duration) -> io::Result<usize> {
        (self.set_timeout)(&mut self.stream, timeout);
        self.stream.read(buf)
    }

    fn write_all_bytes(&mut self, bytes: &[u8]) -> io::Result<()> {
        self.stream.write_all(bytes)?;
        self.stream.flush()
    }
}

impl<S: Read + Write + Send> Transport for StreamTransport<S> {
    fn read_timeout(&mut self, buf: &mut [u8], timeout: Duration) -> io::Result<usize> {
        Line::read_timeout(self, buf, timeout)
    }

    fn write_all_bytes(&mut self, bytes: &[u8]) -> io::Result<()> {
        Line::write_all_bytes(self, bytes)
    }

    fn discard_input(&mut self) -> io::Result<Vec<u8>> {
        drain(self)
    }

    fn describe(&self) -> String {
        self.name.clone()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::net::TcpListener;

    #[test]
    fn a_guardian_owned_line_names_its_guardian_and_no_other_line_does() {
        let name = guardian_line_name("tcp 127.0.0.1:5099", 4242);
        assert_eq!(name, "tcp 127.0.0.1:5099 (guardian process 4242)");
        assert_eq!(guardian_of(&name), Some(4242));
        assert_eq!(guardian_of("/dev/ttyUSB0 115200 8N1"), None);
        assert_eq!(guardian_of("x (guardian process )"), None);
    }

    /// Ports above COM9 need the device namespace: `COM200` as typed, `com200` and
    /// `\\.\COM200` all reach the device layer (serialport adds `\\.\` to a name
    /// without a backslash) and a missing one is said to be missing, with the Device
    /// Manager hint, not refused as a bad name. Runs under Wine in CI.
    #[cfg(windows)]
    #[test]
    fn com_names_above_9_reach_the_device_namespace_and_a_missing_one_is_named() {
        use crate::link::reason::{IoFailure, LineDownReason};
        for name in ["COM200", "com200", r"\\.\COM200"] {
            let Err(e) = SerialTransport::open(name, LineSettings::default()) else {
                panic!("{name} opened: there is no such port here");
            };
            let detail = e.to_string();
            assert!(detail.contains(name), "{detail}");
            // Not ERROR_INVALID_NAME: the name was taken as a device path.
            assert!(!detail.contains("syntax is incorrect"), "{detail}");
            let reason = LineDownReason::OpenFailed(IoFailure {
                kind: e.kind(),
                detail,
            });
            let hint = crate::pendant::connection::open_hint(&reason).unwrap_or_default();
            assert!(hint.contains("Device Manager"), "{reason:?}: {hint}");
        }
    }

    #[cfg(unix)]
    #[test]
    fn serial_pair_carries_a_frame_and_times_out_when_idle() {
        let (master, slave) = serialport::TTYPort::pair().expect("pty pair");
        let settings = LineSettings::default();
        let mut host = SerialTransport::from_port(Box::new(master), "pty", settings);
        let mut device = SerialTransport::from_port(Box::new(slave), "pty-slave", settings);
        host.write_all_bytes(b"!992152B\r\n").unwrap();
        let mut buf = [0u8; 64];
        let mut got = Vec::new();
        while got.len() < 10 {
            let n = device
                .read_timeout(&mut buf, Duration::from_millis(200))
                .unwrap();
            got.extend_from_slice(&buf[..n]);
        }
        assert_eq!(got, b"!992152B\r\n");
        let err = host
            .read_timeout(&mut buf, Duration::from_millis(5))
            .unwrap_err();
        assert!(is_timeout(&err), "idle read gave {err:?}");
    }

    #[test]
    fn tcp_discard_returns_the_garbage_it_dropped() {
        let listener = TcpListener::bind("127.0.0.1:0").unwrap();
        let addr = listener.local_addr().unwrap().to_string();
        let mut link = TcpTransport::connect(&addr, Duration::from_secs(1)).unwrap();
        let (mut peer, _) = listener.accept().unwrap();
        peer.write_all(b"\x00junk").unwrap();
        std::thread::sleep(Duration::from_millis(20));
        assert_eq!(link.discard_input().unwrap(), b"\x00junk");
        assert!(link.describe().contains(&addr));
    }

    #[test]
    fn unreachable_serial_port_names_the_path() {
        let err = SerialTransport::open("/dev/does-not-exist-xsel", LineSettings::default())
            .err()
            .expect("opening a missing port fails");
        assert!(
            err.to_string().contains("/dev/does-not-exist-xsel"),
            "{err}"
        );
    }
}
