//! The alarm history's reads on a virtual clock, the link's events made by hand; and
//! against the simulator's controller through the pendant.

use std::time::{Duration, Instant, SystemTime};

use super::*;
use crate::link::{NotSentReason, Origin, RequestId};

fn reply(query: ErrorDetailQuery, code: u16) -> LinkEvent {
    let mut d = ErrorDetail {
        error: ErrorCode(code),
        ..Default::default()
    };
    d.details[1] = 7;
    d.details[2] = 1;
    LinkEvent::Reply {
        id: RequestId(1),
        origin: Origin::User,
        command: Command::ErrorDetail(query),
        reply: Reply::ErrorDetail(d),
        round_trip: Duration::from_millis(2),
    }
}

fn asked(a: &mut Alarms) -> Vec<u16> {
    a.take_commands()
        .iter()
        .map(|c| match c {
            Command::ErrorDetail(q) => ListKind::record_of(q).unwrap(),
            other => panic!("{other:?}"),
        })
        .collect()
}

#[test]
fn records_are_read_one_by_one_until_error_000() {
    let mut a = Alarms::default();
    assert_eq!(a.apply(AlarmsIntent::Read, true), None);
    for (n, code) in [(1, 0xB0A), (2, 0xC74)] {
        assert_eq!(asked(&mut a), [n]);
        assert_eq!(a.handle_event(&reply(a.kind.query(n), code)), None);
    }
    assert_eq!(asked(&mut a), [3]);
    let said = a.handle_event(&reply(a.kind.query(3), 0)).unwrap();
    assert_eq!(said, (Level::Info, "alarm history: 2 record(s)".to_owned()));
    assert_eq!(a.records().len(), 2);
    assert_eq!(a.reading(), None);
    assert!(asked(&mut a).is_empty());
    let csv = to_csv(a.records());
    assert!(
        csv.contains("\r\n1,B0A,position number holds no data"),
        "{csv}"
    );
    assert!(csv.contains(",7,1,0,"), "step 7, axis 1: {csv}");
}

#[test]
fn a_refusal_half_way_ends_the_list_and_one_at_record_1_says_try_the_other_type() {
    let mut a = Alarms::default();
    a.connected();
    asked(&mut a);
    a.handle_event(&reply(a.kind.query(1), 0xB01));
    asked(&mut a);
    let refused = |n: u16| LinkEvent::ErrorReply {
        id: RequestId(2),
        origin: Origin::User,
        command: Command::ErrorDetail(ListKind::Type3.query(n)),
        code: ErrorCode(0xA03),
    };
    let said = a.handle_event(&refused(2));
    assert_eq!(said, None, "the end of the list, read on connect: not news");
    assert!(a.outcome.as_ref().unwrap().1.contains("taken as the end"));
    assert_eq!(a.records().len(), 1);
    a.apply(AlarmsIntent::Read, true);
    asked(&mut a);
    let (level, text) = a.handle_event(&refused(1)).unwrap();
    assert_eq!(level, Level::Warning);
    assert!(text.contains("try the other list type"), "{text}");
}

#[test]
fn a_list_longer_than_the_bound_stops_there_and_silence_gives_up_after_three() {
    let mut a = Alarms::default();
    a.apply(AlarmsIntent::Read, true);
    for n in 1..=MAX_TYPE_3 {
        assert_eq!(asked(&mut a), [n]);
        a.handle_event(&reply(a.kind.query(n), 0xB01));
    }
    assert!(asked(&mut a).is_empty(), "never past record 255");
    assert_eq!(a.records().len(), 255);
    assert!(
        a.outcome
            .as_ref()
            .unwrap()
            .1
            .contains("the most this list type can name")
    );

    a.apply(AlarmsIntent::Kind(ListKind::Type5), true);
    a.apply(AlarmsIntent::Read, true);
    assert_eq!(
        a.take_commands(),
        [Command::ErrorDetail(ErrorDetailQuery::ExtendedListRecord {
            record: 1
        })]
    );
    for n in 1..=3 {
        a.handle_event(&LinkEvent::Timeout {
            id: RequestId(3),
            origin: Origin::User,
            command: Command::ErrorDetail(ListKind::Type5.query(n)),
            retrying: false,
            recheck: None,
            at: Instant::now(),
        });
    }
    assert_eq!(a.reading(), None);
    assert_eq!(a.records().len(), 3);
    assert!(a.records().iter().all(|r| r.detail.is_err()));
    assert!(a.outcome.as_ref().unwrap().1.contains("3 records in a row"));
}

#[test]
fn answers_to_a_read_begun_again_or_not_sent_are_handled() {
    let mut a = Alarms::default();
    a.apply(AlarmsIntent::Read, true);
    asked(&mut a);
    a.handle_event(&reply(a.kind.query(1), 0xB01));
    asked(&mut a);
    // Begun again: record 2's late answer is not this read's.
    a.apply(AlarmsIntent::Read, true);
    assert_eq!(a.handle_event(&reply(a.kind.query(2), 0xB02)), None);
    assert!(a.records().is_empty());
    let said = a.handle_event(&LinkEvent::NotSent {
        id: RequestId(4),
        command: Command::ErrorDetail(a.kind.query(1)),
        reason: NotSentReason::LineDown,
    });
    assert!(said.unwrap().1.contains("not sent"));
    assert_eq!(
        a.apply(AlarmsIntent::Read, false).unwrap().0,
        Level::Warning
    );
}

#[test]
fn a_live_alarm_is_stamped_and_the_history_read_again() {
    let mut a = Alarms::default();
    let t0 = Instant::now();
    a.alarm_arrived(ErrorCode(0xB0A), t0, SystemTime::UNIX_EPOCH, 41);
    assert_eq!(a.live().len(), 1);
    assert_eq!(a.live()[0].row, 41);
    assert_eq!(asked(&mut a), [1]);
    for i in 0..MAX_LIVE as u64 + 5 {
        a.alarm_arrived(ErrorCode(0xB01), t0, SystemTime::UNIX_EPOCH, i);
    }
    assert_eq!(a.live().len(), MAX_LIVE, "bounded");
    assert_eq!(asked(&mut a), Vec::<u16>::new(), "one read at a time");
}

#[test]
fn through_the_pendant_two_alarms_provoked_on_the_simulator_are_in_the_history() {
    use crate::pendant::sim_bench::{Bench, Fault};
    let mut b = Bench::new(crate::sim::SimSetup::default());
    // Read on connect: the simulator's history starts empty.
    b.pump(|_| Fault::Pass);
    assert_eq!(b.p.alarms.reading(), None);
    assert!(b.p.alarms.records().is_empty());
    for (code, axis) in [(0xC74, Some(2)), (0xB07, None)] {
        b.sim.raise_alarm(code, axis, "provoked by the test");
        b.poll();
        b.pump(|_| Fault::Pass);
        b.sim.reset_alarm();
        b.poll();
        b.pump(|_| Fault::Pass);
    }
    let live: Vec<u16> = b.p.alarms.live().iter().map(|l| l.code.0).collect();
    assert_eq!(live, [0xC74, 0xB07]);
    let codes: Vec<(u16, u32)> =
        b.p.alarms
            .records()
            .iter()
            .map(|r| {
                let d = r.detail.as_ref().unwrap();
                (d.error.0, d.details[2])
            })
            .collect();
    assert_eq!(
        codes,
        [(0xB07, 0), (0xC74, 2)],
        "newest first, the axis in detail 3"
    );
    assert!(
        b.p.messages
            .iter()
            .all(|m| !m.text.contains("alarm history")),
        "reads on connect and after an alarm are not news"
    );
}
