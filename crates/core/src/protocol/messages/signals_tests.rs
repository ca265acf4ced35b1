//! The signal messages against PROTOCOL.md 3.34-3.43 and 3.50.

use super::*;
use crate::protocol::{
    COMMAND_BUFFER, Command, Frame, REPLY_BUFFER, Reply, SMALL_COMMAND_BUFFER, SMALL_REPLY_BUFFER,
    ScMode, Station, describe,
};

fn framed(s: &str) -> Vec<u8> {
    let mut b = s.as_bytes().to_vec();
    b.extend_from_slice(b"\r\n");
    b
}

fn cmd(s: &str) -> Command {
    let b = framed(s);
    Command::decode(&Frame::parse(&b).unwrap()).unwrap()
}

fn reply(s: &str) -> Result<Reply, crate::protocol::MessageError> {
    let b = framed(s);
    Reply::decode(&Frame::parse(&b).unwrap())
}

fn sent(c: &Command) -> String {
    let b = c.to_bytes(Station::DEFAULT, ScMode::Computed).unwrap();
    String::from_utf8(b).unwrap().trim_end().to_string()
}

fn answered(r: &Reply) -> String {
    String::from_utf8(r.to_bytes(Station::DEFAULT).unwrap())
        .unwrap()
        .trim_end()
        .to_string()
}

fn bits(space: BitSpace, program: u8, start: u16, count: u16, on: &[u16]) -> BitData {
    BitData::from_fn(space, program, start, count, |n| on.contains(&n))
}

/// Every frame of PROTOCOL.md 3.50 for sections 3.34-3.43, both ways.
#[test]
fn the_checked_examples_of_section_3_50_decode_and_encode_back() {
    let q = |space, program, start, count| {
        Command::BitQuery(BitQuery {
            space,
            program,
            start,
            count,
        })
    };
    let change = |space, program, number, on| {
        Command::BitChange(BitChange {
            space,
            program,
            number,
            on,
        })
    };
    let vq = |kind, start, count| {
        Command::VarQuery(VarQuery {
            kind,
            program: 0,
            start,
            count,
        })
    };
    let ints = VarData {
        program: 0,
        start: 200,
        values: VarValues::Integer(vec![123, -1]),
    };
    let real = |w: u64| VarData {
        program: 0,
        start: 300,
        values: VarValues::Real(vec![RealWord(w)]),
    };
    let commands = vec![
        ("!9920B00000010B8", q(BitSpace::Input, 0, 0, 16)),
        ("!9920C012C0008D6", q(BitSpace::Output, 0, 300, 8)),
        ("!9924A012C141", change(BitSpace::Output, 0, 300, true)),
        ("!9920D000258001029", q(BitSpace::Flag, 0, 600, 16)),
        ("!9924B00025819B", change(BitSpace::Flag, 0, 600, true)),
        ("!9924B03038409D", change(BitSpace::Flag, 3, 900, false)),
        ("!9920E000C802A7", vq(VarKind::Integer, 200, 2)),
        ("!9920F0012C01A2", vq(VarKind::Real, 300, 1)),
        ("!9921000001057C", vq(VarKind::Text, 1, 5)),
        (
            "!9924C000C8020000007BFFFFFFFF72",
            Command::VarWrite(ints.clone()),
        ),
        (
            "!9924D0012C013FF8000000000000DB",
            Command::VarWrite(real(0x3FF8_0000_0000_0000)),
        ),
    ];
    for (text, want) in commands {
        assert_eq!(cmd(text), want, "{text}");
        assert_eq!(sent(&want), text);
    }
    let replies = vec![
        (
            "#9920B00000010058087",
            Reply::Bits(bits(BitSpace::Input, 0, 0, 16, &[0, 2, 15])),
        ),
        (
            "#9920C012C00080139",
            Reply::Bits(bits(BitSpace::Output, 0, 300, 8, &[300])),
        ),
        ("#9924A3C", Reply::Ack(MessageId::OUTPUT_CHANGE)),
        (
            "#9920D00025800100100EC",
            Reply::Bits(bits(BitSpace::Flag, 0, 600, 16, &[600])),
        ),
        ("#9924B3D", Reply::Ack(MessageId::FLAG_CHANGE)),
        ("#9920E000C8020000007BFFFFFFFF72", Reply::Vars(ints)),
        (
            "#9920F0012C013FF8000000000000DB",
            Reply::Vars(real(0x3FF8_0000_0000_0000)),
        ),
        (
            "#9920F0012C01000000003FF80000DB",
            Reply::Vars(real(0x0000_0000_3FF8_0000)),
        ),
        (
            "#99210000010548454C4C4FBB",
            Reply::Vars(VarData {
                program: 0,
                start: 1,
                values: VarValues::Text(b"HELLO".to_vec()),
            }),
        ),
        (
            "#9924C000C802AB",
            Reply::VarsWritten(VarsWritten {
                kind: VarKind::Integer,
                program: 0,
                start: 200,
                count: 2,
            }),
        ),
        (
            "#9924D0012C01A6",
            Reply::VarsWritten(VarsWritten {
                kind: VarKind::Real,
                program: 0,
                start: 300,
                count: 1,
            }),
        ),
    ];
    for (text, want) in replies {
        assert_eq!(reply(text).unwrap(), want, "{text}");
        assert_eq!(answered(&want), text);
    }
}

