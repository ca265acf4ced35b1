//! `Reply`: every controller-to-host message, including the `&` error reply.

use super::axis::PerAxis;
use super::checksum::ScMode;
use super::describe::FieldDescription;
use super::error::{EncodeError, MessageError, MessageErrorKind};
use super::fields::{Name, Reader};
use super::frame::Frame;
use super::ids::{ErrorCode, Header, MessageId, Role, Station};
use super::messages::basic::{ErrorDetail, TestData, VersionInfo};
use super::messages::coords::{CoordTable, CoordTable2};
use super::messages::positions::{
    PositionData, PositionQueryKind, PositionWriteKind, PositionsWritten,
};
use super::messages::programs::ProgramStatus;
use super::messages::scara_status::{ScaraStatus, ScaraStatus2};
use super::messages::signals::{BitData, BitSpace, VarData, VarKind, VarsWritten};
use super::messages::status::{AxisState, SystemStatus, read_axis_blocks, write_axis_blocks};
use super::messages::zones::ZoneTable;
use super::units::AxisUnit;
use super::writer::{Writer, encode_frame};

/// A reply frame's meaning (PROTOCOL.md sections 2 and 3).
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub enum Reply {
    /// The plain acknowledge (no data) of 232H, 233H, 234H, 235H, 236H, 238H, 24AH, 24BH,
    /// 252H, 253H-257H, 25BH, 262H, 26BH, 2D4H, 2D5H, 2D6H.
    Ack(MessageId),
    /// 200H test call echo.
    TestCall(TestData),
    /// 201H version information.
    Version(VersionInfo),
    /// 212H axis status: one block per reported axis (missing axis = not connected).
    AxisStatus(PerAxis<AxisState>),
    /// 215H system status.
    SystemStatus(SystemStatus),
    /// 216H error details.
    ErrorDetail(ErrorDetail),
    /// 2A0H coordinate system definitions (4 axes per record).
    CoordTable(CoordTable),
    /// 2A1H SCARA axis status.
    ScaraStatus(ScaraStatus),
    /// 2A2H interference-check zone definitions (records sized by the reply length).
    ZoneTable(ZoneTable),
    /// 2A3H SCARA axis status 2.
    ScaraStatus2(ScaraStatus2),
    /// 2A4H coordinate system definitions by axis pattern.
    CoordTable2(CoordTable2),
    /// 209H / 21FH / 22DH effective position records.
    Positions(PositionData),
    /// 244H / 245H / 26DH / 290H / 291H: how many positions were written.
    PositionsWritten(PositionsWritten),
    /// 20BH / 20CH / 20DH: ports or flags, 8 to a group.
    Bits(BitData),
    /// 20EH / 20FH / 210H: variable values.
    Vars(VarData),
    /// 24CH / 24DH: how many variables were changed.
    VarsWritten(VarsWritten),
    /// 213H: one program's status.
    ProgramStatus(ProgramStatus),
    /// `&` error reply: the command was understood but cannot be executed.
    Error(ErrorCode),
}

impl Reply {
    /// The message ID the reply carries; `None` for an error reply.
    pub fn id(&self) -> Option<MessageId> {
        Some(match self {
            Reply::Ack(id) => *id,
            Reply::TestCall(_) => MessageId::TEST_CALL,
            Reply::Version(_) => MessageId::VERSION,
            Reply::AxisStatus(_) => MessageId::AXIS_STATUS,
            Reply::SystemStatus(_) => MessageId::SYSTEM_STATUS,
            Reply::ErrorDetail(_) => MessageId::ERROR_DETAIL,
            Reply::CoordTable(_) => MessageId::COORD_QUERY,
            Reply::ScaraStatus(_) => MessageId::SCARA_STATUS,
            Reply::ZoneTable(_) => MessageId::ZONE_QUERY,
            Reply::ScaraStatus2(_) => MessageId::SCARA_STATUS_2,
            Reply::CoordTable2(_) => MessageId::COORD_QUERY_2,
            Reply::Positions(p) => p.kind.id(),
            Reply::PositionsWritten(w) => w.kind.id(),
            Reply::Bits(b) => b.space.id(),
            Reply::Vars(v) => v.kind().query_id(),
            Reply::VarsWritten(w) => match w.kind {
                VarKind::Real => MessageId::REAL_CHANGE,
                _ => MessageId::INTEGER_CHANGE,
            },
            Reply::ProgramStatus(_) => MessageId::PROGRAM_STATUS,
            Reply::Error(_) => return None,
        })
    }

