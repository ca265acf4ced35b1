//! SCARA model, kinematics, coordinate frames and motion profiles (pure math, no IO).

pub mod frames;
pub mod kinematics;
pub mod model;
pub mod units;

pub use frames::{
    CoordSystem, CoordTable, CoordTables, FrameError, FrameKind, JogFrame, inverse_in_work,
    jog_delta_to_work, jog_delta_to_work_wire, snap_to_wire, tip_in_work,
};
pub use kinematics::{Arm, ArmSystem, IkError, Joint, Scara};
pub use model::{
    BUILTIN_MODELS, G_MM_S2, InPositionBand, JointSpec, ModelError, MoveDefaults, RobotModel,
};
pub use units::{Joints, Micrometres, Millidegrees, Pose, round_wire};
