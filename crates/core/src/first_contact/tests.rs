//! The first-contact run on a virtual clock: against the simulator's controller, a
//! silent line, an echoing line, a late reply and a flood.

use std::time::{Duration, Instant, SystemTime};

use super::*;
use crate::protocol::{Command, Frame};
use crate::sim::{Controller, SimSetup};

const STATION: Station = Station(0x99);
const BYTE: Duration = Duration::from_micros(87); // 115200 8N1

/// Drives a run to its end on a virtual clock; `answer` maps each command to what
/// comes back and when (after it was sent).
fn drive(mut answer: impl FnMut(&[u8]) -> Vec<(Duration, Vec<u8>)>) -> Vec<Exchange> {
    let mut now = Instant::now();
    let mut run = FirstContact::new(STATION, BYTE, now);
    let mut due: Vec<(Instant, Vec<u8>)> = Vec::new();
    for _ in 0..10_000 {
        if let Some(bytes) = run.poll_transmit(now) {
            due.extend(answer(&bytes).into_iter().map(|(d, b)| (now + d, b)));
            due.sort_by_key(|(t, _)| *t);
        }
        if run.is_done() {
            return run.exchanges().to_vec();
        }
        let timeout = run.poll_timeout().expect("a run not done has a time-out");
        match due.first() {
            Some((t, _)) if *t <= timeout => {
                let (t, bytes) = due.remove(0);
                now = now.max(t);
                run.handle_input(now, &bytes);
            }
            _ => {
                now = now.max(timeout);
                run.handle_timeout(now);
            }
        }
    }
    panic!("the run never ended");
}

fn simulator() -> impl FnMut(&[u8]) -> Vec<(Duration, Vec<u8>)> {
    let mut sim = Controller::new(SimSetup::for_model(
        crate::robot::RobotModel::default_model(),
    ));
    let mut t = Duration::ZERO;
    move |bytes| {
        t += Duration::from_millis(50);
        sim.handle(bytes, t)
            .map(|r| vec![(Duration::from_millis(3), r)])
            .unwrap_or_default()
    }
}

fn header() -> ReportHeader {
    ReportHeader {
        written: SystemTime::UNIX_EPOCH,
        pendant: "test".into(),
        line: "virtual line".into(),
        settings: "115200 8N1".into(),
        station: STATION,
    }
}

#[test]
fn only_queries_are_asked_in_the_documented_layouts() {
    // PROTOCOL.md 3.50 and 3.4's frames, byte for byte.
    let sent: Vec<String> = QUESTIONS
        .iter()
        .map(|q| String::from_utf8(q.ask.bytes(STATION)).unwrap())
        .collect();
    for example in [
        "!992152B\r\n",
        "!99213018A\r\n",
        "!992A20101FA\r\n",
        "!9921630100050\r\n",
        "!9921650000152\r\n",
        "!9920E000C802A7\r\n",
        "!9920F0012C01A2\r\n",
        "!992A30F000F\r\n",
        "!99215@@\r\n",
    ] {
        assert!(sent.iter().any(|s| s == example), "{example:?} not asked");
    }
    // Nothing that moves, powers or writes: every frame the pendant can read is a
    // query; the one it refuses to read is the over-size 22DH, a query by its ID.
    for q in QUESTIONS {
        let bytes = q.ask.bytes(STATION);
        let frame = Frame::parse(&bytes).expect("a valid frame");
        match Command::decode(&frame) {
            Ok(c) => {
                assert!(!c.is_motion() && !c.writes_data(), "{c:?} is not a query");
                assert!(!matches!(c, Command::Program(_) | Command::Stop(_)));
            }
            Err(_) => assert!(q.ask.id == 0x22D, "{:?} cannot be read back", q.ask),
        }
    }
}

