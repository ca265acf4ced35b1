//! Conformance of the simulated controller driven by an independent client, over a real
//! pseudo-terminal (Unix) and over TCP (everywhere, Windows too): frames are built by hand
//! with the checksum of `tests/wire`, not with the project's protocol encoder, so the two
//! implementations check each other. Each test runs on both lines (`_over_pty`,
//! `_over_tcp`); what a pty alone shows (the real binary's `--pty`) runs on a pty only.

use std::io::{Read, Write};
use std::time::{Duration, Instant};

#[cfg(unix)]
use xsel_pendant::sim::runner::{PtyServer, start_pty};
use xsel_pendant::sim::runner::{RunOptions, SimCore, SimHandle, TcpServer, start_tcp};
use xsel_pendant::sim::{Controller, FaultSpec, Mode, SimSetup};

use crate::wait::{LONG, eventually, until};
use crate::wire::{frame, sc};

/// The line a test talks over.
#[derive(Clone, Copy, Debug)]
enum Line {
    #[cfg(unix)]
    Pty,
    Tcp,
}

/// The client's end: a pty or a TCP stream, reads time out after 20 ms.
trait Port: Read + Write + Send {}
impl<T: Read + Write + Send> Port for T {}

/// The simulator serving the line (kept alive with the client).
enum Server {
    #[cfg(unix)]
    Pty(PtyServer),
    Tcp(TcpServer),
}

struct Client {
    port: Box<dyn Port>,
    server: Server,
}

/// Generates `NAME_over_pty` (Unix) and `NAME_over_tcp` from `fn NAME(line: Line)`.
macro_rules! on_both_lines {
    ($name:ident) => {
        mod $name {
            #[cfg(unix)]
            #[test]
            fn over_pty() {
                super::$name(super::Line::Pty);
            }

            #[test]
            fn over_tcp() {
                super::$name(super::Line::Tcp);
            }
        }
    };
}

fn fast_setup() -> SimSetup {
    let mut s = SimSetup::default();
    s.config.servo_switch_time = Duration::from_millis(40);
    s.config.homing_time = Duration::from_millis(120);
    s.config.reboot_time = Duration::from_millis(300);
    s.config.reply_delay = Duration::from_millis(1);
    s
}

#[cfg(unix)]
fn open(path: &str) -> serialport::TTYPort {
    serialport::new(path, 115_200)
        .timeout(Duration::from_millis(20))
        .open_native()
        .unwrap_or_else(|e| panic!("cannot open the simulator's pty {path}: {e}"))
}

impl Client {
    fn start(line: Line, setup: SimSetup) -> Client {
        let core = SimCore::new(Controller::new(setup), FaultSpec::none());
        match line {
            #[cfg(unix)]
            Line::Pty => {
                let server = start_pty(core, RunOptions::default()).expect("pty");
                let port = open(&server.path);
                Client {
                    port: Box::new(port),
                    server: Server::Pty(server),
                }
            }
            Line::Tcp => {
                let server = start_tcp(core, "127.0.0.1:0", RunOptions::default()).expect("tcp");
                let port = std::net::TcpStream::connect(server.addr).expect("connect");
                port.set_read_timeout(Some(Duration::from_millis(20)))
                    .expect("read timeout");
                port.set_nodelay(true).expect("no delay");
                Client {
                    port: Box::new(port),
                    server: Server::Tcp(server),
                }
            }
        }
    }

    /// The simulator's handle (counters, the operator's switches).
    fn sim(&self) -> &SimHandle {
        match &self.server {
            #[cfg(unix)]
            Server::Pty(s) => &s.handle,
            Server::Tcp(s) => &s.handle,
        }
    }

    fn send_raw(&mut self, bytes: &[u8]) {
        self.port.write_all(bytes).unwrap();
        self.port.flush().unwrap();
    }

