//! Programs (PROTOCOL.md 3.44-3.45): the status query 213H and the five operations run,
//! end, pause, one-step run and resume (253H-257H), which share one layout.

use crate::protocol::error::{EncodeError, MessageError};
use crate::protocol::fields::{Name, Reader, Show};
use crate::protocol::ids::{ErrorCode, MessageId};
use crate::protocol::writer::Writer;

pub use super::signals::PROGRAMS;

/// The program field's value that means "every program currently running", defined for
/// end, pause and resume only `[spec p.53]`.
pub const ALL_PROGRAMS: u8 = 0;

/// 213H command: the status of one program.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct ProgramStatusQuery {
    /// Program number (2 hex digits).
    pub program: u8,
}

impl ProgramStatusQuery {
    pub(crate) fn read(r: &mut Reader<'_, '_>) -> Result<Self, MessageError> {
        let program = r.u8(Name::new("program number"), 2, Show::Program)?;
        Ok(ProgramStatusQuery { program })
    }

    pub(crate) fn write(&self, w: &mut Writer<'_>) -> Result<(), EncodeError> {
        w.hex_fit(u32::from(self.program), 2);
        Ok(())
    }
}

flags! {
    /// 213H status digit (1 hex digit; bits 1-3 reserved `[spec p.29]`).
    ProgramFlags {
        /// Bit 0: the program is started. A paused program counts as started: the page has
        /// no "paused" bit `[inferred, PROTOCOL.md 3.44]`.
        started / with_started = 0, "started";
    }
}

/// 213H reply: where one program is (PROTOCOL.md 3.44).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct ProgramStatus {
    /// Program number (echo).
    pub program: u8,
    /// The status digit, reserved bits kept as read.
    pub flags: ProgramFlags,
    /// The step being executed; 0 = none (the field is invalid when 0 `[spec p.29]`).
    pub step: u16,
    /// The program's error; `000` = none `[inferred]`.
    pub error: ErrorCode,
    /// The step the error occurred at.
    pub error_step: u16,
}

impl ProgramStatus {
    /// Length of the reply frame with CR LF.
    pub const FRAME_LEN: usize = 24;

    /// Whether the program is started (running or paused).
    pub const fn started(&self) -> bool {
        self.flags.started()
    }

    /// The executing step, when the field is valid.
    pub const fn executing_step(&self) -> Option<u16> {
        if self.step == 0 {
            None
        } else {
            Some(self.step)
        }
    }

    /// The error and its step, when there is one.
    pub fn error(&self) -> Option<(ErrorCode, u16)> {
        (self.error != ErrorCode::NONE).then_some((self.error, self.error_step))
    }

    pub(crate) fn read(r: &mut Reader<'_, '_>) -> Result<Self, MessageError> {
        let program = r.u8(Name::new("program number"), 2, Show::Program)?;
        let flags = ProgramFlags(r.u8(Name::new("status"), 1, Show::Bits(ProgramFlags::BITS))?);
        let step = r.u16(Name::new("executing step"), 4, Show::Number)?;
        let error = r.error_code(Name::new("program error"))?;
        let error_step = r.u16(Name::new("error step"), 4, Show::Number)?;
        Ok(ProgramStatus {
            program,
            flags,
            step,
            error,
            error_step,
        })
    }

    pub(crate) fn write(&self, w: &mut Writer<'_>) -> Result<(), EncodeError> {
        w.hex_fit(u32::from(self.program), 2);
        w.hex("status", u32::from(self.flags.0), 1)?;
        w.hex_fit(u32::from(self.step), 4);
        w.hex("program error", u32::from(self.error.0), 3)?;
        w.hex_fit(u32::from(self.error_step), 4);
        Ok(())
    }
}

/// One of the five program operations of 253H-257H (the heading's ID order, erratum E8).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ProgramAction {
    /// 253H program run.
    Run,
    /// 254H program end.
    End,
    /// 255H program pause.
    Pause,
    /// 256H program one-step run.
    Step,
    /// 257H program resume.
    Resume,
}

impl ProgramAction {
    /// Every operation, in ID order.
    pub const ALL: [ProgramAction; 5] = [
        ProgramAction::Run,
        ProgramAction::End,
        ProgramAction::Pause,
        ProgramAction::Step,
        ProgramAction::Resume,
    ];

