//! The centre until the arm view lands: the position in work, base and joint coordinates,
//! large and readable, marked stale when the status is old.

use std::time::Instant;

use egui::{RichText, Ui};

use super::widgets::AMBER;
use crate::pendant::Pendant;

/// One line of the readout: its name, the four values, their labels and units.
type Row<'a> = (&'a str, Option<[f64; 4]>, [&'a str; 4], [&'a str; 4]);

pub fn show(ui: &mut Ui, pendant: &Pendant, now: Instant) {
    ui.heading("Position");
    let stale = pendant.controller.is_stale(now);
    if stale && pendant.line.is_up() {
        ui.label(RichText::new("out of date: no fresh status from the controller").color(AMBER));
    }
    let c = &pendant.controller;
    let rows: [Row<'_>; 3] = [
        (
            "Work",
            c.work_position().map(|p| p.to_array()),
            ["X", "Y", "Z", "R"],
            ["mm", "mm", "mm", "deg"],
        ),
        (
            "Base",
            c.base_position().map(|p| p.to_array()),
            ["X", "Y", "Z", "R"],
            ["mm", "mm", "mm", "deg"],
        ),
        (
            "Joints",
            c.joint_position().map(|j| j.to_array()),
            ["J1", "J2", "J3", "J4"],
            ["deg", "deg", "mm", "deg"],
        ),
    ];
    egui::Grid::new("position-readout")
        .num_columns(5)
        .spacing([24.0, 8.0])
        .show(ui, |ui| {
            for (name, values, labels, units) in rows {
                ui.label(RichText::new(name).size(18.0).strong());
                for i in 0..4 {
                    let text = values.map_or_else(
                        || format!("{} -", labels[i]),
                        |v| format!("{} {:>10.3} {}", labels[i], v[i], units[i]),
                    );
                    let mut rich = RichText::new(text).monospace().size(20.0);
                    if stale {
                        rich = rich.color(AMBER);
                    }
                    ui.label(rich);
                }
                ui.end_row();
            }
        });
}
