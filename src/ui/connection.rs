//! The connection panel: simulator, serial port or TCP bridge; line settings; station;
//! robot model; connect and disconnect; the first-contact report; live link health.

use egui::{ComboBox, RichText, Ui};

use super::detect::Detect;
use super::first_contact::FirstContactRow;
use super::pane::{Pane, PaneCx};
use super::ports::PortList;
use super::widgets::{AMBER, GREEN, GREY, RED, reserved_line};
use crate::line::Parity;
use crate::line::STANDARD_BAUDS;
use crate::pendant::{Intent, LineKind, LineState, Pendant};
use crate::robot::BUILTIN_MODELS;

/// The panel's own state (the text being typed in the station field, the port list).
#[derive(Default)]
pub struct ConnectionPanel {
    pub ports: PortList,
    detect: Detect,
    station_text: Option<String>,
    first_contact: FirstContactRow,
}

impl ConnectionPanel {
    /// Draws the panel, editing a copy of the connection settings: a change, Connect and
    /// Disconnect go to `intents`.
    pub fn show(&mut self, ui: &mut Ui, cx: &mut PaneCx<'_>) {
        let (pendant, intents) = (cx.pendant, &mut *cx.intents);
        self.ports.poll();
        if !self.ports.listed_once && !self.ports.is_listing() {
            let ctx = ui.ctx().clone();
            self.ports.refresh(move || ctx.request_repaint());
        }
        let line_busy = !matches!(
            pendant.line,
            crate::pendant::LineState::Closed | crate::pendant::LineState::Down { .. }
        );
        let mut edited = pendant.settings.connection.clone();
        let s = &mut edited;
        ui.horizontal(|ui| {
            for kind in [LineKind::Simulator, LineKind::Serial, LineKind::Tcp] {
                ui.selectable_value(&mut s.kind, kind, kind.name());
            }
        });
        egui::Grid::new("connection-grid")
            .num_columns(2)
            .spacing([8.0, 4.0])
            .show(ui, |ui| {
                match s.kind {
                    LineKind::Serial => {
                        let label = ui.label("Port");
                        ui.horizontal(|ui| {
                            ComboBox::from_id_salt("port")
                                .selected_text(if s.port.is_empty() {
                                    "choose a port"
                                } else {
                                    s.port.as_str()
                                })
                                .width(170.0)
                                .show_ui(ui, |ui| {
                                    for p in &self.ports.ports {
                                        ui.selectable_value(
                                            &mut s.port,
                                            p.path.clone(),
                                            p.to_string(),
                                        );
                                    }
                                    if self.ports.ports.is_empty() {
                                        ui.label(if cfg!(windows) {
                                            "no COM ports found: Device Manager lists them \
                                             under Ports (COM & LPT)"
                                        } else {
                                            "no serial ports found"
                                        });
                                    }
                                })
                                .response
                                .labelled_by(label.id);
                            let label = if self.ports.is_listing() {
                                "listing..."
                            } else {
                                "Refresh"
                            };
                            if ui
                                .button(label)
                                .on_hover_text("List the serial ports again")
                                .clicked()
                            {
                                let ctx = ui.ctx().clone();
                                self.ports.refresh(move || ctx.request_repaint());
                            }
                        });
                        ui.end_row();
                        if let Some(p) = self.ports.ports.iter().find(|p| p.path == s.port)
                            && !p.detail.is_empty()
                        {
                            ui.label("");
                            ui.label(RichText::new(&p.detail).small());
                            ui.end_row();
                        }
                        ui.label("");
                        let allowed = if line_busy && s.kind == LineKind::Serial {
                            Err("disconnect first: the connection holds the port")
                        } else {
                            Ok(())
                        };
                        ui.vertical(|ui| {
                            if self.detect.show(ui, s, allowed) {
                                self.station_text = None;
                            }
                        });
                        ui.end_row();
                        if let Some(e) = &self.ports.error {
                            ui.label("");
                            ui.label(RichText::new(e).color(RED));
                            ui.end_row();
                        }
                    }
                    LineKind::Tcp => {
                        let label = ui.label("Address");
                        ui.text_edit_singleline(&mut s.tcp)
                            .labelled_by(label.id)
                            .on_hover_text(
                                "HOST:PORT of a serial-to-Ethernet bridge or xsel-sim --tcp",
                            );
                        ui.end_row();
                    }
                    LineKind::Simulator => {}
                }
                let label = ui.label("Baud");
                ComboBox::from_id_salt("baud")
                    .selected_text(s.baud.to_string())
                    .show_ui(ui, |ui| {
                        for b in STANDARD_BAUDS {
                            ui.selectable_value(&mut s.baud, b, b.to_string());
                        }
                    })
                    .response
                    .labelled_by(label.id);
                ui.end_row();
                ui.label("Data bits");
                ui.horizontal(|ui| {
                    ui.selectable_value(&mut s.data_bits, 8, "8 bits");
                    ui.selectable_value(&mut s.data_bits, 7, "7 bits");
                });
                ui.end_row();
                ui.label("Parity");
                ui.horizontal(|ui| {
                    for p in Parity::ALL {
                        ui.selectable_value(&mut s.parity, p, p.name());
                    }
                });
                ui.end_row();
                ui.label("Stop bits");
                ui.horizontal(|ui| {
                    ui.selectable_value(&mut s.stop_bits, 1, "1 bit");
                    ui.selectable_value(&mut s.stop_bits, 2, "2 bits");
                });
                ui.end_row();
                let label = ui.label("Station");
                let text = self
                    .station_text
                    .get_or_insert_with(|| format!("{:02X}", s.station));
                let edit = ui
                    .add(egui::TextEdit::singleline(text).desired_width(40.0))
                    .labelled_by(label.id);
                match parse_station(text) {
                    Ok(v) => s.station = v,
                    Err(e) => {
                        ui.end_row();
                        ui.label("");
                        ui.label(RichText::new(e).color(RED));
                    }
                }
                if edit.lost_focus() && parse_station(text).is_ok() {
                    *text = format!("{:02X}", s.station);
                }
                ui.end_row();
                let label = ui.label("Robot");
                ComboBox::from_id_salt("robot")
                    .selected_text(s.robot.as_str())
                    .show_ui(ui, |ui| {
                        for (name, _) in BUILTIN_MODELS {
                            ui.selectable_value(&mut s.robot, name.to_owned(), name);
                        }
                    })
                    .response
                    .labelled_by(label.id);
                ui.end_row();
            });
        if let Err(e) = s.line().validate() {
            ui.label(RichText::new(e.to_string()).color(RED));
        }
        if edited != pendant.settings.connection {
            intents.push(Intent::ConnectionSettings(edited));
        }
        ui.horizontal(|ui| {
            let up = !matches!(pendant.line, crate::pendant::LineState::Closed);
            if ui
                .button(if up { "Reconnect" } else { "Connect" })
                .clicked()
            {
                intents.push(Intent::Connect);
            }
            if ui
                .add_enabled(up, egui::Button::new("Disconnect"))
                .clicked()
            {
                intents.push(Intent::Disconnect);
            }
        });
        self.first_contact.show(ui, pendant, cx.folder, cx.now);
        owner(ui, pendant);
        health(ui, pendant);
    }
}

