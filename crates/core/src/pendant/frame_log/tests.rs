//! The frame log store: pairing, verdicts, the cap, filters and files.

use super::file::{read_jsonl, write_jsonl, write_text};
use super::filter::{DirFilter, Filter};
use super::*;

const REQ: &[u8] = b"!99212@@\r\n";

fn framed(body: &str) -> Vec<u8> {
    let mut f = body.as_bytes().to_vec();
    let sc = crate::protocol::checksum(&f);
    f.extend_from_slice(format!("{sc:02X}\r\n").as_bytes());
    f
}

#[test]
fn a_reply_pairs_with_its_request_and_carries_the_latency() {
    let mut log = FrameLog::new(100);
    let req = framed("!99215");
    let rep = framed("#99215000");
    log.push_sent(&req, 1_000_000);
    log.push_received(&rep, 4_500_000);
    assert_eq!(log.len(), 2);
    let r = log.nth(1).unwrap();
    assert_eq!(r.bytes(), rep.as_slice());
    assert_eq!(r.latency_us(), Some(3500));
    assert_eq!(r.verdict(), Verdict::Ok);
    assert_eq!(r.name(), "215H system status query");
    assert_eq!(log.request_of(1), Some(0));
    assert_eq!(log.reply_of(0), Some(1));
    assert_eq!(log.nth(0).unwrap().latency_us(), None);
}

#[test]
fn verdicts_flag_at_at_and_bad_sums_and_error_replies_take_the_request_id() {
    let mut log = FrameLog::new(100);
    log.push_sent(REQ, 0);
    log.push_received(b"&99C1F00\r\n", 10);
    let sent = log.nth(0).unwrap();
    assert_eq!(sent.verdict(), Verdict::AtAt);
    let err = log.nth(1).unwrap();
    assert!(err.is_error_reply() && err.is_problem());
    assert_eq!(err.id(), Some(0x212));
    let mut bad = framed("#99215000");
    let n = bad.len();
    bad[n - 3] = if bad[n - 3] == b'0' { b'1' } else { b'0' };
    log.push_sent(REQ, 20);
    log.push_garbage(&bad, "checksum error", 30);
    let g = log.nth(3).unwrap();
    assert_eq!(g.verdict(), Verdict::Bad);
    assert_eq!(g.note(), "checksum error");
    assert_eq!(g.bytes(), bad.as_slice());
    assert!(g.is_problem());
}

#[test]
fn the_cap_drops_from_the_head_and_counts() {
    let mut log = FrameLog::new(10_000);
    for i in 0..25_000u64 {
        log.push_sent(format!("!99212{:02X}\r\n", i % 256).as_bytes(), i);
    }
    assert_eq!(log.len(), 10_000);
    assert_eq!(log.dropped_head(), 15_000);
    assert_eq!(log.nth(0).unwrap().t_ns(), 15_000);
    assert_eq!(log.nth(9_999).unwrap().t_ns(), 24_999);
    assert!(log.nth(10_000).is_none());
    assert_eq!(log.snapshot().rows().count(), 10_000);
    log.set_cap(10);
    assert_eq!(log.len(), 10);
    assert_eq!(log.nth(0).unwrap().t_ns(), 24_990);
    log.clear();
    assert!(log.is_empty());
}

