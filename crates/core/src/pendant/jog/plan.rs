//! The jog planner: turns a jog button (axis, direction) and the jog settings into one
//! checked protocol command, or a refusal with its reason. Nothing refused reaches the line.

use serde::{Deserialize, Serialize};

use crate::pendant::teach::{TeachPoint, go_command};
use crate::protocol::{
    ArmPolicy as WirePolicy, Axis, AxisPattern, CentiG, Command, Direction, Jog, JogMotion, Milli,
    MmPerSec, PerAxis, Percent, ScaraMotion, ScaraMove,
};
use crate::robot::{
    ArmSystem, CoordSystem, CpMove, CpParams, DEFAULT_CHECK_SPACING_MM, JogFrame, Joints, Move,
    MoveError, PATH_SPACING_MM, PathCheck, Pose, PtpMove, PtpParams, RelativeTo, RobotModel, Scara,
    ZoneBox, jog_delta_to_work, sweep, tip_in_work,
};

/// The step ladder, mm (or deg for R and the rotary joints).
pub const STEP_LADDER: [f64; 5] = [0.01, 0.1, 1.0, 10.0, 50.0];

/// The largest step the pendant sends, mm or deg.
pub const MAX_STEP: f64 = 1000.0;

/// A jog button: a Cartesian axis of the chosen frame, or a joint.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum JogAxis {
    X,
    Y,
    Z,
    R,
    J1,
    J2,
    J3,
    J4,
}

impl JogAxis {
    pub const CARTESIAN: [JogAxis; 4] = [JogAxis::X, JogAxis::Y, JogAxis::Z, JogAxis::R];
    pub const JOINTS: [JogAxis; 4] = [JogAxis::J1, JogAxis::J2, JogAxis::J3, JogAxis::J4];

    pub fn name(self) -> &'static str {
        match self {
            JogAxis::X => "X",
            JogAxis::Y => "Y",
            JogAxis::Z => "Z",
            JogAxis::R => "R",
            JogAxis::J1 => "J1",
            JogAxis::J2 => "J2",
            JogAxis::J3 => "J3",
            JogAxis::J4 => "J4",
        }
    }

    /// Index 0-3 in `[x|j1, y|j2, z|j3, r|j4]`.
    pub fn index(self) -> usize {
        match self {
            JogAxis::X | JogAxis::J1 => 0,
            JogAxis::Y | JogAxis::J2 => 1,
            JogAxis::Z | JogAxis::J3 => 2,
            JogAxis::R | JogAxis::J4 => 3,
        }
    }

    pub fn is_joint(self) -> bool {
        matches!(self, JogAxis::J1 | JogAxis::J2 | JogAxis::J3 | JogAxis::J4)
    }

    /// "mm" or "deg".
    pub fn unit(self) -> &'static str {
        match self {
            JogAxis::Z | JogAxis::X | JogAxis::Y | JogAxis::J3 => "mm",
            _ => "deg",
        }
    }

    fn wire_axis(self) -> Axis {
        Axis::from_index(self.index() as u8).unwrap_or(Axis::A1)
    }
}

/// Step by step, or continuous while held.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum JogMode {
    #[default]
    Step,
    Continuous,
}

/// PTP (joint-interpolated) or CP (straight line).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum Interpolation {
    #[default]
    Ptp,
    Cp,
}

/// The jog panel's choices, persisted between runs.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct JogSettings {
    pub mode: JogMode,
    /// Step size, mm or deg.
    pub step: f64,
    pub interpolation: Interpolation,
    pub arm: WirePolicy,
    pub frame: JogFrame,
    pub relative_to: RelativeTo,
    /// PTP and joint moves: speed, acceleration and deceleration in % (0 = parameter).
    pub ptp_speed_pct: u16,
    pub ptp_accel_pct: u16,
    pub ptp_decel_pct: u16,
    /// CP moves and Cartesian jogs: speed in mm/s, accelerations in 0.01 G.
    pub cp_speed_mm_s: u16,
    pub cp_accel_cg: u16,
    pub cp_decel_cg: u16,
}