    /// Appends the complete frame (header to CR LF) with a computed SC to `out`.
    /// On error `out` is left as it was.
    pub fn encode_into(&self, station: Station, out: &mut Vec<u8>) -> Result<(), EncodeError> {
        self.encode_with_sc(station, ScMode::Computed, out)
    }

    /// As [`Reply::encode_into`], choosing the SC (a controller always computes it; `@@` is
    /// for tests of the client's tolerance).
    pub fn encode_with_sc(
        &self,
        station: Station,
        sc: ScMode,
        out: &mut Vec<u8>,
    ) -> Result<(), EncodeError> {
        match self {
            Reply::Error(code) => {
                encode_frame(out, Header::Error, station, None, MessageId(0), sc, |w| {
                    w.hex("error code", u32::from(code.0), 3)
                })
            }
            _ => {
                let id = self.id().unwrap_or(MessageId(0));
                encode_frame(out, Header::Reply, station, Some(id), id, sc, |w| {
                    self.write_data(w)
                })
            }
        }
    }

    /// The complete frame as a new vector.
    pub fn to_bytes(&self, station: Station) -> Result<Vec<u8>, EncodeError> {
        let mut v = Vec::with_capacity(64);
        self.encode_into(station, &mut v)?;
        Ok(v)
    }

    fn write_data(&self, w: &mut Writer<'_>) -> Result<(), EncodeError> {
        match self {
            Reply::Ack(id) => {
                if id.is_plain_ack() {
                    Ok(())
                } else {
                    Err(w.error("message ID", format!("{id} has no plain acknowledge reply")))
                }
            }
            Reply::TestCall(d) => d.write(w),
            Reply::Version(v) => v.write(w),
            Reply::AxisStatus(a) => write_axis_blocks(w, a),
            Reply::SystemStatus(s) => s.write(w),
            Reply::ErrorDetail(d) => d.write(w),
            Reply::CoordTable(t) => t.write(w),
            Reply::ScaraStatus(s) => s.write(w),
            Reply::ZoneTable(t) => t.write(w),
            Reply::ScaraStatus2(s) => s.write(w),
            Reply::CoordTable2(t) => t.write(w),
            Reply::Positions(p) => p.write(w),
            Reply::PositionsWritten(p) => p.write(w),
            Reply::Bits(b) => b.write(w),
            Reply::Vars(v) => v.write(w),
            Reply::VarsWritten(v) => v.write(w),
            Reply::ProgramStatus(p) => p.write(w),
            Reply::Error(_) => Ok(()),
        }
    }

    /// Decodes a reply frame: `#` by its message ID, `&` into [`Reply::Error`]. Lower-case
    /// hex is accepted; reserved bits of status bytes are ignored, reserved codes refused.
    pub fn decode(frame: &Frame<'_>) -> Result<Reply, MessageError> {
        match (frame.header(), frame.id()) {
            (Header::Error, _) => decode_error_data(frame.data(), frame.data_column(), None),
            (Header::Reply, Some(id)) => {
                decode_reply_data(id, frame.data(), frame.data_column(), None)
            }
            (found, id) => Err(MessageError {
                message: id,
                role: Role::Reply,
                kind: MessageErrorKind::WrongHeader {
                    expected: "a reply ('#' or '&')",
                    found,
                },
            }),
        }
    }
}

/// Decodes the data of an `&` frame (the error code).
pub(crate) fn decode_error_data(
    data: &[u8],
    col0: usize,
    rec: Option<&mut Vec<FieldDescription>>,
) -> Result<Reply, MessageError> {
    let mut r = Reader::new(data, col0, None, Role::Reply, rec);
    let code = r.error_code(Name::new("error code"))?;
    r.finish()?;
    Ok(Reply::Error(code))
}