    /// The message ID.
    pub const fn id(self) -> MessageId {
        match self {
            ProgramAction::Run => MessageId::PROGRAM_RUN,
            ProgramAction::End => MessageId::PROGRAM_END,
            ProgramAction::Pause => MessageId::PROGRAM_PAUSE,
            ProgramAction::Step => MessageId::PROGRAM_STEP,
            ProgramAction::Resume => MessageId::PROGRAM_RESUME,
        }
    }

    /// The operation a message ID names.
    pub const fn from_id(id: MessageId) -> Option<ProgramAction> {
        Some(match id {
            MessageId::PROGRAM_RUN => ProgramAction::Run,
            MessageId::PROGRAM_END => ProgramAction::End,
            MessageId::PROGRAM_PAUSE => ProgramAction::Pause,
            MessageId::PROGRAM_STEP => ProgramAction::Step,
            MessageId::PROGRAM_RESUME => ProgramAction::Resume,
            _ => return None,
        })
    }

    /// The operation in a word, for messages ("run", "one step"...).
    pub const fn name(self) -> &'static str {
        match self {
            ProgramAction::Run => "run",
            ProgramAction::End => "end",
            ProgramAction::Pause => "pause",
            ProgramAction::Step => "one step",
            ProgramAction::Resume => "resume",
        }
    }

    /// Whether `00` (every running program) is defined for it: end, pause and resume
    /// `[spec p.53]`.
    pub const fn takes_all(self) -> bool {
        matches!(
            self,
            ProgramAction::End | ProgramAction::Pause | ProgramAction::Resume
        )
    }

    /// Whether it may set axes moving: run, one step and resume.
    pub const fn may_move(self) -> bool {
        matches!(
            self,
            ProgramAction::Run | ProgramAction::Step | ProgramAction::Resume
        )
    }
}

/// 253H-257H command: one operation on one program, or on every running one (`00`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct ProgramCall {
    /// The operation.
    pub action: ProgramAction,
    /// The program; [`ALL_PROGRAMS`] for every running program.
    pub program: u8,
}

impl ProgramCall {
    /// End every running program: `!99254008E` (PROTOCOL.md 3.45).
    pub const END_ALL: ProgramCall = ProgramCall {
        action: ProgramAction::End,
        program: ALL_PROGRAMS,
    };

    /// Whether it names every running program.
    pub const fn is_all(&self) -> bool {
        self.program == ALL_PROGRAMS
    }

    pub(crate) fn read(
        r: &mut Reader<'_, '_>,
        action: ProgramAction,
    ) -> Result<Self, MessageError> {
        let program = r.u8(Name::new("program number"), 2, Show::ProgramOrAll)?;
        Ok(ProgramCall { action, program })
    }