impl Default for JogSettings {
    fn default() -> Self {
        Self {
            mode: JogMode::Step,
            step: 1.0,
            interpolation: Interpolation::Ptp,
            arm: WirePolicy::KeepNoSwitch,
            frame: JogFrame::Work,
            relative_to: RelativeTo::Command,
            ptp_speed_pct: 20,
            ptp_accel_pct: 30,
            ptp_decel_pct: 30,
            cp_speed_mm_s: 50,
            cp_accel_cg: 30,
            cp_decel_cg: 30,
        }
    }
}

/// Which speed field of [`JogSettings`] a jog carries, and in which unit: the one
/// place every jog planner and the panel's "sends" lines take it from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SpeedSource {
    /// `ptp_speed_pct`, %: PTP steps (2D5H), joint steps and joint jogs (236H in the
    /// each-axis system).
    Percent,
    /// `cp_speed_mm_s`, mm/s: CP steps (2D5H) and Cartesian continuous jogs (236H in the
    /// base, work or tool frame).
    MmPerSec,
}

impl SpeedSource {
    /// The field a jog of a joint (`joint`) or a Cartesian axis carries in `settings`'
    /// mode. A 236H has no PTP or CP: its speed is in % in the each-axis system and in
    /// mm/s in the Cartesian ones (PROTOCOL.md 3.10 and section 5, erratum 12), so a
    /// continuous Cartesian jog carries the mm/s speed whatever the Motion choice.
    pub fn of(settings: &JogSettings, joint: bool) -> SpeedSource {
        match (joint, settings.mode, settings.interpolation) {
            (true, ..) => SpeedSource::Percent,
            (false, JogMode::Continuous, _) => SpeedSource::MmPerSec,
            (false, JogMode::Step, Interpolation::Ptp) => SpeedSource::Percent,
            (false, JogMode::Step, Interpolation::Cp) => SpeedSource::MmPerSec,
        }
    }

    /// "%" or "mm/s".
    pub fn unit(self) -> &'static str {
        match self {
            SpeedSource::Percent => "%",
            SpeedSource::MmPerSec => "mm/s",
        }
    }
}

impl JogSettings {
    /// The speed field `source` names (0 = the controller's parameter value).
    pub fn speed(&self, source: SpeedSource) -> u16 {
        match source {
            SpeedSource::Percent => self.ptp_speed_pct,
            SpeedSource::MmPerSec => self.cp_speed_mm_s,
        }
    }

    /// The next rung of the step ladder up (`larger`) or down.
    pub fn step_ladder(&mut self, larger: bool) {
        let next = if larger {
            STEP_LADDER.iter().find(|&&s| s > self.step + 1e-9)
        } else {
            STEP_LADDER.iter().rev().find(|&&s| s < self.step - 1e-9)
        };
        if let Some(&s) = next {
            self.step = s;
        }
    }
}

/// Why a step was not sent.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum Refusal {
    #[error("the step must be between 0.001 and {MAX_STEP} (got {0})")]
    BadStep(f64),
    #[error("the position is not known yet")]
    NoPosition,
    #[error("the {0} coordinate table has not been read yet")]
    NoTable(&'static str),
    #[error("{0}")]
    Move(#[from] MoveError),
    /// The target was set in other work or tool frames than the selected ones.
    #[error("{0}")]
    FramesChanged(String),
    #[error("{joint} would leave its limit: {value:.3} {unit} is outside {min:.3} to {max:.3}")]
    JointLimit {
        joint: &'static str,
        value: f64,
        unit: &'static str,
        min: f64,
        max: f64,
    },
}

impl Refusal {
    /// One short sentence for the line beside the pad; [`Refusal`]'s `Display` has the
    /// details (check point, distances), shown on hover and in Messages.
    pub fn short(&self) -> String {
        use crate::robot::IkError;
        let ik = |e: &IkError| match e {
            IkError::TooFar { .. } => "out of reach".to_owned(),
            IkError::TooNear { .. } => "too close to the base".to_owned(),
            IkError::Singular { .. } => "in the singular zone (arm nearly straight)".to_owned(),
            IkError::JointLimit { joint, .. } => format!("{joint:?} beyond its limit"),
            IkError::NotFinite => "not a number".to_owned(),
        };
        match self {
            Refusal::Move(MoveError::CpLine {
                position, reason, ..
            }) => {
                let what = match reason {
                    IkError::TooFar { .. } => "leaves the reach".to_owned(),
                    IkError::TooNear { .. } => "comes too close to the base".to_owned(),
                    IkError::Singular { .. } => "crosses the singular zone".to_owned(),
                    IkError::JointLimit { joint, .. } => {
                        format!("takes {joint:?} beyond its limit")
                    }
                    IkError::NotFinite => "is not a number".to_owned(),
                };
                format!(
                    "CP line {what} near X {:.0}, Y {:.0}",
                    position.x, position.y
                )
            }
            Refusal::Move(MoveError::CpAroundBase { .. }) => {
                "CP line would swing the arm around the base".to_owned()
            }
            Refusal::Move(MoveError::Unreachable(e)) => format!("target {}", ik(e)),
            Refusal::Move(MoveError::ArmSwitchNotAllowed { .. }) => {
                "needs the other arm system (this move may not switch)".to_owned()
            }
            Refusal::Move(MoveError::NotReachableWithArm { arm, reason }) => {
                format!("{} with the {arm} arm", ik(reason))
            }
            Refusal::JointLimit { joint, .. } => format!("{joint} would leave its limit"),
            other => other.to_string(),
        }
    }
}

/// What the planner needs to know of the arm now (and of the cell: its zones).
#[derive(Clone, Copy, Debug)]
pub struct ArmNow<'a> {
    /// Polled joints.
    pub joints: Joints,
    /// Where the last accepted move ends (joints), if one is known.
    pub command: Option<Joints>,
    /// Where the profile is now (joints), if a move is being followed.
    pub target: Option<Joints>,
    pub work: CoordSystem,
    pub tool: CoordSystem,
    /// The controller's interference zones, base frame: a path into one asks for a
    /// second press.
    pub zones: &'a [ZoneBox],
}

