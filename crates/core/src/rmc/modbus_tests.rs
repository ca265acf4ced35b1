//! Modbus/TCP framing: known frames, round trips, and no panic on any bytes.

use proptest::prelude::*;

use super::*;
use crate::rmc::command::{Command, MoveRelative};
use crate::robot::RelativeTo;

const H: Header = Header {
    transaction: 0x0102,
    unit: 1,
};

#[test]
fn the_worked_example_is_one_fc16_at_0x5000() {
    let block = Command::MoveRelative(MoveRelative {
        distance: 10.0,
        speed: 5.0,
        accel: 100.0,
        decel: 100.0,
        relative_to: RelativeTo::Target,
    })
    .block(true);
    let frame = encode_request(
        H,
        &Request::Write {
            address: 0x5000,
            words: block,
        },
    );
    let expected: Vec<u8> = vec![
        0x01,
        0x02,
        0,
        0,
        0,
        7 + 24,
        1, // MBAP
        16,
        0x50,
        0x00,
        0,
        12,
        24, // FC16 at 0x5000, 12 registers, 24 bytes
        0x80,
        0x00,
        0x43,
        0x8A, // 277.0
        0x00,
        0x00,
        0x41,
        0x20, // 10.0
        0x00,
        0x00,
        0x40,
        0xA0, // 5.0
        0x00,
        0x00,
        0x42,
        0xC8, // 100.0
        0x00,
        0x00,
        0x42,
        0xC8, // 100.0
        0x00,
        0x00,
        0x40,
        0x00, // 2.0
    ];
    assert_eq!(frame, expected);
}

#[test]
fn a_read_and_its_answer() {
    let frame = encode_request(
        H,
        &Request::Read {
            address: 4096,
            count: 116,
        },
    );
    assert_eq!(frame, [1, 2, 0, 0, 0, 6, 1, 3, 0x10, 0x00, 0, 116]);
    assert_eq!(
        decode_request(&frame),
        Ok((
            H,
            Request::Read {
                address: 4096,
                count: 116
            }
        ))
    );
    let answer = Response::Registers {
        function: 3,
        words: vec![0x1234, 0xABCD],
    };
    let bytes = encode_response(H, &answer);
    assert_eq!(bytes, [1, 2, 0, 0, 0, 7, 1, 3, 4, 0x12, 0x34, 0xAB, 0xCD]);
    assert_eq!(decode_response(&bytes), Ok((H, answer)));
}

#[test]
fn exceptions_go_both_ways() {
    for code in [1, 2, 3] {
        let e = Response::Exception {
            function: 16,
            code: ExceptionCode(code),
        };
        let bytes = encode_response(H, &e);
        assert_eq!(bytes, [1, 2, 0, 0, 0, 3, 1, 0x90, code]);
        assert_eq!(decode_response(&bytes), Ok((H, e)));
    }
}

#[test]
fn a_count_that_disagrees_with_the_bytes_is_exception_3() {
    // FC16 claiming 2 registers with 2 bytes of data.
    let frame = [1, 2, 0, 0, 0, 9, 1, 16, 0x50, 0, 0, 2, 2, 0, 1];
    assert!(matches!(
        decode_request(&frame),
        Err(Refusal::Exception {
            code: ExceptionCode::ILLEGAL_DATA_VALUE,
            ..
        })
    ));
    // A partial FC16 header inside a whole frame (modbus-core's own stream decoder
    // indexes past it): refused, no panic.
    let frame = [1, 2, 0, 0, 0, 5, 1, 16, 0x50, 0, 0];
    assert!(decode_request(&frame).is_err());
}