/// A line of junk (2 MB/s of 1,000-byte lines) for ten minutes on a virtual clock: the
/// rows' memory stays within the budget, what went is counted, the rows kept read.
#[test]
fn a_junk_stream_is_held_to_the_memory_budget_not_only_the_row_cap() {
    let budget = 8 * 1024 * 1024;
    let mut log = FrameLog::new(DEFAULT_CAP);
    log.set_budget(budget);
    let line: Vec<u8> = (0..1_000u32).map(|i| b'a' + (i % 26) as u8).collect();
    let mut most = 0;
    // 2,000 lines a second for 600 s.
    for i in 0..1_200_000u64 {
        log.push_garbage(&line, "no header", i * 500_000);
        if i % 10_000 == 0 {
            most = most.max(log.memory_bytes());
        }
    }
    // One open chunk beyond the budget at most (4,096 rows of 1,000 bytes).
    assert!(most <= budget + 4096 * 1_100, "{most}");
    assert!(log.dropped_budget() > 1_000_000);
    assert_eq!(log.dropped_head(), log.dropped_budget());
    let last = log.nth(log.len() - 1).unwrap();
    assert_eq!(last.bytes().as_ref(), &line[..]);
    // A run longer than a row keeps says how much more there was.
    log.push_garbage(&vec![b'x'; 5_000], "no CR LF", 0);
    let row = log.nth(log.len() - 1).unwrap();
    assert_eq!(row.bytes().len(), GARBAGE_KEEP);
    assert_eq!(row.note(), "no CR LF (+3976 bytes not kept)");
    // The row cap still holds, and a clear keeps the budget.
    log.clear();
    assert_eq!(log.budget(), budget);
}

#[test]
fn timeouts_end_the_outstanding_request() {
    let mut log = FrameLog::new(10);
    log.push_sent(REQ, 0);
    log.push_timeout("no reply to 212H", 100_000_000);
    let t = log.nth(1).unwrap();
    assert_eq!(t.dir(), Dir::Timeout);
    assert_eq!(t.id(), Some(0x212));
    assert!(t.is_problem());
    assert_eq!(log.reply_of(0), Some(1));
    // A late reply answers nothing.
    log.push_received(&framed("#99212"), 200_000_000);
    assert_eq!(log.request_of(2), None);
}

#[test]
fn filters_by_id_direction_problems_time_and_text() {
    let mut log = FrameLog::new(100);
    log.push_sent(&framed("!99212"), 0);
    log.push_received(&framed("#99212"), 1_000_000_000);
    log.push_sent(&framed("!99215"), 2_000_000_000);
    log.push_timeout("no reply to 215H", 3_000_000_000);
    let count = |f: Filter| {
        let m = f.matcher();
        log.snapshot().rows().filter(|r| m.matches(r)).count()
    };
    assert_eq!(count(Filter::default()), 4);
    let id = |id| Filter {
        id: Some(id),
        ..Filter::default()
    };
    assert_eq!(count(id(0x215)), 2);
    let sent = Filter {
        dir: DirFilter::Sent,
        ..Filter::default()
    };
    assert_eq!(count(sent), 2);
    let problems = Filter {
        problems_only: true,
        ..Filter::default()
    };
    assert_eq!(count(problems), 1);
    let window = Filter {
        from_s: Some(0.5),
        to_s: Some(2.0),
        ..Filter::default()
    };
    assert_eq!(count(window), 2);
    let text = |t: &str, decoded| Filter {
        text: t.into(),
        decoded,
        ..Filter::default()
    };
    assert_eq!(count(text("#99212", false)), 1);
    assert_eq!(count(text("SYSTEM STATUS", false)), 2);
    assert_eq!(count(text("\\r\\n", false)), 3);
    assert_eq!(count(text("no reply", false)), 1);
    assert_eq!(count(text("nothing like this", true)), 0);
}