/// A checked step: the command to send and what it will do.
#[derive(Clone, Debug, PartialEq)]
pub struct PlannedStep {
    pub command: Command,
    /// The joints at the end of the step.
    pub end: Joints,
    /// The tool tip at the end, in the work frame (mm, deg).
    pub end_work: Pose,
    /// For CP steps, the straight line's ends in the base frame.
    pub line: Option<(Pose, Pose)>,
    /// A PTP step whose end is in the other arm system.
    pub flips_arm: bool,
    /// The same move as the robot layer plans it, followed to show the motion phase.
    /// [inferred] The controller reports no phase; the pendant replays the profile.
    pub profile: Move,
    /// The tool tip's whole path, sampled and checked (the zones it enters); the ghost
    /// draws the same samples.
    pub path: PathCheck,
}

impl PlannedStep {
    /// Why this move waits for a second press: it flips the arm system, its path enters
    /// interference zones; `None`: it goes on the first.
    pub fn second_press(&self) -> Option<String> {
        let mut why = Vec::new();
        if self.flips_arm {
            why.push("flips the arm system".to_owned());
        }
        if !self.path.zones.is_empty() {
            why.push(format!("enters {}", zones_text(&self.path.zones)));
        }
        (!why.is_empty()).then(|| why.join(" and "))
    }

    /// The words that ask for the second press: `what` (the move's name) and why, what a
    /// zone does, and the time left to press again.
    pub fn confirm_text(&self, what: &str, again: &str) -> Option<String> {
        let why = self.second_press()?;
        let zone = if self.path.zones.is_empty() {
            String::new()
        } else {
            format!(" ({})", crate::pendant::zones::ZONE_ACTION)
        };
        Some(format!(
            "{what} {why}{zone}: press {again} within {} s to confirm",
            crate::pendant::CONFIRM_FOR.as_secs()
        ))
    }
}

/// Zones named as the pendant says them: "zone 2", "zones 1, 2".
pub fn zones_text(zones: &[u8]) -> String {
    let list = zones
        .iter()
        .map(u8::to_string)
        .collect::<Vec<_>>()
        .join(", ");
    if zones.len() == 1 {
        format!("zone {list}")
    } else {
        format!("zones {list}")
    }
}

fn check_step(step: f64) -> Result<f64, Refusal> {
    if step.is_finite() && (0.001..=MAX_STEP).contains(&step) {
        Ok(step)
    } else {
        Err(Refusal::BadStep(step))
    }
}

fn sign(dir: Direction) -> f64 {
    match dir {
        Direction::Positive => 1.0,
        Direction::Negative => -1.0,
    }
}

