//! Protocol figures of issue 2: 2A4H reply decode, 2D5H encode, streaming decode.

use std::hint::black_box;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use xsel_pendant::protocol::*;

/// A 255-record, 8-axis 2A4H reply: the longest legal frame (16,337 bytes).
fn big_2a4_reply() -> Vec<u8> {
    let records = (0..255)
        .map(|i: i32| {
            PerAxis::from_fn(AxisPattern::ALL, |a| {
                Milli(i * 1000 - a.index() as i32 * 12_345)
            })
        })
        .collect();
    let r = Reply::CoordTable2(CoordTable2 {
        axes: AxisPattern::ALL,
        kind: CoordKind::Work,
        first: 0,
        records,
    });
    let bytes = r.to_bytes(Station::DEFAULT).unwrap();
    assert_eq!(bytes.len(), MAX_FRAME_LEN);
    bytes
}

fn scara_move() -> Command {
    Command::ScaraMoveRelative(ScaraMove {
        motion: ScaraMotion::Cp {
            acc: CentiG(30),
            dec: CentiG(30),
            speed: MmPerSec(50),
        },
        targets: PerAxis::new()
            .with(Axis::A1, Milli(1000))
            .with(Axis::A2, Milli(-5000))
            .with(Axis::A3, Milli(0))
            .with(Axis::A4, Milli(45_000)),
    })
}

/// About 1 MB of realistic traffic: polls, status replies, moves, acks, coordinate table
/// chunks, with a little garbage and a few corrupted frames.
fn capture() -> Vec<u8> {
    let st = Station::DEFAULT;
    let mut out = Vec::with_capacity(1 << 20);
    let blk = |p| AxisState {
        status: AxisStatus(0x1C),
        position: Milli(p),
        ..AxisState::default()
    };
    let scara = Reply::ScaraStatus(ScaraStatus {
        work: 1,
        tool: 0,
        common: CommonStatus::default(),
        axes: PerAxis::new()
            .with(Axis::A1, blk(300_000))
            .with(Axis::A2, blk(-150_000))
            .with(Axis::A3, blk(20_000))
            .with(Axis::A4, blk(45_000)),
    });
    let table = Reply::CoordTable2(CoordTable2 {
        axes: AxisPattern::SCARA_1,
        kind: CoordKind::Tool,
        first: 0,
        records: (0..31)
            .map(|i| PerAxis::from_fn(AxisPattern::SCARA_1, |_| Milli(i * 7)))
            .collect(),
    });
    let mut i = 0u32;
    while out.len() < 1 << 20 {
        Command::SystemStatus
            .encode_into(st, ScMode::Computed, &mut out)
            .unwrap();
        Reply::SystemStatus(SystemStatus::default())
            .encode_into(st, &mut out)
            .unwrap();
        Command::ScaraStatus(ScaraStatusQuery {
            axes: AxisPattern::SCARA_1,
            system: PositionSystem::Base,
        })
        .encode_into(st, ScMode::Computed, &mut out)
        .unwrap();
        scara.encode_into(st, &mut out).unwrap();
        scara_move()
            .encode_into(st, ScMode::Computed, &mut out)
            .unwrap();
        Reply::Ack(MessageId::SCARA_MOVE_RELATIVE)
            .encode_into(st, &mut out)
            .unwrap();
        if i.is_multiple_of(8) {
            Command::CoordQuery2(CoordQuery2::default())
                .encode_into(st, ScMode::Computed, &mut out)
                .unwrap();
            table.encode_into(st, &mut out).unwrap();
        }
        if i % 16 == 5 {
            out.extend_from_slice(b"\x00\xffnoise\r\n");
        }
        if i % 16 == 9 {
            out.extend_from_slice(b"#9921202040000000000270EAF\r\n");
        }
        i += 1;
    }
    out
}

fn benches(c: &mut Criterion) {
    let big = big_2a4_reply();
    let mut g = c.benchmark_group("2A4H reply, 255 records x 8 axes");
    g.throughput(Throughput::Bytes(big.len() as u64));
    g.bench_function("parse + verify + decode", |b| {
        b.iter(|| {
            let f = Frame::parse(black_box(&big)).unwrap();
            let r = Reply::decode(&f).unwrap();
            black_box(r)
        })
    });
    g.finish();

    let cmd = scara_move();
    let mut buf = Vec::with_capacity(128);
    let mut g = c.benchmark_group("2D5H command, 4 axes");
    g.bench_function("encode into reused buffer", |b| {
        b.iter(|| {
            buf.clear();
            black_box(&cmd)
                .encode_into(Station::DEFAULT, ScMode::Computed, &mut buf)
                .unwrap();
            black_box(buf.len())
        })
    });
    g.finish();

    let cap = capture();
    let mut g = c.benchmark_group("stream decoder, 1 MB mixed capture");
    g.throughput(Throughput::Bytes(cap.len() as u64));
    g.bench_function("7-byte chunks", |b| {
        b.iter(|| {
            let mut d = StreamDecoder::new();
            let (mut frames, mut errors) = (0usize, 0usize);
            for chunk in black_box(&cap).chunks(7) {
                d.push(chunk);
                while let Some(r) = d.pull() {
                    match r {
                        Ok(_) => frames += 1,
                        Err(_) => errors += 1,
                    }
                }
            }
            black_box((frames, errors))
        })
    });
    g.finish();
}

criterion_group!(protocol, benches);
criterion_main!(protocol);