#[test]
fn jsonl_keeps_exact_bytes_and_times_and_text_is_readable() {
    let mut log = FrameLog::new(100);
    log.push_sent(&framed("!99212"), 5);
    log.push_received(&[b'#', 0x02, b'\r', b'\n', 0xFF], 1_000_005);
    log.push_timeout("no reply", 9_000_000);
    let snap = log.snapshot();
    let mut out = Vec::new();
    assert_eq!(
        write_jsonl(&mut out, snap.origin_wall, snap.rows()).unwrap(),
        3
    );
    let back = read_jsonl(out.as_slice(), 100).unwrap();
    assert_eq!(back.len(), 3);
    for i in 0..3 {
        let (a, b) = (log.nth(i).unwrap(), back.nth(i).unwrap());
        assert_eq!(
            (a.bytes(), a.t_ns(), a.dir()),
            (b.bytes(), b.t_ns(), b.dir())
        );
        assert_eq!((a.latency_us(), a.note()), (b.latency_us(), b.note()));
    }
    let mut text = Vec::new();
    write_text(&mut text, snap.origin_wall, snap.rows()).unwrap();
    let text = String::from_utf8(text).unwrap();
    assert!(text.contains("\\x02\\r\\n\\xff"), "{text}");
    assert!(text.contains("212H axis status query"), "{text}");
    let bad = read_jsonl(
        &b"{\"xsel_pendant_frame_log\":1,\"start_unix_us\":0}\n{oops\n"[..],
        10,
    );
    assert!(bad.unwrap_err().starts_with("line 2"));
    assert!(read_jsonl(&b"hello\n"[..], 10).is_err());
    let long = format!(
        "{{\"xsel_pendant_frame_log\":1,\"start_unix_us\":0}}\n\
         {{\"t_ns\":0,\"dir\":\"garbage\",\"hex\":\"{}\"}}\n",
        "41".repeat(entry::MAX_ROW_BYTES + 1)
    );
    let e = read_jsonl(long.as_bytes(), 10).unwrap_err();
    assert!(
        e.starts_with("line 2: a row longer than any on the line"),
        "{e}"
    );
    let head = "{\"xsel_pendant_frame_log\":1,\"start_unix_us\":0}\n";
    let signed = format!("{head}{{\"t_ns\":0,\"dir\":\"sent\",\"hex\":\"+1+2\"}}\n");
    assert_eq!(
        read_jsonl(signed.as_bytes(), 10).unwrap_err(),
        "line 2: bad hex bytes"
    );
    let later = "{\"xsel_pendant_frame_log\":2,\"start_unix_us\":0}\n";
    let e = read_jsonl(later.as_bytes(), 10).unwrap_err();
    assert!(e.contains("format 2"), "{e}");
}

#[test]
fn raw_bytes_equal_to_a_packed_form_read_back_as_themselves() {
    // A raw row whose bytes happen to be the packed form of an earlier frame (stored as a
    // delta) must not share that frame's storage.
    let reply = |pos: &str| {
        framed(&format!(
            "#992A10100000F1C000000000493E01C000000FFFDB6101C00000000004E201C000000{pos}"
        ))
    };
    let mut log = FrameLog::new(100);
    log.push_received(&reply("0000AFC8"), 0);
    log.push_received(&reply("0000AFD0"), 1);
    let mut packed_second = Vec::new();
    assert!(packed::pack_into(&reply("0000AFD0"), &mut packed_second));
    log.push_sent(&packed_second, 2);
    log.push_garbage(&packed_second, "", 3);
    for (seq, want) in [
        (0, reply("0000AFC8")),
        (1, reply("0000AFD0")),
        (2, packed_second.clone()),
        (3, packed_second.clone()),
    ] {
        assert_eq!(
            log.row(seq).unwrap().bytes().as_ref(),
            want.as_slice(),
            "row {seq}"
        );
    }
}

#[test]
fn wall_clock_times_print_in_utc() {
    let t = std::time::UNIX_EPOCH + Duration::from_micros(1_795_000_000_123_456);
    assert_eq!(file::utc(t), "2026-11-18 11:06:40.123456");
}

#[test]
fn a_lost_line_ends_the_wait_for_a_reply() {
    let mut log = FrameLog::new(10);
    log.push_sent(REQ, 0);
    log.line_lost();
    log.push_received(&framed("#99212"), 10);
    assert_eq!(log.request_of(1), None);
    assert_eq!(log.nth(1).unwrap().latency_us(), None);
}