    /// Writes the program field. `00` is refused for run and one step: the page defines it
    /// for end, pause and resume only.
    pub(crate) fn write(&self, w: &mut Writer<'_>) -> Result<(), EncodeError> {
        if self.is_all() && !self.action.takes_all() {
            return Err(w.error(
                "program number",
                format!(
                    "00 (every program) is defined for end, pause and resume, not for {}",
                    self.action.name()
                ),
            ));
        }
        w.hex_fit(u32::from(self.program), 2);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::protocol::{Command, Frame, Reply, ScMode, Station, describe};

    fn framed(s: &str) -> Vec<u8> {
        let mut b = s.as_bytes().to_vec();
        b.extend_from_slice(b"\r\n");
        b
    }

    fn cmd(s: &str) -> Command {
        let b = framed(s);
        Command::decode(&Frame::parse(&b).unwrap()).unwrap()
    }

    fn reply(s: &str) -> Reply {
        let b = framed(s);
        Reply::decode(&Frame::parse(&b).unwrap()).unwrap()
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

    /// Every frame of PROTOCOL.md 3.50 for sections 3.44 and 3.45, both ways.
    #[test]
    fn the_checked_examples_of_section_3_50_decode_and_encode_back() {
        let q = Command::ProgramStatus(ProgramStatusQuery { program: 1 });
        assert_eq!(cmd("!99213018A"), q);
        assert_eq!(sent(&q), "!99213018A");

        let running = Reply::ProgramStatus(ProgramStatus {
            program: 1,
            flags: ProgramFlags::default().with_started(true),
            step: 12,
            error: ErrorCode::NONE,
            error_step: 0,
        });
        assert_eq!(reply("#99213011000C0000000E0"), running);
        assert_eq!(answered(&running), "#99213011000C0000000E0");

        let failed = ProgramStatus {
            program: 1,
            flags: ProgramFlags::default(),
            step: 0,
            error: ErrorCode(0xA1E),
            error_step: 7,
        };
        assert_eq!(
            reply("#992130100000A1E0007FA"),
            Reply::ProgramStatus(failed)
        );
        assert_eq!(
            answered(&Reply::ProgramStatus(failed)),
            "#992130100000A1E0007FA"
        );
        assert_eq!(failed.error(), Some((ErrorCode(0xA1E), 7)));
        assert_eq!(failed.executing_step(), None);
        assert!(!failed.started());

        let examples = [
            (ProgramAction::Run, 1, "!99253018E", "#992532F"),
            (ProgramAction::End, 0, "!99254008E", "#9925430"),
            (ProgramAction::Pause, 1, "!992550190", "#9925531"),
            (ProgramAction::Step, 1, "!992560191", "#9925632"),
            (ProgramAction::Resume, 1, "!992570192", "#9925733"),
        ];
        for (action, program, command, ack) in examples {
            let c = Command::Program(ProgramCall { action, program });
            assert_eq!(cmd(command), c, "{command}");
            assert_eq!(sent(&c), command);
            let a = Reply::Ack(action.id());
            assert_eq!(reply(ack), a, "{ack}");
            assert_eq!(answered(&a), ack);
            assert_eq!(ProgramAction::from_id(action.id()), Some(action));
        }
        assert_eq!(sent(&Command::Program(ProgramCall::END_ALL)), "!99254008E");
    }

    #[test]
    fn every_program_is_refused_for_run_and_one_step_and_decoded_for_the_simulator_to_answer() {
        for action in ProgramAction::ALL {
            let c = Command::Program(ProgramCall { action, program: 0 });
            let encoded = c.to_bytes(Station::DEFAULT, ScMode::Computed);
            assert_eq!(encoded.is_ok(), action.takes_all(), "{action:?}");
            if let Err(e) = encoded {
                assert!(e.to_string().contains("not for"), "{e}");
            }
        }
        // A client may still send it: the decoder reads it, the controller refuses it.
        assert_eq!(
            cmd("!99253008D"),
            Command::Program(ProgramCall {
                action: ProgramAction::Run,
                program: 0
            })
        );
    }

    #[test]
    fn run_one_step_and_resume_are_motion_end_and_pause_are_not() {
        for action in ProgramAction::ALL {
            let c = Command::Program(ProgramCall { action, program: 1 });
            assert_eq!(c.is_motion(), action.may_move(), "{action:?}");
            assert!(!c.writes_data());
        }
        assert!(!Command::ProgramStatus(ProgramStatusQuery { program: 1 }).is_motion());
        assert_eq!(
            Command::ProgramStatus(ProgramStatusQuery { program: 1 }).max_reply_len(),
            24
        );
    }

    #[test]
    fn the_frame_log_names_every_field() {
        let b = framed("#992130100000A1E0007FA");
        let d = describe(&b);
        let text = format!("{d:?}");
        for needle in ["program 1", "executing step", "A1E", "error step", "7"] {
            assert!(text.contains(needle), "{needle} missing from {text}");
        }
        let b = framed("!99254008E");
        let d = format!("{:?}", describe(&b));
        assert!(d.contains("every running program"), "{d}");
    }

    #[test]
    fn reserved_status_bits_are_kept_as_read() {
        let odd = Reply::ProgramStatus(ProgramStatus {
            program: 64,
            flags: ProgramFlags(0xB),
            step: 0xFFFF,
            error: ErrorCode::NONE,
            error_step: 0,
        });
        let text = answered(&odd);
        assert_eq!(reply(&text), odd);
        let Reply::ProgramStatus(s) = reply(&text) else {
            unreachable!()
        };
        assert!(s.started());
        assert_eq!(s.flags.0, 0xB);
    }
}
