//! The first-contact questions: each a query frame, the PROTOCOL.md section whose
//! inference it tests, and how its answer is read. Only queries: no motion, no writes.

use std::fmt::Write as _;

use super::{Answer, Exchange, ReceivedKind};
use crate::protocol::{
    MessageId, RealEncoding, Reply, ScMode, Station, VarValues, ZoneTable, command_frame,
};

/// What is sent: a message ID and its data characters, with the SC computed or `@@`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Ask {
    pub id: u16,
    pub data: &'static str,
    pub sc: ScMode,
}

impl Ask {
    const fn sum(id: u16, data: &'static str) -> Ask {
        Ask {
            id,
            data,
            sc: ScMode::Computed,
        }
    }

    /// The message ID.
    pub fn id(&self) -> MessageId {
        MessageId(self.id)
    }

    /// The whole frame for `station`, CR LF included.
    pub fn bytes(&self, station: Station) -> Vec<u8> {
        command_frame(station, self.id(), self.data.as_bytes(), self.sc)
    }
}

/// How an answer is read beyond "does the pendant decode it".
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Check {
    /// 215H: answered, the SC the controller sends.
    Status,
    /// 215H with `@@`: accepted or not.
    AtAt,
    /// 200H: the data that came back against the data sent.
    Echo,
    /// A query whose reply the pendant decodes (the generic reading).
    Decode,
    /// 22DH over the buffer: truncated, refused, or more.
    Oversize,
    /// 20FH: the value under both real encodings.
    Real,
    /// 2A2H: the record size from the reply length.
    Zone,
}

/// One question of the run.
#[derive(Clone, Copy, Debug)]
pub struct Question {
    /// What the question asks, in words.
    pub title: &'static str,
    /// Where PROTOCOL.md infers what it tests.
    pub section: &'static str,
    pub ask: Ask,
    pub check: Check,
}

impl Question {
    /// Whether this is a plain status query (the run ends when none is answered).
    pub fn is_status(&self) -> bool {
        self.check == Check::Status
    }
}

const fn q(title: &'static str, section: &'static str, ask: Ask, check: Check) -> Question {
    Question {
        title,
        section,
        ask,
        check,
    }
}

const STATUS: Ask = Ask::sum(0x215, "");
const STATUS_TITLE: &str = "215H system status: answered, with which SC, how soon?";
const STATUS_SECTION: &str = "3.4; 1.5 (reply delay); 5 row 17 (SC in replies)";
const POSITIONS: &str = "3.24 (which position-data query a controller answers)";