#[test]
fn polling_while_the_arm_moves_is_kept_small_and_reads_back_byte_for_byte() {
    let mut log = FrameLog::new(DEFAULT_CAP);
    let mut pushed: Vec<Vec<u8>> = Vec::new();
    let mut seed = 0x2545_F491_4F6C_DD1Du64;
    let mut next = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        seed
    };
    let mut axes = [0x0000_AFC8u32, 0xFFFD_B610, 0x0000_4E20, 0x0000_493E];
    for i in 0..100_000u64 {
        let query = framed(["!992A10F0", "!99215", "!992A10F1"][(i % 3) as usize]);
        log.push_sent(&query, i * 10);
        pushed.push(query);
        // One or two axes move a little; now and then a reply is garbage or missing.
        for _ in 0..1 + next() % 2 {
            let a = (next() % 4) as usize;
            axes[a] = axes[a]
                .wrapping_add((next() % 2000) as u32)
                .wrapping_sub(1000);
        }
        let reply = match next() % 500 {
            0 => {
                log.push_timeout("no reply", i * 10 + 5);
                pushed.push(Vec::new());
                continue;
            }
            1 => b"#992A1\x02\xFFgarbage\r\n".to_vec(),
            2 => framed("#992a1010000").to_vec(),
            _ => framed(&format!(
                "#992A1010000001C{:08X}1C{:08X}1C{:08X}1C{:08X}",
                axes[0], axes[1], axes[2], axes[3]
            )),
        };
        if reply.contains(&0x02) {
            log.push_garbage(&reply, "bad byte", i * 10 + 5);
        } else {
            log.push_received(&reply, i * 10 + 5);
        }
        pushed.push(reply);
    }
    assert_eq!(log.len(), pushed.len());
    let mut buf = Vec::new();
    for (i, bytes) in pushed.iter().enumerate() {
        let row = log.nth(i).unwrap();
        assert_eq!(row.bytes().as_ref(), bytes.as_slice(), "row {i}");
        buf.clear();
        row.write_bytes(&mut buf);
        assert_eq!(&buf, bytes, "row {i}");
    }
    // 16 bytes a row, and the bytes in under a third of their size on the line.
    let on_the_line: usize = pushed.iter().map(Vec::len).sum();
    let rows = log.len() * 16;
    assert!(
        log.memory_bytes() < rows + on_the_line / 3,
        "{} bytes kept for {} rows of {on_the_line} bytes",
        log.memory_bytes(),
        log.len()
    );
}

#[test]
fn a_million_polling_rows_take_about_twenty_megabytes() {
    let mut log = FrameLog::new(DEFAULT_CAP);
    log.fill_synthetic(1_000_000);
    assert_eq!(log.len(), 1_000_000);
    // 16 MB of rows; every 2A1H reply a new position, stored as a delta.
    assert!(
        log.memory_bytes() < 21_000_000,
        "{} bytes",
        log.memory_bytes()
    );
    let last = log.nth(999_997).unwrap();
    assert_eq!(last.verdict(), Verdict::Ok);
    assert_eq!(&last.bytes()[..6], b"#992A1");
}

/// A row as pushed, for the model the store is checked against.
#[derive(Clone, Debug)]
enum Pushed {
    Sent(Vec<u8>),
    Received(Vec<u8>),
    Garbage(Vec<u8>, String),
    Timeout(String),
}