    /// Reads one reply up to LF, or `None` after `timeout` with no complete reply.
    fn read_reply(&mut self, timeout: Duration) -> Option<String> {
        let deadline = Instant::now() + timeout;
        let mut got = Vec::new();
        let mut b = [0u8; 1];
        while Instant::now() < deadline {
            match self.port.read(&mut b) {
                Ok(1) => {
                    got.push(b[0]);
                    if b[0] == b'\n' {
                        return Some(String::from_utf8_lossy(&got).into_owned());
                    }
                }
                _ => continue,
            }
        }
        assert!(
            got.is_empty(),
            "partial reply {:?}",
            String::from_utf8_lossy(&got)
        );
        None
    }

    /// Sends `body` with a computed SC; returns the reply without CR LF, its SC checked.
    fn cmd(&mut self, body: &str) -> String {
        self.send_raw(&frame(body));
        let reply = self
            .read_reply(Duration::from_secs(2))
            .unwrap_or_else(|| panic!("no reply to {body}"));
        check_reply(&reply)
    }

    fn silent(&mut self, bytes: &[u8]) -> bool {
        self.send_raw(bytes);
        self.read_reply(Duration::from_millis(200)).is_none()
    }

    /// 2A1H of axes 1-4 in `system` (0 base, 1 work, 3 joints): (status bytes, positions).
    fn scara(&mut self, system: u8) -> ([u32; 4], [i32; 4]) {
        let r = self.cmd(&format!("!992A10F{system}"));
        assert!(r.starts_with("#992A1"), "{r}");
        assert_eq!(r.len(), 14 + 4 * 16 + 2, "{r}");
        let mut status = [0; 4];
        let mut pos = [0; 4];
        for k in 0..4 {
            let b = 14 + 16 * k;
            status[k] = hex(&r[b..b + 2]);
            pos[k] = hex(&r[b + 8..b + 16]) as i32;
        }
        (status, pos)
    }

    /// Polls 212H (all axes) until no axis is in use (bit 0); returns axes 1-4's statuses.
    fn wait_idle(&mut self) -> [u32; 4] {
        let mut st: Vec<u32> = Vec::new();
        let idle = eventually(LONG, || {
            let r = self.cmd("!99212FF");
            let n = (r.len() - 10) / 16;
            st = (0..n).map(|k| hex(&r[8 + 16 * k..10 + 16 * k])).collect();
            st.iter().all(|s| s & 1 == 0)
        });
        assert!(idle, "axes still in use: {st:?}");
        [st[0], st[1], st[2], st[3]]
    }

    /// Servo on and home axes 1-4, checking the status bits on the way.
    fn servo_and_home(&mut self) {
        assert_eq!(self.cmd("!992320F1"), "#992322C");
        let st = self.wait_idle();
        assert!(st.iter().all(|s| s & 0x08 != 0), "servo on: {st:?}");
        assert_eq!(self.cmd("!992330F000000"), "#992332D");
        let (st, _) = self.scara(0);
        assert!(
            st.iter().all(|s| (s >> 1) & 3 == 1 && s & 1 == 1),
            "homing: {st:?}"
        );
        let st = self.wait_idle();
        assert!(
            st.iter().all(|s| (s >> 1) & 3 == 2 && s & 0x10 != 0),
            "homed: {st:?}"
        );
    }
}

fn hex(s: &str) -> u32 {
    u32::from_str_radix(s, 16).unwrap_or_else(|_| panic!("not hex: {s}"))
}

/// Checks CR LF and the SC of a reply; returns it without SC... no: without CR LF.
fn check_reply(reply: &str) -> String {
    let body = reply.strip_suffix("\r\n").expect("reply ends with CR LF");
    let (payload, got) = body.split_at(body.len() - 2);
    assert_eq!(got, sc(payload), "reply SC of {body}");
    body.to_owned()
}

fn err(code: &str) -> String {
    let body = format!("&99{code}");
    format!("{body}{}", sc(&body))
}

/// 236H: axis pattern, speed, inching distance (0 = jog), operation type.
fn jog(pattern: u8, speed: u16, distance: u32, op: u8) -> String {
    format!("!99236{pattern:02X}00000000{speed:04X}{distance:08X}{op:X}")
}

