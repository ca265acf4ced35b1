//! `Command`: every host-to-controller message, encoded and decoded (both roles).

use super::axis::AxisPattern;
use super::checksum::ScMode;
use super::describe::FieldDescription;
use super::error::{EncodeError, MessageError, MessageErrorKind};
use super::fields::Reader;
use super::frame::Frame;
use super::ids::{Header, MessageId, Role, Station};
use super::messages::basic::{ErrorDetailQuery, TestData, VersionQuery};
use super::messages::coords::{CoordQuery, CoordQuery2};
use super::messages::motion::{AxisMove, Home, Jog, Servo, SpeedChange, Stop};
use super::messages::positions::{
    PositionMove, PositionQuery, PositionQueryKind, PositionWrite, PositionWriteKind,
};
use super::messages::programs::{ProgramAction, ProgramCall, ProgramStatusQuery};
use super::messages::scara::{ScaraMove, ScaraPositionMove};
use super::messages::scara_status::{ScaraStatusQuery, ScaraStatusQuery2};
use super::messages::signals::{BitChange, BitQuery, BitSpace, VarData, VarKind, VarQuery};
use super::messages::zones::ZoneQuery;
use super::writer::{Writer, encode_frame};

/// A command frame's meaning (PROTOCOL.md section 3).
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub enum Command {
    /// 200H test call (echo of 0-10 characters).
    TestCall(TestData),
    /// 201H version code query.
    Version(VersionQuery),
    /// 212H axis status query.
    AxisStatus {
        /// Axes to report.
        axes: AxisPattern,
    },
    /// 215H system status query.
    SystemStatus,
    /// 216H error detail query.
    ErrorDetail(ErrorDetailQuery),
    /// 232H servo ON/OFF.
    Servo(Servo),
    /// 233H home return.
    Home(Home),
    /// 234H absolute-coordinate move.
    MoveAbsolute(AxisMove),
    /// 235H relative-coordinate move.
    MoveRelative(AxisMove),
    /// 236H jog / inching.
    Jog(Jog),
    /// 238H stop and cancel.
    Stop(Stop),
    /// 252H alarm reset.
    AlarmReset,
    /// 25BH software reset (the controller reboots; a reply may never come).
    SoftwareReset,
    /// 262H speed change.
    SpeedChange(SpeedChange),
    /// 2A0H coordinate system definition query (4 axes per record).
    CoordQuery(CoordQuery),
    /// 2A1H SCARA axis status query.
    ScaraStatus(ScaraStatusQuery),
    /// 2A2H simple interference-check zone definition query.
    ZoneQuery(ZoneQuery),
    /// 2A3H SCARA axis status query 2.
    ScaraStatus2(ScaraStatusQuery2),
    /// 2A4H coordinate system definition query 2.
    CoordQuery2(CoordQuery2),
    /// 2D4H SCARA absolute move.
    ScaraMoveAbsolute(ScaraMove),
    /// 2D5H SCARA relative move.
    ScaraMoveRelative(ScaraMove),
    /// 2D6H SCARA position-number move.
    ScaraMovePosition(ScaraPositionMove),
    /// 209H / 21FH / 22DH effective position data query.
    PositionQuery(PositionQuery),
    /// 244H / 245H / 26DH / 290H / 291H position data write.
    PositionWrite(PositionWrite),
    /// 26BH move to a position number.
    PositionMove(PositionMove),
    /// 20BH / 20CH / 20DH input port, output port or flag query.
    BitQuery(BitQuery),
    /// 24AH output port or 24BH flag status change.
    BitChange(BitChange),
    /// 20EH / 20FH / 210H integer, real or string variable query.
    VarQuery(VarQuery),
    /// 24CH / 24DH integer or real variable change (no message changes strings).
    VarWrite(VarData),
    /// 213H program status query.
    ProgramStatus(ProgramStatusQuery),
    /// 253H-257H program run, end, pause, one-step run or resume.
    Program(ProgramCall),
}