#[test]
fn both_encodings_of_a_double_read_1_5_and_the_wrong_one_is_noticed() {
    let plain = RealWord(0x3FF8_0000_0000_0000);
    let swapped = RealWord(0x0000_0000_3FF8_0000);
    assert_eq!(RealEncoding::Plain.decode(plain), 1.5);
    assert_eq!(RealEncoding::WordSwapped.decode(swapped), 1.5);
    assert_eq!(RealEncoding::WordSwapped.encode(1.5), swapped);
    assert_eq!(
        RealEncoding::Plain.encode(-2.25),
        RealWord((-2.25f64).to_bits())
    );
    // PROTOCOL.md 3.40: 0x0123456789ABCDEF is sent word-swapped as 89ABCDEF01234567.
    assert_eq!(
        RealEncoding::WordSwapped.encode(f64::from_bits(0x0123_4567_89AB_CDEF)),
        RealWord(0x89AB_CDEF_0123_4567)
    );
    // Read the wrong way, 1.5 is a subnormal; the right way an ordinary number.
    assert!(RealEncoding::Plain.looks_wrong(swapped));
    assert!(RealEncoding::WordSwapped.looks_wrong(plain));
    assert!(!RealEncoding::Plain.looks_wrong(plain));
    assert!(!RealEncoding::Plain.looks_wrong(RealWord(0)));
}

#[test]
fn the_buffer_limits_are_those_of_the_protocol_pages() {
    // PROTOCOL.md 3.34 and 3.37: groups of 8 in a 2048 / 1024-byte reply.
    assert_eq!(BitSpace::Input.max_count(REPLY_BUFFER), 1015 * 8);
    assert_eq!(BitSpace::Output.max_count(SMALL_REPLY_BUFFER), 503 * 8);
    assert_eq!(BitSpace::Flag.max_count(REPLY_BUFFER), 1014 * 8);
    assert_eq!(BitSpace::Flag.max_count(SMALL_REPLY_BUFFER), 502 * 8);
    // 3.40-3.42.
    assert_eq!(VarKind::Real.max_count(REPLY_BUFFER), 126);
    assert_eq!(VarKind::Real.max_count(SMALL_REPLY_BUFFER), 62);
    assert_eq!(VarKind::Integer.max_write(COMMAND_BUFFER), 254);
    assert_eq!(VarKind::Integer.max_write(SMALL_COMMAND_BUFFER), 125);
    assert_eq!(VarKind::Real.max_write(COMMAND_BUFFER), 127);
    assert_eq!(VarKind::Real.max_write(SMALL_COMMAND_BUFFER), 62);
    assert_eq!(VarKind::Text.max_count(REPLY_BUFFER), 255);
    // Lengths agree with the frames.
    let full = BitData::from_fn(BitSpace::Flag, 0, 600, 64, |n| n % 3 == 0);
    assert_eq!(
        Reply::Bits(full).to_bytes(Station::DEFAULT).unwrap().len(),
        BitSpace::Flag.reply_len(64)
    );
    let q = VarQuery {
        kind: VarKind::Integer,
        program: 0,
        start: 200,
        count: 2,
    };
    assert_eq!(
        q.max_reply_len(),
        "#9920E000C8020000007BFFFFFFFF72\r\n".len()
    );
}

