//! The `rmc-sim` binary as a third-party Modbus/TCP client finds it, in raw bytes: FC4,
//! FC6, FC8 and 125-register reads answered as the RMC151 documents them; idle clients
//! dropped after `--idle-timeout`, a full house refused with exception 06 and the next
//! client served once the idle ones are gone.

use std::io::{Read, Write};
use std::net::TcpStream;
use std::sync::{Arc, Mutex};

use crate::spawn::{self, Guard};
use crate::wait::{LONG, PROCESS, until};

/// Starts `rmc-sim` on a free port with `extra` flags; its address and its log's lines.
fn start(extra: &[&str]) -> (Guard, String, Arc<Mutex<Vec<String>>>) {
    let mut args = vec!["--tcp", "127.0.0.1:0", "--axes", "2", "--no-console"];
    args.extend_from_slice(extra);
    let (guard, first, stderr) = spawn::start(env!("CARGO_BIN_EXE_rmc-sim"), &args);
    (guard, spawn::rmc_address(&first), spawn::collect(stderr))
}

fn count(log: &Arc<Mutex<Vec<String>>>, what: &str) -> usize {
    log.lock()
        .unwrap()
        .iter()
        .filter(|l| l.contains(what))
        .count()
}

fn connect(addr: &str) -> TcpStream {
    let s = TcpStream::connect(addr).expect("connects");
    s.set_read_timeout(Some(LONG)).unwrap();
    s
}

/// One request (transaction 0x1234, unit 1) with PDU `pdu`; the reply's PDU, or `None`
/// when the connection closes first.
fn ask(s: &mut TcpStream, pdu: &[u8]) -> Option<Vec<u8>> {
    let mut frame = vec![0x12, 0x34, 0, 0];
    frame.extend((pdu.len() as u16 + 1).to_be_bytes());
    frame.push(1);
    frame.extend(pdu);
    s.write_all(&frame).ok()?;
    let mut head = [0u8; 7];
    s.read_exact(&mut head).ok()?;
    assert_eq!(
        &head[..4],
        &[0x12, 0x34, 0, 0],
        "transaction and protocol echoed"
    );
    assert_eq!(head[6], 1, "unit echoed");
    let len = usize::from(u16::from_be_bytes([head[4], head[5]]));
    let mut rest = vec![0u8; len - 1];
    s.read_exact(&mut rest).ok()?;
    Some(rest)
}

fn be(v: u16) -> [u8; 2] {
    v.to_be_bytes()
}

/// PDU of a read (FC3 or FC4).
fn read(function: u8, address: u16, count: u16) -> Vec<u8> {
    [vec![function], be(address).to_vec(), be(count).to_vec()].concat()
}

/// Axis 0's status file and Position Scale (RMC.md section 2).
const STATUS_0: u16 = 4096;
const SCALE_0: u16 = 12288;

#[test]
fn fc4_fc6_fc8_and_125_register_reads_are_answered() {
    let (_sim, addr, _log) = start(&[]);
    let mut s = connect(&addr);
    // FC4 reads the same map as FC3: CPU Module ID 17 (RMC151E), low word first.
    assert_eq!(ask(&mut s, &read(4, 3588, 2)).unwrap(), [4, 4, 0, 17, 0, 0]);
    let fc3 = ask(&mut s, &read(3, STATUS_0, 116)).unwrap();
    let fc4 = ask(&mut s, &read(4, STATUS_0, 116)).unwrap();
    assert_eq!((fc3[0], fc4[0]), (3, 4));
    assert_eq!(fc3[1..], fc4[1..], "FC4 and FC3 read the same registers");
    // 125 registers, the Modbus maximum, in each function and across axis 0's status file.
    for (function, address) in [(3, STATUS_0), (4, STATUS_0), (3, STATUS_0 + 400)] {
        let r = ask(&mut s, &read(function, address, 125)).unwrap();
        assert_eq!(&r[..2], &[function, 250], "{function} at {address}: {r:?}");
        assert_eq!(r.len(), 252);
    }
    assert_eq!(ask(&mut s, &read(3, STATUS_0, 126)).unwrap(), [0x83, 3]);
    assert_eq!(ask(&mut s, &read(4, 0, 2)).unwrap(), [0x84, 2]);
    // FC6: Position Scale 1.0 (words 0x0000, 0x3F80) becomes 2.0 by its high word.
    let write = [vec![6], be(SCALE_0 + 1).to_vec(), be(0x4000).to_vec()].concat();
    assert_eq!(ask(&mut s, &write).unwrap(), write, "FC6 is echoed");
    assert_eq!(
        ask(&mut s, &read(4, SCALE_0, 2)).unwrap(),
        [4, 4, 0, 0, 0x40, 0]
    );
    // The Command Area takes whole FC16 blocks only.
    let command = [vec![6], be(20480).to_vec(), be(0).to_vec()].concat();
    assert_eq!(ask(&mut s, &command).unwrap(), [0x86, 2]);
    // FC8 sub-function 0, Return Query Data: the request comes back.
    let echo = [8, 0, 0, 0xA5, 0x37];
    assert_eq!(ask(&mut s, &echo).unwrap(), echo);
    assert_eq!(ask(&mut s, &[8, 0, 1, 0, 0]).unwrap(), [0x88, 1]);
    // The connection still serves FC3.
    assert_eq!(ask(&mut s, &read(3, 3588, 2)).unwrap(), [3, 4, 0, 17, 0, 0]);
}

#[test]
fn an_idle_client_is_dropped_after_the_timeout_and_a_new_one_is_served() {
    let (_sim, addr, log) = start(&["--idle-timeout", "1"]);
    let mut idle = connect(&addr);
    assert!(ask(&mut idle, &read(3, 3588, 2)).is_some());
    until("the silent client is dropped", PROCESS, || {
        count(&log, "silent for 1 s: dropped") == 1
    });
    let mut b = [0u8; 1];
    assert_eq!(idle.read(&mut b).ok(), Some(0), "its connection is closed");
    let mut next = connect(&addr);
    assert_eq!(
        ask(&mut next, &read(3, 3588, 2)).unwrap(),
        [3, 4, 0, 17, 0, 0]
    );
}

#[test]
fn a_full_house_of_idle_clients_is_refused_then_dropped_and_the_next_served() {
    // Long enough that the 64 are surely still there when the 65th comes, on a busy
    // machine too.
    let (_sim, addr, log) = start(&["--idle-timeout", "6"]);
    let idle: Vec<TcpStream> = (0..64).map(|_| connect(&addr)).collect();
    until("64 connections open", PROCESS, || {
        count(&log, "connected") == 64
    });
    // The 65th is told why, while the 64 are still there.
    let mut late = connect(&addr);
    assert_eq!(ask(&mut late, &read(3, 3588, 2)), Some(vec![0x83, 6]));
    // Its log line is read on a thread of its own: it comes, once.
    until("the refusal logged", PROCESS, || {
        count(&log, "refused: 64 connections are open") == 1
    });
    // Once the idle ones are dropped, a new client is served.
    until("the 64 idle clients are dropped", PROCESS, || {
        count(&log, "silent for 6 s: dropped") == 64
    });
    let mut next = connect(&addr);
    assert_eq!(
        ask(&mut next, &read(3, 3588, 2)).unwrap(),
        [3, 4, 0, 17, 0, 0]
    );
    drop(idle);
}