impl Command {
    /// The message ID.
    pub const fn id(&self) -> MessageId {
        match self {
            Command::TestCall(_) => MessageId::TEST_CALL,
            Command::Version(_) => MessageId::VERSION,
            Command::AxisStatus { .. } => MessageId::AXIS_STATUS,
            Command::SystemStatus => MessageId::SYSTEM_STATUS,
            Command::ErrorDetail(_) => MessageId::ERROR_DETAIL,
            Command::Servo(_) => MessageId::SERVO,
            Command::Home(_) => MessageId::HOME,
            Command::MoveAbsolute(_) => MessageId::MOVE_ABSOLUTE,
            Command::MoveRelative(_) => MessageId::MOVE_RELATIVE,
            Command::Jog(_) => MessageId::JOG,
            Command::Stop(_) => MessageId::STOP,
            Command::AlarmReset => MessageId::ALARM_RESET,
            Command::SoftwareReset => MessageId::SOFTWARE_RESET,
            Command::SpeedChange(_) => MessageId::SPEED_CHANGE,
            Command::CoordQuery(_) => MessageId::COORD_QUERY,
            Command::ScaraStatus(_) => MessageId::SCARA_STATUS,
            Command::ZoneQuery(_) => MessageId::ZONE_QUERY,
            Command::ScaraStatus2(_) => MessageId::SCARA_STATUS_2,
            Command::CoordQuery2(_) => MessageId::COORD_QUERY_2,
            Command::ScaraMoveAbsolute(_) => MessageId::SCARA_MOVE_ABSOLUTE,
            Command::ScaraMoveRelative(_) => MessageId::SCARA_MOVE_RELATIVE,
            Command::ScaraMovePosition(_) => MessageId::SCARA_MOVE_POSITION,
            Command::PositionQuery(q) => q.kind.id(),
            Command::PositionWrite(w) => w.kind.id(),
            Command::PositionMove(_) => MessageId::POSITION_MOVE,
            Command::BitQuery(q) => q.space.id(),
            Command::BitChange(c) => c.id(),
            Command::VarQuery(q) => q.kind.query_id(),
            Command::VarWrite(d) => match d.kind() {
                VarKind::Real => MessageId::REAL_CHANGE,
                // Strings have no change message: encoding refuses them.
                _ => MessageId::INTEGER_CHANGE,
            },
            Command::ProgramStatus(_) => MessageId::PROGRAM_STATUS,
            Command::Program(c) => c.action.id(),
        }
    }

    /// Whether this command moves or powers axes (servo and homing too): never re-send it
    /// blindly after a time-out, and send it only on a line proven in step (232H, 233H,
    /// 234H, 235H, 236H, 262H, 26BH, 2D4H, 2D5H, 2D6H).
    pub const fn is_motion(&self) -> bool {
        matches!(
            self,
            Command::Servo(_)
                | Command::Home(_)
                | Command::MoveAbsolute(_)
                | Command::MoveRelative(_)
                | Command::Jog(_)
                | Command::SpeedChange(_)
                | Command::ScaraMoveAbsolute(_)
                | Command::ScaraMoveRelative(_)
                | Command::ScaraMovePosition(_)
                | Command::PositionMove(_)
        ) || matches!(self, Command::Program(c) if c.action.may_move())
    }

    /// Whether this command writes the controller's data (positions, outputs, flags,
    /// variables): automatic
    /// operation for the operator (confirm, refuse while unsafe), never re-sent blindly
    /// after a time-out (the controller may have written it: read back instead).
    pub const fn writes_data(&self) -> bool {
        matches!(
            self,
            Command::PositionWrite(_) | Command::BitChange(_) | Command::VarWrite(_)
        )
    }

    /// Whether this command moves the arm or an axis: a jog or a move (not servo or
    /// homing, which [`Command::is_motion`] also counts as motion).
    pub const fn moves_arm(&self) -> bool {
        matches!(
            self,
            Command::Jog(_)
                | Command::MoveAbsolute(_)
                | Command::MoveRelative(_)
                | Command::ScaraMoveAbsolute(_)
                | Command::ScaraMoveRelative(_)
                | Command::ScaraMovePosition(_)
                | Command::PositionMove(_)
        )
    }

