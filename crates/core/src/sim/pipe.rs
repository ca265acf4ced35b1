//! An in-memory duplex byte pipe: the "serial line" between the pendant and the embedded
//! simulator, optionally paced so that each byte takes its wire time to arrive.

use std::collections::VecDeque;
use std::io::{self, Read, Write};
use std::sync::{Arc, Condvar, Mutex, MutexGuard};
use std::time::{Duration, Instant};

use crate::line::Line;

/// How the pipe behaves: pacing and how long a read waits for a byte.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PipeConfig {
    /// Time one character takes on the wire (start + data + parity + stop bits / baud);
    /// `None` delivers bytes at once.
    pub byte_time: Option<Duration>,
    /// A read with nothing to deliver returns `ErrorKind::TimedOut` after this long.
    pub read_timeout: Duration,
}

impl Default for PipeConfig {
    fn default() -> Self {
        Self {
            byte_time: None,
            read_timeout: Duration::from_millis(50),
        }
    }
}

/// How long a paced byte may wait for the ones behind it before it is handed over: a
/// paced chunk is read when it has all arrived (its last byte exactly on time) or when its
/// oldest unread byte has waited this long, as a UART's FIFO and its driver batch bytes
/// (inferred: USB serial adapters hand bytes over after a latency timer of 1-16 ms). One
/// wake-up per frame of up to 4 ms on the wire, not one per byte.
const GATHER: Duration = Duration::from_millis(4);

/// Bytes written in one call, the first readable at `first_ready`, each next one a byte
/// time later.
struct Chunk {
    data: Vec<u8>,
    taken: usize,
    first_ready: Instant,
}

#[derive(Default)]
struct Direction {
    chunks: VecDeque<Chunk>,
    /// When the (simulated) wire is free for the next byte.
    line_free_at: Option<Instant>,
    writer_gone: bool,
    reader_gone: bool,
}

/// One direction of the pipe with its wake-up signal.
#[derive(Default)]
struct Lane {
    state: Mutex<Direction>,
    signal: Condvar,
}

impl Lane {
    fn lock(&self) -> MutexGuard<'_, Direction> {
        // A panic elsewhere while holding the lock leaves plain byte queues behind;
        // they stay usable, so a poisoned lock is taken over rather than propagated.
        self.state
            .lock()
            .unwrap_or_else(|poisoned| poisoned.into_inner())
    }
}

/// One end of a duplex pipe: reads what the other end wrote, writes what it will read.
/// Dropping an end makes the other end read end-of-file and fail to write (`BrokenPipe`),
/// as a pulled cable would.
pub struct PipeEnd {
    incoming: Arc<Lane>,
    outgoing: Arc<Lane>,
    config: PipeConfig,
}

/// Two connected ends sharing one configuration.
pub fn duplex(config: PipeConfig) -> (PipeEnd, PipeEnd) {
    let a_to_b = Arc::new(Lane::default());
    let b_to_a = Arc::new(Lane::default());
    let a = PipeEnd {
        incoming: b_to_a.clone(),
        outgoing: a_to_b.clone(),
        config,
    };
    let b = PipeEnd {
        incoming: a_to_b,
        outgoing: b_to_a,
        config,
    };
    (a, b)
}

impl PipeEnd {
    /// Changes how long a read waits before answering `TimedOut`.
    pub fn set_read_timeout(&mut self, timeout: Duration) {
        self.config.read_timeout = timeout;
    }

    /// Bytes already arrived (fully transmitted) and not yet read.
    pub fn bytes_waiting(&self) -> usize {
        let now = Instant::now();
        let lane = self.incoming.lock();
        lane.chunks
            .iter()
            .map(|c| ready_count(c, now, self.config.byte_time) - c.taken)
            .sum()
    }

    /// Drops everything that has arrived or is still on its way; returns how many bytes.
    pub fn discard_input(&self) -> usize {
        let mut lane = self.incoming.lock();
        let dropped = lane.chunks.iter().map(|c| c.data.len() - c.taken).sum();
        lane.chunks.clear();
        dropped
    }

    /// True once the other end has been dropped.
    pub fn peer_gone(&self) -> bool {
        self.incoming.lock().writer_gone || self.outgoing.lock().reader_gone
    }
}

