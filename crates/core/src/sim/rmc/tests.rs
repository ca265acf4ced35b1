//! The simulated RMC's axes on a virtual clock: moves, phases, In Position, stops, limits.

use std::time::{Duration, Instant};

use super::*;
use crate::rmc::{AxisId, AxisStatus, Command, ErrorBits, MoveRelative, TgPhase};
use crate::robot::RelativeTo;

/// A controller and a virtual clock in whole milliseconds.
pub(super) struct Sim {
    pub c: RmcController,
    t0: Instant,
    pub ms: u64,
}

impl Sim {
    pub fn new(config: RmcConfig) -> Self {
        let t0 = Instant::now();
        Self {
            c: RmcController::new(config, t0),
            t0,
            ms: 0,
        }
    }

    pub fn enabled() -> Self {
        let mut s = Self::new(RmcConfig::default());
        s.cmd(Command::Enable(true));
        s
    }

    pub fn now(&self) -> Instant {
        self.t0 + Duration::from_millis(self.ms)
    }

    pub fn run(&mut self, ms: u64) {
        self.ms += ms;
        self.c.advance(self.now());
    }

    pub fn cmd(&mut self, command: Command) {
        assert!(self.c.command(axis0(), command));
    }

    pub fn st(&self) -> AxisStatus {
        self.c.status(axis0()).unwrap()
    }

    /// Runs 1 ms at a time until `done`, at most `limit` ms; the phases seen, in order.
    pub fn until(&mut self, limit: u64, done: impl Fn(&AxisStatus) -> bool) -> Vec<TgPhase> {
        let mut phases = vec![self.st().bits.phase()];
        for _ in 0..limit {
            if done(&self.st()) {
                return phases;
            }
            self.run(1);
            let p = self.st().bits.phase();
            if phases.last() != Some(&p) {
                phases.push(p);
            }
        }
        panic!("not done within {limit} ms: {:?}", self.st());
    }
}

fn axis0() -> AxisId {
    AxisId::new(0).unwrap()
}

pub(super) fn mr(distance: f32, relative_to: RelativeTo) -> Command {
    Command::MoveRelative(MoveRelative {
        distance,
        speed: 100.0,
        accel: 1000.0,
        decel: 1000.0,
        relative_to,
    })
}

#[test]
fn relative_to_takes_the_quantity_when_received() {
    for relative_to in RelativeTo::ALL {
        let mut s = Sim::enabled();
        s.cmd(mr(100.0, RelativeTo::Command));
        s.run(50);
        let before = s.st();
        // Mid-move the three differ, so each choice gives its own end.
        assert!(before.actual_position < before.target_position);
        assert!(before.target_position < before.command_position);
        s.cmd(mr(5.0, relative_to));
        let from = match relative_to {
            RelativeTo::Command => before.command_position,
            RelativeTo::Actual => before.actual_position,
            RelativeTo::Target => before.target_position,
        };
        assert_eq!(s.st().command_position, from + 5.0, "{relative_to:?}");
        s.until(3000, |st| st.bits.in_position());
        assert_eq!(s.st().target_position, from + 5.0, "{relative_to:?}");
    }
}

#[test]
fn a_long_move_accelerates_cruises_decelerates_and_completes() {
    let mut s = Sim::enabled();
    s.cmd(mr(100.0, RelativeTo::Command));
    let mut fastest = 0.0f32;
    let mut phases = vec![s.st().bits.phase()];
    while !s.st().bits.tg_done() {
        s.run(1);
        let st = s.st();
        fastest = fastest.max(st.target_velocity.abs());
        assert!(st.target_acceleration.abs() <= 1000.0 * 1.01, "{st:?}");
        if phases.last() != Some(&st.bits.phase()) {
            phases.push(st.bits.phase());
        }
        assert!(s.ms < 2000);
    }
    use TgPhase::*;
    assert_eq!(
        phases,
        [Accelerating, ConstantVelocity, Decelerating, Complete]
    );
    assert!(fastest <= 100.0 && fastest > 99.9);
    // 0.1 s up, 0.9 s at speed, 0.1 s down.
    assert!((1095..=1110).contains(&s.ms), "{} ms", s.ms);
    assert_eq!(s.st().target_position, 100.0);
}

