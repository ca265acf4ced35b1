//! Property tests: every command and reply round-trips; the streaming decoder never
//! panics, stays bounded, accounts for every byte, and recovers after garbage.

use proptest::collection::vec;
use proptest::prelude::*;
use xsel_pendant::protocol::*;

// ---------------------------------------------------------------- strategies

fn pattern() -> impl Strategy<Value = AxisPattern> {
    any::<u8>().prop_map(AxisPattern)
}

fn milli() -> impl Strategy<Value = Milli> {
    any::<i32>().prop_map(Milli)
}

fn per_axis<T: Copy + Default + std::fmt::Debug>(
    p: AxisPattern,
    s: impl Strategy<Value = T>,
) -> impl Strategy<Value = PerAxis<T>> {
    vec(s, 8).prop_map(move |v| PerAxis::from_fn(p, |a| v[a.index()]))
}

fn targets() -> impl Strategy<Value = PerAxis<Milli>> {
    pattern().prop_flat_map(|p| per_axis(p, milli()))
}

fn printable(max: usize) -> impl Strategy<Value = Vec<u8>> {
    vec(0x20u8..=0x7E, 0..=max)
}

fn test_data() -> impl Strategy<Value = TestData> {
    printable(10).prop_map(|v| TestData::new(&v).unwrap())
}

fn centi_g() -> impl Strategy<Value = CentiG> {
    any::<u16>().prop_map(CentiG)
}

fn mm_s() -> impl Strategy<Value = MmPerSec> {
    any::<u16>().prop_map(MmPerSec)
}

fn pct() -> impl Strategy<Value = Percent> {
    any::<u16>().prop_map(Percent)
}

fn arm_policy() -> impl Strategy<Value = ArmPolicy> {
    (0u8..4).prop_map(|c| ArmPolicy::from_code(c).unwrap())
}

fn scara_motion() -> impl Strategy<Value = ScaraMotion> {
    prop_oneof![
        (pct(), pct(), pct(), arm_policy()).prop_map(|(acc, dec, speed, arm)| ScaraMotion::Ptp {
            acc,
            dec,
            speed,
            arm
        }),
        (centi_g(), centi_g(), mm_s()).prop_map(|(acc, dec, speed)| ScaraMotion::Cp {
            acc,
            dec,
            speed
        }),
    ]
}

fn position_system() -> impl Strategy<Value = PositionSystem> {
    prop_oneof![
        Just(PositionSystem::Base),
        Just(PositionSystem::Work),
        Just(PositionSystem::Joint)
    ]
}

fn coord_kind() -> impl Strategy<Value = CoordKind> {
    prop_oneof![Just(CoordKind::Work), Just(CoordKind::Tool)]
}

fn jog_motion() -> impl Strategy<Value = JogMotion> {
    prop_oneof![
        (
            prop_oneof![
                Just(JogFrame::Base),
                Just(JogFrame::Work),
                Just(JogFrame::Tool)
            ],
            centi_g(),
            centi_g(),
            mm_s()
        )
            .prop_map(|(frame, acc, dec, speed)| JogMotion::Cartesian {
                frame,
                acc,
                dec,
                speed
            }),
        (pct(), pct(), pct()).prop_map(|(acc, dec, speed)| JogMotion::Joint { acc, dec, speed }),
    ]
}

fn error_detail_query() -> impl Strategy<Value = ErrorDetailQuery> {
    prop_oneof![
        any::<bool>().prop_map(|latest| ErrorDetailQuery::System { latest }),
        any::<u8>().prop_map(|axis| ErrorDetailQuery::Axis { axis }),
        any::<u8>().prop_map(|program| ErrorDetailQuery::Program { program }),
        any::<u8>().prop_map(|record| ErrorDetailQuery::ListRecord { record }),
        (0u16..0x1000).prop_map(|record| ErrorDetailQuery::ExtendedListRecord { record }),
    ]
}

