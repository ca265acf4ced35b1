//! SCARA model, kinematics, coordinate frames and motion profiles (pure math, no IO).
//!
//! Units: inside `robot` positions are f64 mm and deg ([`Pose`], [`Joints`]); they become
//! wire integers (0.001 mm, 0.001 deg) only at the edges, through [`round_wire`]. Time is
//! always an argument (seconds since a move started); nothing here reads a clock or does IO.

pub mod cp;
pub mod frames;
pub mod kinematics;
pub mod model;
pub mod motion;
pub mod path;
pub mod profile;
pub mod units;

pub use cp::{CpMove, DEFAULT_CHECK_SPACING_MM, MAX_CHECK_POINTS};
pub use frames::{
    CoordSystem, CoordTable, CoordTables, FrameError, FrameKind, JogFrame, inverse_in_work,
    jog_delta_to_work, jog_delta_to_work_wire, snap_to_wire, tip_in_work,
};
pub use kinematics::{Arm, ArmSystem, IkError, Joint, Scara};
pub use model::{
    BUILTIN_MODELS, G_MM_S2, InPositionBand, JointSpec, MAX_TABLE_SIZE, ModelError, MoveDefaults,
    RobotModel,
};
pub use motion::{
    ArmPolicy, CpParams, MotionStatus, Move, MoveError, MoveSample, Positions, PtpMove, PtpParams,
    RelativeTo, in_position, relative_move, solve_arm_policy,
};
pub use path::{MAX_PATH_SAMPLES, PATH_SPACING_MM, PathCheck, PathFault, PathMark, ZoneBox, sweep};
pub use profile::{Phase, ProfileError, ProfileSample, Trapezoid};
pub use units::{Joints, Micrometres, Millidegrees, Pose, round_wire};
