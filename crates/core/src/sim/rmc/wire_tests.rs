//! The simulated RMC through a connection's bytes: the register map, exceptions, REQ/ACK
//! per connection, FIFO answers, split and hostile bytes.

use std::time::Instant;

use super::tests::mr;
use super::*;
use crate::rmc::modbus::{
    ExceptionCode, FrameBuffer, Header, Request, Response, decode_response, encode_request,
};
use crate::rmc::registers::{CONTROLLER_STATUS, CPU_MODULE_ID};
use crate::rmc::words::{dword_at, real_to_words};
use crate::rmc::{AxisId, AxisStatus, Command};
use crate::robot::RelativeTo;

fn header(transaction: u16) -> Header {
    Header {
        transaction,
        unit: 1,
    }
}

struct Wire {
    c: RmcController,
    now: Instant,
}

impl Wire {
    fn new() -> Self {
        let now = Instant::now();
        Self {
            c: RmcController::new(RmcConfig::default(), now),
            now,
        }
    }

    fn ask(&mut self, conn: &mut RmcConnection, request: &Request) -> Response {
        let out = conn
            .handle_bytes(&mut self.c, self.now, &encode_request(header(7), request))
            .unwrap();
        let (h, response) = decode_response(&out).unwrap();
        assert_eq!(h, header(7));
        response
    }

    fn exception(&mut self, request: &Request) -> u8 {
        match self.ask(&mut RmcConnection::new(), request) {
            Response::Exception { function, code } => {
                assert_eq!(function, request.function());
                code.0
            }
            r => panic!("{request:?} answered {r:?}"),
        }
    }

    fn status(&mut self, conn: &mut RmcConnection, axis: usize) -> AxisStatus {
        let address = AxisId::new(axis).unwrap().status_block();
        match self.ask(
            conn,
            &Request::Read {
                address,
                count: 116,
            },
        ) {
            Response::Registers { words, .. } => AxisStatus::decode(&words).unwrap(),
            r => panic!("{r:?}"),
        }
    }

    fn command(&mut self, conn: &mut RmcConnection, axis: usize, c: Command, req: bool) {
        let address = AxisId::new(axis).unwrap().command_block();
        let words = c.block(req);
        let count = words.len() as u16;
        let r = self.ask(conn, &Request::Write { address, words });
        assert_eq!(r, Response::Written { address, count });
    }
}

fn read(address: u16, count: u16) -> Request {
    Request::Read { address, count }
}

fn write(address: u16, words: Vec<u16>) -> Request {
    Request::Write { address, words }
}

#[test]
fn the_controller_registers_read_as_an_rmc151e_in_run() {
    let mut w = Wire::new();
    let mut conn = RmcConnection::new();
    for (address, value) in [(CPU_MODULE_ID, 17), (CONTROLLER_STATUS, 3)] {
        let Response::Registers { words, .. } = w.ask(&mut conn, &read(address, 2)) else {
            panic!()
        };
        assert_eq!(dword_at(&words, 0), Some(value));
    }
    let a1 = AxisId::new(1).unwrap();
    let Response::Registers { words, .. } = w.ask(&mut conn, &read(a1.position_scale(), 4)) else {
        panic!()
    };
    assert_eq!(words, [real_to_words(1.0), real_to_words(0.0)].concat());
    let tolerance = a1.in_position_tolerance();
    w.ask(&mut conn, &write(tolerance, real_to_words(0.5).to_vec()));
    assert_eq!(w.c.axes[1].tolerance, 0.5);
    // The Command Area is write-only: it reads 0s.
    let Response::Registers { words, .. } = w.ask(&mut conn, &read(a1.command_block(), 20)) else {
        panic!()
    };
    assert_eq!(words, [0; 20]);
}

#[test]
fn requests_outside_the_map_are_exceptions_that_change_nothing() {
    let mut w = Wire::new();
    let axis2 = AxisId::new(2).unwrap(); // beyond the default 2 axes
    let a0 = AxisId::new(0).unwrap();
    assert_eq!(w.exception(&Request::Other { function: 5 }), 1);
    assert_eq!(w.exception(&Request::Other { function: 43 }), 1);
    for request in [
        read(0, 2),
        read(axis2.status_block(), 116),
        // Axis 1's files end where axis 2's (not configured) begin.
        read(axis2.status_block() - 124, 125),
        write(a0.status_block(), real_to_words(1.0).to_vec()),
        write(a0.status_block() + 1, vec![0; 2]),
        write(axis2.command_block(), Command::Enable(true).block(true)),
        write(a0.command_block() + 2, real_to_words(97.0).to_vec()),
        write(CPU_MODULE_ID, vec![16, 0]),
    ] {
        assert_eq!(w.exception(&request), 2, "{request:?}");
    }
    for request in [
        read(a0.status_block(), 0),
        read(a0.status_block(), 126),
        write(a0.command_block(), vec![0; 101]),
        write(a0.command_block(), real_to_words(21.5).to_vec()),
    ] {
        assert_eq!(w.exception(&request), 3, "{request:?}");
    }
    // FC23 whose read is refused: its write (an enable with REQ) never happens.
    let mut conn = RmcConnection::new();
    let r = w.ask(
        &mut conn,
        &Request::ReadWrite {
            read_address: 0,
            read_count: 2,
            write_address: a0.command_block(),
            words: Command::Enable(true).block(true),
        },
    );
    let code = ExceptionCode::ILLEGAL_DATA_ADDRESS;
    assert_eq!(r, Response::Exception { function: 23, code });
    let st = w.status(&mut conn, 0);
    assert!(!st.bits.enabled() && !st.bits.ack());
}

