//! The signals watched, forced and edited against the simulator's controller, sans-IO,
//! on a virtual clock; bad input landing on the rows concerned.

use std::time::Duration;

use super::*;
use crate::link::NotSentReason;
use crate::pendant::sim_bench::{Bench, Fault};
use crate::pendant::{Intent, Request, StopCause};
use crate::protocol::{BitQuery, VarQuery};
use crate::sim::SimSetup;

fn bench() -> Bench {
    let mut b = Bench::new(SimSetup::default());
    b.apply(SignalsIntent::Watch(true));
    b
}

/// A line up and a controller ready, no program running.
fn ready() -> SignalsCx {
    SignalsCx {
        ready: Ok(()),
        program_running: Some(false),
        io_interlock: false,
    }
}

fn sig(kind: SignalKind, number: u16) -> Signal {
    Signal::new(kind, 0, number)
}

/// One round: the pendant's tick asks for its reads, the simulator answers them.
fn round(b: &mut Bench) {
    b.t += MIN_ROUND;
    let now = b.now();
    b.p.tick(now);
    b.pump(|_| Fault::Pass);
}

fn value(b: &Bench, s: Signal) -> Option<Value> {
    b.p.signals.state(&s).and_then(|st| st.value.clone())
}

fn said(b: &Bench) -> Vec<String> {
    b.p.messages.iter().map(|m| m.text.clone()).collect()
}

fn add(b: &mut Bench, signal: Signal, name: &str) {
    b.apply(SignalsIntent::Add {
        signal,
        count: 1,
        name: name.into(),
        chars: 8,
    });
}

#[test]
fn the_default_list_is_read_in_three_spare_requests_a_round() {
    let mut b = bench();
    b.t += MIN_ROUND;
    let now = b.now();
    b.p.tick(now);
    let requests = b.p.take_requests();
    let spare: Vec<&Command> = requests
        .iter()
        .filter_map(|r| match r {
            Request::Spare(c) => Some(c),
            _ => None,
        })
        .collect();
    assert_eq!(spare.len(), 3, "{requests:?}");
    assert!(matches!(
        spare[1],
        Command::BitQuery(BitQuery {
            space: BitSpace::Output,
            start: 300,
            count: 32,
            ..
        })
    ));
    // No new round while this one is unanswered, however many frames pass.
    b.t += Duration::from_secs(1);
    let now = b.now();
    b.p.tick(now);
    assert!(b.p.take_requests().is_empty());
}

#[test]
fn an_input_set_on_the_simulator_shows_within_one_round_and_is_counted() {
    let mut b = bench();
    round(&mut b);
    let input = sig(SignalKind::Input, 3);
    assert_eq!(value(&b, input), Some(Value::Bit(false)));
    b.sim.signals_mut().set_input(3, true).unwrap();
    round(&mut b);
    assert_eq!(value(&b, input), Some(Value::Bit(true)));
    let st = b.p.signals.state(&input).unwrap();
    assert_eq!(st.changes, 1);
    assert!(
        st.changed_at
            .is_some_and(|t| t > b.now() - MIN_ROUND && t <= b.now())
    );
    assert!(!b.p.signals.is_stale(&input, b.now()));
    assert!(b.p.signals.is_stale(&input, b.now() + STALE_AFTER * 2));
    assert!(b.p.signals.refresh_rate().is_some());
}