    /// Whether this is a 236H jog that runs until stopped ([`Jog::is_continuous`]).
    pub const fn is_continuous_jog(&self) -> bool {
        matches!(self, Command::Jog(j) if j.is_continuous())
    }

    /// Whether this is a program run, one step or resume (253H, 256H, 257H): the program
    /// may move the arm.
    pub const fn is_program_start(&self) -> bool {
        matches!(self, Command::Program(c) if c.action.may_move())
    }

    /// Whether this is 238H STOP, which goes to the head of the queue.
    pub const fn is_stop(&self) -> bool {
        matches!(self, Command::Stop(_))
    }

    /// The longest legal reply to this command, in bytes from header to LF (at least the
    /// 10 bytes of an error reply). For timeouts.
    pub fn max_reply_len(&self) -> usize {
        let n = |p: AxisPattern| p.count();
        let len = match self {
            // [inferred] PROTOCOL.md 3.1: the echo of up to 10 characters is a guess, so
            // allow the longest echo whatever was sent.
            Command::TestCall(d) => 10 + d.as_bytes().len().max(10),
            Command::Version(_) => 35,
            Command::AxisStatus { axes } => 12 + 16 * n(*axes),
            Command::SystemStatus => 25,
            Command::ErrorDetail(_) => 349,
            Command::CoordQuery(q) => 15 + 32 * usize::from(q.count),
            Command::ScaraStatus(q) => 18 + 16 * n(q.axes),
            Command::ScaraStatus2(q) => 26 + 16 * n(q.axes),
            Command::ZoneQuery(q) => q.max_reply_len(),
            Command::CoordQuery2(q) => 17 + 8 * n(q.axes) * usize::from(q.count),
            Command::PositionQuery(q) => q.max_reply_len(),
            Command::PositionWrite(w) => super::PositionsWritten::frame_len(w.kind),
            Command::BitQuery(q) => q.max_reply_len(),
            Command::VarQuery(q) => q.max_reply_len(),
            Command::VarWrite(_) => super::VarsWritten::FRAME_LEN,
            Command::ProgramStatus(_) => super::ProgramStatus::FRAME_LEN,
            _ => 10,
        };
        len.max(10)
    }

    /// Appends the complete frame (header to CR LF) to `out`. Upper-case hex; the SC is
    /// computed unless `sc` is [`ScMode::AtAt`]. Does not allocate when `out` has room.
    /// On error `out` is left as it was.
    #[inline]
    pub fn encode_into(
        &self,
        station: Station,
        sc: ScMode,
        out: &mut Vec<u8>,
    ) -> Result<(), EncodeError> {
        let id = self.id();
        encode_frame(out, Header::Command, station, Some(id), id, sc, |w| {
            self.write_data(w)
        })
    }

    /// The complete frame as a new vector.
    pub fn to_bytes(&self, station: Station, sc: ScMode) -> Result<Vec<u8>, EncodeError> {
        let mut v = Vec::with_capacity(32);
        self.encode_into(station, sc, &mut v)?;
        Ok(v)
    }

