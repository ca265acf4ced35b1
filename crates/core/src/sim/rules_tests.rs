//! Controller rules found by review, driven with hand-built frames (this file's own
//! checksum, not the protocol encoder) and a simulated clock.

use std::time::Duration;

use super::{Controller, SimSetup};

fn sc(body: &str) -> String {
    format!(
        "{:02X}",
        body.bytes().fold(0u32, |s, b| s + u32::from(b)) & 0xFF
    )
}

fn frame(body: &str) -> Vec<u8> {
    format!("{body}{}\r\n", sc(body)).into_bytes()
}

fn err(code: &str) -> String {
    let body = format!("&99{code}");
    format!("{body}{}", sc(&body))
}

/// 236H: axis pattern, speed, inching distance (0 = jog), operation type.
fn jog(pattern: u8, speed: u16, distance: u32, op: u8) -> String {
    format!("!99236{pattern:02X}00000000{speed:04X}{distance:08X}{op:X}")
}

/// A controller and its clock.
struct Sim {
    c: Controller,
    t: Duration,
}

impl Sim {
    fn new(linear_axes: u8) -> Sim {
        let mut s = SimSetup::default();
        s.config.linear_axes = linear_axes;
        s.config.servo_switch_time = Duration::from_millis(40);
        s.config.homing_time = Duration::from_millis(120);
        Sim {
            c: Controller::new(s),
            t: Duration::ZERO,
        }
    }

    /// The reply to `body` without CR LF, or "" for silence.
    fn cmd(&mut self, body: &str) -> String {
        self.t += Duration::from_millis(1);
        self.c
            .handle(&frame(body), self.t)
            .map(|r| String::from_utf8(r).unwrap().trim_end().to_owned())
            .unwrap_or_default()
    }

    fn wait(&mut self, ms: u64) {
        self.t += Duration::from_millis(ms);
        self.c.advance(self.t);
    }

    /// 212H of `pattern`: (status byte, position) per reported axis.
    fn status(&mut self, pattern: u8) -> Vec<(u32, i32)> {
        let r = self.cmd(&format!("!99212{pattern:02X}"));
        let n = (r.len() - 10) / 16;
        (0..n)
            .map(|k| {
                let b = 8 + 16 * k;
                let st = u32::from_str_radix(&r[b..b + 2], 16).unwrap();
                let pos = u32::from_str_radix(&r[b + 8..b + 16], 16).unwrap() as i32;
                (st, pos)
            })
            .collect()
    }

    /// Servo on and home every axis there is, then wait until done.
    fn ready(&mut self, pattern: u8) {
        assert_eq!(self.cmd(&format!("!99232{pattern:02X}1")), "#992322C");
        self.wait(100);
        assert_eq!(self.cmd(&format!("!99233{pattern:02X}000000")), "#992332D");
        self.wait(300);
        assert_eq!(self.c.in_use(), 0);
    }
}

#[test]
fn a_joint_jog_owns_the_whole_scara() {
    let mut s = Sim::new(0);
    s.ready(0x0F);
    // Inch J2 from +90 to +70 deg (each-axis system, negative).
    assert_eq!(s.cmd(&jog(0x02, 50, 20_000, 6)), "#9923630");
    s.wait(3000);
    let st = s.status(0x0F);
    assert_eq!(st[1].1, 70_000);
    assert!(
        st.iter().all(|(b, _)| b & 0x11 == 0x10),
        "inching done on all four: {st:?}"
    );
    // A continuous J1 jog: every SCARA axis is in use.
    assert_eq!(s.cmd(&jog(0x01, 5, 0, 7)), "#9923630");
    s.wait(20);
    let st = s.status(0x0F);
    assert!(st.iter().all(|(b, _)| b & 1 == 1), "in use: {st:?}");
    assert_eq!(
        s.cmd("!9923302000000"),
        err("B03"),
        "home J2 during a J1 jog"
    );
    assert_eq!(
        s.cmd("!99232040"),
        err("B03"),
        "servo off Z during a J1 jog"
    );
    assert_eq!(
        s.cmd("!99232020"),
        err("B03"),
        "servo off J2 during a J1 jog"
    );
    s.wait(20);
    assert_eq!(s.status(0x02)[0].1, 70_000, "J2 stays put");
    // Stop: cancelled on all four.
    assert_eq!(s.cmd("!992380100"), "#9923832");
    s.wait(2000);
    let st = s.status(0x0F);
    assert!(
        st.iter().all(|(b, _)| b & 0x11 == 0),
        "cancelled on all four: {st:?}"
    );
}

