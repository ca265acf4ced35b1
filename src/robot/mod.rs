//! SCARA model, kinematics, coordinate frames and motion profiles (pure math, no IO).

pub mod model;
pub mod units;

pub use model::{
    BUILTIN_MODELS, G_MM_S2, InPositionBand, JointSpec, ModelError, MoveDefaults, RobotModel,
};
pub use units::{Joints, Micrometres, Millidegrees, Pose, round_wire};