/// Until when the front paced chunk is held for the bytes behind its next one (see
/// [`GATHER`]); `None` when what has arrived is to be read now.
fn gathering(chunk: Option<&Chunk>, now: Instant, byte_time: Option<Duration>) -> Option<Instant> {
    let (chunk, t) = (chunk?, byte_time.filter(|t| !t.is_zero())?);
    let next_due = chunk.first_ready + t.saturating_mul(chunk.taken as u32);
    let last_due = chunk.first_ready + t.saturating_mul(chunk.data.len().saturating_sub(1) as u32);
    let hold = (next_due + GATHER).min(last_due);
    (now < hold).then_some(hold)
}

/// How many bytes of `chunk` have finished arriving at `now`.
fn ready_count(chunk: &Chunk, now: Instant, byte_time: Option<Duration>) -> usize {
    match byte_time {
        None => chunk.data.len(),
        Some(_) if now < chunk.first_ready => 0,
        Some(t) if t.is_zero() => chunk.data.len(),
        Some(t) => {
            let elapsed = now.duration_since(chunk.first_ready).as_nanos();
            let extra = elapsed / t.as_nanos();
            usize::try_from(extra)
                .unwrap_or(usize::MAX)
                .saturating_add(1)
                .min(chunk.data.len())
        }
    }
}

impl Line for PipeEnd {
    fn read_timeout(&mut self, buf: &mut [u8], timeout: Duration) -> io::Result<usize> {
        self.set_read_timeout(timeout);
        self.read(buf)
    }

    fn write_all_bytes(&mut self, bytes: &[u8]) -> io::Result<()> {
        self.write_all(bytes)
    }
}

impl Read for PipeEnd {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        if buf.is_empty() {
            return Ok(0);
        }
        let deadline = Instant::now() + self.config.read_timeout;
        let mut lane = self.incoming.lock();
        loop {
            let now = Instant::now();
            if let Some(hold) = gathering(lane.chunks.front(), now, self.config.byte_time)
                && hold < deadline
            {
                let wait = hold.saturating_duration_since(now);
                lane = self
                    .incoming
                    .signal
                    .wait_timeout(lane, wait)
                    .unwrap_or_else(|poisoned| poisoned.into_inner())
                    .0;
                continue;
            }
            let mut copied = 0;
            while let Some(chunk) = lane.chunks.front_mut() {
                let ready = ready_count(chunk, now, self.config.byte_time);
                let n = (ready - chunk.taken).min(buf.len() - copied);
                buf[copied..copied + n].copy_from_slice(&chunk.data[chunk.taken..chunk.taken + n]);
                chunk.taken += n;
                copied += n;
                if chunk.taken == chunk.data.len() {
                    lane.chunks.pop_front();
                } else {
                    break;
                }
                if copied == buf.len() {
                    break;
                }
            }
            if copied > 0 {
                return Ok(copied);
            }
            if lane.writer_gone && lane.chunks.is_empty() {
                return Ok(0);
            }
            if now >= deadline {
                return Err(io::Error::new(
                    io::ErrorKind::TimedOut,
                    "no byte within the read timeout",
                ));
            }
            // Wake at the deadline, or when the next paced byte is due, or on a write.
            let mut wake = deadline;
            if let (Some(t), Some(chunk)) = (self.config.byte_time, lane.chunks.front()) {
                let next_due = chunk.first_ready + t.saturating_mul(chunk.taken as u32);
                wake = wake.min(next_due.max(now));
            }
            let wait = wake.saturating_duration_since(now);
            lane = self
                .incoming
                .signal
                .wait_timeout(lane, wait)
                .unwrap_or_else(|poisoned| poisoned.into_inner())
                .0;
        }
    }
}

impl Write for PipeEnd {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        let mut lane = self.outgoing.lock();
        if lane.reader_gone {
            return Err(io::Error::new(
                io::ErrorKind::BrokenPipe,
                "the other end of the line is gone",
            ));
        }
        if buf.is_empty() {
            return Ok(0);
        }
        let now = Instant::now();
        let first_ready = match self.config.byte_time {
            None => now,
            Some(t) => lane.line_free_at.map_or(now, |free| free.max(now)) + t,
        };
        if let Some(t) = self.config.byte_time {
            lane.line_free_at = Some(first_ready + t.saturating_mul(buf.len() as u32 - 1));
        }
        lane.chunks.push_back(Chunk {
            data: buf.to_vec(),
            taken: 0,
            first_ready,
        });
        self.outgoing.signal.notify_all();
        Ok(buf.len())
    }

    fn flush(&mut self) -> io::Result<()> {
        Ok(())
    }
}

