//! The Simulator panel (only on the built-in simulator): the operator states a real
//! controller takes from its front panel and wiring (E-stop, MODE switch, drive cut-off,
//! alarms, input sensors, the I/O interlock) and its output lamps, so an operator can
//! rehearse them without a robot. Returns the action; the
//! app hands it to the simulator's front panel after drawing, and the simulator's own
//! thread applies it.

use egui::{RichText, Ui};

use super::pane::{Pane, PaneCx};
use super::widgets::{AMBER, GREEN, GREY, RED, lamp, reserved_line};
use crate::session::simulator::{Mode, OperatorAction, PanelState, parse_code};

/// The panel's own input: the alarm code being typed and what was last done.
pub struct SimulatorPanel {
    code: String,
    feedback: Option<(bool, String)>,
    /// The action clicked this frame, handed to the front panel after drawing.
    pub action: Option<OperatorAction>,
}

impl Default for SimulatorPanel {
    fn default() -> Self {
        Self {
            // A real code to start from (a hint would look filled in and raise nothing).
            code: "C74".into(),
            feedback: None,
            action: None,
        }
    }
}

impl SimulatorPanel {
    /// Draws the panel; the action clicked, if any.
    pub fn show(&mut self, ui: &mut Ui, state: &PanelState) -> Option<OperatorAction> {
        let mut action = None;
        ui.label(
            RichText::new("Operator states of the built-in simulator (not sent on the line)")
                .small(),
        );
        ui.horizontal(|ui| {
            lamp(ui, state.emergency_stop, RED, "E-stop");
            let (text, hover) = if state.emergency_stop {
                ("Release E-stop", "Release the emergency stop button")
            } else {
                (
                    "Press E-stop",
                    "Press the emergency stop button: servos drop, moves stop",
                )
            };
            if ui.button(text).on_hover_text(hover).clicked() {
                action = Some(OperatorAction::EmergencyStop(!state.emergency_stop));
            }
        });
        ui.horizontal(|ui| {
            let manual = state.mode == Mode::Manual;
            lamp(ui, manual, AMBER, if manual { "MANUAL" } else { "AUTO" });
            let (text, to) = if manual {
                ("Switch to AUTO", Mode::Auto)
            } else {
                ("Switch to MANUAL", Mode::Manual)
            };
            if ui
                .button(text)
                .on_hover_text("The controller's MODE switch: MANUAL refuses commands that act")
                .clicked()
            {
                action = Some(OperatorAction::Mode(to));
            }
        });
        ui.horizontal(|ui| {
            lamp(ui, state.drive_cut_off, RED, "Drive cut off");
            let text = if state.drive_cut_off {
                "Restore drive source"
            } else {
                "Cut drive source"
            };
            if ui.button(text).clicked() {
                action = Some(OperatorAction::DriveCutOff(!state.drive_cut_off));
            }
        });
        ui.horizontal(|ui| {
            match state.alarm {
                Some(code) => lamp(ui, true, RED, &format!("Alarm {code:03X}")),
                None => lamp(ui, false, GREEN, "No alarm"),
            }
            let label = ui.label("Code");
            ui.add(
                egui::TextEdit::singleline(&mut self.code)
                    .desired_width(40.0)
                    .hint_text("3 hex digits"),
            )
            .labelled_by(label.id);
            if ui
                .button("Raise alarm")
                .on_hover_text("Raise an alarm with this 3-hex-digit code: servos off")
                .clicked()
            {
                match parse_code(&self.code) {
                    Ok(code) => action = Some(OperatorAction::Alarm { code, axis: None }),
                    Err(e) => self.feedback = Some((false, e)),
                }
            }
            if ui
                .add_enabled(state.alarm.is_some(), egui::Button::new("Clear alarm"))
                .on_hover_text("Clear the alarm as 252H would")
                .clicked()
            {
                action = Some(OperatorAction::ClearAlarm);
            }
        });
        action = signals(ui, state).or(action);
        // What the last action did, in a line that is always there.
        let feedback = self
            .feedback
            .as_ref()
            .map(|(ok, text)| (if *ok { GREEN } else { AMBER }, text.as_str()));
        reserved_line(ui, feedback, feedback.map(|(_, t)| t));
        action
    }

    /// Shows what an applied action did.
    pub fn done(&mut self, text: String) {
        self.feedback = Some((true, text));
    }
}

/// The first inputs as sensors to toggle, the first outputs as lamps, and the I/O
/// interlock switch; the action clicked, if any.
fn signals(ui: &mut Ui, state: &PanelState) -> Option<OperatorAction> {
    let mut action = None;
    ui.separator();
    ui.horizontal_wrapped(|ui| {
        ui.label("Inputs").on_hover_text(
            "Sensors wired to the first input ports: click to switch (20BH reads them)",
        );
        for (i, &on) in state.inputs.iter().enumerate() {
            let number = PanelState::input_number(i);
            let text = format!("In {number:03}");
            if ui
                .selectable_label(on, text)
                .on_hover_text(format!(
                    "Input {number}: click to switch it {}",
                    if on { "OFF" } else { "ON" }
                ))
                .clicked()
            {
                action = Some(OperatorAction::Input { number, on: !on });
            }
        }
    });
    ui.horizontal_wrapped(|ui| {
        ui.label("Outputs")
            .on_hover_text("The first output ports (24AH switches them; 20CH reads them)");
        // Each lamp laid out in the wrapping row itself (a nested row would not wrap).
        for (i, &on) in state.outputs.iter().enumerate() {
            let (rect, _) = ui.allocate_exact_size(egui::vec2(12.0, 12.0), egui::Sense::hover());
            let fill = if on { GREEN } else { GREY.gamma_multiply(0.4) };
            ui.painter().circle_filled(rect.center(), 5.5, fill);
            ui.label(format!("Out {}", PanelState::output_number(i)));
        }
    });
    ui.horizontal(|ui| {
        lamp(ui, state.interlock, AMBER, "I/O interlock");
        let (text, hover) = if state.interlock {
            (
                "Release I/O interlock",
                "Release the interlock: the held output changes apply in order",
            )
        } else {
            (
                "Set I/O interlock",
                "Output changes (24AH) are acknowledged but held until released; 238H can drop them",
            )
        };
        if ui.button(text).on_hover_text(hover).clicked() {
            action = Some(OperatorAction::Interlock(!state.interlock));
        }
        if state.held > 0 {
            ui.label(format!("{} output changes held", state.held));
        }
    });
    action
}

impl Pane for SimulatorPanel {
    fn ui(&mut self, ui: &mut Ui, cx: &mut PaneCx<'_>) {
        match cx.sim.map(|panel| panel.state()) {
            Some(Some(state)) => {
                if let Some(action) = self.show(ui, state) {
                    self.action = Some(action);
                }
            }
            Some(None) => {
                ui.label("Waiting for the built-in simulator's panel...");
            }
            None => {
                ui.label("Not on the built-in simulator: the line goes to a real controller.");
            }
        }
    }
}