/// Plans one step of `axis` in `dir` with `settings`: 2D5H for Cartesian axes (PTP or CP,
/// in the selected work frame), 236H inching in the each-axis system for joints.
pub fn plan_step(
    model: &RobotModel,
    kin: &Scara,
    settings: &JogSettings,
    axis: JogAxis,
    dir: Direction,
    now: &ArmNow,
) -> Result<PlannedStep, Refusal> {
    let step = check_step(settings.step)? * sign(dir);
    if axis.is_joint() {
        return plan_joint_step(model, kin, settings, axis, step, dir, now);
    }
    let at = |j: &Joints| tip_in_work(kin, j, &now.work, &now.tool);
    let actual = at(&now.joints);
    let positions = crate::robot::Positions {
        command: now.command.map_or(actual, |j| at(&j)),
        actual,
        target: now.target.map_or(actual, |j| at(&j)),
    };
    let mut delta = [0.0; 4];
    delta[axis.index()] = step;
    let delta = Pose::from_array(delta);
    let flange_r = kin.forward(&now.joints).r;
    let delta_work = jog_delta_to_work(&delta, settings.frame, &now.work, &now.tool, flange_r);
    let (_, end_work) = crate::robot::relative_move(settings.relative_to, &positions, delta_work);
    // [inferred] The controller adds a 2D5H distance to its command position (where its
    // last move ends, where the arm stands once in position); PROTOCOL.md 3.20 does not
    // say which of its positions it uses. The pendant's estimate of it is the end of the
    // last move it saw accepted, else the polled position. The distance sent is the
    // chosen end minus that estimate, so steps relative to the command position carry
    // exactly the step, and a stale or quantised poll never creeps into them.
    let reference = positions.command;
    let distance = (end_work - reference).to_wire();
    let mut targets = PerAxis::new();
    for (i, d) in distance.iter().enumerate() {
        if *d != 0 || i == axis.index() {
            targets.set(Axis::from_index(i as u8).unwrap_or(Axis::A1), Milli(*d));
        }
    }
    let end_work = reference + Pose::from_wire(distance);
    let checked = check_move(model, kin, settings, settings.arm, &end_work, now)?;
    let motion = checked.motion;
    Ok(checked.into_plan(Command::ScaraMoveRelative(ScaraMove { motion, targets })))
}

/// A move to `end_work` that passed every check, with its motion field and profile.
struct CheckedMove {
    motion: ScaraMotion,
    end_work: Pose,
    profile: Move,
    line: Option<(Pose, Pose)>,
    flips_arm: bool,
    path: PathCheck,
}

impl CheckedMove {
    fn into_plan(self, command: Command) -> PlannedStep {
        PlannedStep {
            command,
            end: self.profile.end(),
            end_work: self.end_work,
            line: self.line,
            flips_arm: self.flips_arm,
            profile: self.profile,
            path: self.path,
        }
    }
}

/// Checks a move of the tool tip to `end_work` (work frame) as the controller would run
/// it: PTP under `policy` (reach, joint limits, arm system), or CP along the whole line.
fn check_move(
    model: &RobotModel,
    kin: &Scara,
    settings: &JogSettings,
    policy: WirePolicy,
    end_work: &Pose,
    now: &ArmNow,
) -> Result<CheckedMove, Refusal> {
    let end_tip = now.work.work_to_base(end_work);
    let (motion, profile, line, flips_arm) = match settings.interpolation {
        Interpolation::Ptp => {
            let params = PtpParams::from_command(
                model,
                settings.ptp_accel_pct,
                settings.ptp_decel_pct,
                settings.ptp_speed_pct,
            );
            let flange = now.tool.tip_to_flange(&end_tip);
            let m = PtpMove::to_pose(kin, now.joints, &flange, policy.into(), &params)?;
            let flips = arm_of(kin, &m.end()) != arm_of(kin, &now.joints)
                && arm_of(kin, &now.joints) != ArmSystem::Undetermined;
            let motion = ScaraMotion::Ptp {
                acc: Percent(settings.ptp_accel_pct),
                dec: Percent(settings.ptp_decel_pct),
                speed: Percent(settings.speed(SpeedSource::Percent)),
                arm: policy,
            };
            (motion, Move::Ptp(m), None, flips)
        }
        Interpolation::Cp => {
            let params = CpParams::from_command(
                model,
                settings.cp_accel_cg,
                settings.cp_decel_cg,
                settings.cp_speed_mm_s,
            );
            let m = CpMove::plan(
                kin,
                now.joints,
                &end_tip,
                &now.tool,
                &params,
                DEFAULT_CHECK_SPACING_MM,
            )?;
            let motion = ScaraMotion::Cp {
                acc: CentiG(settings.cp_accel_cg),
                dec: CentiG(settings.cp_decel_cg),
                speed: MmPerSec(settings.speed(SpeedSource::MmPerSec)),
            };
            let line = Some(m.tip_line());
            (motion, Move::Cp(Box::new(m)), line, false)
        }
    };
    let path = sweep(kin, &profile, &now.tool, now.zones, PATH_SPACING_MM);
    Ok(CheckedMove {
        motion,
        end_work: *end_work,
        profile,
        line,
        flips_arm,
        path,
    })
}