/// Frames and near-frames: the same few replies with a byte changed here and there
/// (packed, shared and delta forms), lower case, `@@`, no CR LF, and raw bytes.
fn pushed_row() -> impl proptest::strategy::Strategy<Value = Pushed> {
    use proptest::prelude::*;
    let base = prop_oneof![
        Just(framed("#992A10100000F1C000000000493E01C0000000000AFC8")),
        Just(framed("#9921510000000000060")),
        Just(framed("!992A10F0")),
        Just(b"!99212@@\r\n".to_vec()),
        Just(b"#992a1000\r\n".to_vec()),
        Just(b"&99C1F00\r\n".to_vec()),
        proptest::collection::vec(any::<u8>(), 0..24),
    ];
    const SUBSTITUTES: &[u8] = b"0123456789ABCDEFa@\r";
    let edits = proptest::collection::vec(
        (any::<prop::sample::Index>(), any::<prop::sample::Index>()),
        0..3,
    );
    let edited = (base, edits).prop_map(|(mut bytes, edits)| {
        for (at, with) in edits {
            if !bytes.is_empty() {
                let i = at.index(bytes.len());
                bytes[i] = SUBSTITUTES[with.index(SUBSTITUTES.len())];
            }
        }
        bytes
    });
    (edited, 0u8..8, "[a-zé ]{0,12}").prop_map(|(bytes, kind, note)| match kind {
        0..=2 => Pushed::Sent(bytes),
        3..=5 => Pushed::Received(bytes),
        6 => Pushed::Garbage(bytes, note),
        _ => Pushed::Timeout(note),
    })
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig::with_cases(48))]

    #[test]
    fn every_row_reads_back_as_pushed_across_chunk_boundaries(
        filler in 0usize..2 * CHUNK,
        rows in proptest::collection::vec((pushed_row(), proptest::bool::weighted(0.3)), 1..400),
    ) {
        let mut log = FrameLog::new(DEFAULT_CAP);
        let filler_row = framed("!992A10F0");
        for i in 0..filler {
            log.push_sent(&filler_row, i as u64);
        }
        let protocol = |modbus: bool| if modbus { Protocol::Modbus } else { Protocol::FormatB };
        for (i, (row, modbus)) in rows.iter().enumerate() {
            let t = (filler + i) as u64;
            let p = protocol(*modbus);
            match row {
                Pushed::Sent(b) => log.push_row(p, Dir::Sent, b, "", t),
                Pushed::Received(b) => log.push_row(p, Dir::Received, b, "", t),
                Pushed::Garbage(b, note) => log.push_row(p, Dir::Garbage, b, note, t),
                Pushed::Timeout(note) => log.push_row(p, Dir::Timeout, b"", note, t),
            }
        }
        let snapshot = log.snapshot();
        for (i, (row, modbus)) in rows.iter().enumerate() {
            let seq = (filler + i) as u64;
            let (dir, bytes, note): (Dir, &[u8], &str) = match row {
                Pushed::Sent(b) => (Dir::Sent, b, ""),
                Pushed::Received(b) => (Dir::Received, b, ""),
                Pushed::Garbage(b, n) => (Dir::Garbage, b, n),
                Pushed::Timeout(n) => (Dir::Timeout, b"", n),
            };
            for r in [log.row(seq).unwrap(), snapshot.row(seq).unwrap()] {
                proptest::prop_assert_eq!(r.dir(), dir, "row {}", i);
                let read = r.bytes();
                proptest::prop_assert_eq!(read.as_ref(), bytes, "row {}", i);
                proptest::prop_assert_eq!(r.note(), note, "row {}", i);
                proptest::prop_assert_eq!(r.t_ns(), seq);
                let mut written = Vec::new();
                r.write_bytes(&mut written);
                proptest::prop_assert_eq!(written.as_slice(), bytes);
                proptest::prop_assert_eq!(r.protocol(), protocol(*modbus));
                let error = if *modbus {
                    bytes.get(7).is_some_and(|f| f & 0x80 != 0)
                } else {
                    bytes.first() == Some(&b'&')
                };
                proptest::prop_assert_eq!(r.is_error_reply(), dir == Dir::Received && error);
                // Every answer's request is the last of its line before it.
                if let Some(req) = log.request_of(seq) {
                    let q = log.row(req).unwrap();
                    proptest::prop_assert_eq!((q.dir(), q.protocol()), (Dir::Sent, r.protocol()));
                    let between_is_other = (req + 1..seq).all(|s| {
                        let o = log.row(s).unwrap();
                        o.protocol() != r.protocol() || o.dir() != Dir::Sent
                    });
                    proptest::prop_assert!(between_is_other);
                    proptest::prop_assert_eq!(log.reply_of(req), Some(seq));
                }
            }
        }
    }
}

