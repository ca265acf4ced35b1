//! A long seeded run: 10,000 random valid and invalid commands into the sans-IO
//! controller, with time passing and control-API events between them. Nothing panics, the
//! state stays coherent, and every reply is a frame the protocol decoder accepts.

use std::time::Duration;

use xsel_pendant::protocol::{Frame, Reply};
use xsel_pendant::sim::faults::SplitMix64;
use xsel_pendant::sim::{Controller, Mode, SimSetup};

use crate::wire::sc;

fn pick<'a>(rng: &mut SplitMix64, items: &[&'a str]) -> &'a str {
    items[rng.range(0, items.len())]
}

fn delta(rng: &mut SplitMix64, max_um: i32) -> String {
    let v = rng.range(0, (2 * max_um + 1) as usize) as i32 - max_um;
    format!("{:08X}", v as u32)
}

/// A random command body (without SC), mostly well-formed.
fn command(rng: &mut SplitMix64) -> String {
    let pattern = pick(
        rng,
        &[
            "0F", "01", "02", "04", "08", "03", "10", "30", "FF", "00", "1F",
        ],
    );
    let pct = format!("{:04X}", rng.range(0, 120));
    let op = pick(rng, &["02", "03", "0A", "0B", "12", "1A", "00", "22"]);
    match rng.range(0, 22) {
        0 => "!99200ABC".into(),
        1 => "!99201000".into(),
        2 => format!("!99212{pattern}"),
        3 => "!99215".into(),
        4 => format!("!99216{}{:02X}000", rng.range(0, 4), rng.range(0, 4)),
        5 | 6 => format!("!99232{pattern}{}", rng.range(0, 2)),
        7 => format!("!99233{pattern}000000"),
        8 => format!("!99235{pattern}00000000{pct}{}", delta(rng, 100_000)),
        9 => format!(
            "!99236{}00000000{:04X}{:08X}{:X}",
            pick(rng, &["01", "02", "04", "08", "10", "03"]),
            rng.range(0, 200),
            if rng.range(0, 2) == 0 {
                0
            } else {
                rng.range(0, 50_000)
            },
            rng.range(0, 8)
        ),
        10 | 11 => format!("!99238{pattern}00"),
        12 => "!99252".into(),
        13 if rng.range(0, 15) == 0 => "!9925B".into(),
        13 => format!("!99232{pattern}1"),
        14 => format!("!99262{pattern}{pct}"),
        15 => format!(
            "!992A0{}{:02X}{:02X}",
            rng.range(0, 3),
            rng.range(0, 140),
            rng.range(0, 255)
        ),
        16 => format!("!992A1{pattern}{}", rng.range(0, 4)),
        17 => format!("!992A3{pattern}{:02X}", rng.range(0, 4)),
        18 => format!(
            "!992A4{}{}{:02X}{:02X}",
            pick(rng, &["0F", "F0", "FF"]),
            rng.range(0, 2),
            rng.range(0, 130),
            rng.range(0, 255)
        ),
        19 => {
            let n = u8::from_str_radix(pattern, 16).unwrap_or(0).count_ones();
            let values: String = (0..n).map(|_| delta(rng, 150_000)).collect();
            format!("!992D5{pattern}{pct}{pct}{pct}{op}{values}")
        }
        20 => {
            let values: String = (0..4).map(|_| delta(rng, 400_000)).collect();
            format!("!992D40F00000000{pct}{op}{values}")
        }
        _ => format!("!992D60F000000000000{op}{:04X}", rng.range(0, 14)),
    }
}

/// Breaks a frame in one of many ways (or not at all).
fn mangle(rng: &mut SplitMix64, mut f: Vec<u8>) -> Vec<u8> {
    match rng.range(0, 12) {
        0 => {
            let i = rng.range(0, f.len());
            f[i] = (rng.next_u64() & 0x7F) as u8;
        }
        1 => f.truncate(rng.range(0, f.len())),
        2 => {
            let i = rng.range(1, f.len() - 2);
            f.remove(i);
        }
        3 => {
            f = (0..rng.range(0, 40))
                .map(|_| (rng.next_u64() & 0xFF) as u8)
                .collect()
        }
        4 => {
            let n = f.len();
            f[n - 4] = b'@';
            f[n - 3] = b'@';
        }
        _ => {}
    }
    f
}

#[test]
fn ten_thousand_random_commands_keep_the_controller_coherent() {
    let mut setup = SimSetup::default();
    setup.config.linear_axes = 2;
    setup.config.servo_switch_time = Duration::from_millis(20);
    setup.config.homing_time = Duration::from_millis(60);
    setup.config.reboot_time = Duration::from_millis(100);
    let mut c = Controller::new(setup);
    let mut rng = SplitMix64::new(20240315);
    let mut now = Duration::ZERO;
    let mut out = Vec::new();
    let (mut replies, mut errors) = (0u64, 0u64);
    for n in 0..10_000 {
        now += Duration::from_micros(rng.range(0, 40_000) as u64);
        c.advance(now);
        match rng.range(0, 1000) {
            0 => c.set_emergency_stop(true),
            1 | 2 => c.set_emergency_stop(false),
            3 => c.set_mode(Mode::Manual),
            4 | 5 => c.set_mode(Mode::Auto),
            6 => c.raise_alarm(0xD0A, Some(rng.range(1, 7) as u8), "random alarm"),
            7 => {
                c.select_work(rng.range(0, 40));
            }
            8 => {
                c.select_tool(rng.range(0, 140));
            }
            _ => {}
        }
        let body = command(&mut rng);
        let framed = format!("{body}{}\r\n", sc(&body)).into_bytes();
        let framed = mangle(&mut rng, framed);
        if c.handle_into(&framed, now, &mut out) {
            let frame = Frame::parse(&out).unwrap_or_else(|e| {
                panic!(
                    "#{n}: reply {:?} is not a frame: {e}",
                    String::from_utf8_lossy(&out)
                )
            });
            let reply = Reply::decode(&frame).unwrap_or_else(|e| {
                panic!(
                    "#{n}: the protocol decoder refuses the reply {:?} to {:?}: {e}",
                    String::from_utf8_lossy(&out),
                    String::from_utf8_lossy(&framed)
                )
            });
            if matches!(reply, Reply::Error(_)) {
                errors += 1;
            } else {
                replies += 1;
            }
        }
        if let Err(e) = c.check_invariants() {
            panic!("#{n}: after {:?}: {e}", String::from_utf8_lossy(&framed));
        }
    }
    let k = *c.counters();
    assert_eq!(k.frames, 10_000);
    assert_eq!(k.replies, replies);
    assert_eq!(k.errors, errors);
    assert_eq!(k.frames, k.replies + k.errors + k.silent(), "{k:?}");
    assert_eq!(k.motion_received, k.motion_started + k.motion_refused);
    // The run exercised the interesting paths.
    assert!(
        k.motion_started > 50 && k.motion_completed > 20 && k.motion_cancelled > 5,
        "{k:?}"
    );
    assert!(
        k.silent_checksum > 100 && errors > 1000 && replies > 1000,
        "{k:?}"
    );
}