fn i32hex(v: i32) -> String {
    format!("{:08X}", v as u32)
}

on_both_lines!(framing_checksum_and_at_at);
fn framing_checksum_and_at_at(line: Line) {
    let mut c = Client::start(line, fast_setup());
    assert_eq!(c.cmd("!99200"), "#9920027");
    assert_eq!(
        c.cmd("!992000123456789"),
        format!("#992000123456789{}", sc("#992000123456789"))
    );
    // `@@` in the SC position is accepted; the reply carries a real SC.
    c.send_raw(b"!99215@@\r\n");
    let r = check_reply(&c.read_reply(Duration::from_secs(1)).expect("reply to @@"));
    assert_eq!(r, "#9921510000000000060004");
    // Lower-case hex in a data field is accepted.
    assert!(c.cmd("!992a10f0").starts_with("#992A1"));
    // Noise before a frame is skipped.
    c.send_raw(b"zz\x01");
    assert_eq!(c.cmd("!99200"), "#9920027");
}

on_both_lines!(silence_on_wrong_station_header_checksum_or_terminator);
fn silence_on_wrong_station_header_checksum_or_terminator(line: Line) {
    let mut c = Client::start(line, fast_setup());
    assert!(c.silent(&frame("!98215")), "wrong station");
    assert!(c.silent(&frame("#99215")), "wrong header");
    assert!(c.silent(b"!99215FF\r\n"), "wrong checksum");
    assert!(c.silent(b"!992152B\r"), "missing LF");
    assert!(c.silent(b"!992152B\n"), "missing CR");
    assert!(c.silent(b"!99215\r\n"), "no SC");
    // Still alive and answering afterwards.
    assert_eq!(c.cmd("!99215"), "#9921510000000000060004");
    let n = c.sim().counters();
    assert!(n.silent_station >= 1 && n.silent_checksum >= 1, "{n:?}");
}