#[test]
fn an_output_forced_through_the_confirmation_is_sent_once_and_read_back() {
    let mut b = bench();
    let out = sig(SignalKind::Output, 305);
    b.apply(SignalsIntent::Rename(out, "gripper close".into()));
    round(&mut b);
    b.apply(SignalsIntent::Propose {
        signal: out,
        text: "on".into(),
    });
    let text =
        b.p.signals
            .proposal
            .as_ref()
            .unwrap()
            .text(b.p.signals.encoding);
    assert_eq!(text, "Output 305 'gripper close' OFF -> ON");
    assert!(
        b.p.take_requests().is_empty(),
        "nothing sent before Confirm"
    );
    b.sent.clear();
    b.apply(SignalsIntent::Confirm {
        take_the_risk: false,
    });
    b.pump(|_| Fault::Pass);
    let changes = b
        .sent
        .iter()
        .filter(|c| matches!(c, Command::BitChange(_)))
        .count();
    assert_eq!(changes, 1);
    assert_eq!(b.sim.signals().bit(BitSpace::Output, 0, 305), Some(true));
    assert_eq!(value(&b, out), Some(Value::Bit(true)));
    let all = said(&b);
    assert!(
        all.iter()
            .any(|t| t == "sending Output 305 'gripper close' OFF -> ON"),
        "{all:?}"
    );
    assert!(
        all.iter()
            .any(|t| t == "Output 305 'gripper close' is ON (read back)"),
        "{all:?}"
    );
    assert!(!b.p.signals.change_pending());
}

#[test]
fn an_integer_variable_edited_is_read_back() {
    let mut b = bench();
    let v = sig(SignalKind::Integer, 205);
    add(&mut b, v, "count");
    round(&mut b);
    assert_eq!(value(&b, v), Some(Value::Int(0)));
    b.apply(SignalsIntent::Propose {
        signal: v,
        text: "-42".into(),
    });
    b.apply(SignalsIntent::Confirm {
        take_the_risk: false,
    });
    b.pump(|_| Fault::Pass);
    assert_eq!(b.sim.signals().int(205, 0), Ok(-42));
    assert_eq!(value(&b, v), Some(Value::Int(-42)));
    assert!(
        said(&b)
            .iter()
            .any(|t| t == "Integer 205 'count' is -42 (read back)")
    );
}

#[test]
fn a_real_variable_is_read_in_the_chosen_encoding() {
    let mut b = bench();
    let v = sig(SignalKind::Real, 300);
    add(&mut b, v, "");
    b.sim.signals_mut().set_real(300, 0, 1.5).unwrap();
    round(&mut b);
    let got = value(&b, v).unwrap();
    assert_eq!(got.show(b.p.signals.encoding), "1.5");
    // Read the other way it is a tiny number, and the view says to check the encoding.
    assert!(
        got.show(RealEncoding::WordSwapped)
            .contains("check the real encoding")
    );
}

#[test]
fn bad_input_is_refused_at_the_row_with_the_reason() {
    let mut b = bench();
    b.apply(SignalsIntent::Add {
        signal: sig(SignalKind::Integer, 150),
        count: 1,
        name: String::new(),
        chars: 0,
    });
    let fb = b.p.signals.feedback.clone().unwrap().1;
    assert_eq!(fb, "Integer 150 is not a global integer number: 200-299");
    b.apply(SignalsIntent::Add {
        signal: Signal::new(SignalKind::Flag, 70, 900),
        count: 1,
        name: String::new(),
        chars: 0,
    });
    assert!(
        b.p.signals
            .feedback
            .clone()
            .unwrap()
            .1
            .contains("program 70 does not exist")
    );
    let v = sig(SignalKind::Integer, 200);
    add(&mut b, v, "");
    b.apply(SignalsIntent::Propose {
        signal: v,
        text: "12x".into(),
    });
    assert!(b.p.signals.proposal.is_none());
    assert_eq!(
        b.p.signals.feedback.clone().unwrap().1,
        "Integer 200: `12x` is not an integer from -2147483648 to 2147483647"
    );
    b.apply(SignalsIntent::Propose {
        signal: sig(SignalKind::Input, 3),
        text: "on".into(),
    });
    assert!(b.p.signals.proposal.is_none());
    assert!(
        b.p.signals
            .feedback
            .clone()
            .unwrap()
            .1
            .contains("cannot be changed")
    );
}