    #[inline]
    fn write_data(&self, w: &mut Writer<'_>) -> Result<(), EncodeError> {
        match self {
            Command::TestCall(d) => d.write(w),
            Command::Version(q) => q.write(w),
            Command::AxisStatus { axes } => {
                w.hex_fit(u32::from(axes.0), 2);
                Ok(())
            }
            Command::SystemStatus | Command::AlarmReset | Command::SoftwareReset => Ok(()),
            Command::ErrorDetail(q) => q.write(w),
            Command::Servo(c) => c.write(w),
            Command::Home(c) => c.write(w),
            Command::MoveAbsolute(m) | Command::MoveRelative(m) => m.write(w),
            Command::Jog(j) => j.write(w),
            Command::Stop(s) => s.write(w),
            Command::SpeedChange(s) => s.write(w),
            Command::CoordQuery(q) => q.write(w),
            Command::ScaraStatus(q) => q.write(w),
            Command::ScaraStatus2(q) => q.write(w),
            Command::ZoneQuery(q) => q.write(w),
            Command::CoordQuery2(q) => q.write(w),
            Command::ScaraMoveAbsolute(m) | Command::ScaraMoveRelative(m) => m.write(w),
            Command::ScaraMovePosition(m) => m.write(w),
            Command::PositionQuery(q) => q.write(w),
            Command::PositionWrite(p) => p.write(w),
            Command::PositionMove(m) => m.write(w),
            Command::BitQuery(q) => q.write(w),
            Command::BitChange(c) => c.write(w),
            Command::VarQuery(q) => q.write(w),
            Command::VarWrite(d) if d.kind() == VarKind::Text => Err(w.error(
                "values",
                "string variables cannot be written (no change message was found)",
            )),
            Command::VarWrite(d) => d.write(w),
            Command::ProgramStatus(q) => q.write(w),
            Command::Program(c) => c.write(w),
        }
    }

    /// Decodes a command frame (`!`). Lower-case hex is accepted; reserved bits and codes
    /// are refused with an error naming the field.
    pub fn decode(frame: &Frame<'_>) -> Result<Command, MessageError> {
        let Some(id) = frame.id().filter(|_| frame.header() == Header::Command) else {
            return Err(MessageError {
                message: frame.id(),
                role: Role::Command,
                kind: MessageErrorKind::WrongHeader {
                    expected: "a command ('!')",
                    found: frame.header(),
                },
            });
        };
        decode_command_data(id, frame.data(), frame.data_column(), None)
    }
}

