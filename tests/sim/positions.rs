//! The simulator's position table as a third-party host sees it: the exact example frames
//! of PROTOCOL.md 3.50 (209H, 21FH, 22DH, 244H, 245H, 26DH, 290H, 291H, 26BH) sent as raw
//! bytes over TCP, their replies checked byte for byte; reads that walk a table larger than
//! the reply buffer; the real `xsel-sim` binary with `--positions` and `--position-digits 3`.

use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::time::{Duration, Instant};

use xsel_pendant::sim::runner::{RunOptions, SimCore, TcpServer, start_tcp};
use xsel_pendant::sim::{Controller, FaultSpec, SimSetup};

use crate::wait::{LONG, PROCESS};
use crate::wire::{frame, sc};

/// A host on a TCP line to the simulator (kept alive with it, if it runs in this process).
struct Host {
    stream: TcpStream,
    _server: Option<TcpServer>,
}

impl Host {
    /// The simulator in this process, serving `setup` on a free port.
    fn start(setup: SimSetup) -> Host {
        let core = SimCore::new(Controller::new(setup), FaultSpec::none());
        let server = start_tcp(core, "127.0.0.1:0", RunOptions::default()).expect("tcp");
        let mut host = Host::connect(server.addr);
        host._server = Some(server);
        host
    }

    fn connect(addr: std::net::SocketAddr) -> Host {
        let stream = TcpStream::connect(addr).expect("connect");
        stream
            .set_read_timeout(Some(Duration::from_millis(20)))
            .expect("read timeout");
        stream.set_nodelay(true).expect("no delay");
        Host {
            stream,
            _server: None,
        }
    }

    /// Sends `text` and CR LF as they are (its SC included); the reply without CR LF.
    fn exact(&mut self, text: &str) -> String {
        self.stream
            .write_all(format!("{text}\r\n").as_bytes())
            .unwrap();
        self.reply(text)
    }

    /// Sends `body` with its SC computed; the reply without CR LF, its SC checked.
    fn ask(&mut self, body: &str) -> String {
        self.stream.write_all(&frame(body)).unwrap();
        let r = self.reply(body);
        let (payload, got) = r.split_at(r.len() - 2);
        assert_eq!(got, sc(payload), "reply SC of {r}");
        r
    }

    fn reply(&mut self, to: &str) -> String {
        let deadline = Instant::now() + LONG;
        let mut got = Vec::new();
        let mut buf = [0u8; 4096];
        while !got.ends_with(b"\r\n") {
            assert!(Instant::now() < deadline, "no reply to {to}");
            if let Ok(n) = self.stream.read(&mut buf) {
                got.extend_from_slice(&buf[..n]);
            }
        }
        String::from_utf8(got).unwrap().trim_end().to_owned()
    }
}

/// A simulator with an empty position table (servos on, homed).
fn empty() -> SimSetup {
    let mut s = SimSetup::default();
    s.positions.clear();
    s.config.start_ready = true;
    s.config.reply_delay = Duration::from_millis(1);
    s
}

fn hex8(v: i32) -> String {
    format!("{:08X}", v as u32)
}

fn err(code: &str) -> String {
    let body = format!("&99{code}");
    format!("{body}{}", sc(&body))
}

/// PROTOCOL.md 3.50, 22DH/290H/291H: SCARA positions with their arm systems.
#[test]
fn the_scara_examples_write_and_read_back_byte_for_byte() {
    let mut h = Host::start(empty());
    // 290H: position 1 = X 300, Y -150, Z 20, R 45, right arm.
    assert_eq!(
        h.exact("!9929000000100010F000000000000000493E0FFFDB61000004E200000AFC81018"),
        "#99290000001000112"
    );
    // 291H (its reconstructed layout): the same record, the same answer shape.
    assert_eq!(
        h.exact("!9929100000100010F000000000000000493E0FFFDB61000004E200000AFC81019"),
        "#9929100000152"
    );
    // Position 2 of the 22DH example: X 250, Y 100, Z 0, R -90, left arm.
    let two = [
        "!99291",
        "00",
        "0001",
        "0002",
        "0F",
        "000000000000",
        &hex8(250_000),
        &hex8(100_000),
        &hex8(0),
        &hex8(-90_000),
        "20",
    ]
    .concat();
    assert_eq!(h.ask(&two), "#9929100000152");
    assert_eq!(
        h.exact("!9922D00000100021E"),
        "#9922D00000200010F000000000000000493E0FFFDB61000004E200000AFC81000020F0000000000000003D090000186A000000000FFFEA07020B1"
    );
    // 21FH reports the same records without the arm systems.
    let r = h.ask("!9921F00010002");
    assert!(
        r.starts_with("#9921F000200010F000000000000000493E0FFFDB61000004E200000AFC8"),
        "{r}"
    );
}