#[test]
fn categories_put_queries_on_their_own_grid() {
    assert!(INPUTS.on_grid(0) && INPUTS.on_grid(8) && !INPUTS.on_grid(4));
    assert!(OUTPUTS.on_grid(300) && OUTPUTS.on_grid(308) && !OUTPUTS.on_grid(304));
    assert_eq!(OUTPUTS.group_start(305), 300);
    assert_eq!(LOCAL_FLAGS.group_start(911), 908);
    assert!(!OUTPUTS.on_grid(600));
    assert_eq!(BitSpace::Flag.category(905), Some(&LOCAL_FLAGS));
    assert_eq!(BitSpace::Flag.category(610), Some(&GLOBAL_FLAGS));
    assert_eq!(BitSpace::Flag.category(12), None);
    assert_eq!(BitSpace::Output.category(12), None);
    // Bit 0 is the lowest-numbered member of a group [inferred].
    assert_eq!(group_bit(0), 0x01);
    assert_eq!(group_bit(15), 0x80);
}

#[test]
fn a_reply_short_of_its_count_is_refused_naming_the_groups() {
    // 16 inputs need 2 groups; one follows.
    let e = reply("#9920B0000001005@@")
        .map(|_| ())
        .unwrap_err()
        .to_string();
    assert!(e.contains("16 bits need 2 2-digit groups; 1 follow"), "{e}");
    // 2 integers need 16 characters; 8 follow.
    let e = reply("#9920E000C8020000007B@@")
        .map(|_| ())
        .unwrap_err()
        .to_string();
    assert!(e.contains("2 values need 16 characters; 8 follow"), "{e}");
    // A group too many is trailing data.
    assert!(reply("#9920C012C00080101@@").is_err());
    // A change type with reserved bits set.
    let b = framed("!9924A012C2@@");
    assert!(Command::decode(&Frame::parse(&b).unwrap()).is_err());
}

#[test]
fn what_cannot_be_sent_is_refused_when_encoding() {
    let input = Command::BitChange(BitChange {
        space: BitSpace::Input,
        program: 0,
        number: 3,
        on: true,
    });
    assert!(input.to_bytes(Station::DEFAULT, ScMode::Computed).is_err());
    let text = Command::VarWrite(VarData {
        program: 0,
        start: 300,
        values: VarValues::Text(b"A".to_vec()),
    });
    assert!(text.to_bytes(Station::DEFAULT, ScMode::Computed).is_err());
    let many = Command::VarWrite(VarData {
        program: 0,
        start: 200,
        values: VarValues::Integer(vec![0; 256]),
    });
    assert!(many.to_bytes(Station::DEFAULT, ScMode::Computed).is_err());
    let port_program = Command::BitQuery(BitQuery {
        space: BitSpace::Input,
        program: 2,
        start: 0,
        count: 8,
    });
    assert!(
        port_program
            .to_bytes(Station::DEFAULT, ScMode::Computed)
            .is_err()
    );
    assert!(
        Command::BitChange(BitChange::default()).writes_data()
            && Command::VarWrite(VarData::default()).writes_data()
            && !Command::BitQuery(BitQuery::default()).writes_data()
    );
}

#[test]
fn the_frame_log_names_ports_that_are_on_and_both_readings_of_a_double() {
    let d = describe(&framed("#9920B00000010058087"));
    let text = d.to_string();
    assert!(text.contains("0-7: ON 0, 2"), "{text}");
    assert!(text.contains("8-15: ON 15"), "{text}");
    let d = describe(&framed("#9920F0012C013FF8000000000000DB"));
    let text = d.to_string();
    assert!(text.contains("1.5 (most significant first)"), "{text}");
    let d = describe(&framed("#9920E000C8020000007BFFFFFFFF72"));
    assert!(d.to_string().contains("-1"), "{d}");
    let d = describe(&framed("!9924B03038409D"));
    let text = d.to_string();
    assert!(text.contains("program 3") && text.contains("OFF"), "{text}");
}