fn command() -> impl Strategy<Value = Command> {
    prop_oneof![
        test_data().prop_map(Command::TestCall),
        (any::<u8>(), 0u8..16).prop_map(|(u, device)| Command::Version(VersionQuery {
            unit: UnitType(u),
            device
        })),
        pattern().prop_map(|axes| Command::AxisStatus { axes }),
        Just(Command::SystemStatus),
        error_detail_query().prop_map(Command::ErrorDetail),
        (pattern(), any::<bool>()).prop_map(|(axes, on)| Command::Servo(Servo { axes, on })),
        (pattern(), 0u16..0x1000, 0u16..0x1000).prop_map(|(axes, s, c)| Command::Home(Home {
            axes,
            search: MmPerSec(s),
            creep: MmPerSec(c)
        })),
        (centi_g(), centi_g(), mm_s(), targets(), any::<bool>()).prop_map(
            |(acc, dec, speed, targets, abs)| {
                let m = AxisMove {
                    acc,
                    dec,
                    speed,
                    targets,
                };
                if abs {
                    Command::MoveAbsolute(m)
                } else {
                    Command::MoveRelative(m)
                }
            }
        ),
        (pattern(), any::<bool>(), 0..=i32::MAX, jog_motion()).prop_map(
            |(axes, pos, d, motion)| {
                Command::Jog(Jog {
                    axes,
                    direction: if pos {
                        Direction::Positive
                    } else {
                        Direction::Negative
                    },
                    distance: Milli(d),
                    motion,
                })
            }
        ),
        (pattern(), any::<bool>()).prop_map(|(axes, c)| Command::Stop(Stop {
            axes,
            cancel_held_outputs: c
        })),
        Just(Command::AlarmReset),
        Just(Command::SoftwareReset),
        (pattern(), mm_s())
            .prop_map(|(axes, speed)| Command::SpeedChange(SpeedChange { axes, speed })),
        (coord_kind(), any::<u8>(), any::<u8>()).prop_map(|(kind, first, count)| {
            Command::CoordQuery(CoordQuery { kind, first, count })
        }),
        (pattern(), position_system())
            .prop_map(|(axes, system)| Command::ScaraStatus(ScaraStatusQuery { axes, system })),
        (pattern(), position_system(), position_system()).prop_map(|(axes, a, b)| {
            Command::ScaraStatus2(ScaraStatusQuery2 {
                axes,
                system_1_4: a,
                system_5_8: b,
            })
        }),
        (
            prop_oneof![Just(0x0Fu8), Just(0xF0), Just(0xFF)],
            coord_kind(),
            any::<u8>(),
            any::<u8>()
        )
            .prop_map(|(p, kind, first, count)| Command::CoordQuery2(CoordQuery2 {
                axes: AxisPattern(p),
                kind,
                first,
                count
            })),
        (any::<u8>(), any::<u8>())
            .prop_map(|(first, count)| Command::ZoneQuery(ZoneQuery { first, count })),
        (scara_motion(), targets(), any::<bool>()).prop_map(|(motion, targets, abs)| {
            let m = ScaraMove { motion, targets };
            if abs {
                Command::ScaraMoveAbsolute(m)
            } else {
                Command::ScaraMoveRelative(m)
            }
        }),
        (pattern(), scara_motion(), any::<u16>()).prop_map(|(axes, motion, position)| {
            Command::ScaraMovePosition(ScaraPositionMove {
                axes,
                motion,
                position,
            })
        }),
    ]
}

fn axis_state() -> impl Strategy<Value = AxisState> {
    (any::<u8>(), 0u8..16, 0u16..0x1000, any::<u8>(), milli()).prop_map(
        |(s, sensor, e, enc, position)| AxisState {
            status: AxisStatus(s),
            sensor: SensorInput(sensor),
            error: ErrorCode(e),
            encoder: EncoderStatus(enc),
            position,
        },
    )
}

fn axis_blocks() -> impl Strategy<Value = PerAxis<AxisState>> {
    pattern().prop_flat_map(|p| per_axis(p, axis_state()))
}

fn common_status() -> impl Strategy<Value = CommonStatus> {
    (
        prop_oneof![
            Just(ArmSystem::Right),
            Just(ArmSystem::Left),
            Just(ArmSystem::Undetermined)
        ],
        position_system(),
    )
        .prop_map(|(arm, system)| CommonStatus { arm, system })
}

fn unit_status() -> impl Strategy<Value = ScaraUnitStatus> {
    (any::<u8>(), any::<u8>(), common_status()).prop_map(|(work, tool, common)| ScaraUnitStatus {
        work,
        tool,
        common,
    })
}

fn plain_ack_id() -> impl Strategy<Value = MessageId> {
    proptest::sample::select(
        MessageId::ALL
            .iter()
            .copied()
            .filter(|id| id.is_plain_ack())
            .collect::<Vec<_>>(),
    )
}

