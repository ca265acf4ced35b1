//! Hold-to-run: which jog inputs are down, the press edges that start a jog or a step,
//! and the STOP latch. Written once for the pointer and every key; no clock, no egui.
//!
//! The window reports, every frame, what each jog input is doing ([`Press`]); this
//! machine turns that into actions. A jog starts only on the **edge** of a press (an input
//! not down before), never on a level, so nothing restarts by itself: not after a
//! reconnection, a mode change, a refusal or a STOP. After a STOP the latch holds until
//! every jog input is up.

use std::collections::BTreeMap;
use std::time::Instant;

use super::plan::JogAxis;
use crate::pendant::controller::readiness::NotReady;
use crate::protocol::Direction;

/// A jog button: an axis and a direction.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct JogTarget {
    pub axis: JogAxis,
    pub direction: Direction,
}

impl JogTarget {
    pub fn new(axis: JogAxis, direction: Direction) -> Self {
        Self { axis, direction }
    }

    /// "X+", "J2-": the axis and the sign sent.
    pub fn label(self) -> String {
        let sign = match self.direction {
            Direction::Positive => "+",
            Direction::Negative => "-",
        };
        format!("{}{sign}", self.axis.name())
    }
}

/// One physical jog input: the pointer on the pad, or one jog key (the window's own
/// number for it).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum JogInput {
    Pointer,
    Key(u8),
}

impl JogInput {
    fn name(self) -> &'static str {
        match self {
            JogInput::Pointer => "button",
            JogInput::Key(_) => "key",
        }
    }
}

/// What one jog input is doing this frame (on the arm's pad by default, or on another
/// device's jog controls).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Press<T = JogTarget> {
    /// Not down.
    Up,
    /// Down on this jog control (a pad button, a jog key while no text field types).
    On(T),
    /// Down, but not on a jog control: the pointer pressed elsewhere or moved off its
    /// button, a key held while a text field has the keyboard. Never starts anything.
    Aside,
}

/// Who or what stopped the motion; the latch says it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StopCause {
    /// The STOP button.
    Button,
    /// The Esc key.
    Esc,
    /// The link's own STOP: the jog lease was not renewed in time.
    LeaseLapsed,
    /// The link's own STOP: the line stalled or was lost mid-motion.
    LinkSafety,
    /// The guardian process that owns the line sent 238H of its own.
    Guardian,
    /// The line went down.
    LineLost,
    /// The jog was refused (by the pendant's checks or the controller).
    Refused,
    /// The controller left the state that allows motion.
    NotReady(NotReady),
    /// The window lost the keyboard and pointer.
    FocusLost,
    /// A continuous jog came within its stopping distance of this interference zone.
    Zone(u8),
    /// An RMC axis held toward a configured soft limit came within stopping distance of it.
    SoftLimit,
    /// The window is closing.
    Exit,
}

impl StopCause {
    /// Who sent the STOP, for Messages: "STOP (Esc)".
    pub fn name(self) -> String {
        match self {
            StopCause::Button => "STOP button".into(),
            StopCause::Esc => "Esc".into(),
            StopCause::LeaseLapsed => "the jog lease lapsed".into(),
            StopCause::LinkSafety => "the line stalled or was lost mid-motion".into(),
            StopCause::Guardian => "the guardian process".into(),
            StopCause::LineLost => "the line went down".into(),
            StopCause::Refused => "the jog was refused".into(),
            StopCause::NotReady(why) => why.to_string(),
            StopCause::FocusLost => "the window lost focus".into(),
            StopCause::Zone(n) => format!("zone {n} ahead"),
            StopCause::SoftLimit => "the axis reached its soft limit".into(),
            StopCause::Exit => "the window closed".into(),
        }
    }
}

/// A continuous jog this machine drives: the input holding it and since when.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HeldJog<T = JogTarget> {
    pub target: T,
    pub input: JogInput,
    pub since: Instant,
}

/// What the pendant must do after an input report.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HoldAction<T = JogTarget> {
    /// Nothing.
    None,
    /// A fresh press of this target: a step, or the start of a continuous jog.
    Press(T),
    /// The held jog's input is still on it: renew the lease.
    Renew,
    /// The held jog's input let go (or moved off): send STOP.
    Release,
    /// A fresh press that the latch swallowed.
    Latched(T),
}

/// The hold-to-run state: inputs down, the jog they drive, the latch.
/// Written once for any jog target: the arm's pad ([`JogTarget`]) and an RMC axis's jog
/// buttons keep the same rules.
#[derive(Clone, Debug)]
pub struct HoldMachine<T = JogTarget> {
    /// Every input down now, with the control it is on (`None`: aside).
    down: BTreeMap<JogInput, Option<T>>,
    /// The continuous jog running on an input's hold.
    jog: Option<HeldJog<T>>,
    /// STOP latched (and why): nothing starts until every input is up.
    latch: Option<StopCause>,
}

