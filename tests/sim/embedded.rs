//! The embedded simulator: a thread behind the in-memory pipe, with its control API,
//! counters and fault injection.

use std::io::{Read, Write};
use std::time::{Duration, Instant};

use std::sync::{Arc, Mutex};
use xsel_pendant::sim::pipe::PipeEnd;

use xsel_pendant::sim::framing::Silence;
use xsel_pendant::sim::runner::{Dir, format_entry};
use xsel_pendant::sim::{EmbeddedOptions, Fault, FaultSpec, Mode, start_embedded};

use crate::wait::{LONG, eventually};
use crate::wire::frame;

fn ask(pipe: &mut PipeEnd, body: &str, wait: Duration) -> Option<String> {
    pipe.write_all(&frame(body)).unwrap();
    let deadline = Instant::now() + wait;
    let mut got = Vec::new();
    let mut buf = [0u8; 256];
    while !got.ends_with(b"\n") && Instant::now() < deadline {
        if let Ok(n) = pipe.read(&mut buf) {
            got.extend_from_slice(&buf[..n]);
        }
    }
    (!got.is_empty()).then(|| String::from_utf8_lossy(&got).into_owned())
}

#[test]
fn embedded_simulator_answers_and_reports() {
    let mut opts = EmbeddedOptions::default();
    opts.setup.config.start_ready = true;
    opts.read_timeout = Duration::from_millis(10);
    let (mut pipe, sim) = start_embedded(opts);
    let w = LONG;
    assert_eq!(
        ask(&mut pipe, "!99215", w).as_deref(),
        Some("#9921510000000000060004\r\n")
    );
    let mv = format!("!992D50100000000000002{:08X}", 1_000);
    assert!(ask(&mut pipe, &mv, w).unwrap().starts_with("#992D5"));
    sim.set_mode(Mode::Manual);
    assert!(ask(&mut pipe, &mv, w).unwrap().starts_with("&99B05"));
    sim.set_mode(Mode::Auto);
    let n = sim.counters();
    assert_eq!(
        (n.motion_received, n.motion_started, n.motion_refused),
        (2, 1, 1)
    );
    // Every reply dropped: no answer, and the drop is counted.
    sim.set_faults(FaultSpec::none().with(Fault::Drop, 1.0));
    pipe.write_all(&frame("!99215")).unwrap();
    assert!(
        eventually(LONG, || sim.fault_counts().drop == 1),
        "the drop is counted"
    );
    // The drop is decided before anything is written: no byte of that reply will come.
    assert_eq!(pipe.bytes_waiting(), 0, "a dropped reply sends nothing");
    sim.set_faults(FaultSpec::none());
    assert!(ask(&mut pipe, "!99215", w).is_some());
    let traffic = sim.traffic();
    assert!(
        traffic
            .iter()
            .any(|t| t.dir == Dir::In && t.bytes == frame(&mv))
    );
    assert!(traffic.iter().any(|t| t.fault == Some("drop")));
    assert!(sim.is_running());
    drop(pipe);
    assert!(
        eventually(LONG, || !sim.is_running()),
        "the thread ends when the pendant's end is dropped"
    );
    sim.join();
}

#[test]
fn every_frame_in_is_logged_with_the_reason_of_a_silence() {
    let lines = Arc::new(Mutex::new(Vec::<String>::new()));
    let sink = lines.clone();
    let opts = EmbeddedOptions {
        read_timeout: Duration::from_millis(10),
        log: Some(Box::new(move |e| {
            sink.lock().unwrap().push(format_entry(e))
        })),
        ..EmbeddedOptions::default()
    };
    let (mut pipe, sim) = start_embedded(opts);
    pipe.write_all(b"#992152D\r\nhello\r\n!99215FF\r\nzz!99215")
        .unwrap();
    let r = ask(&mut pipe, "!99215", LONG);
    assert_eq!(r.as_deref(), Some("#9921510000000000060004\r\n"));
    let ins: Vec<(Vec<u8>, Option<Silence>)> = sim
        .traffic()
        .into_iter()
        .filter(|t| t.dir == Dir::In)
        .map(|t| (t.bytes, t.silence))
        .collect();
    let want: Vec<(&[u8], Option<Silence>)> = vec![
        (b"#992152D\r\n", Some(Silence::Header)),
        (b"hello\r\n", Some(Silence::Header)),
        (b"!99215FF\r\n", Some(Silence::Checksum)),
        (b"zz", Some(Silence::Header)),
        (b"!99215", Some(Silence::Terminator)),
        (b"!992152B\r\n", None),
    ];
    let want: Vec<(Vec<u8>, Option<Silence>)> =
        want.into_iter().map(|(b, s)| (b.to_vec(), s)).collect();
    assert_eq!(ins, want);
    let n = sim.counters();
    assert_eq!(n.frames, 6);
    assert_eq!(
        (n.silent_header, n.silent_checksum, n.silent_terminator),
        (3, 1, 1)
    );
    assert_eq!(n.frames, n.replies + n.errors + n.silent(), "{n:?}");
    // The reply is logged once written: it may reach us first.
    eventually(LONG, || lines.lock().unwrap().len() >= 7);
    let lines = lines.lock().unwrap();
    assert_eq!(lines.len(), 7, "six in, one out: {lines:#?}");
    assert!(
        lines[0].contains(" rx #992152D\\r\\n") && lines[0].contains("[silent: no '!' header]")
    );
    assert!(
        lines[2].contains("[silent: wrong checksum]"),
        "{}",
        lines[2]
    );
    assert!(!lines[5].contains("silent") && lines[6].contains(" tx "));
}
