//! The simulator's front panel as seen from outside its thread: operator actions (E-stop,
//! MODE switch, drive cut-off, alarms, input sensors, the I/O interlock) and tables to
//! try go in on a channel and are
//! applied by the simulator's own thread between frames, as a real controller takes its
//! front panel between scans; what the panel shows comes back whenever it changes.
//! Nothing outside the simulator's thread locks its controller, so the window never
//! holds up a reply.

use crossbeam_channel::{Receiver, Sender, TryRecvError, unbounded};

use super::console::OperatorAction;
use super::controller::Controller;
use super::state::Mode;
use crate::protocol::{BitSpace, INPUTS, OUTPUTS};
use crate::robot::CoordTables;

/// How many ports from each category head the panel shows: inputs 000-015 as sensors to
/// toggle, outputs 300-315 as lamps (the rest are reached by the console and the line).
pub const PANEL_PORTS: usize = 16;

/// What the front panel shows.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PanelState {
    pub emergency_stop: bool,
    pub mode: Mode,
    pub drive_cut_off: bool,
    /// The pending alarm's code.
    pub alarm: Option<u16>,
    /// The first [`PANEL_PORTS`] inputs from the inputs' head.
    pub inputs: [bool; PANEL_PORTS],
    /// The first [`PANEL_PORTS`] outputs from the outputs' head.
    pub outputs: [bool; PANEL_PORTS],
    /// The I/O interlock (24AH changes held while on).
    pub interlock: bool,
    /// Output changes the interlock holds.
    pub held: usize,
}

impl PanelState {
    /// The number of the `i`th input the panel shows.
    pub fn input_number(i: usize) -> u16 {
        INPUTS.head() + i as u16
    }

    /// The number of the `i`th output the panel shows.
    pub fn output_number(i: usize) -> u16 {
        OUTPUTS.head() + i as u16
    }
}

impl PanelState {
    fn of(c: &Controller) -> Self {
        let s = c.snapshot();
        let signals = c.signals();
        let port = |space, n| signals.bit(space, 0, n).unwrap_or(false);
        PanelState {
            emergency_stop: s.emergency_stop,
            mode: s.mode,
            drive_cut_off: s.drive_cut_off,
            alarm: s.alarm.map(|a| a.code),
            inputs: std::array::from_fn(|i| port(BitSpace::Input, Self::input_number(i))),
            outputs: std::array::from_fn(|i| port(BitSpace::Output, Self::output_number(i))),
            interlock: signals.interlock(),
            held: signals.held().len(),
        }
    }
}

enum PanelRequest {
    Act(OperatorAction),
    /// Answer 2A0H/2A4H from these tables (a draft to try).
    Tables(CoordTables),
}

enum PanelNews {
    State(PanelState),
    /// What an action did, in a line.
    Done(String),
}

/// The window's end: push actions, read what the panel shows.
pub struct FrontPanel {
    requests: Sender<PanelRequest>,
    news: Receiver<PanelNews>,
    state: Option<PanelState>,
}

/// The simulator thread's end.
pub struct PanelDesk {
    requests: Receiver<PanelRequest>,
    news: Sender<PanelNews>,
    shown: Option<PanelState>,
}

/// A front panel and the desk the simulator's thread serves it from.
pub fn front_panel() -> (FrontPanel, PanelDesk) {
    let (request_tx, requests) = unbounded();
    let (news_tx, news) = unbounded();
    let panel = FrontPanel {
        requests: request_tx,
        news,
        state: None,
    };
    let desk = PanelDesk {
        requests,
        news: news_tx,
        shown: None,
    };
    (panel, desk)
}

impl FrontPanel {
    /// Asks the simulator to take `action` (its result arrives with [`FrontPanel::take_news`]).
    pub fn act(&self, action: OperatorAction) {
        let _ = self.requests.send(PanelRequest::Act(action));
    }

    /// Gives the simulator these tables to answer table reads from.
    pub fn try_tables(&self, tables: CoordTables) {
        let _ = self.requests.send(PanelRequest::Tables(tables));
    }