#[test]
fn a_stream_is_cut_into_frames() {
    let a = encode_request(
        H,
        &Request::Read {
            address: 0,
            count: 2,
        },
    );
    let b = encode_request(
        H,
        &Request::Write {
            address: 2,
            words: vec![7, 8],
        },
    );
    let mut stream = a.clone();
    stream.extend(&b);
    let mut buf = FrameBuffer::default();
    for byte in &stream {
        buf.push(&[*byte]);
    }
    assert_eq!(buf.next_frame(), Some(Ok(a)));
    assert_eq!(buf.next_frame(), Some(Ok(b)));
    assert_eq!(buf.next_frame(), None);
    buf.push(&[0, 0, 0, 9, 0, 6, 1]);
    assert_eq!(buf.next_frame(), Some(Err(FrameError::NotModbus(9))));
    assert!(buf.is_empty());
}

fn request() -> impl Strategy<Value = Request> {
    prop_oneof![
        (any::<u16>(), 1..=125u16).prop_map(|(address, count)| Request::Read { address, count }),
        (any::<u16>(), prop::collection::vec(any::<u16>(), 1..=100))
            .prop_map(|(address, words)| Request::Write { address, words }),
        (
            any::<u16>(),
            1..=125u16,
            any::<u16>(),
            prop::collection::vec(any::<u16>(), 1..=100)
        )
            .prop_map(|(read_address, read_count, write_address, words)| {
                Request::ReadWrite {
                    read_address,
                    read_count,
                    write_address,
                    words,
                }
            }),
    ]
}

fn response() -> impl Strategy<Value = Response> {
    prop_oneof![
        (
            prop_oneof![Just(3u8), Just(23u8)],
            prop::collection::vec(any::<u16>(), 1..=125)
        )
            .prop_map(|(function, words)| Response::Registers { function, words }),
        (any::<u16>(), 1..=100u16)
            .prop_map(|(address, count)| Response::Written { address, count }),
        (1..=4u8, 1..=4u8).prop_map(|(f, c)| Response::Exception {
            function: [3, 16, 23, 5][usize::from(f) - 1],
            code: ExceptionCode(c),
        }),
    ]
}

fn header() -> impl Strategy<Value = Header> {
    (any::<u16>(), any::<u8>()).prop_map(|(transaction, unit)| Header { transaction, unit })
}

proptest! {
    #[test]
    fn requests_round_trip(h in header(), r in request()) {
        let bytes = encode_request(h, &r);
        prop_assert_eq!(cut(&bytes), Cut::Whole(bytes.len()));
        prop_assert_eq!(decode_request(&bytes), Ok((h, r)));
    }

    #[test]
    fn responses_round_trip(h in header(), r in response()) {
        let bytes = encode_response(h, &r);
        prop_assert_eq!(cut(&bytes), Cut::Whole(bytes.len()));
        prop_assert_eq!(decode_response(&bytes), Ok((h, r)));
    }

    #[test]
    fn no_bytes_make_either_side_panic(bytes in prop::collection::vec(any::<u8>(), 0..300)) {
        let _ = decode_request(&bytes);
        let _ = decode_response(&bytes);
        let mut buf = FrameBuffer::default();
        buf.push(&bytes);
        while let Some(frame) = buf.next_frame() {
            if let Ok(frame) = frame {
                let _ = decode_request(&frame);
                let _ = decode_response(&frame);
            }
        }
    }

    #[test]
    fn a_well_framed_header_with_any_pdu_never_panics(
        function in prop_oneof![Just(3u8), Just(16u8), Just(23u8), any::<u8>()],
        body in prop::collection::vec(any::<u8>(), 0..252),
    ) {
        let mut frame = vec![0, 1, 0, 0];
        frame.extend(((body.len() + 2) as u16).to_be_bytes());
        frame.push(1);
        frame.push(function);
        frame.extend(&body);
        let _ = decode_request(&frame);
        let _ = decode_response(&frame);
    }

    #[test]
    fn command_blocks_read_back(distance in -1e6f32..1e6, speed in 0.001f32..1e4, req: bool) {
        let c = Command::MoveRelative(MoveRelative {
            distance, speed, accel: speed * 10.0, decel: speed * 10.0,
            relative_to: RelativeTo::Actual,
        });
        prop_assert_eq!(Command::from_block(&c.block(req)), Ok((c, req)));
    }
}
