//! The RMC axis panel's lamps and the word beside the axis buttons, each derived from the
//! pendant's state (the last trusted status, the commands the RMC took, the line, the hold
//! machine): the window draws them and decides nothing.

use super::{AxisView, RmcAxes};
use crate::pendant::{Level, LineState};
use crate::rmc::{AxisId, Command, StatusBits, TgPhase};

/// What a lamp says when lit.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LampKind {
    /// A state the operator wants (enabled, in position): green.
    Good,
    /// A fault (halted): red.
    Bad,
    /// A phase of the target generator: amber.
    Phase,
}

/// How a lamp is drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Lit {
    On,
    Off,
    /// Read before the line went down: no colour, whatever it last read (`was_on`).
    Stale {
        was_on: bool,
    },
}

/// One lamp: its name, kind, state and what it means.
#[derive(Clone, Debug, PartialEq)]
pub struct Lamp {
    pub name: &'static str,
    pub kind: LampKind,
    pub lit: Lit,
    pub hover: String,
}

impl Lamp {
    fn new(name: &'static str, kind: LampKind, on: bool, stale: bool, hover: String) -> Self {
        let lit = match (stale, on) {
            (true, was_on) => Lit::Stale { was_on },
            (false, true) => Lit::On,
            (false, false) => Lit::Off,
        };
        Self {
            name,
            kind,
            lit,
            hover,
        }
    }

    /// Lit now (a stale lamp never is).
    pub fn on(&self) -> bool {
        self.lit == Lit::On
    }
}

/// The word beside stale lamps.
pub const STALE: &str = "stale";

/// Whether the axis stands: its target generator done and its Target not moving.
fn still(view: &AxisView) -> bool {
    view.status
        .is_some_and(|s| s.bits.tg_done() && s.target_velocity == 0.0)
}

impl RmcAxes {
    /// Lamps show what was read on a line that is up; from a line that is down (or
    /// closed) they are stale.
    pub fn lamps_stale(&self) -> bool {
        !self.line.is_up()
    }

    /// Why the lamps are stale, for the line beside them; `None` while the line is up.
    pub fn stale_text(&self) -> Option<String> {
        let why = match &self.line {
            LineState::Up { .. } => return None,
            LineState::Closed => "the RMC is not connected".to_string(),
            LineState::Opening => "connecting".to_string(),
            LineState::Down { reason, .. } => format!("the RMC line is down: {reason}"),
        };
        Some(format!("{STALE}: {why}; lamps as last read"))
    }

    /// The controller's lamps: RUN (or PROGRAM) and Controller enabled.
    pub fn controller_lamps(&self) -> [Lamp; 2] {
        let stale = self.lamps_stale();
        let c = self.controller;
        let run = c.is_some_and(|c| c.run_mode());
        [
            Lamp::new(
                if c.is_some() && !run {
                    "PROGRAM"
                } else {
                    "RUN"
                },
                LampKind::Good,
                run,
                stale,
                "Controller Status Bits: RUN mode (PROGRAM when off)".into(),
            ),
            Lamp::new(
                "Controller enabled",
                LampKind::Good,
                c.is_some_and(|c| c.enabled()),
                stale,
                "Controller Status Bits: the controller is enabled".into(),
            ),
        ]
    }

    /// An axis's lamps in two rows: Enabled, In Position, TG Done, Halted; Stopped, the
    /// three moving phases, ACK. From the last trusted status (ACK from the latest read).
    pub fn axis_lamps(&self, axis: AxisId) -> [Vec<Lamp>; 2] {
        let stale = self.lamps_stale();
        let view = self.view(axis).cloned().unwrap_or_default();
        let bits = view.status.map(|s| s.bits);
        let bit = |b: u32| bits.is_some_and(|bits| bits.bit(b));
        let phase = view.phase();
        let stopped = stopped_by_stop(&view);
        let first = vec![
            Lamp::new(
                "Enabled",
                LampKind::Good,
                bit(StatusBits::ENABLED),
                stale,
                "Status Bits bit 13: enabled by Enable/Disable Axis (97)".into(),
            ),
            Lamp::new(
                "In Position",
                LampKind::Good,
                bit(StatusBits::IN_POSITION),
                stale,
                "Status Bits bit 0: the Target reached the Command Position and Actual is \
                 within tolerance (never set after Stop (6))"
                    .into(),
            ),
            Lamp::new(
                "TG Done",
                LampKind::Good,
                bit(StatusBits::TG_DONE),
                stale,
                "Status Bits bit 9: the target generator reached the Command Position".into(),
            ),
            Lamp::new(
                "Halted",
                LampKind::Bad,
                bit(StatusBits::HALTED),
                stale,
                "Status Bits bit 15: a halt is in effect until Clear Faults (4)".into(),
            ),
        ];
        let mut second = vec![Lamp::new(
            "Stopped",
            LampKind::Good,
            stopped,
            stale,
            format!(
                "lit when the last command the RMC took for {axis} was Stop (Closed Loop) (6) \
                 (the pendant's, STOP's or the link's own) and the axis stands; a move that \
                 ends normally leaves it dark (Status Bits bit 6 reads {})",
                if bit(StatusBits::STOPPED) { "1" } else { "0" }
            ),
        )];
        for (p, name) in [
            (TgPhase::Accelerating, "Accel"),
            (TgPhase::ConstantVelocity, "Constant"),
            (TgPhase::Decelerating, "Decel"),
        ] {
            second.push(Lamp::new(
                name,
                LampKind::Phase,
                view.status.is_some() && phase == p,
                stale,
                format!("the target generator is {} (TG State B A)", p.name()),
            ));
        }
        second.push(Lamp::new(
            "ACK",
            LampKind::Good,
            view.latest.is_some_and(|s| s.bits.ack()),
            stale,
            "Command Acknowledge (Status Bits bit 31) on this connection".into(),
        ));
        [first, second]
    }

    /// The line beside the axis buttons, derived from state: the latch's reason while
    /// latched, "jogging Axis 1+" only while that jog runs, else the last word said.
    pub fn jog_line(&self) -> Option<(Level, String)> {
        if let Some(text) = self.hold.latch_text() {
            return Some((Level::Error, text));
        }
        if let Some(j) = self.hold.jog() {
            return Some((Level::Info, format!("jogging {}", j.target.label())));
        }
        self.feedback.as_ref().map(|m| (m.level, m.text.clone()))
    }
}

/// Whether the axis stands after a Stop (Closed Loop) (6) the RMC took.
fn stopped_by_stop(view: &AxisView) -> bool {
    matches!(view.taken, Some(Command::Stop { .. })) && still(view)
}