#[test]
fn a_short_move_is_a_triangle() {
    let mut s = Sim::enabled();
    s.cmd(mr(2.0, RelativeTo::Command));
    let phases = s.until(1000, |st| st.bits.tg_done());
    use TgPhase::*;
    assert_eq!(phases, [Accelerating, Decelerating, Complete]);
    assert_eq!(s.st().target_position, 2.0);
}

#[test]
fn every_move_lands_exactly_on_its_command_position() {
    for (distance, speed, accel, decel) in [
        (7.3f32, 33.0f32, 250.0f32, 400.0f32),
        (-12.345, 50.0, 1000.0, 75.0),
        (0.001, 10.0, 10.0, 10.0),
        (250.0, 1000.0, 5000.0, 3000.0),
        (0.0, 1.0, 1.0, 1.0),
    ] {
        let mut s = Sim::enabled();
        s.cmd(mr(1.25, RelativeTo::Command));
        s.until(1000, |st| st.bits.tg_done());
        s.cmd(Command::MoveRelative(MoveRelative {
            distance,
            speed,
            accel,
            decel,
            relative_to: RelativeTo::Command,
        }));
        let end = 1.25f32 + distance;
        assert_eq!(s.st().command_position, end);
        s.until(20_000, |st| st.bits.tg_done());
        assert_eq!(s.st().target_position, end, "{distance}");
        s.until(1000, |st| st.bits.bit(crate::rmc::StatusBits::STOPPED));
        assert_eq!(s.st().actual_position, end, "{distance}");
        assert_eq!(s.c.next_change(), None);
    }
}

#[test]
fn in_position_only_within_tolerance_and_never_after_stop() {
    let mut s = Sim::enabled();
    s.cmd(mr(10.0, RelativeTo::Command));
    let mut seen = false;
    for _ in 0..1000 {
        s.run(1);
        let st = s.st();
        let close = (st.actual_position - st.command_position).abs() < DEFAULT_TOLERANCE;
        assert_eq!(st.bits.in_position(), st.bits.tg_done() && close, "{st:?}");
        seen |= st.bits.in_position();
    }
    assert!(seen);
    // Stop (6) mid-move: the target ramps down and stays; In Position never comes.
    s.cmd(mr(50.0, RelativeTo::Command));
    s.run(100);
    s.cmd(Command::Stop { decel: 500.0 });
    let phases = s.until(1000, |st| st.bits.tg_done());
    assert_eq!(phases, [TgPhase::Decelerating, TgPhase::Complete]);
    s.run(1000);
    let st = s.st();
    assert_eq!(st.command_position, st.target_position);
    assert!(st.command_position < 60.0 && st.command_position > 10.0);
    assert!(!st.bits.in_position() && !st.bits.halted(), "{st:?}");
    // The next motion command lets it come back.
    s.cmd(mr(1.0, RelativeTo::Command));
    s.until(1000, |st| st.bits.in_position());
}

#[test]
fn a_disabled_axis_ignores_motion_and_bad_parameters_are_ignored() {
    let mut s = Sim::new(RmcConfig::default());
    s.cmd(mr(10.0, RelativeTo::Command));
    s.run(100);
    let st = s.st();
    assert_eq!(st.last_error, ERROR_NOT_ENABLED);
    assert_eq!((st.command_position, st.target_position), (0.0, 0.0));
    assert!(!st.bits.enabled());
    s.cmd(Command::Enable(true));
    let st = s.st();
    assert!(st.bits.enabled() && st.bits.bit(crate::rmc::StatusBits::ENABLE_OUTPUT));
    s.cmd(Command::MoveRelative(MoveRelative {
        distance: 5.0,
        speed: 0.0,
        accel: 1.0,
        decel: 1.0,
        relative_to: RelativeTo::Command,
    }));
    s.run(100);
    assert_eq!(s.st().last_error, ERROR_BAD_PARAMETER);
    assert_eq!(s.st().command_position, 0.0);
    s.cmd(Command::Enable(false));
    assert!(!s.st().bits.enabled());
}

