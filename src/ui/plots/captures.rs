//! The captures list: one row per move captured (its number, when, the command, how it
//! went), ticked to overlay, clicked to select for saving.

use egui::{RichText, Ui};

use super::PlotsPanel;
use crate::pendant::{Intent, Pendant};

/// `0.123` or `—`.
fn num(v: Option<f64>) -> String {
    v.map_or("—".to_string(), |v| format!("{v:.3}"))
}

pub fn list(p: &mut PlotsPanel, ui: &mut Ui, pendant: &Pendant, intents: &mut Vec<Intent>) {
    let captures = &pendant.samples.captures;
    ui.horizontal(|ui| {
        ui.label(RichText::new(format!("{} captures", captures.list.len())).strong());
        if ui.button("Overlay none").clicked() {
            p.overlaid.clear();
        }
        if ui.button("Clear captures").clicked() {
            intents.push(Intent::ClearCaptures);
            p.overlaid.clear();
            p.selected = None;
        }
    });
    if captures.list.is_empty() {
        ui.label("No captures yet: a step, a jog, a Go or a Move Relative starts one.");
        return;
    }
    egui::ScrollArea::vertical()
        .id_salt("plot-captures")
        .max_height(ui.available_height())
        .show(ui, |ui| {
            egui::Grid::new("plot-capture-grid")
                .striped(true)
                .num_columns(8)
                .show(ui, |ui| {
                    for h in [
                        "show",
                        "#",
                        "at (s)",
                        "move",
                        "duration (s)",
                        "final error",
                        "overshoot",
                        "settling (s)",
                    ] {
                        ui.label(RichText::new(h).strong());
                    }
                    ui.end_row();
                    for c in captures.list.iter().rev() {
                        let mut on = p.overlaid.contains(&c.number);
                        if ui.checkbox(&mut on, "").on_hover_text("Overlay").changed() {
                            if on {
                                p.overlaid.insert(c.number);
                            } else {
                                p.overlaid.remove(&c.number);
                            }
                        }
                        let selected = p.selected == Some(c.number);
                        if ui
                            .selectable_label(selected, format!("#{}", c.number))
                            .clicked()
                        {
                            p.selected = Some(c.number);
                        }
                        ui.label(format!("{:.3}", c.trigger_s));
                        ui.label(&c.label);
                        let s = c.summary;
                        ui.label(num(s.duration));
                        ui.label(num(s.final_error));
                        ui.label(num(s.overshoot));
                        ui.label(num(s.settling));
                        ui.end_row();
                    }
                });
        });
}