/// Reads of up to 125 registers succeed wherever the map is contiguous, at any address
/// and count: each 16-bit register is its half of a 32-bit one.
#[test]
fn reads_of_up_to_125_registers_and_odd_ones_are_answered() {
    let mut w = Wire::new();
    let mut conn = RmcConnection::new();
    let a0 = AxisId::new(0).unwrap();
    let whole = match w.ask(&mut conn, &read(a0.status_block(), 116)) {
        Response::Registers { words, .. } => words,
        r => panic!("{r:?}"),
    };
    for (address, count) in [
        (a0.status_block(), 125),
        (a0.status_block() + 1, 3),
        (a0.status_block() + 3, 124),
        // Across axis 0's status file into axis 1's.
        (a0.status_block() + 450, 125),
        (a0.position_scale(), 125),
    ] {
        match w.ask(&mut conn, &read(address, count)) {
            Response::Registers { words, .. } => {
                assert_eq!(words.len(), usize::from(count), "{address} {count}");
                if address >= a0.status_block() && address < a0.status_block() + 116 {
                    let from = usize::from(address - a0.status_block());
                    let shared = (116 - from).min(usize::from(count));
                    assert_eq!(words[..shared], whole[from..from + shared]);
                }
            }
            r => panic!("{address} {count}: {r:?}"),
        }
    }
}

/// FC4, FC6 and FC8 in raw bytes (the project's codec sends none of them).
#[test]
fn fc4_fc6_and_fc8_are_answered() {
    let mut w = Wire::new();
    let mut conn = RmcConnection::new();
    fn raw(w: &mut Wire, conn: &mut RmcConnection, pdu: &[u8]) -> Vec<u8> {
        let mut frame = vec![0, 9, 0, 0];
        frame.extend((pdu.len() as u16 + 1).to_be_bytes());
        frame.push(3);
        frame.extend(pdu);
        let out = conn.handle_bytes(&mut w.c, w.now, &frame).unwrap();
        assert_eq!(&out[..4], &[0, 9, 0, 0]);
        assert_eq!(
            usize::from(u16::from_be_bytes([out[4], out[5]])),
            out.len() - 6
        );
        assert_eq!(out[6], 3, "unit echoed");
        out[7..].to_vec()
    }
    let mut ask = |w: &mut Wire, pdu: &[u8]| raw(w, &mut conn, pdu);
    let a1 = AxisId::new(1).unwrap();
    let [hi, lo] = CPU_MODULE_ID.to_be_bytes();
    assert_eq!(ask(&mut w, &[4, hi, lo, 0, 2]), [4, 4, 0, 17, 0, 0]);
    assert_eq!(ask(&mut w, &[4, hi, lo, 0, 0]), [0x84, 3]);
    assert_eq!(ask(&mut w, &[4, hi, lo, 0]), [0x84, 3], "a short PDU");
    // Tolerance 0.05: its high word written, its low word kept.
    let tol = a1.in_position_tolerance() + 1;
    let [th, tl] = tol.to_be_bytes();
    assert_eq!(
        ask(&mut w, &[6, th, tl, 0x3F, 0x00]),
        [6, th, tl, 0x3F, 0x00]
    );
    let expect = f32::from_bits((0x3F00u32 << 16) | u32::from(real_to_words(0.05)[0]));
    assert_eq!(w.c.axes[1].tolerance, expect);
    // A negative tolerance is refused and changes nothing.
    assert_eq!(ask(&mut w, &[6, th, tl, 0xBF, 0x00]), [0x86, 3]);
    assert_eq!(w.c.axes[1].tolerance, expect);
    let [ch, cl] = a1.command_block().to_be_bytes();
    assert_eq!(ask(&mut w, &[6, ch, cl, 0, 0]), [0x86, 2]);
    assert_eq!(ask(&mut w, &[6, hi, lo, 0, 0]), [0x86, 2]);
    assert_eq!(ask(&mut w, &[8, 0, 0, 1, 2, 3]), [8, 0, 0, 1, 2, 3]);
    assert_eq!(ask(&mut w, &[8, 0, 0]), [8, 0, 0]);
    assert_eq!(ask(&mut w, &[8, 0, 4, 0, 0]), [0x88, 1]);
}