#[test]
fn a_soft_limit_halts_with_its_error_bit_until_cleared_inside() {
    let mut s = Sim::new(RmcConfig {
        axes: 1,
        travel: (-10.0, 10.0),
    });
    s.cmd(Command::Enable(true));
    s.cmd(mr(20.0, RelativeTo::Command));
    s.until(2000, |st| st.bits.halted());
    let st = s.st();
    assert_eq!(st.target_position, 10.0);
    assert_eq!(st.target_velocity, 0.0);
    assert!(st.errors.bit(ErrorBits::POSITIVE_LIMIT));
    assert!(!st.bits.tg_done() && !st.bits.in_position());
    // At the limit the cause is still there: the bit stays, Halted goes.
    s.cmd(Command::ClearFaults);
    assert!(s.st().errors.bit(ErrorBits::POSITIVE_LIMIT));
    assert!(!s.st().bits.halted());
    s.cmd(mr(-5.0, RelativeTo::Target));
    assert!(s.st().errors.bit(ErrorBits::POSITIVE_LIMIT));
    s.until(2000, |st| st.bits.in_position());
    assert_eq!(s.st().target_position, 5.0);
    s.cmd(Command::ClearFaults);
    assert_eq!(s.st().errors, ErrorBits(0));
    s.cmd(mr(-30.0, RelativeTo::Command));
    s.until(2000, |st| st.bits.halted());
    assert_eq!(s.st().target_position, -10.0);
    assert_eq!(s.st().errors, ErrorBits(1 << ErrorBits::NEGATIVE_LIMIT));
}

#[test]
fn halt_stops_at_once_and_hold_takes_the_actual_position() {
    let mut s = Sim::enabled();
    s.cmd(mr(100.0, RelativeTo::Command));
    s.run(300);
    s.cmd(Command::ClosedLoopHalt);
    let st = s.st();
    assert!(st.bits.halted() && !st.bits.in_position());
    assert_eq!(st.target_velocity, 0.0);
    assert_eq!(st.command_position, 100.0);
    s.run(500);
    assert!(!s.st().bits.in_position());
    s.cmd(Command::ClearFaults);
    assert!(!s.st().bits.halted());
    s.cmd(mr(10.0, RelativeTo::Command));
    s.run(200);
    s.cmd(Command::HoldCurrentPosition { reset: false });
    let st = s.st();
    assert_eq!(st.command_position, st.actual_position);
    assert_eq!(st.target_position, st.actual_position);
    assert_eq!(st.target_velocity, 0.0);
}

#[test]
fn a_new_move_backwards_decelerates_first_then_lands() {
    let mut s = Sim::enabled();
    s.cmd(mr(100.0, RelativeTo::Command));
    s.run(300);
    let v = s.st().target_velocity;
    assert!(v > 99.0);
    s.cmd(mr(-50.0, RelativeTo::Target));
    let end = s.st().command_position;
    s.run(1);
    let st = s.st();
    assert!(st.target_velocity > 0.0 && st.target_velocity < v);
    assert_eq!(st.bits.phase(), TgPhase::Decelerating);
    s.until(3000, |st| st.bits.tg_done());
    assert_eq!(s.st().target_position, end);
}