/// Plans a move to a taught point with 2D4H (absolute, selected work frame): PTP with
/// the point's own arm system, or CP, at the jog panel's rates, after the same checks
/// as a step.
pub fn plan_go(
    model: &RobotModel,
    kin: &Scara,
    settings: &JogSettings,
    point: &TeachPoint,
    now: &ArmNow,
) -> Result<PlannedStep, Refusal> {
    let end_work = Pose::from_wire(point.pose);
    let checked = check_move(model, kin, settings, point.arm_policy(), &end_work, now)?;
    let command = go_command(point, checked.motion);
    Ok(checked.into_plan(command))
}

/// Plans a move to the controller's position record `rec` with 2D6H (the controller moves
/// to what it holds at that number, in the selected work frame), PTP with the record's arm
/// system (the jog panel's policy where the record names none) or CP, at the jog panel's
/// rates (capped), after the same checks as a step. Axes the record lacks stay where they
/// are.
pub fn plan_position_go(
    model: &RobotModel,
    kin: &Scara,
    settings: &JogSettings,
    rec: &crate::protocol::PositionRecord,
    now: &ArmNow,
) -> Result<PlannedStep, Refusal> {
    use crate::protocol::{RecordArm, ScaraPositionMove};
    let here = tip_in_work(kin, &now.joints, &now.work, &now.tool).to_wire();
    let axes = [Axis::A1, Axis::A2, Axis::A3, Axis::A4];
    let mut wire = here;
    for (i, a) in axes.into_iter().enumerate() {
        if let Some(v) = rec.coords.get(a) {
            wire[i] = v.0;
        }
    }
    let policy = match rec.arms.scara1 {
        RecordArm::Right => WirePolicy::Right,
        RecordArm::Left => WirePolicy::Left,
        RecordArm::Unspecified => settings.arm,
    };
    let checked = check_move(model, kin, settings, policy, &Pose::from_wire(wire), now)?;
    let command = Command::ScaraMovePosition(ScaraPositionMove {
        axes: AxisPattern::SCARA_1,
        motion: checked.motion,
        position: rec.number,
    });
    Ok(checked.into_plan(command))
}

/// Plans a move of the tool tip to `end_work` (selected work frame) with 2D4H: the jog
/// panel's interpolation, arm policy and rates, after the same checks as a step.
pub fn plan_to(
    model: &RobotModel,
    kin: &Scara,
    settings: &JogSettings,
    end_work: &Pose,
    now: &ArmNow,
) -> Result<PlannedStep, Refusal> {
    let checked = check_move(model, kin, settings, settings.arm, end_work, now)?;
    let [x, y, z, r] = end_work.to_wire();
    let targets = PerAxis::from_pairs([
        (Axis::A1, Milli(x)),
        (Axis::A2, Milli(y)),
        (Axis::A3, Milli(z)),
        (Axis::A4, Milli(r)),
    ]);
    let motion = checked.motion;
    Ok(checked.into_plan(Command::ScaraMoveAbsolute(ScaraMove { motion, targets })))
}

fn arm_of(kin: &Scara, j: &Joints) -> ArmSystem {
    kin.arm_system(j)
}