#[test]
fn a_refused_group_marks_its_rows_and_the_rest_keeps_updating() {
    let mut b = bench();
    b.t += MIN_ROUND;
    let now = b.now();
    b.p.tick(now);
    // The outputs' read is refused; inputs and flags answer.
    b.pump(|c| match c {
        Command::BitQuery(q) if q.space == BitSpace::Output => Fault::Error(0xA03),
        _ => Fault::Pass,
    });
    let out = sig(SignalKind::Output, 300);
    let st = b.p.signals.state(&out).unwrap();
    let error = st.error.as_deref().unwrap();
    assert!(error.starts_with("refused: error A03"), "{error}");
    assert_eq!(
        value(&b, sig(SignalKind::Input, 0)),
        Some(Value::Bit(false))
    );
    // The next round goes out (the refused read counted as answered) and clears it.
    round(&mut b);
    assert_eq!(b.p.signals.state(&out).unwrap().error, None);
}

#[test]
fn a_change_that_times_out_is_not_sent_again_but_read_back() {
    let mut b = bench();
    let out = sig(SignalKind::Output, 301);
    round(&mut b);
    b.apply(SignalsIntent::Propose {
        signal: out,
        text: "on".into(),
    });
    b.apply(SignalsIntent::Confirm {
        take_the_risk: false,
    });
    b.sent.clear();
    b.pump(|c| match c {
        Command::BitChange(_) => Fault::Timeout,
        _ => Fault::Pass,
    });
    let changes = b
        .sent
        .iter()
        .filter(|c| matches!(c, Command::BitChange(_)))
        .count();
    assert_eq!(changes, 1, "{:?}", b.sent);
    assert!(b.sent.iter().any(|c| matches!(c, Command::BitQuery(_))));
    let all = said(&b);
    assert!(
        all.iter()
            .any(|t| t.contains("no reply to the change (not sent again)"))
    );
    // The simulator never got it: the read-back says the output is still OFF.
    assert!(
        all.iter().any(|t| t.contains("reads OFF, not ON")),
        "{all:?}"
    );
}

#[test]
fn a_running_program_needs_the_risk_taken_and_a_dead_line_refuses() {
    let mut b = bench();
    let out = sig(SignalKind::Output, 302);
    round(&mut b);
    b.apply(SignalsIntent::Propose {
        signal: out,
        text: "on".into(),
    });
    // 215H says a program runs.
    let now = b.now();
    if let Some(s) = b.p.controller.system.as_mut() {
        s.value.status2 = s.value.status2.with_program_running(true);
        s.at = now;
    }
    b.apply(SignalsIntent::Confirm {
        take_the_risk: false,
    });
    assert!(b.p.take_requests().is_empty());
    assert!(
        b.p.signals
            .feedback
            .clone()
            .unwrap()
            .1
            .contains("a program is running")
    );
    assert!(b.p.signals.proposal.as_ref().unwrap().program_running);
    b.apply(SignalsIntent::Confirm {
        take_the_risk: true,
    });
    assert!(
        b.p.take_requests()
            .iter()
            .any(|r| matches!(r, Request::Submit(Command::BitChange(_))))
    );
    // A line that is down refuses with its reason.
    let mut b = bench();
    round(&mut b);
    let now = b.now();
    b.p.disconnect(now);
    b.apply(SignalsIntent::Propose {
        signal: out,
        text: "on".into(),
    });
    b.apply(SignalsIntent::Confirm {
        take_the_risk: false,
    });
    assert!(
        b.p.signals
            .feedback
            .clone()
            .unwrap()
            .1
            .starts_with("not sent:")
    );
    assert!(
        !b.p.take_requests()
            .iter()
            .any(|r| matches!(r, Request::Submit(_)))
    );
}

