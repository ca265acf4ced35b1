//! The `rmc-sim` binary over real TCP, driven by a plain Modbus/TCP client written here
//! from raw bytes (not the project's codec): enable, Move Relative, poll to In Position
//! with ACK; ACK per connection; garbage closes only its own connection.

use std::io::{Read, Write};
use std::net::TcpStream;
use std::time::Duration;

use crate::spawn::{self, Guard};
use crate::wait::{LONG, until};

/// Starts `rmc-sim` on a free port; its address from the `listening on` line (its log
/// drained on a thread of its own).
fn start() -> (Guard, String) {
    let (guard, first, stderr) = spawn::start(
        env!("CARGO_BIN_EXE_rmc-sim"),
        &["--tcp", "127.0.0.1:0", "--axes", "2", "--no-console"],
    );
    let _log = spawn::collect(stderr);
    (guard, spawn::rmc_address(&first))
}

struct Client {
    stream: TcpStream,
    transaction: u16,
}

impl Client {
    fn connect(addr: &str) -> Self {
        let stream = TcpStream::connect(addr).expect("connects");
        stream
            .set_read_timeout(Some(Duration::from_secs(5)))
            .unwrap();
        Self {
            stream,
            transaction: 0,
        }
    }

    /// One request PDU out (unit 1), its response PDU back.
    fn ask(&mut self, pdu: &[u8]) -> Vec<u8> {
        self.transaction += 1;
        let mut frame = self.transaction.to_be_bytes().to_vec();
        frame.extend([0, 0]);
        frame.extend((pdu.len() as u16 + 1).to_be_bytes());
        frame.push(1);
        frame.extend(pdu);
        self.stream.write_all(&frame).unwrap();
        let mut header = [0u8; 7];
        self.stream.read_exact(&mut header).unwrap();
        assert_eq!(header[..2], self.transaction.to_be_bytes());
        assert_eq!(header[2..4], [0, 0]);
        assert_eq!(header[6], 1, "the unit ID is echoed");
        let len = u16::from_be_bytes([header[4], header[5]]) as usize;
        let mut body = vec![0u8; len - 1];
        self.stream.read_exact(&mut body).unwrap();
        body
    }

    /// FC3: registers as words.
    fn read(&mut self, address: u16, count: u16) -> Vec<u16> {
        let mut pdu = vec![3];
        pdu.extend(address.to_be_bytes());
        pdu.extend(count.to_be_bytes());
        let r = self.ask(&pdu);
        assert_eq!(r[0], 3, "FC3 answered {r:?}");
        assert_eq!(r[1] as usize, 2 * count as usize);
        r[2..]
            .chunks(2)
            .map(|b| u16::from_be_bytes([b[0], b[1]]))
            .collect()
    }

    /// FC16 of REALs, each two registers low word first.
    fn write_reals(&mut self, address: u16, reals: &[f32]) {
        let words: Vec<u16> = reals
            .iter()
            .flat_map(|r| {
                let bits = r.to_bits();
                [bits as u16, (bits >> 16) as u16]
            })
            .collect();
        let mut pdu = vec![16];
        pdu.extend(address.to_be_bytes());
        pdu.extend((words.len() as u16).to_be_bytes());
        pdu.push(2 * words.len() as u8);
        for w in &words {
            pdu.extend(w.to_be_bytes());
        }
        let r = self.ask(&pdu);
        assert_eq!(r[0], 16, "FC16 answered {r:?}");
        assert_eq!(r[1..5], pdu[1..5]);
    }

    /// Axis 1's Status Bits and Command Position from one 116-register read at 4096.
    fn status(&mut self) -> (u32, f32) {
        let w = self.read(4096, 116);
        let bits = u32::from(w[0]) | (u32::from(w[1]) << 16);
        let command = f32::from_bits(u32::from(w[112]) | (u32::from(w[113]) << 16));
        (bits, command)
    }
}

const IN_POSITION: u32 = 1 << 0;
const ENABLED: u32 = 1 << 13;
const ACK: u32 = 1 << 31;

#[test]
fn rmc_sim_moves_an_axis_for_a_plain_modbus_client() {
    let (_guard, addr) = start();
    let mut first = Client::connect(&addr);
    // Enable/Disable Axis (97) with REQ: 353.0, parameter 1.0 (enable).
    first.write_reals(20480, &[353.0, 1.0]);
    let (bits, _) = first.status();
    assert_eq!(bits & (ENABLED | ACK), ENABLED | ACK, "{bits:#x}");
    // Zeros reset ACK; then Move Relative (21) with REQ: 10 pu relative to command.
    first.write_reals(20480, &[0.0; 6]);
    assert_eq!(first.status().0 & ACK, 0);
    first.write_reals(20480, &[277.0, 10.0, 100.0, 1000.0, 1000.0, 0.0]);
    let (mut bits, mut command) = first.status();
    until("In Position and ACK", LONG, || {
        (bits, command) = first.status();
        bits & (IN_POSITION | ACK) == IN_POSITION | ACK
    });
    assert_eq!(command, 10.0, "{bits:#x}");

    // A second connection has its own ACK bits: 0 for the axis the first commanded.
    let mut second = Client::connect(&addr);
    let (bits, command) = second.status();
    assert_eq!(bits & ACK, 0, "{bits:#x}");
    assert_eq!(command, 10.0);

    // Garbage on a third connection closes that one only.
    let mut third = TcpStream::connect(&addr).unwrap();
    third
        .set_read_timeout(Some(Duration::from_secs(5)))
        .unwrap();
    third
        .write_all(b"GET / HTTP/1.1\r\nHost: rmc\r\n\r\n")
        .unwrap();
    let mut buf = [0u8; 64];
    match third.read(&mut buf) {
        Ok(0) | Err(_) => {}
        Ok(n) => panic!("garbage was answered: {:?}", &buf[..n]),
    }
    // CPU Module ID 17 (an RMC151E) on both that remain.
    for client in [&mut first, &mut second] {
        let w = client.read(3588, 2);
        assert_eq!(u32::from(w[0]) | (u32::from(w[1]) << 16), 17);
    }
    assert!(first.status().0 & ACK != 0);
}