/// Every question, in the order asked. Layouts as in PROTOCOL.md's tables and the
/// example frames of 3.50.
pub const QUESTIONS: &[Question] = &[
    q(STATUS_TITLE, STATUS_SECTION, STATUS, Check::Status),
    q(STATUS_TITLE, STATUS_SECTION, STATUS, Check::Status),
    q(STATUS_TITLE, STATUS_SECTION, STATUS, Check::Status),
    q(STATUS_TITLE, STATUS_SECTION, STATUS, Check::Status),
    q(STATUS_TITLE, STATUS_SECTION, STATUS, Check::Status),
    q(
        "215H with `@@` in place of the SC (some hosts send it): accepted?",
        "1.4; 6.2",
        Ask {
            id: 0x215,
            data: "",
            sc: ScMode::AtAt,
        },
        Check::AtAt,
    ),
    q(
        "200H test call with no data: echo or error?",
        "3.1 (page not retrieved)",
        Ask::sum(0x200, ""),
        Check::Echo,
    ),
    q(
        "200H test call with ten characters (the observed host's form): echoed?",
        "3.1 (page not retrieved)",
        Ask::sum(0x200, "0123456789"),
        Check::Echo,
    ),
    q(
        "201H version of the main CPU application",
        "3.2",
        Ask::sum(0x201, "000"),
        Check::Decode,
    ),
    q(
        "201H version of the main CPU core",
        "3.2",
        Ask::sum(0x201, "010"),
        Check::Decode,
    ),
    q(
        "201H version of driver CPU 0",
        "3.2",
        Ask::sum(0x201, "020"),
        Check::Decode,
    ),
    q(
        "201H version of SIO board 0",
        "3.2",
        Ask::sum(0x201, "030"),
        Check::Decode,
    ),
    q(
        "209H position data, 3-digit numbers: position 1",
        POSITIONS,
        Ask::sum(0x209, "001001"),
        Check::Decode,
    ),
    q(
        "21FH position data, 4-digit numbers: position 1",
        POSITIONS,
        Ask::sum(0x21F, "00010001"),
        Check::Decode,
    ),
    q(
        "22DH position data with arm systems: position 1",
        POSITIONS,
        Ask::sum(0x22D, "0000010001"),
        Check::Decode,
    ),
    q(
        "22DH asking 20000 numbers at once: cut to the buffer, refused, or more?",
        "3.24 (record limits: truncate or refuse is not stated)",
        Ask::sum(0x22D, "0000014E20"),
        Check::Oversize,
    ),
    q(
        "2A1H SCARA status of axes 1-4 (base coordinates)",
        "3.17",
        Ask::sum(0x2A1, "0F0"),
        Check::Decode,
    ),
    q(
        "2A3H SCARA status 2: the three fields between columns 16 and 24",
        "3.18 (inferred fields)",
        Ask::sum(0x2A3, "0F00"),
        Check::Decode,
    ),
    q(
        "216H latest system error: details 5-8 and the reserved digits",
        "3.5 (details 5-8 not retrievable)",
        Ask::sum(0x216, "001000"),
        Check::Decode,
    ),
    q(
        "216H type 3, error-list record 1",
        "3.47",
        Ask::sum(0x216, "301000"),
        Check::Decode,
    ),
    q(
        "216H type 5, error-list record 1 (extended count)",
        "3.47 (named models only)",
        Ask::sum(0x216, "500001"),
        Check::Decode,
    ),
    q(
        "20BH input ports 0-15",
        "3.34",
        Ask::sum(0x20B, "00000010"),
        Check::Decode,
    ),
    q(
        "20EH global integers 200-201 (layout inferred: page not retrieved)",
        "3.39",
        Ask::sum(0x20E, "000C802"),
        Check::Decode,
    ),
    q(
        "20FH global real 300: which of the two encodings reads sensibly?",
        "3.40 (tail not retrieved; encoding per controller)",
        Ask::sum(0x20F, "0012C01"),
        Check::Real,
    ),
    q(
        "213H status of program 1",
        "3.44",
        Ask::sum(0x213, "01"),
        Check::Decode,
    ),
    q(
        "2A2H interference zone 1: how long is a record?",
        "3.46 (record tail not retrieved)",
        Ask::sum(0x2A2, "0101"),
        Check::Zone,
    ),
];

/// What the answer to `e` settles, in a few lines (each a sentence).
pub fn findings(e: &Exchange) -> Vec<String> {
    let question = e.question();
    let mut out = Vec::new();
    match &e.answer {
        Answer::NotAsked(why) => out.push(format!("not asked: {why}")),
        Answer::Silent => out.push(silent(e, question.check)),
        Answer::Refused(code) => out.push(match question.check {
            Check::AtAt => {
                format!("refused with &{code}: the controller reads `@@` as a wrong SC and says so")
            }
            Check::Oversize => format!(
                "refused with &{code}: a request over the buffer is an error (not cut short)"
            ),
            _ => format!("refused with &{code}"),
        }),
        Answer::Reply(frame) => {
            let decoded = Reply::decode(frame);
            match &decoded {
                Ok(_) => out.push(format!(
                    "answered ({} bytes); the pendant reads it as PROTOCOL.md lays it out",
                    frame.raw().len()
                )),
                Err(err) => out.push(format!(
                    "answered ({} bytes), but NOT as PROTOCOL.md lays it out: {err}",
                    frame.raw().len()
                )),
            }
            reply_findings(e, question, frame.raw(), decoded.ok(), &mut out);
        }
    }
    if e.received.iter().any(|r| r.kind == ReceivedKind::Echo) {
        out.push("the line echoed the command back before the answer".into());
    }
    if e.dropped > 0 {
        out.push(format!(
            "{} more bytes arrived than are kept here",
            e.dropped
        ));
    }
    out
}