impl Drop for PipeEnd {
    fn drop(&mut self) {
        self.outgoing.lock().writer_gone = true;
        self.outgoing.signal.notify_all();
        self.incoming.lock().reader_gone = true;
        self.incoming.signal.notify_all();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bytes_cross_in_both_directions() {
        let (mut a, mut b) = duplex(PipeConfig::default());
        a.write_all(b"!992152B\r\n").unwrap();
        let mut buf = [0u8; 32];
        let n = b.read(&mut buf).unwrap();
        assert_eq!(&buf[..n], b"!992152B\r\n");
        b.write_all(b"#9921510000000000060004\r\n").unwrap();
        let n = a.read(&mut buf).unwrap();
        assert_eq!(&buf[..n], b"#9921510000000000060004\r\n");
    }

    #[test]
    fn empty_line_times_out_and_dropped_peer_reads_eof() {
        let config = PipeConfig {
            read_timeout: Duration::from_millis(5),
            ..PipeConfig::default()
        };
        let (mut a, b) = duplex(config);
        let mut buf = [0u8; 4];
        assert_eq!(
            a.read(&mut buf).unwrap_err().kind(),
            io::ErrorKind::TimedOut
        );
        drop(b);
        assert_eq!(a.read(&mut buf).unwrap(), 0);
        assert_eq!(a.write(b"x").unwrap_err().kind(), io::ErrorKind::BrokenPipe);
        assert!(a.peer_gone());
    }

    #[test]
    fn paced_bytes_take_their_wire_time() {
        // 9600 baud, 10 bits a character: about 1.04 ms a byte; 20 bytes take about 21 ms.
        let byte_time = Duration::from_nanos(1_000_000_000 * 10 / 9600);
        let config = PipeConfig {
            byte_time: Some(byte_time),
            read_timeout: Duration::from_millis(200),
        };
        let (mut a, mut b) = duplex(config);
        let start = Instant::now();
        a.write_all(&[b'x'; 20]).unwrap();
        let mut got = 0;
        let mut buf = [0u8; 64];
        while got < 20 {
            got += b.read(&mut buf).unwrap();
        }
        let took = start.elapsed();
        assert!(took >= byte_time * 20, "20 paced bytes arrived in {took:?}");
    }

    #[test]
    fn paced_bytes_come_in_batches_and_the_last_one_never_early() {
        // 9600 baud: a 20-byte frame is on the wire ~21 ms, so it comes in a few
        // batches of about GATHER each, not in 20 reads; a frame shorter than GATHER
        // comes in one read, when its last byte is due.
        let byte_time = Duration::from_nanos(1_000_000_000 * 10 / 9600);
        let config = PipeConfig {
            byte_time: Some(byte_time),
            read_timeout: Duration::from_millis(500),
        };
        let (mut a, mut b) = duplex(config);
        let mut buf = [0u8; 64];
        let start = Instant::now();
        a.write_all(&[b'x'; 20]).unwrap();
        let (mut got, mut reads) = (0, 0);
        while got < 20 {
            got += b.read(&mut buf).unwrap();
            reads += 1;
        }
        assert!(start.elapsed() >= byte_time * 20);
        assert!(reads <= 8, "20 bytes in {reads} reads");
        let start = Instant::now();
        a.write_all(&[b'y'; 3]).unwrap();
        assert_eq!(b.read(&mut buf).unwrap(), 3, "a short frame was split");
        assert!(start.elapsed() >= byte_time * 3);
    }

    #[test]
    fn discard_drops_pending_bytes() {
        let (mut a, b) = duplex(PipeConfig::default());
        a.write_all(b"garbage").unwrap();
        assert_eq!(b.bytes_waiting(), 7);
        assert_eq!(b.discard_input(), 7);
        assert_eq!(b.bytes_waiting(), 0);
    }
}
