//! The embedded simulator: a thread behind the in-memory pipe, with its control API,
//! counters and fault injection.

use std::io::{Read, Write};
use std::time::{Duration, Instant};

use xsel_pendant::sim::pipe::PipeEnd;
use xsel_pendant::sim::runner::Dir;
use xsel_pendant::sim::{EmbeddedOptions, Fault, FaultSpec, Mode, start_embedded};

fn frame(body: &str) -> Vec<u8> {
    let sc = body.bytes().fold(0u8, |s, b| s.wrapping_add(b));
    format!("{body}{sc:02X}\r\n").into_bytes()
}

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
    let w = Duration::from_secs(1);
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
    assert_eq!(ask(&mut pipe, "!99215", Duration::from_millis(100)), None);
    assert_eq!(sim.fault_counts().drop, 1);
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
    std::thread::sleep(Duration::from_millis(50));
    assert!(
        !sim.is_running(),
        "the thread ends when the pendant's end is dropped"
    );
    sim.join();
}
