//! Precise pacing of written bytes at a wire time per byte, as a UART would send them.

use std::io;
use std::time::{Duration, Instant};

use super::Line;

/// Sleeps until `deadline` with about 100 µs precision: a coarse sleep to 100 µs before
/// it (Linux wakes a sleeper some 50-60 µs late), then a yielding spin. The spin is kept
/// short: every reply of a simulator waits here, and a 400 µs spin for each was most of
/// an idle simulator's CPU.
pub fn sleep_until(deadline: Instant) {
    loop {
        let now = Instant::now();
        if now >= deadline {
            return;
        }
        let left = deadline - now;
        if left > Duration::from_micros(150) {
            std::thread::sleep(left - Duration::from_micros(100));
        } else {
            std::thread::yield_now();
        }
    }
}

/// Asks the OS to wake the calling thread on time: on Linux its timer slack goes from the
/// default 50 µs to 1 µs, so a wait for a reply or a line gap ends within some tens of µs
/// rather than a hundred, without spinning. Best effort, for the threads that pace a
/// line (the link driver, the simulator); elsewhere it does nothing.
pub fn wake_on_time() {
    #[cfg(target_os = "linux")]
    {
        // The thread's id from /proc/thread-self (-> "PID/task/TID"); /proc/TID reaches
        // any thread of this process.
        let tid = std::fs::read_link("/proc/thread-self")
            .ok()
            .and_then(|p| p.file_name().and_then(|n| n.to_str()).map(str::to_owned));
        if let Some(tid) = tid {
            let _ = std::fs::write(format!("/proc/{tid}/timerslack_ns"), "1000");
        }
    }
}

/// Writes `bytes` so that byte *i* has left the wire at `start + (i + 1) * byte_time`,
/// as a UART at that rate would: each byte is written when its last bit would be sent.
pub fn write_paced(
    line: &mut dyn Line,
    bytes: &[u8],
    byte_time: Duration,
    start: Instant,
) -> io::Result<()> {
    if byte_time.is_zero() {
        return line.write_all_bytes(bytes);
    }
    let mut sent = 0;
    while sent < bytes.len() {
        let elapsed = start.elapsed().as_nanos();
        let due = (elapsed / byte_time.as_nanos()).min(bytes.len() as u128) as usize;
        if due > sent {
            line.write_all_bytes(&bytes[sent..due])?;
            sent = due;
            continue;
        }
        sleep_until(start + byte_time.saturating_mul(sent as u32 + 1));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Records when each byte was written.
    struct Recorder(Vec<(u8, Instant)>);

    impl Line for Recorder {
        fn read_timeout(&mut self, _: &mut [u8], _: Duration) -> io::Result<usize> {
            Err(io::ErrorKind::TimedOut.into())
        }
        fn write_all_bytes(&mut self, bytes: &[u8]) -> io::Result<()> {
            let now = Instant::now();
            self.0.extend(bytes.iter().map(|&b| (b, now)));
            Ok(())
        }
    }

    // Only lower bounds: an upper bound on wall-clock time flakes on a loaded machine.
    #[test]
    fn no_byte_leaves_before_its_wire_time() {
        let bt = crate::line::byte_time_8n1(9600);
        let mut line = Recorder(Vec::new());
        let start = Instant::now();
        let bytes: Vec<u8> = (0..20).collect();
        write_paced(&mut line, &bytes, bt, start).unwrap();
        let got: Vec<u8> = line.0.iter().map(|&(b, _)| b).collect();
        assert_eq!(got, bytes, "every byte once, in order");
        for (i, &(_, at)) in line.0.iter().enumerate() {
            let due = bt * (i as u32 + 1);
            assert!(at - start >= due, "byte {i} at {:?} < {due:?}", at - start);
        }
    }

    #[test]
    fn zero_byte_time_writes_at_once() {
        let mut line = Recorder(Vec::new());
        write_paced(&mut line, b"abc", Duration::ZERO, Instant::now()).unwrap();
        assert_eq!(line.0.len(), 3);
    }
}