/// Decodes the data of a `#` frame with message ID `id`.
pub(crate) fn decode_reply_data(
    id: MessageId,
    data: &[u8],
    col0: usize,
    rec: Option<&mut Vec<FieldDescription>>,
) -> Result<Reply, MessageError> {
    let mut r = Reader::new(data, col0, Some(id), Role::Reply, rec);
    let r = &mut r;
    let reply = match id {
        _ if id.is_plain_ack() => Reply::Ack(id),
        MessageId::TEST_CALL => Reply::TestCall(TestData::read(r)?),
        MessageId::VERSION => Reply::Version(VersionInfo::read(r)?),
        MessageId::AXIS_STATUS => {
            let p = r.pattern("axis pattern")?;
            Reply::AxisStatus(read_axis_blocks(r, p, |_| AxisUnit::Mm)?)
        }
        MessageId::SYSTEM_STATUS => Reply::SystemStatus(SystemStatus::read(r)?),
        MessageId::ERROR_DETAIL => Reply::ErrorDetail(ErrorDetail::read(r)?),
        MessageId::COORD_QUERY => Reply::CoordTable(CoordTable::read(r)?),
        MessageId::SCARA_STATUS => Reply::ScaraStatus(ScaraStatus::read(r)?),
        MessageId::ZONE_QUERY => Reply::ZoneTable(ZoneTable::read(r)?),
        MessageId::SCARA_STATUS_2 => Reply::ScaraStatus2(ScaraStatus2::read(r)?),
        MessageId::COORD_QUERY_2 => Reply::CoordTable2(CoordTable2::read(r)?),
        MessageId::POSITION_QUERY => positions(r, PositionQueryKind::Query)?,
        MessageId::POSITION_QUERY_2 => positions(r, PositionQueryKind::Query2)?,
        MessageId::POSITION_QUERY_3 => positions(r, PositionQueryKind::Query3)?,
        MessageId::POSITION_RANGE_WRITE => written(r, PositionWriteKind::Range)?,
        MessageId::POSITION_CHANGE_WRITE => written(r, PositionWriteKind::Change)?,
        MessageId::POSITION_CHANGE_WRITE_2 => written(r, PositionWriteKind::Change2)?,
        MessageId::POSITION_RANGE_WRITE_3 => written(r, PositionWriteKind::Range3)?,
        MessageId::POSITION_CHANGE_WRITE_3 => written(r, PositionWriteKind::Change3)?,
        MessageId::INPUT_QUERY => Reply::Bits(BitData::read(r, BitSpace::Input)?),
        MessageId::OUTPUT_QUERY => Reply::Bits(BitData::read(r, BitSpace::Output)?),
        MessageId::FLAG_QUERY => Reply::Bits(BitData::read(r, BitSpace::Flag)?),
        MessageId::INTEGER_QUERY => Reply::Vars(VarData::read(r, VarKind::Integer)?),
        MessageId::REAL_QUERY => Reply::Vars(VarData::read(r, VarKind::Real)?),
        MessageId::STRING_QUERY => Reply::Vars(VarData::read(r, VarKind::Text)?),
        MessageId::INTEGER_CHANGE => Reply::VarsWritten(VarsWritten::read(r, VarKind::Integer)?),
        MessageId::REAL_CHANGE => Reply::VarsWritten(VarsWritten::read(r, VarKind::Real)?),
        MessageId::PROGRAM_STATUS => Reply::ProgramStatus(ProgramStatus::read(r)?),
        _ => {
            return Err(MessageError {
                message: Some(id),
                role: Role::Reply,
                kind: MessageErrorKind::UnknownMessage,
            });
        }
    };
    r.finish()?;
    Ok(reply)
}

fn positions(r: &mut Reader<'_, '_>, kind: PositionQueryKind) -> Result<Reply, MessageError> {
    Ok(Reply::Positions(PositionData::read(r, kind)?))
}

fn written(r: &mut Reader<'_, '_>, kind: PositionWriteKind) -> Result<Reply, MessageError> {
    Ok(Reply::PositionsWritten(PositionsWritten::read(r, kind)?))
}
