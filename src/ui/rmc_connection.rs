//! The connection panel's Delta RMC151 (Modbus/TCP) section: where the controller is,
//! its unit ID, the axes shown, and per axis its units' name and soft travel limits;
//! Connect and Disconnect.

use egui::{Button, DragValue, RichText, Ui};

use super::pane::{Pane, PaneCx};
use super::widgets::{AMBER, GREEN, GREY, RED, reserved_line};
use crate::pendant::axes::{AxisIntent, RmcSettings};
use crate::pendant::{Intent, LineState, Pendant};
use crate::rmc::AxisId;

/// Draws the section, editing a copy of the RMC's settings: a change, Connect and
/// Disconnect go to `intents`.
pub fn show(ui: &mut Ui, pendant: &Pendant, intents: &mut Vec<Intent>) {
    let rmc = &pendant.axes;
    let mut edited: RmcSettings = pendant.settings.rmc.clone();
    let (color, state) = match &rmc.line {
        LineState::Closed => (GREY, "not connected".to_string()),
        LineState::Opening => (AMBER, "connecting...".to_string()),
        LineState::Up { line, .. } => (GREEN, format!("connected: {line}")),
        LineState::Down { reason, .. } => (RED, format!("down: {reason}")),
    };
    reserved_line(ui, Some((color, &state)), None);
    egui::Grid::new("rmc-connection-grid")
        .num_columns(2)
        .spacing([8.0, 4.0])
        .show(ui, |ui| {
            let l = ui.label("Address");
            ui.add(
                egui::TextEdit::singleline(&mut edited.address)
                    .hint_text("built-in RMC151")
                    .desired_width(170.0),
            )
            .labelled_by(l.id)
            .on_hover_text(
                "host:port of the RMC151 (port 502 when none is given); empty: the \
                 built-in simulated RMC151",
            );
            ui.end_row();
            let l = ui.label("Unit ID");
            ui.add(DragValue::new(&mut edited.unit).range(0..=255))
                .labelled_by(l.id)
                .on_hover_text("Modbus unit ID (Delta does not document it; 1 by default)");
            ui.end_row();
            let l = ui.label("Axes shown");
            ui.add(DragValue::new(&mut edited.axes).range(1..=crate::rmc::MAX_AXES))
                .labelled_by(l.id);
            ui.end_row();
            let l = ui.label("Units");
            ui.add(egui::TextEdit::singleline(&mut edited.units).desired_width(60.0))
                .labelled_by(l.id)
                .on_hover_text(
                    "The position units' name set in RMCTools (scale and offset), for axes \
                     without one of their own",
                );
            ui.end_row();
        });
    ui.label(
        RichText::new("Per axis: units, and soft limits the pendant keeps its moves within")
            .size(11.0)
            .color(GREY),
    );
    egui::Grid::new("rmc-axes-grid")
        .num_columns(4)
        .spacing([6.0, 2.0])
        .show(ui, |ui| {
            for h in ["", "Units", "Min", "Max"] {
                ui.label(RichText::new(h).size(11.0).color(GREY));
            }
            ui.end_row();
            for axis in AxisId::first(edited.axis_count()) {
                let default_units = edited.units.clone();
                let own = edited.axis_mut(axis);
                ui.label(axis.to_string());
                ui.add(
                    egui::TextEdit::singleline(&mut own.units)
                        .hint_text(default_units)
                        .desired_width(50.0),
                )
                .on_hover_text(format!("{axis}'s units' name (empty: the RMC's)"));
                limit_field(ui, &mut own.limits.min, &format!("{axis} minimum"));
                limit_field(ui, &mut own.limits.max, &format!("{axis} maximum"));
                ui.end_row();
            }
        });
    if let Some(why) = AxisId::first(edited.axis_count())
        .find_map(|a| edited.limits(a).check().err().map(|e| format!("{a}: {e}")))
    {
        ui.label(RichText::new(why).color(RED));
    }
    ui.horizontal(|ui| {
        let up = !matches!(rmc.line, LineState::Closed);
        if ui
            .button(if up { "Reconnect RMC" } else { "Connect RMC" })
            .on_hover_text("Open the RMC151's connection with these settings")
            .clicked()
        {
            intents.push(Intent::Axes(AxisIntent::Connect));
        }
        if ui.add_enabled(up, Button::new("Disconnect RMC")).clicked() {
            intents.push(Intent::Axes(AxisIntent::Disconnect));
        }
    });
    // Growing the axis list for the editor alone is no change.
    let trimmed = |s: &RmcSettings| {
        let mut s = s.clone();
        while s.axis.last().is_some_and(|a| *a == Default::default()) {
            s.axis.pop();
        }
        s
    };
    if trimmed(&edited) != trimmed(&pendant.settings.rmc) {
        intents.push(Intent::Axes(AxisIntent::Connection(trimmed(&edited))));
    }
}

/// A limit that may be off: a tick and, when on, its value.
fn limit_field(ui: &mut Ui, limit: &mut Option<f32>, name: &str) {
    ui.horizontal(|ui| {
        let mut on = limit.is_some();
        if ui
            .checkbox(&mut on, "")
            .on_hover_text(format!("Keep to a {name}"))
            .changed()
        {
            *limit = on.then_some(0.0);
        }
        if let Some(v) = limit {
            ui.add(
                DragValue::new(v)
                    .speed(0.1)
                    .max_decimals(3)
                    .range(-1e6..=1e6),
            )
            .on_hover_text(name.to_string());
        }
    });
}

/// The Delta RMC151's connection section of the left column.
#[derive(Default)]
pub struct RmcConnectionPane;

impl Pane for RmcConnectionPane {
    fn ui(&mut self, ui: &mut Ui, cx: &mut PaneCx<'_>) {
        show(ui, cx.pendant, cx.intents);
    }
}