/// Who owns the line, and what that means when this window dies: one line, always there.
fn owner(ui: &mut Ui, pendant: &Pendant) {
    let (color, text, hover) = match &pendant.line {
        LineState::Up { .. } => match pendant.line.guardian_pid() {
            Some(pid) => (
                GREEN,
                format!("Line owner: guardian process {pid}"),
                "A process of its own holds the line: if this window dies, freezes or is \
                 killed, it sends 238H STOP and closes the line. It is no enabling switch or \
                 E-stop: a real cell needs those hard-wired.",
            ),
            None if pendant.line_kind == Some(LineKind::Simulator) => (
                GREY,
                "Line owner: this window (the built-in simulator stops with it)".to_owned(),
                "The built-in simulator runs inside this window and ends with it.",
            ),
            None => (
                AMBER,
                "Line owner: this window, no guardian (--no-guardian)".to_owned(),
                "If this process is killed while a jog runs, nothing sends STOP: the arm \
                 jogs until the controller stops it. Start without --no-guardian.",
            ),
        },
        _ => (GREY, "Line owner: none (no line)".to_owned(), ""),
    };
    let hover = (!hover.is_empty()).then_some(hover);
    reserved_line(ui, Some((color, &text)), hover);
}

/// Exactly two hex digits, as the wire carries them (no sign).
fn parse_station(text: &str) -> Result<u8, String> {
    let t = text.trim();
    t.parse::<crate::protocol::Station>()
        .map(|s| s.0)
        .map_err(|_| format!("station `{t}`: 2 hex digits, 00 to FF"))
}

/// The link's figures in four lines that are always there (cut to the width, whole on
/// hover), so the panels below never move when a figure grows or polling pauses.
fn health(ui: &mut Ui, pendant: &Pendant) {
    ui.separator();
    let Some(h) = pendant.health.as_ref().filter(|_| pendant.line.is_up()) else {
        let idle = if pendant.line.is_up() {
            "waiting for the link's first figures"
        } else {
            "no line"
        };
        reserved_line(ui, Some((GREY, idle)), None);
        for _ in 0..3 {
            reserved_line(ui, None, None);
        }
        return;
    };
    let text = ui.visuals().text_color();
    let rt = h
        .median_round_trip
        .map_or("-".into(), |d| format!("{:.1} ms", d.as_secs_f64() * 1e3));
    let line = format!(
        "round trip {rt}, {:.0} polls/s, line busy {:.0} %",
        h.polls_per_second,
        h.line_busy * 100.0
    );
    reserved_line(ui, Some((text, &line)), Some(&line));
    let (timeouts, errors) = pendant.faults_last_minute().unwrap_or((0, 0));
    let color = if timeouts + errors > 0 { AMBER } else { text };
    let line = format!("last minute: {timeouts} time-outs, {errors} errors (bad frames, refusals)");
    reserved_line(ui, Some((color, &line)), Some(&line));
    let line = format!(
        "since connected: {} transactions, {} time-outs, {} bad frames, {} refusals",
        h.transactions, h.timeouts, h.bad_frames, h.error_replies
    );
    reserved_line(ui, Some((text, &line)), Some(&line));
    let paused = "polling paused: the window fell behind the link";
    reserved_line(ui, h.polling_paused.then_some((AMBER, paused)), None);
}

impl Pane for ConnectionPanel {
    fn ui(&mut self, ui: &mut Ui, cx: &mut PaneCx<'_>) {
        self.show(ui, cx);
    }
}