/// PROTOCOL.md 3.50, 209H/21FH/244H/245H/26DH/26BH.
#[test]
fn the_linear_examples_write_read_and_move_byte_for_byte() {
    let mut h = Host::start(empty());
    // Positions 1 and 5 of the 209H example, written with 245H: position 1 axes 1+2,
    // 100 mm/s, X 100, Y -50; position 5 axis 1, 0.30 G / 0.30 G, 200 mm/s, X 12.345.
    let write = [
        "!99245",
        "002",
        "001",
        "03",
        "0000",
        "0000",
        "0064",
        &hex8(100_000),
        &hex8(-50_000),
        "005",
        "01",
        "001E",
        "001E",
        "00C8",
        &hex8(12_345),
    ]
    .concat();
    assert_eq!(h.ask(&write), "#99245002C2");
    assert_eq!(
        h.exact("!9920900100A60"),
        "#9920900200103000000000064000186A0FFFF3CB000501001E001E00C800003039AC"
    );
    assert_eq!(
        h.exact("!9921F0001000ACE"),
        "#9921F0002000103000000000064000186A0FFFF3CB0000501001E001E00C8000030394A"
    );
    // 244H: positions 10 and 11 from one start number.
    assert_eq!(
        h.exact("!9924400A002010000000000640000C35001000000000064000124F8F6"),
        "#9924400A00262"
    );
    let r = h.ask("!9921F000A0002");
    assert_eq!(
        r,
        format!(
            "#9921F0002000A010000000000640000C350000B01000000000064000124F8{}",
            sc("#9921F0002000A010000000000640000C350000B01000000000064000124F8")
        )
    );
    // 245H: positions 10 and 20 (position 10 overwritten with the same values).
    assert_eq!(
        h.exact("!9924500200A010000000000640000C35001401000000000064000124F88C"),
        "#99245002C2"
    );
    // 26DH: position 10000.
    assert_eq!(
        h.exact("!9926D00012710010000000000640000C35010"),
        "#9926D000102"
    );
    assert!(h.ask("!9921F27100001").starts_with("#9921F00012710010000"));
    // 26BH: axis 1 to position 10 (X 50.000 in the work frame), rates from the record.
    assert_eq!(h.exact("!9926B01000000000000000AAF"), "#9926B3F");
    // Polled over the line (each 212H waits for its reply): axes 1-4 idle (bit 0).
    let deadline = Instant::now() + LONG;
    loop {
        let r = h.ask("!992120F");
        let status = |k: usize| u32::from_str_radix(&r[8 + 16 * k..10 + 16 * k], 16).unwrap();
        if (0..4).all(|k| status(k) & 1 == 0) {
            break;
        }
        assert!(Instant::now() < deadline, "the 26BH move never ended: {r}");
    }
    // 2A1H, work coordinates, axis 1: X within 0.001 mm of the record's 50.000.
    let r = h.ask("!992A1011");
    let x = u32::from_str_radix(&r[22..30], 16).unwrap() as i32;
    assert!((x - 50_000).abs() <= 1, "{r}");
    // Position 3 holds nothing: B0A; position 0: A03.
    assert_eq!(h.ask("!9926B010000000000000003"), err("B0A"));
    assert_eq!(h.ask("!9926B010000000000000000"), err("A03"));
}