#[test]
fn ack_is_per_connection_and_zeros_reset_it() {
    let mut w = Wire::new();
    let (mut a, mut b) = (RmcConnection::new(), RmcConnection::new());
    w.command(&mut a, 0, Command::Enable(true), true);
    assert!(w.status(&mut a, 0).bits.ack());
    assert!(w.status(&mut a, 0).bits.enabled());
    assert!(!w.status(&mut b, 0).bits.ack());
    assert!(!w.status(&mut a, 1).bits.ack());
    // Zeros: ACK back to 0, nothing else happens.
    let address = AxisId::new(0).unwrap().command_block();
    w.ask(&mut a, &write(address, vec![0; 12]));
    let st = w.status(&mut a, 0);
    assert!(!st.bits.ack() && st.bits.enabled());
    // A command without REQ runs and leaves ACK 0; FC23 writes, then reads.
    w.command(&mut b, 0, mr(3.0, RelativeTo::Command), true);
    let r = w.ask(
        &mut b,
        &Request::ReadWrite {
            read_address: AxisId::new(0).unwrap().status_block(),
            read_count: 116,
            write_address: address,
            words: mr(4.0, RelativeTo::Command).block(false),
        },
    );
    let Response::Registers {
        function: 23,
        words,
    } = r
    else {
        panic!("{r:?}")
    };
    let st = AxisStatus::decode(&words).unwrap();
    assert!(!st.bits.ack());
    assert_eq!(st.command_position, 7.0);
}

#[test]
fn bytes_that_are_not_modbus_close_the_connection() {
    let mut w = Wire::new();
    let mut conn = RmcConnection::new();
    let r = conn.handle_bytes(&mut w.c, w.now, b"GET / HTTP/1.1\r\n\r\n");
    assert!(r.is_err());
    // A length past any PDU too.
    let r = RmcConnection::new().handle_bytes(&mut w.c, w.now, &[0, 1, 0, 0, 1, 0, 1, 3]);
    assert!(r.is_err());
}

#[test]
fn requests_are_answered_in_order_and_only_once_whole() {
    let mut w = Wire::new();
    let mut conn = RmcConnection::new();
    let mut bytes = encode_request(header(1), &read(CPU_MODULE_ID, 2));
    bytes.extend(encode_request(header(2), &read(CONTROLLER_STATUS, 2)));
    let out = conn.handle_bytes(&mut w.c, w.now, &bytes).unwrap();
    let mut frames = FrameBuffer::default();
    frames.push(&out);
    let mut seen = Vec::new();
    while let Some(frame) = frames.next_frame() {
        let (h, r) = decode_response(&frame.unwrap()).unwrap();
        let Response::Registers { words, .. } = r else {
            panic!()
        };
        seen.push((h.transaction, dword_at(&words, 0)));
    }
    assert_eq!(seen, [(1, Some(17)), (2, Some(3))]);
    // Byte by byte: nothing until the last byte, then one answer.
    let request = encode_request(header(9), &read(CPU_MODULE_ID, 2));
    let (last, head) = request.split_last().unwrap();
    for b in head {
        let out = conn.handle_bytes(&mut w.c, w.now, &[*b]).unwrap();
        assert!(out.is_empty());
    }
    let out = conn.handle_bytes(&mut w.c, w.now, &[*last]).unwrap();
    let (h, _) = decode_response(&out).unwrap();
    assert_eq!(h.transaction, 9);
}

#[test]
fn the_server_counts_connections_and_stops_promptly() {
    use std::io::Read;
    use std::time::Duration;
    let listener = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    let server = RmcServer::start(listener, RmcConfig::default()).unwrap();
    let mut client = std::net::TcpStream::connect(server.local_addr()).unwrap();
    client
        .set_read_timeout(Some(Duration::from_secs(5)))
        .unwrap();
    let deadline = Instant::now() + Duration::from_secs(5);
    while server.connections() != 1 {
        assert!(Instant::now() < deadline, "the connection is never counted");
        std::thread::sleep(Duration::from_millis(5));
    }
    let started = Instant::now();
    drop(server);
    assert!(started.elapsed() < Duration::from_secs(1));
    let mut b = [0u8; 8];
    assert!(matches!(client.read(&mut b), Ok(0) | Err(_)));
}