fn reply() -> impl Strategy<Value = Reply> {
    prop_oneof![
        plain_ack_id().prop_map(Reply::Ack),
        test_data().prop_map(Reply::TestCall),
        (
            (
                any::<u8>(),
                0u8..16,
                any::<u8>(),
                any::<u8>(),
                any::<u16>(),
                any::<u16>()
            ),
            (
                any::<u8>(),
                any::<u8>(),
                any::<u8>(),
                any::<u8>(),
                any::<u8>()
            )
        )
            .prop_map(
                |(
                    (u, device, model, unit_code, version, year),
                    (month, day, hour, minute, second),
                )| {
                    Reply::Version(VersionInfo {
                        unit: UnitType(u),
                        device,
                        model,
                        unit_code,
                        version,
                        year,
                        month,
                        day,
                        hour,
                        minute,
                        second,
                    })
                }
            ),
        axis_blocks().prop_map(Reply::AxisStatus),
        (0u8..16, 0u16..0x1000, 0u16..0x1000, any::<[u8; 4]>()).prop_map(|(m, c, l, b)| {
            Reply::SystemStatus(SystemStatus {
                mode: SystemMode(m),
                critical_error: ErrorCode(c),
                latest_error: ErrorCode(l),
                status1: SystemStatus1(b[0]),
                status2: SystemStatus2(b[1]),
                status3: SystemStatus3(b[2]),
                status4: b[3],
            })
        }),
        (
            0u16..0x1000,
            any::<[u32; 8]>(),
            vec(b'0'..=b'9', 15),
            printable(60)
        )
            .prop_map(|(e, details, res, message)| {
                Reply::ErrorDetail(ErrorDetail {
                    error: ErrorCode(e),
                    details,
                    reserved: res.try_into().unwrap(),
                    message,
                })
            }),
        (
            coord_kind(),
            any::<u8>(),
            vec((milli(), milli(), milli(), milli()), 0..20)
        )
            .prop_map(|(kind, first, recs)| {
                Reply::CoordTable(CoordTable {
                    kind,
                    first,
                    records: recs
                        .into_iter()
                        .map(|(x, y, z, r)| XyzR { x, y, z, r })
                        .collect(),
                })
            }),
        (any::<u8>(), any::<u8>(), common_status(), axis_blocks()).prop_map(
            |(work, tool, common, axes)| {
                Reply::ScaraStatus(ScaraStatus {
                    work,
                    tool,
                    common,
                    axes,
                })
            }
        ),
        (pattern(), unit_status(), unit_status(), axis_blocks()).prop_map(
            |(scara_axes, unit1, unit2, axes)| {
                Reply::ScaraStatus2(ScaraStatus2 {
                    scara_axes,
                    unit1,
                    unit2,
                    axes,
                })
            }
        ),
        (pattern(), coord_kind(), any::<u8>())
            .prop_flat_map(|(p, kind, first)| (
                Just(p),
                Just(kind),
                Just(first),
                vec(per_axis(p, milli()), 0..12)
            ))
            .prop_map(
                |(axes, kind, first, records)| Reply::CoordTable2(CoordTable2 {
                    axes,
                    kind,
                    first,
                    records
                })
            ),
        (pattern(), any::<u8>(), 0usize..9)
            .prop_flat_map(|(p, first, tail)| (
                Just(first),
                vec(
                    (
                        per_axis(p, milli()),
                        per_axis(p, milli()),
                        vec(prop_oneof![Just(b'0'), Just(b'A'), Just(b' ')], tail..=tail)
                    ),
                    0..6
                )
            ))
            .prop_map(|(first, records)| Reply::ZoneTable(ZoneTable {
                first,
                records: records
                    .into_iter()
                    .map(|(corner1, corner2, surplus)| ZoneRecord {
                        corner1,
                        corner2,
                        surplus
                    })
                    .collect()
            })),
        (0u16..0x1000).prop_map(|c| Reply::Error(ErrorCode(c))),
    ]
}

fn sc_mode() -> impl Strategy<Value = ScMode> {
    prop_oneof![Just(ScMode::Computed), Just(ScMode::AtAt)]
}

/// Splits `bytes` at the given cut points (taken modulo the length).
fn split<'a>(bytes: &'a [u8], cuts: &[usize]) -> Vec<&'a [u8]> {
    let mut points: Vec<usize> = cuts.iter().map(|c| c % (bytes.len() + 1)).collect();
    points.push(0);
    points.push(bytes.len());
    points.sort_unstable();
    points.windows(2).map(|w| &bytes[w[0]..w[1]]).collect()
}