#[test]
fn an_endless_line_is_refused_after_a_bounded_read_not_held_whole() {
    /// Bytes without end (no LF), counting how many were read.
    struct Endless(std::rc::Rc<std::cell::Cell<usize>>);
    impl std::io::Read for Endless {
        fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
            buf.fill(b'7');
            self.0.set(self.0.get() + buf.len());
            Ok(buf.len())
        }
    }
    let count = std::rc::Rc::new(std::cell::Cell::new(0));
    let input = std::io::BufReader::new(Endless(count.clone()));
    let e = read_jsonl(input, 100).unwrap_err();
    assert!(e.contains("longer than any this program writes"), "{e}");
    assert!(
        count.get() < 1 << 20,
        "read {} bytes of an endless line",
        count.get()
    );
}

mod modbus {
    use super::*;
    use crate::rmc::modbus::{Header, Request, Response, encode_request, encode_response};
    use crate::rmc::{AxisId, AxisStatus};

    fn status_read(transaction: u16, axis: usize) -> Vec<u8> {
        let axis = AxisId::new(axis).unwrap();
        encode_request(
            Header {
                transaction,
                unit: 1,
            },
            &Request::Read {
                address: axis.status_block(),
                count: crate::rmc::registers::STATUS_REGISTERS,
            },
        )
    }

    fn status_reply(transaction: u16, position: f32) -> Vec<u8> {
        let status = AxisStatus {
            actual_position: position,
            target_position: position,
            command_position: position,
            ..AxisStatus::default()
        };
        encode_response(
            Header {
                transaction,
                unit: 1,
            },
            &Response::Registers {
                function: 3,
                words: status.encode(),
            },
        )
    }

    #[test]
    fn modbus_rows_pair_across_the_x_sel_traffic_between_them() {
        let mut log = FrameLog::new(100);
        let t = |ms: u64| ms * 1_000_000;
        log.push_row(Protocol::Modbus, Dir::Sent, &status_read(1, 0), "", t(0));
        log.push_sent(REQ, t(1));
        log.push_received(&framed("#99212000"), t(2));
        log.push_row(
            Protocol::Modbus,
            Dir::Received,
            &status_reply(1, 5.0),
            "",
            t(3),
        );
        let reply = log.nth(3).unwrap();
        assert_eq!(reply.latency_us(), Some(3000));
        assert_eq!(log.request_of(3), Some(0));
        assert_eq!(log.reply_of(0), Some(3));
        assert_eq!(log.request_of(2), Some(1), "the X-SEL pair is kept too");
        assert_eq!(
            reply.name(),
            "FC3 reply: Status Bits..Command Velocity, Axis 1"
        );
        assert_eq!(
            log.nth(0).unwrap().name(),
            "FC3 read Status Bits..Command Velocity, Axis 1"
        );
        assert_eq!(reply.id(), None, "a Modbus row has no Format B message ID");
        assert_eq!(reply.function(), Some(3));
        assert!(reply.ascii().starts_with("00 01 00 00 00 EB 01 03 E8"));
        let d = reply.describe();
        assert!(
            d.fields
                .iter()
                .any(|f| f.name == "Actual Position, Axis 1" && f.value == "5 pu"),
            "{d}"
        );

        // A late reply of another transaction answers nothing.
        log.push_row(Protocol::Modbus, Dir::Sent, &status_read(2, 1), "", t(4));
        log.push_row(
            Protocol::Modbus,
            Dir::Received,
            &status_reply(1, 5.0),
            "",
            t(5),
        );
        assert_eq!(log.request_of(5), None);
        assert_eq!(log.nth(5).unwrap().latency_us(), None);

        // An exception is a problem, named; a time-out names what it waited for.
        let exception = encode_response(
            Header {
                transaction: 3,
                unit: 1,
            },
            &Response::Exception {
                function: 3,
                code: crate::rmc::modbus::ExceptionCode::ILLEGAL_DATA_ADDRESS,
            },
        );
        log.push_row(Protocol::Modbus, Dir::Sent, &status_read(3, 7), "", t(6));
        log.push_row(Protocol::Modbus, Dir::Received, &exception, "", t(7));
        let e = log.nth(7).unwrap();
        assert!(e.is_error_reply() && e.is_problem());
        assert_eq!(e.name(), "exception 02 (illegal data address) to FC3");
        log.push_row(Protocol::Modbus, Dir::Sent, &status_read(4, 0), "", t(8));
        log.push_row(
            Protocol::Modbus,
            Dir::Timeout,
            b"",
            "no reply to transaction 4",
            t(108),
        );
        let timeout = log.nth(9).unwrap();
        assert_eq!(
            timeout.name(),
            "Modbus time-out to FC3 read Status Bits..Command Velocity, Axis 1"
        );
        assert!(timeout.is_problem());
    }

