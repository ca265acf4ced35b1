//! Status queries: 212H axis status, 2A1H and 2A3H SCARA axis status.

use crate::protocol::{
    self, AxisPattern, AxisStatus, CommonStatus, EncoderStatus, ErrorCode, Milli, PerAxis,
    PositionSystem, Reply, ScaraStatus, ScaraStatus2, ScaraUnitStatus, SensorInput,
};
use crate::robot::round_wire;
use crate::sim::controller::Controller;

impl Controller {
    /// 212H status byte of axis index `i` (PROTOCOL.md 3.3).
    pub(crate) fn status_byte(&self, i: usize, in_use: u8) -> AxisStatus {
        let a = &self.axes[i];
        AxisStatus::default()
            .with_in_use(in_use & (1 << i) != 0)
            .with_home_state(a.home.state())
            .with_servo_on(a.servo)
            .with_completed_normally(a.completed)
    }

    /// The axis blocks of `pattern`: status, sensors, error, encoder, and the position
    /// `position(i)` gives.
    fn axis_blocks(
        &self,
        pattern: AxisPattern,
        position: impl Fn(usize) -> i32,
    ) -> PerAxis<protocol::AxisState> {
        let in_use = self.in_use();
        PerAxis::from_fn(pattern, |axis| {
            let i = axis.index();
            let homed_here =
                self.axes[i].is_homed() && (self.values[i] - self.home_value(i)).abs() < 0.001;
            protocol::AxisState {
                status: self.status_byte(i, in_use),
                sensor: SensorInput::default().with_home(homed_here),
                error: ErrorCode(self.axes[i].error),
                encoder: EncoderStatus::default(),
                position: Milli(position(i)),
            }
        })
    }

    /// Home position of axis index `i` in its each-axis unit.
    pub(crate) fn home_value(&self, i: usize) -> f64 {
        match i {
            0..=3 => self.model.home.to_array()[i],
            _ => 0.0,
        }
    }

    /// Each-axis wire value (0.001 deg / 0.001 mm) of axis index `i`.
    pub(crate) fn axis_wire(&self, i: usize) -> i32 {
        round_wire(self.values[i] * 1000.0)
    }

    /// 212H axis status: each-axis positions.
    pub(crate) fn msg_axis_status(&mut self, axes: AxisPattern) -> Reply {
        let pattern = AxisPattern(axes.0 & self.present());
        Reply::AxisStatus(self.axis_blocks(pattern, |i| self.axis_wire(i)))
    }

    /// The pattern's axis blocks with SCARA positions in base, work or each-axis
    /// coordinates (linear axes always in their own unit), and the common status.
    fn scara_blocks(
        &self,
        axes: AxisPattern,
        system: PositionSystem,
    ) -> (CommonStatus, PerAxis<protocol::AxisState>) {
        let tip = self.tip_base();
        let scara = match system {
            PositionSystem::Base => tip.to_wire(),
            PositionSystem::Work => self.work().base_to_work(&tip).to_wire(),
            PositionSystem::Joint => std::array::from_fn(|i| self.axis_wire(i)),
        };
        let arm = self.kin.arm_system(&self.joints()).into();
        let pattern = AxisPattern(axes.0 & self.present());
        let blocks = self.axis_blocks(
            pattern,
            |i| {
                if i < 4 { scara[i] } else { self.axis_wire(i) }
            },
        );
        (CommonStatus { arm, system }, blocks)
    }

    /// 2A1H SCARA axis status (PROTOCOL.md 3.17); the arm code is this message's own
    /// (PROTOCOL.md 5, erratum 4: the protocol layer encodes it per message).
    pub(crate) fn msg_scara_status(&mut self, axes: AxisPattern, system: PositionSystem) -> Reply {
        let (common, axes) = self.scara_blocks(axes, system);
        Reply::ScaraStatus(ScaraStatus {
            work: self.work_no as u8,
            tool: self.tool_no as u8,
            common,
            axes,
        })
    }

    /// 2A3H SCARA axis status 2 (PROTOCOL.md 3.18): one SCARA (axes 1-4); the second
    /// unit's fields are zero `[inferred layout, 3.18]`.
    pub(crate) fn msg_scara_status2(&mut self, axes: AxisPattern, system: PositionSystem) -> Reply {
        let (common, blocks) = self.scara_blocks(axes, system);
        Reply::ScaraStatus2(ScaraStatus2 {
            scara_axes: AxisPattern(axes.0 & self.present() & 0x0F),
            unit1: ScaraUnitStatus {
                work: self.work_no as u8,
                tool: self.tool_no as u8,
                common,
            },
            unit2: ScaraUnitStatus {
                work: 0,
                tool: 0,
                common: CommonStatus {
                    arm: protocol::ArmSystem::Undetermined,
                    system: PositionSystem::Base,
                },
            },
            axes: blocks,
        })
    }
}