on_both_lines!(every_message_is_answered_with_its_layout);
fn every_message_is_answered_with_its_layout(line: Line) {
    let mut setup = fast_setup();
    setup.config.linear_axes = 1;
    let mut c = Client::start(line, setup);
    let lens = |r: &str| r.len();
    // 201H: 31 characters before SC.
    let r = c.cmd("!99201000");
    assert!(r.starts_with("#99201000") && lens(&r) == 33, "{r}");
    // 212H: axes 1 and 5 (16 chars each).
    let r = c.cmd("!9921211");
    assert!(r.starts_with("#9921211") && lens(&r) == 8 + 32 + 2, "{r}");
    // 212H asks for axis 8, which is not connected: its bit is missing.
    let r = c.cmd("!9921281");
    assert!(r.starts_with("#99212010"), "{r}");
    assert_eq!(c.cmd("!99215").len(), 23);
    let r = c.cmd("!99216000000");
    assert!(r.starts_with("#99216000") && lens(&r) == 90 + 2, "{r}");
    c.servo_and_home();
    assert_eq!(c.cmd("!992321"), err("A02"));
    assert_eq!(c.cmd("!99232101"), "#992322C");
    c.wait_idle();
    assert_eq!(c.cmd("!9923310000000"), "#992332D");
    c.wait_idle();
    // 2A3H: arm code 1 = right after homing (J2 = +90).
    let r = c.cmd("!992A30F00");
    assert!(
        r.starts_with("#992A30F0000") && &r[12..14] == "01" && &r[20..22] == "0F",
        "{r}"
    );
    assert_eq!(lens(&r), 22 + 64 + 2);
    // 2A1H: arm code 0 = right.
    let r = c.cmd("!992A10F0");
    assert_eq!(&r[10..12], "00", "{r}");
    // 234H / 235H on linear axis 5, 262H while it moves, 238H, 236H.
    assert_eq!(
        c.cmd(&format!("!9923410000000000064{}", i32hex(300_000))),
        "#992342E"
    );
    assert_eq!(c.cmd("!992621000C8"), "#992622F");
    c.wait_idle();
    let r = c.cmd("!9921210");
    assert_eq!(hex(&r[16..24]) as i32, 300_000, "{r}");
    assert_eq!(
        c.cmd(&format!("!9923510000000000064{}", i32hex(-50_000))),
        "#992352F"
    );
    c.wait_idle();
    let r = c.cmd("!9921210");
    assert_eq!(hex(&r[16..24]) as i32, 250_000, "{r}");
    assert_eq!(c.cmd(&jog(0x10, 10, 1_000, 0)), "#9923630");
    c.wait_idle();
    let r = c.cmd("!9921210");
    assert_eq!(hex(&r[16..24]) as i32, 249_000, "{r}");
    assert_eq!(c.cmd("!99238FF00"), "#9923832");
    // 2A0H: work No. 1 from the example file (300, -100, 0, 0).
    let r = c.cmd("!992A000101");
    assert_eq!(r, {
        let b = format!(
            "#992A000101{}{}{}{}",
            i32hex(300_000),
            i32hex(-100_000),
            i32hex(0),
            i32hex(0)
        );
        format!("{b}{}", sc(&b))
    });
    // 2A4H: tool No. 1 (Z 35 mm).
    let r = c.cmd("!992A40F10101");
    assert!(
        r.starts_with("#992A40F10101") && r[29..37] == i32hex(35_000),
        "{r}"
    );
    // 2D4H, 2D5H, 2D6H.
    assert_eq!(
        c.cmd(&format!(
            "!992D40F00000000001E02{}{}{}{}",
            i32hex(300_000),
            i32hex(50_000),
            i32hex(20_000),
            i32hex(10_000)
        )),
        "#992D43F"
    );
    c.wait_idle();
    let (_, p) = c.scara(1);
    assert_eq!(p, [300_000, 50_000, 20_000, 10_000]);
    assert_eq!(
        c.cmd(&format!("!992D50400000000000002{}", i32hex(5_000))),
        "#992D540"
    );
    c.wait_idle();
    assert_eq!(c.cmd("!992D60F000000000000020001"), "#992D641");
    c.wait_idle();
    let (_, p) = c.scara(1);
    assert_eq!(p, [350_000, 0, 20_000, 0], "position No. 1");
    assert_eq!(c.cmd("!99252"), "#992522E");
    // 25BH: acknowledged, then silent while rebooting, then back (servos off).
    assert_eq!(c.cmd("!9925B"), "#9925B3E");
    assert!(c.silent(&frame("!99215")), "silent while rebooting");
    until("the controller back from its reboot", LONG, || {
        !c.sim().with(|ctl| ctl.is_rebooting())
    });
    let (st, _) = c.scara(0);
    assert!(
        st.iter().all(|s| s & 0x08 == 0),
        "servo off after reset: {st:?}"
    );
    // Unknown message.
    assert_eq!(c.cmd("!99299"), err("A01"));
}

on_both_lines!(relative_ptp_and_cp_moves_change_work_positions_by_exactly_the_delta);
fn relative_ptp_and_cp_moves_change_work_positions_by_exactly_the_delta(line: Line) {
    let mut c = Client::start(line, fast_setup());
    assert!(c.sim().select_work(2));
    assert!(c.sim().select_tool(1));
    c.servo_and_home();
    let r = c.cmd("!992A10F1");
    assert_eq!(
        &r[6..12],
        "020104",
        "work 2, tool 1, right arm, work coordinates: {r}"
    );
    for (op, delta) in [
        ("02", [10_000, -20_000, 5_000, 15_000]),
        ("03", [-25_000, 12_345, -3_000, -7_500]),
        ("0A", [1_000, 1_000, 0, 0]),
    ] {
        let (_, before) = c.scara(1);
        let body = format!(
            "!992D50F000000000032{op}{}{}{}{}",
            i32hex(delta[0]),
            i32hex(delta[1]),
            i32hex(delta[2]),
            i32hex(delta[3])
        );
        assert_eq!(c.cmd(&body), "#992D540");
        let (st, _) = c.scara(0);
        assert!(st.iter().all(|s| s & 1 == 1), "in use while moving: {st:?}");
        let st = c.wait_idle();
        assert!(
            st.iter().all(|s| s & 0x10 != 0),
            "completed normally: {st:?}"
        );
        let (_, after) = c.scara(1);
        for k in 0..4 {
            assert_eq!(
                after[k] - before[k],
                delta[k],
                "op {op} axis {}: {before:?} -> {after:?}",
                k + 1
            );
        }
    }
    let n = c.sim().counters();
    assert_eq!(n.motion_started, 4); // home + 3 moves
    assert_eq!(n.motion_completed, 4);
}

