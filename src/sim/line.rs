//! The byte lines the simulator serves (embedded pipe, pseudo-terminal, TCP socket) and
//! precise pacing of reply bytes at a wire time per byte.

use std::io::{self, Read, Write};
use std::net::TcpStream;
use std::time::{Duration, Instant};

use super::pipe::PipeEnd;

/// What the runner needs of a line: read with a timeout, write everything.
pub trait SimLine: Send {
    /// Reads what has arrived, waiting at most `timeout`; `Ok(0)` = the line is gone;
    /// `TimedOut`/`WouldBlock` = nothing yet.
    fn read_some(&mut self, buf: &mut [u8], timeout: Duration) -> io::Result<usize>;
    /// Writes every byte and pushes them out.
    fn write_bytes(&mut self, bytes: &[u8]) -> io::Result<()>;
}

impl SimLine for PipeEnd {
    fn read_some(&mut self, buf: &mut [u8], timeout: Duration) -> io::Result<usize> {
        self.set_read_timeout(timeout);
        self.read(buf)
    }

    fn write_bytes(&mut self, bytes: &[u8]) -> io::Result<()> {
        self.write_all(bytes)
    }
}

impl SimLine for serialport::TTYPort {
    fn read_some(&mut self, buf: &mut [u8], timeout: Duration) -> io::Result<usize> {
        use serialport::SerialPort;
        self.set_timeout(timeout.max(Duration::from_micros(100)))?;
        match self.read(buf) {
            // A pty master reads EIO while no client has the slave open on some systems;
            // treat it as "nothing yet".
            Err(e) if e.raw_os_error() == Some(5) => {
                std::thread::sleep(timeout);
                Err(io::Error::new(io::ErrorKind::TimedOut, "no client"))
            }
            other => other,
        }
    }

    fn write_bytes(&mut self, bytes: &[u8]) -> io::Result<()> {
        self.write_all(bytes)?;
        self.flush()
    }
}

impl SimLine for TcpStream {
    fn read_some(&mut self, buf: &mut [u8], timeout: Duration) -> io::Result<usize> {
        self.set_read_timeout(Some(timeout.max(Duration::from_micros(100))))?;
        self.read(buf)
    }

    fn write_bytes(&mut self, bytes: &[u8]) -> io::Result<()> {
        self.write_all(bytes)
    }
}

/// Whether a read error only means "nothing yet".
pub fn is_timeout(err: &io::Error) -> bool {
    matches!(
        err.kind(),
        io::ErrorKind::TimedOut | io::ErrorKind::WouldBlock | io::ErrorKind::Interrupted
    )
}

/// Sleeps until `deadline` with sub-100 µs precision: a coarse sleep, then a yielding spin.
pub fn sleep_until(deadline: Instant) {
    loop {
        let now = Instant::now();
        if now >= deadline {
            return;
        }
        let left = deadline - now;
        if left > Duration::from_micros(400) {
            std::thread::sleep(left - Duration::from_micros(250));
        } else {
            std::thread::yield_now();
        }
    }
}

/// Writes `bytes` so that byte *i* has left the wire at `start + (i + 1) * byte_time`,
/// as a UART at that rate would: each byte is written when its last bit would be sent.
pub fn write_paced(
    line: &mut dyn SimLine,
    bytes: &[u8],
    byte_time: Duration,
    start: Instant,
) -> io::Result<()> {
    if byte_time.is_zero() {
        return line.write_bytes(bytes);
    }
    let mut sent = 0;
    while sent < bytes.len() {
        let elapsed = start.elapsed().as_nanos();
        let due = (elapsed / byte_time.as_nanos()).min(bytes.len() as u128) as usize;
        if due > sent {
            line.write_bytes(&bytes[sent..due])?;
            sent = due;
            continue;
        }
        sleep_until(start + byte_time.saturating_mul(sent as u32 + 1));
    }
    Ok(())
}

/// The wire time of one character at `baud` with 10 bits a character (8N1).
pub fn byte_time_8n1(baud: u32) -> Duration {
    Duration::from_nanos(10_000_000_000 / u64::from(baud.max(1)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::pipe::{PipeConfig, duplex};

    #[test]
    fn paced_write_takes_the_wire_time() {
        let (mut a, mut b) = duplex(PipeConfig::default());
        let bt = byte_time_8n1(9600);
        let start = Instant::now();
        write_paced(&mut a, &[b'x'; 20], bt, start).unwrap();
        let took = start.elapsed();
        assert!(took >= bt * 20, "{took:?}");
        assert!(took < bt * 20 + Duration::from_millis(15), "{took:?}");
        let mut buf = [0u8; 64];
        assert_eq!(b.read_some(&mut buf, Duration::from_millis(5)).unwrap(), 20);
    }
}