#[test]
fn stop_forgets_the_proposal_and_drops_a_change_not_yet_sent() {
    let mut b = bench();
    let out = sig(SignalKind::Output, 303);
    round(&mut b);
    b.apply(SignalsIntent::Propose {
        signal: out,
        text: "on".into(),
    });
    b.apply(Intent::Stop(StopCause::Button));
    assert!(b.p.signals.proposal.is_none());
    b.pump(|_| Fault::Pass);
    b.apply(SignalsIntent::Propose {
        signal: out,
        text: "on".into(),
    });
    b.apply(SignalsIntent::Confirm {
        take_the_risk: false,
    });
    b.apply(Intent::Stop(StopCause::Button));
    let requests = b.p.take_requests();
    assert!(
        !requests
            .iter()
            .any(|r| matches!(r, Request::Submit(Command::BitChange(_)))),
        "{requests:?}"
    );
    assert!(!b.p.signals.change_pending());
    assert!(
        said(&b)
            .iter()
            .any(|t| t.ends_with("not sent: STOP came first"))
    );
    // One already with the link is refused there, and said so.
    let mut b = bench();
    round(&mut b);
    b.apply(SignalsIntent::Propose {
        signal: out,
        text: "on".into(),
    });
    b.apply(SignalsIntent::Confirm {
        take_the_risk: false,
    });
    b.pump(|c| match c {
        Command::BitChange(_) => Fault::NotSent(NotSentReason::StopCameFirst),
        _ => Fault::Pass,
    });
    assert!(!b.p.signals.change_pending());
    assert_eq!(b.sim.signals().bit(BitSpace::Output, 0, 303), Some(false));
}

#[test]
fn an_output_held_by_the_io_interlock_is_said_so() {
    let mut b = bench();
    let out = sig(SignalKind::Output, 304);
    b.sim.signals_mut().set_interlock(true);
    b.poll();
    round(&mut b);
    b.apply(SignalsIntent::Propose {
        signal: out,
        text: "on".into(),
    });
    b.apply(SignalsIntent::Confirm {
        take_the_risk: false,
    });
    b.pump(|_| Fault::Pass);
    let all = said(&b);
    assert!(
        all.iter().any(|t| t.contains("held by the I/O interlock")),
        "{all:?}"
    );
}

#[test]
fn plotted_rows_become_series_on_the_plots_clock() {
    let mut b = bench();
    let input = sig(SignalKind::Input, 4);
    b.apply(SignalsIntent::Plot(input, true));
    round(&mut b);
    b.sim.signals_mut().set_input(4, true).unwrap();
    round(&mut b);
    let now = b.now();
    b.p.tick(now);
    let store = &b.p.samples.store;
    let series = store.all().iter().find(|s| s.name == "Input 4").unwrap();
    assert_eq!(series.len(), 2);
    assert_eq!(series.value(1, 0), Some(1.0));
    assert!(series.channels[0].step);
    // No more than MAX_PLOTTED at once.
    for n in 0..MAX_PLOTTED as u16 {
        b.apply(SignalsIntent::Plot(sig(SignalKind::Input, 10 + n), true));
    }
    assert!(b.p.signals.feedback.clone().unwrap().1.contains("at most"));
}

#[test]
fn reads_are_planned_on_the_grid_merged_and_split_at_the_reply_buffer() {
    let rows = |v: &[(SignalKind, u8, u16)]| -> Vec<WatchRow> {
        v.iter()
            .map(|&(k, p, n)| WatchRow::new(Signal::new(k, p, n), ""))
            .collect()
    };
    // Outputs 305 and 322: groups 304 and 320 (grid from 300) are 300-307 and 316-323.
    let plan = plan_reads(&rows(&[
        (SignalKind::Output, 0, 305),
        (SignalKind::Output, 0, 322),
        (SignalKind::Flag, 3, 905),
        (SignalKind::Flag, 0, 905 - 300),
        (SignalKind::Integer, 0, 200),
        (SignalKind::Integer, 0, 203),
        (SignalKind::Integer, 0, 260),
    ]));
    let cmds: Vec<Command> = plan.into_iter().map(|p| p.command).collect();
    assert_eq!(
        cmds,
        vec![
            Command::BitQuery(BitQuery {
                space: BitSpace::Output,
                program: 0,
                start: 300,
                count: 24
            }),
            Command::BitQuery(BitQuery {
                space: BitSpace::Flag,
                program: 0,
                start: 600,
                count: 8
            }),
            Command::BitQuery(BitQuery {
                space: BitSpace::Flag,
                program: 3,
                start: 900,
                count: 8
            }),
            Command::VarQuery(VarQuery {
                kind: VarKind::Integer,
                program: 0,
                start: 200,
                count: 4
            }),
            Command::VarQuery(VarQuery {
                kind: VarKind::Integer,
                program: 0,
                start: 260,
                count: 1
            }),
        ]
    );
    // Every input: one read carries at most what the reply buffer holds; the last
    // group stops at the category's end (296-299, not into the outputs).
    let all: Vec<WatchRow> = (0..300)
        .map(|n| WatchRow::new(sig(SignalKind::Input, n), ""))
        .collect();
    let plan = plan_reads(&all);
    assert_eq!(plan.len(), 1);
    assert!(matches!(
        plan[0].command,
        Command::BitQuery(BitQuery {
            start: 0,
            count: 300,
            ..
        })
    ));
    let reals: Vec<WatchRow> = (300..400)
        .chain(1300..1300)
        .map(|n| WatchRow::new(sig(SignalKind::Real, n), ""))
        .collect();
    assert_eq!(plan_reads(&reals).len(), 1);
}