#[test]
fn time_only_moves_forward_and_idle_gaps_are_free() {
    let mut s = Sim::enabled();
    assert_eq!(s.c.next_change(), None);
    s.cmd(mr(1.0, RelativeTo::Command));
    assert_eq!(s.c.next_change(), Some(s.now() + LOOP));
    s.run(10);
    let p = s.st().target_position;
    s.c.advance(s.now() - Duration::from_millis(5));
    assert_eq!(s.st().target_position, p);
    // A day later in one call: the move ended and the clock caught up.
    s.run(86_400_000);
    assert_eq!(s.st().actual_position, 1.0);
    assert_eq!(s.c.next_change(), None);
    assert_eq!(s.c.axis_count(), 2);
    assert!(s.c.status(AxisId::new(2).unwrap()).is_none());
}

#[test]
fn a_fault_input_halts_and_holds_the_error_until_it_goes_off() {
    let mut s = Sim::enabled();
    s.cmd(mr(50.0, RelativeTo::Command));
    s.run(100);
    assert!(s.c.operate(RmcAction::FaultInput(axis0(), true)));
    let st = s.st();
    assert!(st.bits.halted() && st.bits.bit(crate::rmc::StatusBits::FAULT_INPUT));
    assert!(st.errors.bit(ErrorBits::FAULT_INPUT));
    let at = st.target_position;
    s.run(100);
    assert_eq!(s.st().target_position, at, "halted at once");
    s.cmd(Command::ClearFaults);
    assert!(s.st().bits.halted(), "the cause is still there");
    s.c.operate(RmcAction::FaultInput(axis0(), false));
    s.cmd(Command::ClearFaults);
    assert!(!s.st().bits.halted());
    assert!(!s.st().errors.any());
    // A following error is an Auto Stop too, cleared at once by Clear Faults.
    s.c.operate(RmcAction::FollowingError(axis0()));
    assert!(s.st().errors.bit(ErrorBits::FOLLOWING_ERROR) && s.st().bits.halted());
    s.cmd(Command::ClearFaults);
    assert!(!s.st().errors.any());
}

#[test]
fn program_mode_refuses_motion_and_shows_in_the_controller_status() {
    let mut s = Sim::enabled();
    s.c.operate(RmcAction::Program(true));
    assert_eq!(s.c.controller_status() & 1, 0, "RUN bit clear");
    s.cmd(mr(5.0, RelativeTo::Command));
    s.run(100);
    assert_eq!(s.st().command_position, 0.0);
    assert_eq!(s.st().last_error, ERROR_PROGRAM_MODE);
    s.c.operate(RmcAction::Program(false));
    s.cmd(mr(5.0, RelativeTo::Command));
    assert_eq!(s.st().command_position, 5.0);
}

#[test]
fn console_lines_read_as_actions_or_say_why_not() {
    let a = |i| AxisId::new(i).unwrap();
    assert_eq!(
        RmcAction::parse("fault 2 on"),
        Ok(RmcAction::FaultInput(a(1), true))
    );
    assert_eq!(
        RmcAction::parse(" ferror 1 "),
        Ok(RmcAction::FollowingError(a(0)))
    );
    assert_eq!(RmcAction::parse("program"), Ok(RmcAction::Program(true)));
    assert_eq!(RmcAction::parse("run"), Ok(RmcAction::Program(false)));
    assert!(
        RmcAction::parse("fault 0 on")
            .unwrap_err()
            .contains("not an axis")
    );
    assert!(RmcAction::parse("fault 1").is_err());
    assert!(RmcAction::parse("jump").is_err());
}

#[test]
fn move_absolute_lands_on_its_position_whatever_the_start() {
    let mut s = Sim::enabled();
    s.cmd(mr(7.0, RelativeTo::Command));
    s.until(2000, |st| st.bits.in_position());
    s.cmd(Command::MoveAbsolute(crate::rmc::MoveAbsolute {
        position: -3.25,
        speed: 100.0,
        accel: 1000.0,
        decel: 1000.0,
    }));
    s.until(2000, |st| st.bits.in_position());
    assert_eq!(s.st().command_position, -3.25);
    assert_eq!(s.st().target_position, -3.25);
}