    #[test]
    fn filters_pick_a_line_and_find_modbus_rows_by_name_and_hex() {
        let mut log = FrameLog::new(100);
        log.push_row(Protocol::Modbus, Dir::Sent, &status_read(1, 1), "", 0);
        log.push_row(
            Protocol::Modbus,
            Dir::Received,
            &status_reply(1, 2.0),
            "",
            1,
        );
        log.push_sent(REQ, 2);
        let shown = |f: Filter| {
            let m = f.matcher();
            log.snapshot()
                .rows()
                .filter(|r| m.matches(r))
                .map(|r| r.seq())
                .collect::<Vec<_>>()
        };
        let rmc = Filter {
            protocol: Some(Protocol::Modbus),
            ..Filter::default()
        };
        assert_eq!(shown(rmc), vec![0, 1]);
        let xsel = Filter {
            protocol: Some(Protocol::FormatB),
            ..Filter::default()
        };
        assert_eq!(shown(xsel), vec![2]);
        let by_name = Filter {
            text: "axis 2".into(),
            ..Filter::default()
        };
        assert_eq!(shown(by_name), vec![0, 1]);
        let by_hex = Filter {
            text: "01 03 12".into(),
            ..Filter::default()
        };
        assert_eq!(shown(by_hex), vec![0], "the request's function and address");
        let in_decode = Filter {
            text: "Actual Position".into(),
            decoded: true,
            ..Filter::default()
        };
        assert_eq!(shown(in_decode), vec![1]);
    }

    #[test]
    fn modbus_rows_survive_a_jsonl_round_trip_and_polling_stays_small() {
        let mut log = FrameLog::new(DEFAULT_CAP);
        let mut sent = 0u64;
        for i in 0..20_000u16 {
            let t = u64::from(i) * 2_000_000;
            log.push_row(Protocol::Modbus, Dir::Sent, &status_read(i, 0), "", t);
            // A position that moves: each reply differs from the one before.
            let reply = status_reply(i, f32::from(i) * 0.01);
            sent += reply.len() as u64;
            log.push_row(Protocol::Modbus, Dir::Received, &reply, "", t + 900_000);
        }
        log.push_sent(REQ, u64::MAX / 2);
        // The replies are stored as changes against their predecessors.
        assert!(
            (log.memory_bytes() as u64) < sent / 3,
            "{} bytes for {sent} bytes of replies",
            log.memory_bytes()
        );
        let mut file = Vec::new();
        write_jsonl(&mut file, log.origin_wall(), log.snapshot().rows()).unwrap();
        let back = read_jsonl(file.as_slice(), DEFAULT_CAP).unwrap();
        assert_eq!(back.len(), log.len());
        for seq in [0, 1, 39_998, 39_999, 40_000] {
            let (a, b) = (log.row(seq).unwrap(), back.row(seq).unwrap());
            assert_eq!(
                (a.protocol(), a.dir(), a.t_ns()),
                (b.protocol(), b.dir(), b.t_ns())
            );
            assert_eq!(a.bytes(), b.bytes());
            assert_eq!(a.latency_us(), b.latency_us());
        }
        let mut text = Vec::new();
        write_text(&mut text, log.origin_wall(), log.snapshot().rows().take(2)).unwrap();
        let text = String::from_utf8(text).unwrap();
        assert!(
            text.contains("FC3 reply: Status Bits..Command Velocity, Axis 1"),
            "{text}"
        );
    }
}