/// Decodes command data (optionally recording fields for a description).
pub(crate) fn decode_command_data(
    id: MessageId,
    data: &[u8],
    col0: usize,
    rec: Option<&mut Vec<FieldDescription>>,
) -> Result<Command, MessageError> {
    let mut r = Reader::new(data, col0, Some(id), Role::Command, rec);
    let r = &mut r;
    let cmd = match id {
        MessageId::TEST_CALL => Command::TestCall(TestData::read(r)?),
        MessageId::VERSION => Command::Version(VersionQuery::read(r)?),
        MessageId::AXIS_STATUS => Command::AxisStatus {
            axes: r.pattern("query axis pattern")?,
        },
        MessageId::SYSTEM_STATUS => Command::SystemStatus,
        MessageId::ERROR_DETAIL => Command::ErrorDetail(ErrorDetailQuery::read(r)?),
        MessageId::SERVO => Command::Servo(Servo::read(r)?),
        MessageId::HOME => Command::Home(Home::read(r)?),
        MessageId::MOVE_ABSOLUTE => Command::MoveAbsolute(AxisMove::read(r, "target")?),
        MessageId::MOVE_RELATIVE => Command::MoveRelative(AxisMove::read(r, "distance")?),
        MessageId::JOG => Command::Jog(Jog::read(r)?),
        MessageId::STOP => Command::Stop(Stop::read(r)?),
        MessageId::ALARM_RESET => Command::AlarmReset,
        MessageId::SOFTWARE_RESET => Command::SoftwareReset,
        MessageId::SPEED_CHANGE => Command::SpeedChange(SpeedChange::read(r)?),
        MessageId::COORD_QUERY => Command::CoordQuery(CoordQuery::read(r)?),
        MessageId::SCARA_STATUS => Command::ScaraStatus(ScaraStatusQuery::read(r)?),
        MessageId::SCARA_STATUS_2 => Command::ScaraStatus2(ScaraStatusQuery2::read(r)?),
        MessageId::ZONE_QUERY => Command::ZoneQuery(ZoneQuery::read(r)?),
        MessageId::COORD_QUERY_2 => Command::CoordQuery2(CoordQuery2::read(r)?),
        MessageId::SCARA_MOVE_ABSOLUTE => Command::ScaraMoveAbsolute(ScaraMove::read(r, "target")?),
        MessageId::SCARA_MOVE_RELATIVE => {
            Command::ScaraMoveRelative(ScaraMove::read(r, "distance")?)
        }
        MessageId::SCARA_MOVE_POSITION => Command::ScaraMovePosition(ScaraPositionMove::read(r)?),
        MessageId::POSITION_QUERY => query(r, PositionQueryKind::Query)?,
        MessageId::POSITION_QUERY_2 => query(r, PositionQueryKind::Query2)?,
        MessageId::POSITION_QUERY_3 => query(r, PositionQueryKind::Query3)?,
        MessageId::POSITION_RANGE_WRITE => write(r, PositionWriteKind::Range)?,
        MessageId::POSITION_CHANGE_WRITE => write(r, PositionWriteKind::Change)?,
        MessageId::POSITION_CHANGE_WRITE_2 => write(r, PositionWriteKind::Change2)?,
        MessageId::POSITION_RANGE_WRITE_3 => write(r, PositionWriteKind::Range3)?,
        MessageId::POSITION_CHANGE_WRITE_3 => write(r, PositionWriteKind::Change3)?,
        MessageId::POSITION_MOVE => Command::PositionMove(PositionMove::read(r)?),
        MessageId::INPUT_QUERY => Command::BitQuery(BitQuery::read(r, BitSpace::Input)?),
        MessageId::OUTPUT_QUERY => Command::BitQuery(BitQuery::read(r, BitSpace::Output)?),
        MessageId::FLAG_QUERY => Command::BitQuery(BitQuery::read(r, BitSpace::Flag)?),
        MessageId::OUTPUT_CHANGE => Command::BitChange(BitChange::read(r, BitSpace::Output)?),
        MessageId::FLAG_CHANGE => Command::BitChange(BitChange::read(r, BitSpace::Flag)?),
        MessageId::INTEGER_QUERY => Command::VarQuery(VarQuery::read(r, VarKind::Integer)?),
        MessageId::REAL_QUERY => Command::VarQuery(VarQuery::read(r, VarKind::Real)?),
        MessageId::STRING_QUERY => Command::VarQuery(VarQuery::read(r, VarKind::Text)?),
        MessageId::INTEGER_CHANGE => Command::VarWrite(VarData::read(r, VarKind::Integer)?),
        MessageId::REAL_CHANGE => Command::VarWrite(VarData::read(r, VarKind::Real)?),
        MessageId::PROGRAM_STATUS => Command::ProgramStatus(ProgramStatusQuery::read(r)?),
        MessageId::PROGRAM_RUN => program(r, ProgramAction::Run)?,
        MessageId::PROGRAM_END => program(r, ProgramAction::End)?,
        MessageId::PROGRAM_PAUSE => program(r, ProgramAction::Pause)?,
        MessageId::PROGRAM_STEP => program(r, ProgramAction::Step)?,
        MessageId::PROGRAM_RESUME => program(r, ProgramAction::Resume)?,
        _ => {
            return Err(MessageError {
                message: Some(id),
                role: Role::Command,
                kind: MessageErrorKind::UnknownMessage,
            });
        }
    };
    r.finish()?;
    Ok(cmd)
}

fn query(r: &mut Reader<'_, '_>, kind: PositionQueryKind) -> Result<Command, MessageError> {
    Ok(Command::PositionQuery(PositionQuery::read(r, kind)?))
}

fn program(r: &mut Reader<'_, '_>, action: ProgramAction) -> Result<Command, MessageError> {
    Ok(Command::Program(ProgramCall::read(r, action)?))
}

fn write(r: &mut Reader<'_, '_>, kind: PositionWriteKind) -> Result<Command, MessageError> {
    Ok(Command::PositionWrite(PositionWrite::read(r, kind)?))
}
