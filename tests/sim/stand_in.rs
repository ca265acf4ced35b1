//! The simulator as a stand-in for a real controller (sans-IO part): relative and
//! absolute moves go the way and distance they name, jog before homing, servo-on time,
//! 216H after a refusal, and the habits of third-party host code. Frames are built
//! by hand with the checksum of `tests/wire`.

use std::time::Duration;

use xsel_pendant::sim::{Controller, SimSetup};

use crate::wire::{frame, sc};

fn i32hex(v: i32) -> String {
    format!("{:08X}", v as u32)
}

/// The simulator's clock for one test.
struct Host {
    c: Controller,
    t: Duration,
}

impl Host {
    fn new(ready: bool) -> Host {
        let mut setup = SimSetup::default();
        setup.config.start_ready = ready;
        Host {
            c: Controller::new(setup),
            t: Duration::ZERO,
        }
    }

    /// Sends `body` with its SC; the reply without CR LF, or "" for silence.
    fn ask(&mut self, body: &str) -> String {
        self.ask_raw(&frame(body))
    }

    fn ask_raw(&mut self, bytes: &[u8]) -> String {
        self.t += Duration::from_millis(1);
        let reply = self.c.handle(bytes, self.t).unwrap_or_default();
        String::from_utf8_lossy(&reply).trim_end().to_owned()
    }

    fn wait(&mut self, d: Duration) {
        self.t += d;
        self.c.advance(self.t);
    }

    /// Lets every motion run to its end.
    fn settle(&mut self) {
        self.wait(Duration::from_secs(60));
        assert_eq!(self.c.in_use(), 0, "still moving after a minute");
    }

    fn j4(&self) -> f64 {
        self.c.snapshot().joints.j4
    }

    /// The error code of an `&` reply, or the whole reply when it is not one.
    fn code(reply: &str) -> &str {
        reply
            .strip_prefix("&99")
            .map_or(reply, |r| r.get(..3).unwrap_or(r))
    }
}

/// 2D5H relative (or 2D4H absolute) of R alone: PTP (op 02) or CP (op 03).
fn scara_r(id: &str, op: u8, r_mdeg: i32) -> String {
    format!("!99{id}08001E001E0014{op:02X}{}", i32hex(r_mdeg))
}

/// 236H inching of axis 4 by `mdeg`, in the base frame (`each_axis` false) or joint system.
fn inch_r(mdeg: i32, each_axis: bool) -> String {
    let dir = u8::from(mdeg > 0);
    let op = if each_axis { 6 | dir } else { dir };
    format!("!9923608000000000014{:08X}{op:X}", mdeg.unsigned_abs())
}

const OK_2D5: &str = "#992D540";

#[test]
fn relative_r_turns_the_way_and_distance_it_names() {
    for op in [0x02, 0x03] {
        for deg in [179, -179, 181, -181, 300, -300, 360, -360] {
            let mut h = Host::new(true);
            assert_eq!(h.j4(), 0.0);
            let reply = h.ask(&scara_r("2D5", op, deg * 1000));
            assert_eq!(reply, OK_2D5, "op {op:02X}, R {deg:+}");
            h.settle();
            assert!(
                (h.j4() - f64::from(deg)).abs() < 1e-6,
                "op {op:02X}: R {deg:+} deg turned the joint to {} deg",
                h.j4()
            );
        }
    }
}

#[test]
fn relative_r_beyond_the_joint_limit_is_refused_and_the_arm_stays() {
    // From home (J1 0, J2 +90, J4 0) the left arm (J1 90, J2 -90) puts the same Cartesian
    // R at J4 + 180: a PTP move that only the left arm reaches is refused for the arm
    // switch (B09) under policy 0; CP keeps the arm and meets the R limit (C74).
    for (op, mdeg, code) in [
        (0x02, 361_000, "C74"),
        (0x02, -361_000, "B09"),
        (0x02, 1_000_000, "C74"),
        (0x02, -1_000_000, "C74"),
        (0x02, 360_001, "C74"),
        (0x02, -360_001, "B09"),
        (0x02, -540_001, "C74"),
        (0x03, 361_000, "C74"),
        (0x03, -361_000, "C74"),
        (0x03, 1_000_000, "C74"),
        (0x03, -1_000_000, "C74"),
        (0x03, 360_001, "C74"),
        (0x03, -360_001, "C74"),
    ] {
        {
            let mut h = Host::new(true);
            let reply = h.ask(&scara_r("2D5", op, mdeg));
            assert_eq!(Host::code(&reply), code, "op {op:02X}, R {mdeg:+} mdeg");
            h.settle();
            assert_eq!(h.j4(), 0.0, "op {op:02X}, R {mdeg:+}: the arm stays");
        }
    }
    // Chained to the limit, then one unit more.
    let mut h = Host::new(true);
    assert_eq!(h.ask(&scara_r("2D5", 2, 300_000)), OK_2D5);
    h.settle();
    assert_eq!(h.ask(&scara_r("2D5", 2, 60_000)), OK_2D5);
    h.settle();
    assert!((h.j4() - 360.0).abs() < 1e-6, "at the limit: {}", h.j4());
    assert_eq!(Host::code(&h.ask(&scara_r("2D5", 2, 1))), "C74");
    assert_eq!(Host::code(&h.ask(&scara_r("2D5", 3, 1))), "C74");
    assert_eq!(h.ask(&scara_r("2D5", 2, -1)), OK_2D5, "back from the limit");
}