on_both_lines!(stop_mid_move_ends_short_and_not_completed);
fn stop_mid_move_ends_short_and_not_completed(line: Line) {
    let mut c = Client::start(line, fast_setup());
    c.servo_and_home();
    let (_, before) = c.scara(0);
    // CP, Y -150 mm at 50 mm/s: 3 s.
    assert_eq!(
        c.cmd(&format!(
            "!992D50F0000000000320300000000{}0000000000000000",
            i32hex(-150_000)
        )),
        "#992D540"
    );
    // Stopped once it has run 10 mm of the 150.
    until("the line to run 10 mm", LONG, || {
        before[1] - c.scara(0).1[1] >= 10_000
    });
    assert_eq!(c.cmd("!992380F00"), "#9923832");
    let st = c.wait_idle();
    assert!(
        st.iter().all(|s| s & 0x10 == 0 && s & 0x08 != 0),
        "cancelled, servo still on: {st:?}"
    );
    let (_, after) = c.scara(0);
    let moved = before[1] - after[1];
    assert!(
        moved > 5_000 && moved < 100_000,
        "moved {moved} µm of 150 mm"
    );
    assert_eq!(after[0], before[0], "a CP line in Y keeps X");
    let n = c.sim().counters();
    assert_eq!(n.motion_cancelled, 1);
    // Jog until STOP, then an inching step in the each-axis system.
    let (_, rest) = c.scara(3);
    assert_eq!(c.cmd(&jog(1, 20, 0, 1)), "#9923630");
    until("the jog to move the arm", LONG, || c.scara(3).1 != rest);
    let (st, _) = c.scara(0);
    assert!(st.iter().all(|s| s & 1 == 1), "jogging: {st:?}");
    assert_eq!(c.cmd("!992380F00"), "#9923832");
    c.wait_idle();
    let (_, j0) = c.scara(3);
    assert_eq!(c.cmd(&jog(1, 10, 1_000, 7)), "#9923630");
    c.wait_idle();
    let (_, j1) = c.scara(3);
    assert_eq!(j1[0] - j0[0], 1_000, "J1 +1.000 deg");
}

on_both_lines!(moves_out_of_reach_or_range_are_refused_and_the_arm_stays);
fn moves_out_of_reach_or_range_are_refused_and_the_arm_stays(line: Line) {
    let mut c = Client::start(line, fast_setup());
    c.servo_and_home();
    let (_, before) = c.scara(0);
    let (_, joints_before) = c.scara(3);
    let started = c.sim().counters().motion_started;
    let refusals = [
        // X +400 mm: beyond the 500 mm reach.
        (format!("!992D50100000000000002{}", i32hex(400_000)), "B08"),
        // Z +250 mm: beyond the Z stroke (joint limit).
        (format!("!992D50400000000000002{}", i32hex(250_000)), "C74"),
        // CP line through the base (J1 axis) to the other side.
        (
            format!(
                "!992D50300000000000003{}{}",
                i32hex(-500_000),
                i32hex(-500_000)
            ),
            "B08",
        ),
        // Each-axis inching J1 by 200 deg: beyond +-125.
        (jog(1, 20, 200_000, 7), "C74"),
        // Absolute target at the base origin.
        (
            format!("!992D40300000000000002{}{}", i32hex(0), i32hex(0)),
            "B08",
        ),
    ];
    for (body, code) in &refusals {
        assert_eq!(c.cmd(body), err(code), "{body}");
        let (st, now) = c.scara(0);
        assert_eq!(now, before, "arm moved after {body}");
        assert!(st.iter().all(|s| s & 1 == 0), "axis in use after a refusal");
    }
    // A refused move never starts: none counted as started, the joints where they were.
    assert_eq!(
        c.sim().counters().motion_started,
        started,
        "a refused move started"
    );
    assert_eq!(c.scara(3).1, joints_before);
    let n = c.sim().counters();
    assert_eq!(n.motion_refused, refusals.len() as u64);
}

