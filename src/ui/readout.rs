//! The position readout (until the arm view lands): work, base and joint coordinates
//! side by side, large and readable, marked stale when the status is old.

use std::time::Instant;

use egui::{RichText, Ui};

use super::widgets::AMBER;
use crate::pendant::Pendant;

const ROWS: [(&str, &str, &str, &str); 4] = [
    ("X", "J1", "mm", "deg"),
    ("Y", "J2", "mm", "deg"),
    ("Z", "J3 (Z)", "mm", "mm"),
    ("R", "J4", "deg", "deg"),
];

pub fn show(ui: &mut Ui, pendant: &Pendant, now: Instant) {
    let stale = pendant.controller.is_stale(now);
    if stale && pendant.line.is_up() {
        ui.label(RichText::new("out of date: no fresh status from the controller").color(AMBER));
    }
    let c = &pendant.controller;
    // Work and base from one sample (the same poll, rounded alike).
    let sample = c.sample();
    let columns = [
        sample.map(|(w, _)| w.to_array()),
        sample.map(|(_, b)| b.to_array()),
        c.joint_position().map(|j| j.to_array()),
    ];
    let value = |v: Option<[f64; 4]>, i: usize| {
        let text = v.map_or_else(|| "-".to_owned(), |v| format!("{:9.3}", v[i]));
        let rich = RichText::new(text).monospace().size(17.0);
        if stale { rich.color(AMBER) } else { rich }
    };
    egui::Grid::new("position-readout")
        .num_columns(7)
        .spacing([10.0, 8.0])
        .show(ui, |ui| {
            ui.label("");
            for head in ["Work", "", "Base", "", "Joints", ""] {
                ui.label(RichText::new(head).strong());
            }
            ui.end_row();
            for (i, (axis, joint, unit, joint_unit)) in ROWS.iter().enumerate() {
                ui.label(RichText::new(*axis).size(18.0).strong());
                ui.label(value(columns[0], i));
                ui.label(*unit);
                ui.label(value(columns[1], i));
                ui.label(*unit);
                ui.horizontal(|ui| {
                    ui.label(RichText::new(*joint).size(14.0));
                    ui.label(value(columns[2], i));
                });
                ui.label(*joint_unit);
                ui.end_row();
            }
        });
    if let Some(w) = pendant.controller.work.map(|s| s.value) {
        ui.label(format!(
            "{}, work No. {}, tool No. {}",
            w.common.arm, w.work, w.tool
        ));
    }
}
