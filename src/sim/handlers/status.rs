//! Status queries: 212H axis status, 2A1H and 2A3H SCARA axis status.

use super::{Fields, expect_len};
use crate::robot::ArmSystem;
use crate::robot::Pose;
use crate::robot::round_wire;
use crate::sim::controller::Controller;
use crate::sim::errors::SimError;
use crate::sim::framing::{begin_reply, finish, push_hex, push_i32};

impl Controller {
    /// 212H status byte of axis index `i` (PROTOCOL.md 3.3).
    pub(crate) fn status_byte(&self, i: usize, in_use: u8) -> u32 {
        let a = &self.axes[i];
        u32::from(in_use & (1 << i) != 0)
            | (u32::from(a.home.code()) << 1)
            | (u32::from(a.servo) << 3)
            | (u32::from(a.completed) << 4)
    }

    /// One 16-character axis block: status, sensors, error, encoder, position.
    fn push_block(&self, out: &mut Vec<u8>, i: usize, in_use: u8, position: i32) {
        push_hex(out, self.status_byte(i, in_use), 2);
        let homed_here =
            self.axes[i].is_homed() && (self.values[i] - self.home_value(i)).abs() < 0.001;
        push_hex(out, u32::from(homed_here) << 2, 1);
        push_hex(out, u32::from(self.axes[i].error), 3);
        push_hex(out, 0, 2);
        push_i32(out, position);
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
    pub(crate) fn msg_axis_status(
        &mut self,
        id: [u8; 3],
        data: &[u8],
        out: &mut Vec<u8>,
    ) -> Result<(), SimError> {
        expect_len(data, 2)?;
        let pattern = Fields::new(data).u8(2)? & self.present();
        let in_use = self.in_use();
        begin_reply(out, self.cfg.station, id);
        push_hex(out, u32::from(pattern), 2);
        for i in 0..8 {
            if pattern & (1 << i) != 0 {
                self.push_block(out, i, in_use, self.axis_wire(i));
            }
        }
        finish(out);
        Ok(())
    }

    /// SCARA positions as the coordinate-system code asks: 0 base, 1 work, 3 each-axis.
    fn scara_positions(&self, system: u8) -> Result<[i32; 4], SimError> {
        let tip = self.tip_base();
        let pose: Pose = match system {
            0 => tip,
            1 => self.work().base_to_work(&tip),
            3 => return Ok(std::array::from_fn(|i| self.axis_wire(i))),
            _ => return Err(SimError::BadValue),
        };
        Ok(pose.to_wire())
    }

    /// 2A1H (`two` = false) and 2A3H (`two` = true) SCARA axis status (PROTOCOL.md 3.17,
    /// 3.18). The arm-system code is per message (PROTOCOL.md 5, erratum 4).
    pub(crate) fn msg_scara_status(
        &mut self,
        id: [u8; 3],
        data: &[u8],
        out: &mut Vec<u8>,
        two: bool,
    ) -> Result<(), SimError> {
        expect_len(data, if two { 4 } else { 3 })?;
        let mut f = Fields::new(data);
        let pattern = f.u8(2)? & self.present();
        let typ = f.u8(if two { 2 } else { 1 })?;
        let system = typ & 0x03;
        let positions = self.scara_positions(system)?;
        let arm = self.kin.arm_system(&self.joints());
        let in_use = self.in_use();
        begin_reply(out, self.cfg.station, id);
        let common = u32::from(system) << 2;
        if two {
            let arm_code = match arm {
                ArmSystem::Undetermined => 0,
                ArmSystem::Right => 1,
                ArmSystem::Left => 2,
            };
            push_hex(out, u32::from(pattern & 0x0F), 2);
            push_hex(out, self.work_no as u32, 2);
            push_hex(out, self.tool_no as u32, 2);
            push_hex(out, common | arm_code, 2);
            // Second SCARA (axes 5-8): none on this controller [inferred layout, 3.18].
            out.extend_from_slice(b"000000");
        } else {
            let arm_code = match arm {
                ArmSystem::Right => 0,
                ArmSystem::Left => 1,
                ArmSystem::Undetermined => 2,
            };
            push_hex(out, self.work_no as u32, 2);
            push_hex(out, self.tool_no as u32, 2);
            push_hex(out, common | arm_code, 2);
        }
        push_hex(out, u32::from(pattern), 2);
        for i in 0..8 {
            if pattern & (1 << i) != 0 {
                let pos = if i < 4 {
                    positions[i]
                } else {
                    self.axis_wire(i)
                };
                self.push_block(out, i, in_use, pos);
            }
        }
        finish(out);
        Ok(())
    }
}