#[test]
fn a_watch_list_goes_through_csv_and_json_and_a_bad_file_names_its_line() {
    let mut rows = default_rows();
    rows.truncate(3);
    rows[1].name = "pick, left \"A\"".into();
    rows[2].plot = true;
    rows.push(WatchRow {
        chars: 5,
        ..WatchRow::new(sig(SignalKind::Text, 300), "part")
    });
    let (back, enc) = file::parse(file::to_csv(&rows).as_bytes()).unwrap();
    assert_eq!(back, rows);
    assert_eq!(enc, None);
    let json = file::to_json(&rows, RealEncoding::WordSwapped);
    let (back, enc) = file::parse(json.as_bytes()).unwrap();
    assert_eq!(back, rows);
    assert_eq!(enc, Some(RealEncoding::WordSwapped));
    let bad = "Kind,Program,Number,Name,Chars,Plot\r\noutput,0,305,,,\r\nrelay,0,3,,,\r\n";
    let e = file::parse(bad.as_bytes()).unwrap_err().to_string();
    assert_eq!(
        e,
        "line 3, field \"Kind\": `relay` is not input, output, flag, integer, real or string"
    );
    let twice = "Kind,Program,Number\noutput,0,305\noutput,0,305\n";
    assert!(
        file::parse(twice.as_bytes())
            .unwrap_err()
            .to_string()
            .contains("listed twice")
    );
    let off = "Kind,Program,Number\noutput,0,30\n";
    assert!(
        file::parse(off.as_bytes())
            .unwrap_err()
            .to_string()
            .contains("300-599")
    );
    assert!(file::parse(b"\x00\x01binary").is_err());
}

#[test]
fn a_lost_line_ends_the_round_and_says_a_change_is_unknown() {
    let mut b = bench();
    round(&mut b);
    b.t += MIN_ROUND;
    let now = b.now();
    b.p.tick(now);
    let _unanswered = b.p.take_requests();
    b.apply(SignalsIntent::Propose {
        signal: sig(SignalKind::Output, 306),
        text: "on".into(),
    });
    b.apply(SignalsIntent::Confirm {
        take_the_risk: false,
    });
    let _ = b.p.take_requests();
    let now = b.now();
    b.p.disconnect(now);
    assert!(
        said(&b)
            .iter()
            .any(|t| t.contains("line went down before the change"))
    );
    // The next line starts a round at once.
    b.p.handle_event(
        now,
        crate::link::LinkEvent::Connected {
            line: "again".into(),
        },
    );
    round(&mut b);
    assert!(b.sent.iter().any(|c| matches!(c, Command::BitQuery(_))));
}

