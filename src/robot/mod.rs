//! SCARA model, kinematics, coordinate frames and motion profiles (pure math, no IO).
