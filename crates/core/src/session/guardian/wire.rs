//! What the window and its guardian say to each other over the guardian's stdin and
//! stdout: typed messages (serde), one JSON object per line, read with a length bound.

use std::io::{self, BufRead, Write};

use serde::{Deserialize, Serialize};

use crate::line::ConnectionSettings;

/// The longest message line either side accepts: a frame is at most a few hundred bytes
/// (PROTOCOL.md 1.3), about four characters each as JSON numbers.
pub const MAX_MESSAGE: usize = 64 * 1024;

/// The window to the guardian.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum ToGuardian {
    /// The first message: the line to open and the guardian's lease.
    Open(OpenLine),
    /// One frame (or any bytes) the window's link writes to the line.
    Bytes(Vec<u8>),
    /// The window's process is alive (sent every [`super::HEARTBEAT`]).
    Heartbeat,
    /// The window's link lets go of the line (the pipe closes next); its process may run
    /// on. A pipe that closes without it means the window's process ended.
    LetGo,
}

/// The line the guardian opens, and how long it lets the window fall silent while motion
/// may run.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct OpenLine {
    pub connection: ConnectionSettings,
    pub lease_ms: u64,
    /// An RMC151 at this address instead of the X-SEL's line (`connection` then unused).
    #[serde(default)]
    pub rmc: Option<RmcLine>,
}

/// The RMC151 a guardian connects to, and how it stops its axes.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RmcLine {
    /// `host:port`.
    pub address: String,
    pub unit: u8,
    /// Stop (Closed Loop) (6)'s deceleration, pu/s².
    pub stop_decel: f32,
}

/// The guardian to the window.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum FromGuardian {
    /// The line is open; its description (as the connection panel shows it) and the
    /// guardian's process id.
    Opened { line: String, pid: u32 },
    /// The line could not be opened, or was lost: the guardian exits after this.
    Failed(String),
    /// Bytes the line delivered.
    Bytes(Vec<u8>),
    /// The guardian sent 238H of its own, and why.
    Stopped(String),
}

/// Writes one message as a line and pushes it out.
pub fn send<T: Serialize>(out: &mut impl Write, message: &T) -> io::Result<()> {
    let mut line = serde_json::to_vec(message).map_err(io::Error::other)?;
    line.push(b'\n');
    out.write_all(&line)?;
    out.flush()
}

/// Reads the next message; `Ok(None)` when the other side closed the pipe. A line longer
/// than [`MAX_MESSAGE`] or one that is not a message is an error (the pipe carries
/// nothing else, so the other side is not what it should be).
pub fn receive<T: for<'de> Deserialize<'de>>(input: &mut impl BufRead) -> io::Result<Option<T>> {
    let mut line = Vec::new();
    let mut bounded = io::Read::take(&mut *input, MAX_MESSAGE as u64 + 1);
    let read = bounded.read_until(b'\n', &mut line)?;
    if read == 0 {
        return Ok(None);
    }
    if line.last() != Some(&b'\n') {
        let why = if line.len() > MAX_MESSAGE {
            format!("a message longer than {MAX_MESSAGE} bytes")
        } else {
            "a message cut off by the end of the pipe".to_owned()
        };
        return Err(io::Error::new(io::ErrorKind::InvalidData, why));
    }
    serde_json::from_slice(&line)
        .map(Some)
        .map_err(|e| io::Error::new(io::ErrorKind::InvalidData, format!("not a message: {e}")))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn messages_cross_in_order_and_a_closed_pipe_reads_as_none() {
        let mut pipe = Vec::new();
        let sent = [
            FromGuardian::Opened {
                line: "TCP 127.0.0.1:5099".into(),
                pid: 42,
            },
            FromGuardian::Bytes(b"#99215\r\n".to_vec()),
            FromGuardian::Stopped("the window went silent".into()),
        ];
        for m in &sent {
            send(&mut pipe, m).unwrap();
        }
        let mut input = io::Cursor::new(pipe);
        for m in &sent {
            assert_eq!(
                receive::<FromGuardian>(&mut input).unwrap().as_ref(),
                Some(m)
            );
        }
        assert_eq!(receive::<FromGuardian>(&mut input).unwrap(), None);
    }

    #[test]
    fn an_endless_line_or_garbage_is_an_error_not_a_hang() {
        let endless = vec![b'x'; 3 * MAX_MESSAGE];
        let e = receive::<ToGuardian>(&mut io::Cursor::new(endless)).unwrap_err();
        assert!(e.to_string().contains("longer than"), "{e}");
        let e = receive::<ToGuardian>(&mut io::Cursor::new(b"hello\n".to_vec())).unwrap_err();
        assert!(e.to_string().starts_with("not a message"), "{e}");
        let e =
            receive::<ToGuardian>(&mut io::Cursor::new(b"{\"Bytes\":[1,".to_vec())).unwrap_err();
        assert!(e.to_string().contains("cut off"), "{e}");
    }
}