fn raw_of(r: &Result<OwnedFrame, DecodeError>) -> Vec<u8> {
    match r {
        Ok(f) => f.raw().to_vec(),
        Err(e) => e.raw().to_vec(),
    }
}

/// Feeds `chunks` and drains after each; checks the bound after every drain.
fn feed(chunks: &[&[u8]]) -> (Vec<Result<OwnedFrame, DecodeError>>, StreamDecoder) {
    let mut d = StreamDecoder::new();
    let mut out = Vec::new();
    for c in chunks {
        d.push(c);
        while let Some(r) = d.pull() {
            out.push(r);
        }
        assert!(d.pending() <= MAX_FRAME_LEN + 1, "pending {}", d.pending());
    }
    (out, d)
}

// ---------------------------------------------------------------- properties

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    #[test]
    fn every_command_round_trips(c in command(), st in any::<u8>(), sc in sc_mode()) {
        let bytes = c.to_bytes(Station(st), sc).unwrap();
        if !matches!(c, Command::TestCall(_)) {
            // Hex is always sent upper case (200H test data is free text).
            prop_assert!(bytes.iter().all(|b| !b.is_ascii_lowercase()), "upper case only");
        }
        let f = Frame::parse(&bytes).unwrap();
        prop_assert_eq!(f.station(), Station(st));
        prop_assert_eq!(f.id(), Some(c.id()));
        prop_assert_eq!(Command::decode(&f).unwrap(), c);
        prop_assert!(bytes.len() <= MAX_FRAME_LEN);
        let d = describe(&bytes);
        prop_assert!(d.is_ok(), "{}", d);
    }

    #[test]
    fn every_reply_round_trips(r in reply(), st in any::<u8>()) {
        let bytes = r.to_bytes(Station(st)).unwrap();
        prop_assert!(bytes.iter().take(bytes.len() - 2).all(|b| !b.is_ascii_control()));
        let f = Frame::parse(&bytes).unwrap();
        prop_assert_eq!(f.station(), Station(st));
        prop_assert_eq!(Reply::decode(&f).unwrap(), r);
        let d = describe(&bytes);
        prop_assert!(d.is_ok(), "{}", d);
    }

    #[test]
    fn replies_fit_the_commands_max_reply_len(c in command()) {
        // Every reply the command can get is at most max_reply_len: check the full reply
        // for the queries whose reply size the command fixes.
        let max = c.max_reply_len();
        prop_assert!(max >= 10);
        if let Command::CoordQuery2(q) = c {
            let full = Reply::CoordTable2(CoordTable2 {
                axes: q.axes,
                kind: q.kind,
                first: q.first,
                records: vec![PerAxis::from_fn(q.axes, |_| Milli(0)); usize::from(q.count)],
            });
            prop_assert_eq!(full.to_bytes(Station::DEFAULT).unwrap().len(), max);
        }
        if let Command::AxisStatus { axes } = c {
            let full = Reply::AxisStatus(PerAxis::from_fn(axes, |_| AxisState::default()));
            prop_assert_eq!(full.to_bytes(Station::DEFAULT).unwrap().len(), max);
        }
        if let Some(full) = longest_reply(&c) {
            prop_assert_eq!(full.to_bytes(Station::DEFAULT).unwrap().len(), max, "{:?}", c);
        }
    }

    #[test]
    fn decoder_survives_arbitrary_bytes_in_arbitrary_splits(
        bytes in vec(any::<u8>(), 0..3000),
        cuts in vec(any::<usize>(), 0..40),
    ) {
        let chunks = split(&bytes, &cuts);
        let (out, mut d) = feed(&chunks);
        // Every byte is accounted for exactly once, in order.
        let mut seen: Vec<u8> = out.iter().flat_map(raw_of).collect();
        seen.extend(d.take_pending());
        prop_assert_eq!(seen, bytes);
    }

    #[test]
    fn decoder_survives_header_heavy_noise(
        bytes in vec(prop_oneof![Just(b'!'), Just(b'#'), Just(b'&'), Just(b'\r'), Just(b'\n'), Just(b'9'), any::<u8>()], 0..3000),
        cuts in vec(any::<usize>(), 0..40),
    ) {
        let chunks = split(&bytes, &cuts);
        let (out, mut d) = feed(&chunks);
        let mut seen: Vec<u8> = out.iter().flat_map(raw_of).collect();
        seen.extend(d.take_pending());
        prop_assert_eq!(seen, bytes);
    }

    #[test]
    fn a_valid_frame_after_any_garbage_line_is_recovered(
        garbage in vec(any::<u8>(), 0..400),
        c in command(),
        r in reply(),
        cuts in vec(any::<usize>(), 0..20),
    ) {
        let good_c = c.to_bytes(Station::DEFAULT, ScMode::Computed).unwrap();
        let good_r = r.to_bytes(Station::DEFAULT).unwrap();
        let mut stream = garbage.clone();
        stream.extend_from_slice(b"\r\n");
        stream.extend_from_slice(&good_c);
        stream.extend_from_slice(&good_r);
        let (out, d) = feed(&split(&stream, &cuts));
        prop_assert_eq!(d.pending(), 0);
        let n = out.len();
        prop_assert!(n >= 2);
        let last_c = out[n - 2].as_ref().unwrap();
        let last_r = out[n - 1].as_ref().unwrap();
        prop_assert_eq!(last_c.raw(), &good_c[..]);
        prop_assert_eq!(Command::decode(last_c).unwrap(), c);
        prop_assert_eq!(Reply::decode(last_r).unwrap(), r);
    }

    #[test]
    fn a_stream_of_valid_frames_comes_out_unchanged(
        cmds in vec(command(), 1..20),
        cuts in vec(any::<usize>(), 0..60),
    ) {
        let mut stream = Vec::new();
        for c in &cmds {
            c.encode_into(Station::DEFAULT, ScMode::Computed, &mut stream).unwrap();
        }
        let (out, d) = feed(&split(&stream, &cuts));
        prop_assert_eq!(d.pending(), 0);
        let got: Vec<Command> = out.iter().map(|r| Command::decode(r.as_ref().unwrap()).unwrap()).collect();
        prop_assert_eq!(got, cmds);
    }

    #[test]
    fn decoders_and_describer_never_panic_on_checksummed_junk(
        id in proptest::sample::select(MessageId::ALL.to_vec()),
        data in vec(prop_oneof![Just(b'0'), Just(b'F'), Just(b'f'), Just(b'1'), Just(b'3'), any::<u8>()], 0..120),
        header in prop_oneof![Just(b'!'), Just(b'#'), Just(b'&')],
    ) {
        let mut b = vec![header, b'9', b'9'];
        if header != b'&' {
            b.extend_from_slice(format!("{:03X}", id.0).as_bytes());
        }
        b.extend(data.iter().copied().filter(|&c| c != b'\n'));
        let sc = checksum(&b);
        b.extend_from_slice(format!("{sc:02X}\r\n").as_bytes());
        let d = describe(&b);
        if let Ok(f) = Frame::parse(&b) {
            let decoded_ok = match header {
                b'!' => Command::decode(&f).is_ok(),
                _ => Reply::decode(&f).is_ok(),
            };
            // The describer and the decoders agree on what is valid.
            prop_assert_eq!(d.is_ok(), decoded_ok, "{}", d);
        }
    }

    #[test]
    fn describe_never_panics(bytes in vec(any::<u8>(), 0..300)) {
        let d = describe(&bytes);
        let _ = d.to_string();
    }
}