fn silent(e: &Exchange, check: Check) -> String {
    let arrived: usize = e.received.iter().map(|r| r.bytes.len()).sum();
    let base = if arrived == 0 {
        "no answer at all".to_string()
    } else {
        format!("no valid answer ({arrived} bytes arrived, listed below)")
    };
    match check {
        Check::AtAt => format!(
            "{base}: the controller ignores a frame with `@@` (it checks every SC); keep the SC computed"
        ),
        Check::Oversize => format!("{base}: a request over the buffer gets nothing"),
        _ => base,
    }
}

fn reply_findings(
    e: &Exchange,
    question: &Question,
    raw: &[u8],
    decoded: Option<Reply>,
    out: &mut Vec<String>,
) {
    let body = raw.get(..raw.len().saturating_sub(2)).unwrap_or(&[]);
    let sc_at_at = body.ends_with(b"@@");
    match question.check {
        Check::Status if sc_at_at => out.push(
            "its reply carries `@@` in place of the SC (PROTOCOL.md expects a real SC)".into(),
        ),
        Check::Status => out.push("its reply carries a real SC".into()),
        Check::AtAt => out.push(
            "`@@` is accepted: a host that sends it (the pendant's debug setting) is answered"
                .into(),
        ),
        Check::Echo => {
            let sent = &e.sent;
            let data_sent = sent.get(6..sent.len().saturating_sub(4)).unwrap_or(&[]);
            let data_back = body.get(6..body.len().saturating_sub(2)).unwrap_or(&[]);
            out.push(if data_sent == data_back {
                format!(
                    "the data came back as sent ({} characters): 200H echoes",
                    data_sent.len()
                )
            } else {
                format!(
                    "the data came back different: sent `{}`, got `{}`",
                    data_sent.escape_ascii(),
                    data_back.escape_ascii()
                )
            });
        }
        Check::Oversize => {
            if let Some(Reply::Positions(data)) = &decoded {
                out.push(format!(
                    "answered {} record(s) in {} bytes ({} than the 1024-byte small buffer; the 2048-byte buffer is {})",
                    data.records.len(),
                    raw.len(),
                    if raw.len() > crate::protocol::SMALL_REPLY_BUFFER {
                        "more"
                    } else {
                        "no more"
                    },
                    if raw.len() > crate::protocol::REPLY_BUFFER {
                        "exceeded"
                    } else {
                        "kept"
                    }
                ));
            }
        }
        Check::Real => {
            if let Some(Reply::Vars(data)) = &decoded
                && let VarValues::Real(words) = &data.values
                && let Some(word) = words.first()
            {
                let plain = RealEncoding::Plain.decode(*word);
                let swapped = RealEncoding::WordSwapped.decode(*word);
                out.push(format!(
                    "real 300 reads {plain} as sent most significant first, {swapped} word-swapped (a value you know settles the setting)"
                ));
            }
        }
        Check::Zone => {
            if let Some(Reply::ZoneTable(table)) = &decoded {
                out.push(zone_record(table));
            }
        }
        Check::Decode => match &decoded {
            Some(Reply::Version(v)) => out.push(format!(
                "model {:02X}, unit code {:02X}, version {:04X}, built {:04}-{:02}-{:02} {:02}:{:02}",
                v.model, v.unit_code, v.version, v.year, v.month, v.day, v.hour, v.minute
            )),
            Some(Reply::ErrorDetail(d)) => out.push(format!(
                "error {}, details 5-8 {:08X} {:08X} {:08X} {:08X} (not named on the pages read)",
                d.error, d.details[4], d.details[5], d.details[6], d.details[7]
            )),
            _ => {}
        },
    }
}

/// What a 2A2H reply says of the record's length (PROTOCOL.md 3.46): the protocol's
/// reader sizes records from the reply's length and keeps what follows coordinate 2.
pub(super) fn zone_record(table: &ZoneTable) -> String {
    let Some(first) = table.records.first() else {
        return "no record came back (zone 1 not defined?)".into();
    };
    let readable = first.readable_len();
    let whole = readable + first.surplus.len();
    let mut s = format!(
        "{} record(s) of {whole} characters; coordinates end at {readable} ({} axes)",
        table.records.len(),
        first.corner1.len()
    );
    if first.surplus.is_empty() {
        s.push_str("; nothing follows coordinate 2");
    } else {
        let _ = write!(
            s,
            "; {} more character(s) follow coordinate 2 in each record: `{}` (the unread tail of p.69)",
            first.surplus.len(),
            first.surplus_text()
        );
    }
    s
}