on_both_lines!(coordinate_queries_are_limited_to_the_reply_buffer);
fn coordinate_queries_are_limited_to_the_reply_buffer(line: Line) {
    let mut c = Client::start(line, fast_setup());
    // 2A4H, tool table (128 entries), ask for 100: 63 fit in 2048 bytes.
    c.send_raw(&frame("!992A40F10064"));
    let r = check_reply(&c.read_reply(Duration::from_secs(2)).unwrap());
    assert_eq!(&r[9..13], "003F", "{}", &r[..13]);
    assert_eq!(r.len(), 13 + 63 * 32 + 2);
    assert!(r.len() + 2 <= 2048);
    // 2A0H likewise.
    let r = c.cmd("!992A0100FF");
    assert_eq!(&r[9..11], "3F");
    // Near the end of the table only what exists comes.
    let r = c.cmd("!992A40F17E10");
    assert_eq!(&r[11..13], "02", "records 126 and 127");
    assert_eq!(c.cmd("!992A40F18001"), err("A03"));
    assert_eq!(c.cmd("!992A4F010001"), err("A04"));
    // A J/K/TT reply buffer of 1024 bytes: 31 records.
    let mut setup = fast_setup();
    setup.config.reply_buffer = 1024;
    let mut small = Client::start(line, setup);
    let r = small.cmd("!992A40F10064");
    assert_eq!(&r[11..13], "1F");
}

on_both_lines!(zones_are_answered_as_protocol_md_says);
fn zones_are_answered_as_protocol_md_says(line: Line) {
    // PROTOCOL.md 3.46/3.50's zone 1, from a coordinate file: the reply byte for byte.
    let mut setup = fast_setup();
    let model = setup.model.clone();
    let file = xsel_pendant::files::coords_file::parse(
        "[[zone]]\nnumber = 1\ncorner1 = [100.0, -100.0, 0.0]\ncorner2 = [200.0, 100.0, 50.0]\n",
        &model,
    )
    .expect("a zone file");
    setup.zones = file.zones;
    let mut c = Client::start(line, setup);
    assert_eq!(
        c.cmd("!992A20101"),
        "#992A2010107000186A0FFFE79600000000000030D40000186A00000C35046"
    );
    // Zones 1-10, each record ending after coordinate 2: a zone not in the file is zeros.
    let r = c.cmd("!992A2010A");
    assert_eq!(&r[6..10], "010A", "{r}");
    assert_eq!(r.len(), 10 + 10 * (2 + 6 * 8) + 2, "{r}");
    assert_eq!(&r[60..110], format!("07{}", "0".repeat(48)), "zone 2: {r}");
    // A bad number or count: A03, as the position table's range queries answer.
    for bad in ["!992A20001", "!992A20B01", "!992A20100", "!992A20A02"] {
        assert_eq!(c.cmd(bad), err("A03"), "{bad}");
    }
    // Wrong length: A02.
    assert_eq!(c.cmd("!992A201"), err("A02"));
}