impl<T> Default for HoldMachine<T> {
    fn default() -> Self {
        Self {
            down: BTreeMap::new(),
            jog: None,
            latch: None,
        }
    }
}

impl<T: Copy + PartialEq> HoldMachine<T> {
    /// One input's state this frame.
    pub fn report(&mut self, input: JogInput, press: Press<T>) -> HoldAction<T> {
        let driving = self.jog.filter(|j| j.input == input);
        match press {
            Press::Up => {
                self.down.remove(&input);
                if self.down.is_empty() {
                    self.latch = None;
                }
                self.end_jog_of(driving)
            }
            Press::Aside => {
                self.down.insert(input, None);
                self.end_jog_of(driving)
            }
            Press::On(target) => match self.down.insert(input, Some(target)) {
                // The edge: this input was not down before.
                None if self.latch.is_some() => HoldAction::Latched(target),
                None if self.jog.is_some() => HoldAction::None,
                None => HoldAction::Press(target),
                Some(_) => match driving {
                    Some(j) if j.target == target => HoldAction::Renew,
                    // Slid onto another button while held: the jog ends, nothing starts.
                    Some(_) => self.end_jog_of(driving),
                    None => HoldAction::None,
                },
            },
        }
    }

    fn end_jog_of(&mut self, driving: Option<HeldJog<T>>) -> HoldAction<T> {
        if driving.is_some() {
            self.jog = None;
            HoldAction::Release
        } else {
            HoldAction::None
        }
    }

    /// The continuous jog of `target` went out, held by `input`.
    pub fn started(&mut self, input: JogInput, target: T, now: Instant) {
        self.jog = Some(HeldJog {
            target,
            input,
            since: now,
        });
    }

    /// STOP, whoever sent it: the jog ends and, while any input is down, the latch holds.
    /// A latch keeps the cause that set it (the one the operator saw: a lost line's
    /// latch does not turn into the lapsed lease that follows it). Answers the jog that
    /// was running.
    pub fn stop(&mut self, cause: StopCause) -> Option<HeldJog<T>> {
        if !self.down.is_empty() {
            self.latch.get_or_insert(cause);
        }
        self.jog.take()
    }

    /// The window lost focus: it will see no release, so the jog ends and every input
    /// counts as down-and-spent until it is reported up.
    pub fn focus_lost(&mut self) -> Option<HeldJog<T>> {
        for target in self.down.values_mut() {
            *target = None;
        }
        self.stop(StopCause::FocusLost)
    }

    /// The continuous jog running, if any.
    pub fn jog(&self) -> Option<HeldJog<T>> {
        self.jog
    }

    /// Why nothing may start until the jog controls are released, if latched.
    pub fn latch(&self) -> Option<StopCause> {
        self.latch
    }

    /// Whether any jog input is down (on a control or aside).
    pub fn any_down(&self) -> bool {
        !self.down.is_empty()
    }

    /// The control `input` is down on, if any.
    pub fn on(&self, input: JogInput) -> Option<T> {
        self.down.get(&input).copied().flatten()
    }