    /// Takes what the simulator said since the last call: the panel's state is kept
    /// ([`FrontPanel::state`]), the lines saying what actions did are returned.
    pub fn take_news(&mut self) -> Vec<String> {
        let mut done = Vec::new();
        while let Ok(news) = self.news.try_recv() {
            match news {
                PanelNews::State(state) => self.state = Some(state),
                PanelNews::Done(line) => done.push(line),
            }
        }
        done
    }

    /// What the panel shows, once the simulator has said.
    pub fn state(&self) -> Option<&PanelState> {
        self.state.as_ref()
    }
}

impl PanelDesk {
    /// Applies what the window asked and says what the panel shows when it changed (an
    /// alarm also clears by 252H on the line). Called by the simulator's thread between
    /// frames.
    pub fn serve(&mut self, c: &mut Controller) {
        loop {
            let news = match self.requests.try_recv() {
                Ok(PanelRequest::Act(action)) => PanelNews::Done(action.apply(c)),
                Ok(PanelRequest::Tables(tables)) => {
                    c.set_coords(tables);
                    PanelNews::Done(
                        "the simulator now answers 2A4H with the draft (unread rows as zeros)"
                            .into(),
                    )
                }
                Err(TryRecvError::Empty | TryRecvError::Disconnected) => break,
            };
            let _ = self.news.send(news);
        }
        let state = PanelState::of(c);
        if self.shown != Some(state) {
            self.shown = Some(state);
            let _ = self.news.send(PanelNews::State(state));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::SimSetup;

    #[test]
    fn actions_are_applied_by_the_desk_and_the_panel_hears_the_state_once_per_change() {
        let (mut panel, mut desk) = front_panel();
        let mut c = Controller::new(SimSetup::default());
        desk.serve(&mut c);
        assert!(panel.take_news().is_empty());
        assert_eq!(panel.state().map(|s| s.emergency_stop), Some(false));
        panel.act(OperatorAction::EmergencyStop(true));
        assert!(
            !c.snapshot().emergency_stop,
            "nothing happens outside the desk"
        );
        desk.serve(&mut c);
        assert!(c.snapshot().emergency_stop);
        assert_eq!(panel.take_news(), ["E-stop on"]);
        assert_eq!(panel.state().map(|s| s.emergency_stop), Some(true));
        desk.serve(&mut c);
        assert!(desk.news.is_empty(), "no news when nothing changed");
        panel.act(OperatorAction::Alarm {
            code: 0xC74,
            axis: None,
        });
        desk.serve(&mut c);
        let _ = panel.take_news();
        assert_eq!(panel.state().and_then(|s| s.alarm), Some(0xC74));
        // The alarm clears on the line (252H): the panel hears it at the next serve.
        c.reset_alarm();
        desk.serve(&mut c);
        let _ = panel.take_news();
        assert_eq!(panel.state().and_then(|s| s.alarm), None);
    }

    #[test]
    fn the_panel_toggles_inputs_shows_outputs_and_the_interlock() {
        use crate::protocol::BitChange;
        let (mut panel, mut desk) = front_panel();
        let mut c = Controller::new(SimSetup::default());
        panel.act(OperatorAction::Input {
            number: PanelState::input_number(3),
            on: true,
        });
        panel.act(OperatorAction::Interlock(true));
        desk.serve(&mut c);
        assert_eq!(
            panel.take_news(),
            ["input 3 on", "I/O interlock on: output changes held"]
        );
        let s = *panel.state().unwrap();
        assert!(s.inputs[3] && !s.inputs[2] && s.interlock);
        let out = PanelState::output_number(1);
        let change = BitChange {
            space: BitSpace::Output,
            program: 0,
            number: out,
            on: true,
        };
        c.signals_mut().change_bit(&change).unwrap();
        desk.serve(&mut c);
        let _ = panel.take_news();
        let s = *panel.state().unwrap();
        assert_eq!((s.held, s.outputs[1]), (1, false), "held by the interlock");
        panel.act(OperatorAction::Interlock(false));
        desk.serve(&mut c);
        let _ = panel.take_news();
        let s = *panel.state().unwrap();
        assert_eq!((s.held, s.outputs[1], s.interlock), (0, true, false));
    }
}
