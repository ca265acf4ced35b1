//! The Format B codec, sans-IO: bytes <-> typed commands and replies, in both roles.
//!
//! * [`Frame`] parses one complete frame and checks its SC; [`StreamDecoder`] splits a byte
//!   stream into frames and typed errors, resynchronising on the next header; both it and
//!   the simulator's receiver split the stream with [`deframe::Deframer`].
//! * [`Command`] and [`Reply`] encode and decode every message of PROTOCOL.md section 3.
//! * [`describe()`] explains any bytes field by field, for the frame log.
//!
//! No IO, no clock, no threads; nothing else of the project is imported.

pub mod arm;
pub mod axis;
pub mod checksum;
pub mod command;
pub mod decoder;
pub mod deframe;
pub mod describe;
pub mod error;
mod fields;
pub mod frame;
mod hex;
pub mod ids;
pub mod messages;
pub mod peek;
pub mod reply;
pub mod units;
mod writer;

pub use arm::{ArmPolicy, ArmSystem};
pub use axis::{Axis, AxisIter, AxisPattern, PerAxis};
pub use checksum::{Sc, ScMode, checksum};
pub use command::Command;
pub use decoder::{DecodeError, StreamDecoder};
pub use describe::{
    BitNote, ChecksumVerdict, FieldDescription, FrameDescription, Problem, describe,
};
pub use error::{Columns, EncodeError, MessageError, MessageErrorKind};
pub use frame::{
    COMMAND_BUFFER, Frame, FrameError, FrameErrorKind, MAX_FRAME_LEN, MIN_FRAME_LEN, OwnedFrame,
    REPLY_BUFFER, SMALL_COMMAND_BUFFER, SMALL_REPLY_BUFFER,
};
pub use ids::{ErrorCode, Header, MessageId, Role, Station, StationParseError};
pub use messages::basic::{
    ErrorDetail, ErrorDetailQuery, TestData, UnitType, VersionInfo, VersionQuery,
};
pub use messages::coords::{
    COORD_RECORDS, CoordKind, CoordQuery, CoordQuery2, CoordTable, CoordTable2, XyzR,
};
pub use messages::motion::{
    AxisMove, Direction, Home, Jog, JogFrame, JogMotion, Servo, SpeedChange, Stop,
};
pub use messages::positions::{
    MAX_POSITIONS_3_DIGIT, MAX_POSITIONS_4_DIGIT, PositionData, PositionMove, PositionQuery,
    PositionQueryKind, PositionRecord, PositionWrite, PositionWriteKind, PositionsWritten,
    RecordArm, RecordArms,
};
pub use messages::programs::{
    ALL_PROGRAMS, PROGRAMS, ProgramAction, ProgramCall, ProgramFlags, ProgramStatus,
    ProgramStatusQuery,
};
pub use messages::scara::{ScaraMotion, ScaraMove, ScaraPositionMove};
pub use messages::scara_status::{
    CommonStatus, PositionSystem, ScaraStatus, ScaraStatus2, ScaraStatusQuery, ScaraStatusQuery2,
    ScaraUnitStatus,
};
pub use messages::signals::{
    BitChange, BitData, BitQuery, BitSpace, Category, GLOBAL_FLAGS, INPUTS, LOCAL_FLAGS, OUTPUTS,
    RealEncoding, RealWord, VarData, VarKind, VarQuery, VarValues, VarsWritten,
};
pub use messages::status::{
    AxisState, AxisStatus, EncoderStatus, HomeState, SensorInput, SystemMode, SystemStatus,
    SystemStatus1, SystemStatus2, SystemStatus3,
};
pub use messages::zones::{ZONE_NUMBERS, ZONE_TAIL_ALLOWANCE, ZoneQuery, ZoneRecord, ZoneTable};
pub use reply::Reply;
pub use units::{AxisUnit, CentiG, Milli, MmPerSec, Percent};
pub use writer::command_frame;