    /// Words for the latch beside the pad.
    pub fn latch_text(&self) -> Option<String> {
        let cause = self.latch?;
        let held: Vec<&str> = self.down.keys().map(|i| i.name()).collect();
        let what = if held.iter().all(|n| *n == "key") {
            "release the jog keys"
        } else {
            "release the jog controls"
        };
        Some(format!("STOP ({}): {what}", cause.name()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const X_PLUS: JogTarget = JogTarget {
        axis: JogAxis::X,
        direction: Direction::Positive,
    };
    const Y_MINUS: JogTarget = JogTarget {
        axis: JogAxis::Y,
        direction: Direction::Negative,
    };

    #[test]
    fn a_latch_keeps_the_cause_that_set_it() {
        let t = Instant::now();
        let mut m = HoldMachine::default();
        let key = JogInput::Key(0);
        assert_eq!(m.report(key, Press::On(X_PLUS)), HoldAction::Press(X_PLUS));
        m.started(key, X_PLUS, t);
        assert!(m.stop(StopCause::LineLost).is_some());
        assert!(m.stop(StopCause::LeaseLapsed).is_none());
        assert_eq!(m.latch(), Some(StopCause::LineLost));
        assert_eq!(m.report(key, Press::Up), HoldAction::None);
        assert_eq!(m.latch(), None);
        // A new latch takes the new cause.
        assert_eq!(m.report(key, Press::On(X_PLUS)), HoldAction::Press(X_PLUS));
        m.stop(StopCause::Esc);
        assert_eq!(m.latch(), Some(StopCause::Esc));
    }

    #[test]
    fn only_the_edge_of_a_press_acts() {
        let mut m = HoldMachine::default();
        let key = JogInput::Key(0);
        assert_eq!(m.report(key, Press::On(X_PLUS)), HoldAction::Press(X_PLUS));
        // Not started (refused): the level never presses again.
        for _ in 0..100 {
            assert_eq!(m.report(key, Press::On(X_PLUS)), HoldAction::None);
        }
        assert_eq!(m.report(key, Press::Up), HoldAction::None);
        assert_eq!(m.report(key, Press::On(X_PLUS)), HoldAction::Press(X_PLUS));
    }

    #[test]
    fn a_held_jog_renews_and_ends_on_release_or_sliding_off() {
        let t = Instant::now();
        let mut m = HoldMachine::default();
        let p = JogInput::Pointer;
        assert_eq!(m.report(p, Press::On(X_PLUS)), HoldAction::Press(X_PLUS));
        m.started(p, X_PLUS, t);
        assert_eq!(m.report(p, Press::On(X_PLUS)), HoldAction::Renew);
        assert_eq!(m.report(p, Press::Aside), HoldAction::Release);
        assert_eq!(m.jog(), None);
        // Back on the button with the pointer still down: no new jog.
        assert_eq!(m.report(p, Press::On(X_PLUS)), HoldAction::None);
        // Onto another button: no new jog either.
        assert_eq!(m.report(p, Press::On(Y_MINUS)), HoldAction::None);
        assert_eq!(m.report(p, Press::Up), HoldAction::None);
        assert_eq!(m.report(p, Press::On(Y_MINUS)), HoldAction::Press(Y_MINUS));
        m.started(p, Y_MINUS, t);
        assert_eq!(m.report(p, Press::On(X_PLUS)), HoldAction::Release);
    }

    #[test]
    fn stop_latches_until_every_input_is_up() {
        let t = Instant::now();
        let mut m = HoldMachine::default();
        let (k0, k1) = (JogInput::Key(0), JogInput::Key(1));
        m.report(k0, Press::On(X_PLUS));
        m.started(k0, X_PLUS, t);
        assert!(m.stop(StopCause::Esc).is_some());
        assert_eq!(m.latch(), Some(StopCause::Esc));
        assert_eq!(m.report(k0, Press::On(X_PLUS)), HoldAction::None);
        // Another key pressed while the first is still down: swallowed by the latch.
        assert_eq!(
            m.report(k1, Press::On(Y_MINUS)),
            HoldAction::Latched(Y_MINUS)
        );
        m.report(k0, Press::Up);
        assert!(m.latch().is_some(), "k1 is still down");
        m.report(k1, Press::Up);
        assert_eq!(m.latch(), None);
        assert_eq!(m.report(k1, Press::On(Y_MINUS)), HoldAction::Press(Y_MINUS));
    }

    #[test]
    fn a_stop_with_nothing_held_leaves_no_latch() {
        let mut m = HoldMachine::default();
        assert_eq!(m.stop(StopCause::Button), None);
        assert_eq!(m.latch(), None);
        assert_eq!(
            m.report(JogInput::Key(2), Press::On(X_PLUS)),
            HoldAction::Press(X_PLUS)
        );
    }

    #[test]
    fn after_focus_loss_a_key_still_down_is_spent() {
        let t = Instant::now();
        let mut m = HoldMachine::default();
        let k = JogInput::Key(0);
        m.report(k, Press::On(X_PLUS));
        m.started(k, X_PLUS, t);
        assert!(m.focus_lost().is_some());
        assert_eq!(m.report(k, Press::On(X_PLUS)), HoldAction::None);
        assert_eq!(m.on(k), Some(X_PLUS));
        m.report(k, Press::Up);
        assert_eq!(m.report(k, Press::On(X_PLUS)), HoldAction::Press(X_PLUS));
    }

    #[test]
    fn a_second_input_pressed_during_a_jog_starts_nothing() {
        let t = Instant::now();
        let mut m = HoldMachine::default();
        m.report(JogInput::Pointer, Press::On(X_PLUS));
        m.started(JogInput::Pointer, X_PLUS, t);
        assert_eq!(
            m.report(JogInput::Key(3), Press::On(Y_MINUS)),
            HoldAction::None
        );
        assert_eq!(m.report(JogInput::Key(3), Press::Up), HoldAction::None);
        assert_eq!(m.jog().map(|j| j.target), Some(X_PLUS));
    }
}