fn plan_joint_step(
    model: &RobotModel,
    kin: &Scara,
    settings: &JogSettings,
    axis: JogAxis,
    step: f64,
    dir: Direction,
    now: &ArmNow,
) -> Result<PlannedStep, Refusal> {
    let mut end = now.joints.to_array();
    end[axis.index()] += step;
    let end = Joints::from_array(end);
    let spec = [kin.j1, kin.j2, kin.z, kin.r][axis.index()];
    let value = end.to_array()[axis.index()];
    if !spec.contains(value) {
        return Err(Refusal::JointLimit {
            joint: axis.name(),
            value,
            unit: axis.unit(),
            min: spec.min,
            max: spec.max,
        });
    }
    let params = PtpParams::from_command(
        model,
        settings.ptp_accel_pct,
        settings.ptp_decel_pct,
        settings.ptp_speed_pct,
    );
    let distance = crate::robot::round_wire(step.abs() * 1000.0);
    let command = Command::Jog(Jog {
        axes: AxisPattern::single(axis.wire_axis()),
        direction: dir,
        distance: Milli(distance),
        motion: JogMotion::Joint {
            acc: Percent(settings.ptp_accel_pct),
            dec: Percent(settings.ptp_decel_pct),
            speed: Percent(settings.speed(SpeedSource::Percent)),
        },
    });
    let profile = Move::Ptp(PtpMove::joints(kin, now.joints, end, &params)?);
    Ok(PlannedStep {
        command,
        end,
        end_work: tip_in_work(kin, &end, &now.work, &now.tool),
        line: None,
        flips_arm: false,
        path: sweep(kin, &profile, &now.tool, now.zones, PATH_SPACING_MM),
        profile,
    })
}

/// The 236H of a continuous jog ([`Jog::until_stopped`]): Cartesian axes in the chosen
/// frame at the mm/s rates, joints at the % rates, whatever the Motion (PTP/CP) choice,
/// which a 236H does not have ([`SpeedSource::of`]).
pub fn continuous_jog(settings: &JogSettings, axis: JogAxis, dir: Direction) -> Command {
    let settings = &JogSettings {
        mode: JogMode::Continuous,
        ..settings.clone()
    };
    let speed = settings.speed(SpeedSource::of(settings, axis.is_joint()));
    let motion = if axis.is_joint() {
        JogMotion::Joint {
            acc: Percent(settings.ptp_accel_pct),
            dec: Percent(settings.ptp_decel_pct),
            speed: Percent(speed),
        }
    } else {
        JogMotion::Cartesian {
            frame: settings.frame.into(),
            acc: CentiG(settings.cp_accel_cg),
            dec: CentiG(settings.cp_decel_cg),
            speed: MmPerSec(speed),
        }
    };
    Command::Jog(Jog::until_stopped(
        AxisPattern::single(axis.wire_axis()),
        dir,
        motion,
    ))
}

/// A jog as the operator's hand means it: the direction in the world, not the sign.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PhysicalJog {
    XPlus,
    XMinus,
    YPlus,
    YMinus,
    /// Raise the tool.
    ZUp,
    /// Lower the tool.
    ZDown,
    /// R counter-clockwise seen from above (R+: angles count counter-clockwise).
    RCcw,
    RCw,
}

impl PhysicalJog {
    pub fn name(self) -> &'static str {
        match self {
            PhysicalJog::XPlus => "X+",
            PhysicalJog::XMinus => "X-",
            PhysicalJog::YPlus => "Y+",
            PhysicalJog::YMinus => "Y-",
            PhysicalJog::ZUp => "Z up",
            PhysicalJog::ZDown => "Z down",
            PhysicalJog::RCcw => "R ccw",
            PhysicalJog::RCw => "R cw",
        }
    }

    /// The axis and sign sent for this motion on `model`.
    pub fn target(self, model: &RobotModel) -> super::hold::JogTarget {
        use Direction::{Negative, Positive};
        let (up, down) = if model.z_counts_down {
            (Negative, Positive)
        } else {
            (Positive, Negative)
        };
        let (axis, direction) = match self {
            PhysicalJog::XPlus => (JogAxis::X, Positive),
            PhysicalJog::XMinus => (JogAxis::X, Negative),
            PhysicalJog::YPlus => (JogAxis::Y, Positive),
            PhysicalJog::YMinus => (JogAxis::Y, Negative),
            PhysicalJog::ZUp => (JogAxis::Z, up),
            PhysicalJog::ZDown => (JogAxis::Z, down),
            PhysicalJog::RCcw => (JogAxis::R, Positive),
            PhysicalJog::RCw => (JogAxis::R, Negative),
        };
        super::hold::JogTarget::new(axis, direction)
    }
}