#[test]
fn home_or_servo_of_a_scara_axis_waits_for_the_others() {
    let mut s = Sim::new(0);
    s.ready(0x0F);
    assert_eq!(s.cmd("!9923301000000"), "#992332D");
    assert_eq!(s.cmd("!9923302000000"), err("B03"), "J1 homing");
    assert_eq!(s.cmd("!99232080"), err("B03"), "J1 homing");
    s.wait(300);
    assert_eq!(s.cmd("!9923302000000"), "#992332D");
}

#[test]
fn speed_change_refuses_scara_axes() {
    let mut s = Sim::new(1);
    s.ready(0x1F);
    for pattern in ["01", "0F", "11"] {
        assert_eq!(
            s.cmd(&format!("!99262{pattern}0064")),
            err("A04"),
            "{pattern}"
        );
    }
    assert_eq!(s.cmd("!99262100064"), err("CC1"), "axis 5 idle");
    // Axis 5 to 300 mm: its speed can change.
    assert_eq!(s.cmd("!9923410000000000064000493E0"), "#992342E");
    s.wait(50);
    assert_eq!(s.cmd("!99262100032"), "#992622F");
}

#[test]
fn a_reset_without_reply_is_not_counted_as_a_reply() {
    let mut setup = SimSetup::default();
    setup.config.reset_replies = false;
    let mut s = Sim {
        c: Controller::new(setup),
        t: Duration::ZERO,
    };
    assert_eq!(s.cmd("!99215"), "#9921510000000000060004");
    assert_eq!(s.cmd("!99999"), err("A01"));
    assert_eq!(s.cmd("!9925B"), "", "no reply before the reboot");
    assert_eq!(s.cmd("!99215"), "", "rebooting");
    let n = *s.c.counters();
    assert_eq!((n.frames, n.replies, n.errors), (4, 1, 1), "{n:?}");
    assert_eq!((n.resets, n.silent_reset, n.silent_rebooting), (1, 1, 1));
    assert_eq!(n.frames, n.replies + n.errors + n.silent(), "{n:?}");
}

#[test]
fn a_jog_into_the_limit_it_sits_at_is_refused() {
    let mut s = Sim::new(1);
    s.ready(0x1F);
    // Axis 5 homes to 0 mm, its lower limit.
    assert_eq!(s.cmd(&jog(0x10, 10, 0, 0)), err("C74"), "axis 5 negative");
    assert_eq!(s.c.in_use(), 0);
    assert_eq!(s.cmd(&jog(0x10, 10, 0, 1)), "#9923630", "axis 5 positive");
    assert_eq!(s.cmd("!992381000"), "#9923832");
    s.wait(1000);
    // J1 jogged to its upper limit, then again.
    assert_eq!(s.cmd(&jog(0x01, 100, 0, 7)), "#9923630");
    s.wait(20_000);
    assert_eq!(s.c.in_use(), 0);
    assert_eq!(s.cmd(&jog(0x01, 100, 0, 7)), err("C74"), "J1 at its limit");
}

#[test]
fn a_scara_jog_waits_for_the_linear_axes() {
    let mut s = Sim::new(1);
    s.ready(0x1F);
    // Axis 5 to 300 mm at 100 mm/s.
    assert_eq!(s.cmd("!9923410000000000064000493E0"), "#992342E");
    s.wait(50);
    assert_eq!(s.cmd(&jog(0x01, 10, 1_000, 7)), err("B03"), "joint inching");
    assert_eq!(
        s.cmd(&jog(0x01, 10, 1_000, 1)),
        err("B03"),
        "base X inching"
    );
    s.wait(5000);
    assert_eq!(s.cmd(&jog(0x01, 10, 1_000, 7)), "#9923630");
}

#[test]
fn the_receive_limit_follows_the_reply_buffer() {
    // A 200H frame of `len` bytes with CR LF.
    let long = |len: usize| format!("!99200{}", "0".repeat(len - 10));
    for (buffer, limit) in [(1024, 1023), (2048, 2051)] {
        let mut setup = SimSetup::default();
        setup.config.reply_buffer = buffer;
        let mut s = Sim {
            c: Controller::new(setup),
            t: Duration::ZERO,
        };
        assert_ne!(s.cmd(&long(limit)), "", "{limit} bytes fit {buffer}");
        assert_eq!(s.cmd(&long(limit + 1)), "", "{} bytes overflow", limit + 1);
        assert_eq!(s.c.counters().silent_other, 1);
    }
}