/// The longest reply each fixed-size query can get (2A4H and 212H are built above).
fn longest_reply(c: &Command) -> Option<Reply> {
    let blocks = |axes: AxisPattern| PerAxis::from_fn(axes, |_| AxisState::default());
    Some(match *c {
        Command::TestCall(_) => Reply::TestCall(TestData::new(b"0123456789").unwrap()),
        Command::Version(_) => Reply::Version(VersionInfo::default()),
        Command::SystemStatus => Reply::SystemStatus(SystemStatus::default()),
        Command::ErrorDetail(_) => Reply::ErrorDetail(ErrorDetail {
            message: vec![b'M'; 255],
            ..ErrorDetail::default()
        }),
        Command::CoordQuery(q) => Reply::CoordTable(CoordTable {
            kind: q.kind,
            first: q.first,
            records: vec![XyzR::default(); usize::from(q.count)],
        }),
        Command::ScaraStatus(q) => Reply::ScaraStatus(ScaraStatus {
            axes: blocks(q.axes),
            ..ScaraStatus::default()
        }),
        Command::ScaraStatus2(q) => Reply::ScaraStatus2(ScaraStatus2 {
            scara_axes: q.axes,
            unit1: ScaraUnitStatus::default(),
            unit2: ScaraUnitStatus::default(),
            axes: blocks(q.axes),
        }),
        _ => return None,
    })
}