#[test]
fn the_simulator_answers_every_question_and_the_report_says_so() {
    let exchanges = drive(simulator());
    assert_eq!(exchanges.len(), QUESTIONS.len());
    for e in &exchanges {
        assert!(
            matches!(e.answer, Answer::Reply(_) | Answer::Refused(_)),
            "{} got {:?}",
            e.question().title,
            e.answer
        );
        assert!(
            e.received.iter().all(|r| r.kind == ReceivedKind::Answer),
            "{:?}",
            e.received
        );
    }
    let text = render(&header(), &exchanges);
    assert!(text.contains("- 215H: 5 of 5 answered"), "{text}");
    assert!(text.contains("its reply carries a real SC"), "{text}");
    assert!(text.contains("`@@` is accepted"), "{text}");
    assert!(text.contains("200H echoes"), "{text}");
    assert!(text.contains("The 10 characters") || text.contains("(10 characters)"));
    assert!(text.contains("22DH position data with arm systems: position 1: answered"));
    assert!(text.contains("real 300 reads"), "{text}");
    assert!(text.contains("nothing follows coordinate 2"), "{text}");
    // Every frame is listed, in order, with its direction.
    let sent = text.matches("  ->  !99").count();
    let got = text.matches("  <-  ").count();
    assert_eq!(sent, QUESTIONS.len());
    assert_eq!(got, QUESTIONS.len());
}

#[test]
fn a_silent_line_ends_after_three_status_queries() {
    let exchanges = drive(|_| Vec::new());
    assert_eq!(exchanges.len(), QUESTIONS.len());
    assert!(
        exchanges[..3]
            .iter()
            .all(|e| e.answer == Answer::Silent && !e.sent.is_empty())
    );
    assert!(exchanges[3..].iter().all(|e| e.sent.is_empty()
        && matches!(&e.answer, Answer::NotAsked(why) if why.contains("answered none"))));
    let text = render(&header(), &exchanges);
    assert!(text.contains("none of 3 answered"), "{text}");
}

#[test]
fn an_echoing_line_and_a_late_reply_are_told_apart_from_the_answer() {
    let mut sim = simulator();
    let mut first = true;
    let exchanges = drive(move |bytes| {
        let mut out = vec![(Duration::from_millis(1), bytes.to_vec())];
        let replies = sim(bytes);
        if first {
            // The first reply comes long after its wait: it is late, not the answer
            // to the second status query.
            first = false;
            out.extend(
                replies
                    .into_iter()
                    .map(|(_, r)| (Duration::from_millis(1300), r)),
            );
        } else {
            out.extend(replies);
        }
        out
    });
    assert_eq!(exchanges[0].answer, Answer::Silent);
    assert!(
        exchanges[0]
            .received
            .iter()
            .any(|r| r.kind == ReceivedKind::Late)
    );
    assert!(matches!(exchanges[1].answer, Answer::Reply(_)));
    assert_eq!(exchanges[1].received[0].kind, ReceivedKind::Echo);
    let text = render(&header(), &exchanges);
    assert!(text.contains("the line echoed the command back"));
    assert!(text.contains("- 215H: 4 of 5 answered"), "{text}");
}

#[test]
fn a_flood_is_counted_not_kept() {
    let exchanges = drive(|_| {
        (0..100)
            .map(|i| (Duration::from_millis(i), vec![b'x'; 1000]))
            .collect()
    });
    for e in exchanges.iter().filter(|e| !e.sent.is_empty()) {
        let kept: usize = e.received.iter().map(|r| r.bytes.len()).sum();
        assert!(kept <= KEEP_BYTES, "{kept}");
    }
    assert!(exchanges[0].dropped > 0);
    let text = render(&header(), &exchanges);
    assert!(text.contains("more bytes arrived than are kept"));
}

#[test]
fn a_zone_record_is_sized_from_the_reply_length_with_its_tail_shown() {
    // PROTOCOL.md 3.46's example: records end after coordinate 2.
    let read = |text: &str| {
        let bytes = format!("{text}\r\n").into_bytes();
        match crate::protocol::Reply::decode(&Frame::parse(&bytes).unwrap()).unwrap() {
            crate::protocol::Reply::ZoneTable(t) => t,
            other => panic!("{other:?}"),
        }
    };
    let said = probes::zone_record(&read(
        "#992A2010107000186A0FFFE79600000000000030D40000186A00000C35046",
    ));
    assert!(said.contains("1 record(s) of 50 characters"), "{said}");
    assert!(said.contains("nothing follows coordinate 2"), "{said}");
    // The same record with a 4-character tail (an output number, say).
    let tail = "#992A2010107000186A0FFFE79600000000000030D40000186A00000C350012C";
    let sc = crate::protocol::checksum(tail.as_bytes());
    let said = probes::zone_record(&read(&format!("{tail}{sc:02X}")));
    assert!(said.contains("4 more character(s)"), "{said}");
    assert!(said.contains("`012C`"), "{said}");
}