#[test]
fn absolute_r_goes_where_it_names() {
    // At home the flange's Cartesian R is J1 + J2 + J4 = 0 + 90 + 0 (work 0 = base).
    for (r, j4) in [(390_000, 300.0), (-270_000, -360.0), (270_000, 180.0)] {
        let mut h = Host::new(true);
        assert_eq!(h.ask(&scara_r("2D4", 2, r)), "#992D43F", "R {r}");
        h.settle();
        assert!((h.j4() - j4).abs() < 1e-6, "R {r}: J4 {} not {j4}", h.j4());
    }
    // J4 would be 361 / -541 on the right arm, 451 / -451 on the left.
    for r in [451_000, -451_000] {
        let mut h = Host::new(true);
        assert_eq!(Host::code(&h.ask(&scara_r("2D4", 2, r))), "C74", "R {r}");
    }
}

#[test]
fn r_inching_turns_the_way_and_distance_it_names() {
    for each_axis in [true, false] {
        for deg in [181, -181, 300, -300] {
            let mut h = Host::new(true);
            assert_eq!(h.ask(&inch_r(deg * 1000, each_axis)), "#9923630");
            h.settle();
            assert!(
                (h.j4() - f64::from(deg)).abs() < 1e-6,
                "each-axis {each_axis}: R {deg:+} gave {}",
                h.j4()
            );
        }
        let mut h = Host::new(true);
        assert_eq!(Host::code(&h.ask(&inch_r(361_000, each_axis))), "C74");
    }
}

/// Servo on for axes 1-4 and wait `ms`.
fn servo_on(h: &mut Host, ms: u64) {
    assert_eq!(h.ask("!992320F1"), "#992322C");
    h.wait(Duration::from_millis(ms));
}

#[test]
fn jog_and_inching_in_the_each_axis_system_need_no_homing() {
    let mut h = Host::new(false);
    servo_on(&mut h, 500);
    // Each-axis inching and a continuous joint jog, then its stop.
    assert_eq!(h.ask(&inch_r(10_000, true)), "#9923630");
    h.settle();
    assert!((h.j4() - 10.0).abs() < 1e-6, "J4 {}", h.j4());
    assert_eq!(h.ask("!9923602000000000014000000007"), "#9923630");
    h.wait(Duration::from_millis(50));
    assert_eq!(h.ask("!99238FF00"), "#9923832");
    h.settle();
    // Cartesian jog, relative and absolute moves still want a reference.
    assert_eq!(Host::code(&h.ask(&inch_r(10_000, false))), "B02");
    assert_eq!(Host::code(&h.ask(&scara_r("2D5", 2, 1000))), "B02");
    assert_eq!(Host::code(&h.ask(&scara_r("2D4", 2, 1000))), "B02");
}

/// A published C++ host waits 100 ms after the 232H reply before its next command;
/// another sends it at once and polls 212H.
#[test]
fn a_host_that_waits_100_ms_after_servo_on_may_then_home_and_move() {
    let mut h = Host::new(false);
    servo_on(&mut h, 100);
    assert_eq!(
        h.ask("!992330F000000"),
        "#992332D",
        "home 100 ms after 232H"
    );
    h.settle();
    assert_eq!(h.ask(&scara_r("2D5", 2, 5_000)), OK_2D5);
}

#[test]
fn error_detail_reports_the_last_refusal() {
    let mut h = Host::new(false);
    // Before anything went wrong: error 000.
    for query in ["!99216000000", "!99216001000"] {
        let r = h.ask(query);
        assert_eq!(r.get(6..9), Some("000"), "{query}: {r}");
    }
    assert_eq!(Host::code(&h.ask(&scara_r("2D5", 2, 1000))), "B01");
    for query in ["!99216000000", "!99216001000"] {
        let r = h.ask(query);
        assert_eq!(r.get(6..9), Some("B01"), "{query} after B01: {r}");
    }
    servo_on(&mut h, 500);
    assert_eq!(Host::code(&h.ask(&scara_r("2D5", 2, 1000))), "B02");
    let r = h.ask("!99216001000");
    assert_eq!(r.get(6..9), Some("B02"), "216H latest error after B02: {r}");
    // An alarm is reported the same way, ahead of older refusals.
    h.c.raise_alarm(0xC74, Some(4), "test");
    let r = h.ask("!99216000000");
    assert_eq!(r.get(6..9), Some("C74"), "pending alarm: {r}");
}

// Third-party habits.

#[test]
fn lower_case_hex_is_answered() {
    let mut h = Host::new(true);
    // 2A1H axes 0f, work system; 2D5H with lower-case digits and a lower-case checksum.
    let r = h.ask_raw(format!("!992a10f1{}\r\n", sc("!992a10f1").to_lowercase()).as_bytes());
    assert!(r.starts_with("#992A1"), "{r}");
    let body = "!992d508001e001e001402000003e8";
    let r = h.ask_raw(format!("{body}{}\r\n", sc(body).to_lowercase()).as_bytes());
    assert_eq!(r, OK_2D5);
}

#[test]
fn at_at_in_place_of_the_checksum_is_answered() {
    let mut h = Host::new(true);
    assert_eq!(h.ask_raw(b"!99215@@\r\n").get(..6), Some("#99215"));
    assert_eq!(
        h.ask_raw(b"!9923608000000000014000003e81@@\r\n"),
        "#9923630"
    );
    assert_eq!(h.c.counters().at_at, 2);
}