/// A read of 100 positions of 4 axes walks the table in replies cut to the 2048-byte
/// buffer; the host goes on from the last number it got.
#[test]
fn a_large_table_is_read_in_replies_that_fit_the_buffer() {
    let mut setup = empty();
    let text: String = (1..=100)
        .map(|n| format!("[[position]]\nnumber = {n}\nx = {n}.5\ny = -2.0\nz = 3.0\nr = 4.0\narm = \"left\"\n"))
        .collect();
    let file = xsel_pendant::files::coords_file::parse(&text, &setup.model).expect("positions");
    setup.positions = file.positions;
    let mut h = Host::start(setup);
    let mut next = 1u32;
    let mut seen = Vec::new();
    let mut replies = 0;
    while next <= 100 {
        let count = 101 - next;
        let r = h.ask(&format!("!9922D00{next:04X}{count:04X}"));
        assert!(r.len() + 2 <= 2048, "{} bytes", r.len() + 2);
        let n = u32::from_str_radix(&r[8..12], 16).unwrap() as usize;
        assert!(n > 0, "{r}");
        // Records of 4 axes: 4 + 2 + 12 + 32 + 2 characters each.
        assert_eq!(r.len(), 12 + n * 52 + 2, "{r}");
        for k in 0..n {
            let rec = &r[12 + 52 * k..12 + 52 * (k + 1)];
            let number = u32::from_str_radix(&rec[..4], 16).unwrap();
            assert_eq!(&rec[4..6], "0F");
            assert_eq!(&rec[18..26], hex8(number as i32 * 1000 + 500));
            assert_eq!(&rec[50..52], "20", "left arm");
            seen.push(number);
        }
        next = seen.last().unwrap() + 1;
        replies += 1;
    }
    assert_eq!(seen, (1..=100).collect::<Vec<_>>());
    assert_eq!(replies, 3, "39 + 39 + 22");
    // Past the 4-digit models' 20000: refused.
    assert_eq!(h.ask("!9922D004E200002"), err("A03"));
}

/// `xsel-sim --positions FILE --position-digits 3`: the file's positions, 3-digit
/// messages only.
#[test]
fn the_real_binary_loads_positions_and_speaks_three_digits() {
    let path = std::env::temp_dir().join(format!("xsel-sim-positions-{}.toml", std::process::id()));
    std::fs::write(
        &path,
        "[[position]]\nnumber = 1\nx = 100.0\ny = -50.0\nspeed = 100\n\n\
         [[position]]\nnumber = 5\nx = 12.345\naccel = 30\ndecel = 30\nspeed = 200\n",
    )
    .unwrap();
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_xsel-sim"))
        .args(["--tcp", "127.0.0.1:0", "--quiet", "--no-console"])
        .args(["--position-digits", "3", "--positions"])
        .arg(&path)
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::null())
        .spawn()
        .expect("xsel-sim starts");
    let mut out = BufReader::new(child.stdout.take().unwrap());
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let mut line = String::new();
        let _ = out.read_line(&mut line);
        let _ = tx.send(line);
    });
    let line = rx.recv_timeout(PROCESS).expect("the address on stdout");
    let addr = line.trim().parse().expect("an address");
    let mut h = Host::connect(addr);
    assert_eq!(
        h.exact("!9920900100A60"),
        "#9920900200103000000000064000186A0FFFF3CB000501001E001E00C800003039AC"
    );
    for body in ["!9921F00010001", "!9922D0000010001"] {
        assert_eq!(h.ask(body), err("A01"), "{body}");
    }
    assert_eq!(
        h.exact("!9926D00012710010000000000640000C35010"),
        err("A01")
    );
    // 3000 is the top; 244H stays.
    assert_eq!(h.ask("!99209BB8002"), err("A03"));
    assert_eq!(
        h.exact("!9924400A002010000000000640000C35001000000000064000124F8F6"),
        "#9924400A00262"
    );
    let _ = child.kill();
    let _ = child.wait();
    let _ = std::fs::remove_file(&path);
}