on_both_lines!(error_replies_name_the_reason);
fn error_replies_name_the_reason(line: Line) {
    let mut c = Client::start(line, fast_setup());
    let mv = format!("!992D50100000000000002{}", i32hex(1_000));
    assert_eq!(c.cmd("!99999"), err("A01"));
    assert_eq!(c.cmd("!99215FF"), err("A02"));
    assert_eq!(
        c.cmd("!992380F"),
        err("A02"),
        "238H without its appended byte"
    );
    assert_eq!(c.cmd("!99212G1"), err("A03"));
    assert_eq!(c.cmd("!992324F1"), err("A04"), "axes 5-8 absent");
    assert_eq!(c.cmd(&mv), err("B01"));
    assert_eq!(c.cmd("!992330F000000"), err("B01"));
    assert_eq!(c.cmd("!992320F1"), "#992322C");
    assert_eq!(c.cmd(&mv), err("B03"), "servo still switching");
    c.wait_idle();
    assert_eq!(c.cmd(&mv), err("B02"));
    assert_eq!(c.cmd("!992330F000000"), "#992332D");
    c.wait_idle();
    assert_eq!(c.cmd("!992620F0064"), err("A04"), "262H: no SCARA axes");
    assert_eq!(
        c.cmd("!992D60F000000000000020063"),
        err("B0A"),
        "no position 99"
    );
    c.sim().set_mode(Mode::Manual);
    assert_eq!(c.cmd(&mv), err("B05"));
    assert_eq!(c.cmd("!99215")[6..7], *"2");
    c.sim().set_mode(Mode::Auto);
    c.sim().set_emergency_stop(true);
    assert_eq!(c.cmd(&mv), err("B04"));
    let r = c.cmd("!99215");
    assert_eq!(hex(&r[13..15]) & 0x08, 0x08, "E-stop bit: {r}");
    let (st, _) = c.scara(0);
    assert!(st.iter().all(|s| s & 0x08 == 0), "servo off under E-stop");
    c.sim().set_emergency_stop(false);
    assert_eq!(c.cmd("!992320F1"), "#992322C");
    c.wait_idle();
    c.sim().raise_alarm(0xD0A, Some(2));
    assert_eq!(c.cmd(&mv), err("B07"));
    let r = c.cmd("!99215");
    assert_eq!(&r[7..10], "D0A", "critical error: {r}");
    let r = c.cmd("!99216000000");
    assert_eq!(&r[6..9], "D0A");
    assert_eq!(hex(&r[25..33]), 2, "detail 3 = axis 2: {r}");
    assert_eq!(c.cmd("!99252"), "#992522E");
    assert_eq!(
        &c.cmd("!99215")[7..13],
        "000D0A",
        "latest error kept after reset"
    );
}

#[cfg(unix)]
#[test]
fn the_real_binary_serves_a_pty() {
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_xsel-sim"))
        .args(["--pty", "--quiet", "--delay-ms", "1", "--ready"])
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::null())
        .spawn()
        .expect("xsel-sim starts");
    let mut out = child.stdout.take().unwrap();
    let mut path = Vec::new();
    let mut b = [0u8; 1];
    while out.read(&mut b).unwrap_or(0) == 1 && b[0] != b'\n' {
        path.push(b[0]);
    }
    let path = String::from_utf8(path).unwrap();
    assert!(
        path.starts_with("/dev/"),
        "first stdout line is the pty path: {path:?}"
    );
    let mut port = open(&path);
    let mut ask = |body: &str| {
        port.write_all(&frame(body)).unwrap();
        let mut got = Vec::new();
        let deadline = Instant::now() + Duration::from_secs(2);
        while !got.ends_with(b"\n") && Instant::now() < deadline {
            if let Ok(1) = port.read(&mut b) {
                got.push(b[0]);
            }
        }
        check_reply(&String::from_utf8_lossy(&got))
    };
    assert_eq!(ask("!99215"), "#9921510000000000060004");
    let r = ask("!992A10F0");
    assert!(
        r.starts_with("#992A10000000F0C"),
        "ready: servo on, homed: {r}"
    );
    assert_eq!(
        ask(&format!("!992D50100000000000002{}", i32hex(2_000))),
        "#992D540"
    );
    let _ = child.kill();
    let _ = child.wait();
}