#[test]
fn a_read_the_link_sends_again_keeps_its_round_open() {
    use crate::link::{LinkEvent, Origin, RequestId};
    let cx = ready();
    let t0 = std::time::Instant::now();
    let mut s = Signals::default();
    s.apply(SignalsIntent::Watch(true), cx.clone(), t0);
    s.tick(t0, true);
    let reads = s.take_commands();
    assert_eq!(reads.len(), 3);
    let timeout = |command: Command, retrying| LinkEvent::Timeout {
        id: RequestId(1),
        origin: Origin::User,
        command,
        retrying,
        recheck: None,
        at: t0,
    };
    s.handle_event(&timeout(reads[0].0.clone(), true), cx.clone(), t0);
    assert_eq!(s.reads_in_flight(), 3, "the retry is still to answer");
    s.handle_event(&timeout(reads[0].0.clone(), false), cx.clone(), t0);
    s.handle_event(&timeout(reads[1].0.clone(), false), cx.clone(), t0);
    let later = t0 + MIN_ROUND * 2;
    s.tick(later, true);
    assert!(s.take_commands().is_empty(), "one read still out");
    s.handle_event(&timeout(reads[2].0.clone(), false), cx.clone(), t0);
    s.tick(later, true);
    assert_eq!(s.take_commands().len(), 3);
    let inputs = s.state(&sig(SignalKind::Input, 0)).unwrap();
    assert!(
        inputs
            .error
            .as_deref()
            .unwrap()
            .starts_with("no valid reply")
    );
}

/// A read of another group between a change's reply and its read-back says nothing of
/// the change: only the read that carries it does.
#[test]
fn only_the_read_that_carries_a_changed_signal_judges_the_change() {
    use crate::link::{LinkEvent, Origin, RequestId};
    use crate::protocol::{BitData, Reply};
    let cx = ready();
    let t0 = std::time::Instant::now();
    let mut s = Signals::default();
    let reply = |command: Command, reply: Reply| LinkEvent::Reply {
        id: RequestId(1),
        origin: Origin::User,
        command,
        reply,
        round_trip: Duration::from_millis(5),
    };
    let out = sig(SignalKind::Output, 300);
    // The output was read OFF.
    let outputs = BitQuery {
        space: BitSpace::Output,
        program: 0,
        start: 300,
        count: 32,
    };
    s.handle_event(
        &reply(
            Command::BitQuery(outputs),
            Reply::Bits(BitData::from_fn(BitSpace::Output, 0, 300, 32, |_| false)),
        ),
        cx.clone(),
        t0,
    );
    assert_eq!(s.state(&out).unwrap().value, Some(Value::Bit(false)));
    s.apply(
        SignalsIntent::Propose {
            signal: out,
            text: "on".into(),
        },
        cx.clone(),
        t0,
    );
    s.apply(
        SignalsIntent::Confirm {
            take_the_risk: false,
        },
        cx.clone(),
        t0,
    );
    let (change, _) = s.take_commands().remove(0);
    s.handle_event(
        &reply(change.clone(), Reply::Ack(change.id())),
        cx.clone(),
        t0,
    );
    let (back, _) = s.take_commands().remove(0);
    // An inputs read answers first: the change is not judged by it.
    let inputs = BitQuery {
        space: BitSpace::Input,
        program: 0,
        start: 0,
        count: 32,
    };
    let said = s.handle_event(
        &reply(
            Command::BitQuery(inputs),
            Reply::Bits(BitData::from_fn(BitSpace::Input, 0, 0, 32, |_| false)),
        ),
        cx.clone(),
        t0,
    );
    assert!(said.is_empty(), "{said:?}");
    assert!(s.change_pending());
    let Command::BitQuery(q) = back.clone() else {
        panic!("{back:?}")
    };
    let said = s.handle_event(
        &reply(
            back,
            Reply::Bits(BitData::from_fn(
                BitSpace::Output,
                0,
                q.start,
                q.count,
                |n| n == 300,
            )),
        ),
        cx,
        t0,
    );
    assert_eq!(
        said,
        vec![(Level::Info, "Output 300 is ON (read back)".to_owned())]
    );
}
