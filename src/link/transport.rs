//! The byte lines the link can own: a serial port, a TCP socket (serial-to-Ethernet
//! bridge) or any `Read + Write` stream such as the embedded simulator's pipe.

use std::io::{self, Read, Write};
use std::net::{TcpStream, ToSocketAddrs};
use std::time::Duration;

use super::line::{LineSettings, Parity};

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
}

/// Whether a read error only means "nothing yet".
pub fn is_timeout(err: &io::Error) -> bool {
    matches!(
        err.kind(),
        io::ErrorKind::TimedOut | io::ErrorKind::WouldBlock | io::ErrorKind::Interrupted
    )
}

/// Longest time spent dropping input before a command: a line that never falls silent
/// (wrong baud rate, a floating receive wire) must not hold a STOP back.
const DRAIN_LIMIT: Duration = Duration::from_millis(5);

/// Reads what is waiting, within a short timeout, until nothing more comes (or the
/// time or size limit is reached).
fn drain(read: &mut dyn FnMut(&mut [u8]) -> io::Result<usize>) -> io::Result<Vec<u8>> {
    let started = std::time::Instant::now();
    let mut dropped = Vec::new();
    let mut buf = [0u8; 512];
    loop {
        match read(&mut buf) {
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

/// A serial port opened exclusively with the given line settings.
pub struct SerialTransport {
    port: serialport::TTYPort,
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
        let mut port = builder
            .open_native()
            .map_err(|e| io::Error::other(format!("cannot open {path}: {e}")))?;
        port.set_exclusive(true)
            .map_err(|e| io::Error::other(format!("cannot lock {path} for this program: {e}")))?;
        Ok(Self::from_port(port, path, settings))
    }

    /// Wraps an already open port (for example one end of `TTYPort::pair()`).
    pub fn from_port(port: serialport::TTYPort, name: &str, settings: LineSettings) -> Self {
        Self {
            port,
            name: name.to_owned(),
            settings,
        }
    }
}

impl Transport for SerialTransport {
    fn read_timeout(&mut self, buf: &mut [u8], timeout: Duration) -> io::Result<usize> {
        use serialport::SerialPort;
        self.port
            .set_timeout(timeout.max(Duration::from_micros(100)))?;
        self.port.read(buf)
    }

    fn write_all_bytes(&mut self, bytes: &[u8]) -> io::Result<()> {
        self.port.write_all(bytes)?;
        self.port.flush()
    }

    fn discard_input(&mut self) -> io::Result<Vec<u8>> {
        use serialport::SerialPort;
        self.port.set_timeout(Duration::from_micros(100))?;
        let port = &mut self.port;
        drain(&mut |buf| port.read(buf))
    }

    fn describe(&self) -> String {
        format!("{} {}", self.name, self.settings)
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
        self.stream
            .set_read_timeout(Some(timeout.max(Duration::from_micros(100))))?;
        self.stream.read(buf)
    }

    fn write_all_bytes(&mut self, bytes: &[u8]) -> io::Result<()> {
        self.stream.write_all(bytes)
    }

    fn discard_input(&mut self) -> io::Result<Vec<u8>> {
        self.stream
            .set_read_timeout(Some(Duration::from_micros(100)))?;
        let stream = &mut self.stream;
        drain(&mut |buf| stream.read(buf))
    }

    fn describe(&self) -> String {
        format!("tcp {}", self.peer)
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

impl<S: Read + Write + Send> Transport for StreamTransport<S> {
    fn read_timeout(&mut self, buf: &mut [u8], timeout: Duration) -> io::Result<usize> {
        (self.set_timeout)(&mut self.stream, timeout);
        self.stream.read(buf)
    }

    fn write_all_bytes(&mut self, bytes: &[u8]) -> io::Result<()> {
        self.stream.write_all(bytes)?;
        self.stream.flush()
    }

    fn discard_input(&mut self) -> io::Result<Vec<u8>> {
        (self.set_timeout)(&mut self.stream, Duration::ZERO);
        let stream = &mut self.stream;
        drain(&mut |buf| stream.read(buf))
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
    fn serial_pair_carries_a_frame_and_times_out_when_idle() {
        let (master, slave) = serialport::TTYPort::pair().expect("pty pair");
        let mut host = SerialTransport::from_port(master, "pty", LineSettings::default());
        let mut device = SerialTransport::from_port(slave, "pty-slave", LineSettings::default());
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
