//! Byte lines, below both `link` and `sim`: a read-with-timeout + write trait, what a
//! "nothing yet" read looks like, and wire timing (line settings, byte time, pacing).
//!
//! Serial ports are handled as `Box<dyn serialport::SerialPort>` so the same code builds
//! on Linux, macOS and Windows.

mod address;
pub mod connection;
mod pace;
pub mod ports;
pub mod settings;

use std::io::{self, Read, Write};
use std::net::TcpStream;
use std::time::Duration;

pub use address::address;
pub use connection::{ConnectionSettings, LineKind};
pub use pace::{sleep_until, wake_on_time, write_paced};
pub use settings::{BAUD_RANGE, LineSettings, LineSettingsError, Parity, STANDARD_BAUDS};

/// Shortest read timeout handed to an OS handle (a zero timeout means "block" to some).
const MIN_TIMEOUT: Duration = Duration::from_micros(100);

/// A byte line: `std::io::Read + Write` plus a read timeout.
///
/// A read with nothing to deliver answers `ErrorKind::TimedOut` (or `WouldBlock`, see
/// [`is_timeout`]) after at most `timeout`; `Ok(0)` or another error means the line is gone.
pub trait Line: Send {
    /// Reads what has arrived, waiting at most `timeout` for the first byte.
    fn read_timeout(&mut self, buf: &mut [u8], timeout: Duration) -> io::Result<usize>;
    /// Writes every byte and pushes them out.
    fn write_all_bytes(&mut self, bytes: &[u8]) -> io::Result<()>;
}

impl Line for TcpStream {
    fn read_timeout(&mut self, buf: &mut [u8], timeout: Duration) -> io::Result<usize> {
        if timeout.is_zero() {
            // What is already there, without waiting: [observed] a socket read time-out
            // is kept in kernel ticks (4-8 ms on Linux), so even 100 us waited that long
            // before every command while the input was drained.
            self.set_nonblocking(true)?;
            let got = self.read(buf);
            self.set_nonblocking(false)?;
            return got;
        }
        self.set_read_timeout(Some(timeout.max(MIN_TIMEOUT)))?;
        self.read(buf)
    }

    fn write_all_bytes(&mut self, bytes: &[u8]) -> io::Result<()> {
        self.write_all(bytes)
    }
}

impl Line for Box<dyn serialport::SerialPort> {
    fn read_timeout(&mut self, buf: &mut [u8], timeout: Duration) -> io::Result<usize> {
        self.set_timeout(timeout.max(MIN_TIMEOUT))?;
        self.read(buf)
    }

    fn write_all_bytes(&mut self, bytes: &[u8]) -> io::Result<()> {
        self.write_all(bytes)?;
        self.flush()
    }
}

/// How long a TCP connection may be quiet before the OS probes the peer, and how often
/// it probes again `[inferred]`: well inside the simulators' 60 s idle time-out, so a
/// peer that vanished without a FIN (a PC that lost its network) is found even when
/// the idle time-out is turned off.
pub const KEEPALIVE_IDLE: Duration = Duration::from_secs(30);
pub const KEEPALIVE_INTERVAL: Duration = Duration::from_secs(10);

/// Turns TCP keepalive on for `stream` ([`KEEPALIVE_IDLE`], [`KEEPALIVE_INTERVAL`]).
pub fn keepalive(stream: &TcpStream) -> io::Result<()> {
    let probes = socket2::TcpKeepalive::new()
        .with_time(KEEPALIVE_IDLE)
        .with_interval(KEEPALIVE_INTERVAL);
    socket2::SockRef::from(stream).set_tcp_keepalive(&probes)
}

/// Whether a read error only means "nothing yet".
pub fn is_timeout(err: &io::Error) -> bool {
    matches!(
        err.kind(),
        io::ErrorKind::TimedOut | io::ErrorKind::WouldBlock | io::ErrorKind::Interrupted
    )
}

/// The wire time of one character at `baud` with 10 bits a character (8N1).
pub fn byte_time_8n1(baud: u32) -> Duration {
    LineSettings {
        baud,
        ..LineSettings::default()
    }
    .byte_time()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn byte_time_of_8n1_is_ten_bits() {
        assert_eq!(byte_time_8n1(9_600), Duration::from_nanos(1_041_666));
        assert_eq!(byte_time_8n1(115_200), Duration::from_nanos(86_805));
        assert_eq!(
            byte_time_8n1(0),
            Duration::from_secs(10),
            "no division by zero"
        );
    }

    #[test]
    fn timeouts_are_told_from_lost_lines() {
        assert!(is_timeout(&io::Error::from(io::ErrorKind::TimedOut)));
        assert!(is_timeout(&io::Error::from(io::ErrorKind::WouldBlock)));
        assert!(!is_timeout(&io::Error::from(io::ErrorKind::BrokenPipe)));
    }

    #[test]
    fn keepalive_is_turned_on() {
        let listener = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
        let stream = TcpStream::connect(listener.local_addr().unwrap()).unwrap();
        let sock = socket2::SockRef::from(&stream);
        assert!(!sock.keepalive().unwrap());
        keepalive(&stream).unwrap();
        assert!(sock.keepalive().unwrap());
    }
}
