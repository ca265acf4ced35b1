//! The position readout (until the arm view lands): work, base and joint coordinates
//! side by side, large and readable, marked stale when the status is old.

use std::time::Instant;

use egui::{RichText, Ui};

use super::pane::{Pane, PaneCx};
use super::widgets::AMBER;
use crate::pendant::Pendant;

/// Below this width or height the readout is drawn compact: the wide grid with figures in
/// every cell needs about 400 points across and 170 down (measured at the default size).
const WIDE_WIDTH: f32 = 410.0;
const WIDE_HEIGHT: f32 = 190.0;

const ROWS: [(&str, &str, &str, &str); 4] = [
    ("X", "J1", "mm", "deg"),
    ("Y", "J2", "mm", "deg"),
    ("Z", "J3 (Z)", "mm", "mm"),
    ("R", "J4", "deg", "deg"),
];

pub fn show(ui: &mut Ui, pendant: &Pendant, now: Instant) {
    // Chosen from the pane's room before anything is drawn, so a line that comes and goes
    // (out of date) never switches the layout frame by frame.
    let compact = ui.available_width() < WIDE_WIDTH || ui.available_height() < WIDE_HEIGHT;
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
    // A narrow or short pane (a small window) gets the compact readout: the joint named
    // beside the axis, units once under the grid, smaller figures, tighter rows; nothing
    // is left out.
    let (size, spacing) = if compact {
        (14.0, [6.0, 2.0])
    } else {
        (17.0, [10.0, 8.0])
    };
    let value = |v: Option<[f64; 4]>, i: usize| {
        let text = v.map_or_else(
            || "-".to_owned(),
            |v| {
                if compact {
                    format!("{:8.3}", v[i])
                } else {
                    format!("{:9.3}", v[i])
                }
            },
        );
        let rich = RichText::new(text).monospace().size(size);
        if stale { rich.color(AMBER) } else { rich }
    };
    egui::Grid::new("position-readout")
        .num_columns(if compact { 4 } else { 7 })
        .spacing(spacing)
        .show(ui, |ui| {
            ui.label("");
            let heads: &[&str] = if compact {
                &["Work", "Base", "Joints"]
            } else {
                &["Work", "", "Base", "", "Joints", ""]
            };
            for head in heads {
                ui.label(RichText::new(*head).strong());
            }
            ui.end_row();
            for (i, (axis, joint, unit, joint_unit)) in ROWS.iter().enumerate() {
                if compact {
                    ui.horizontal(|ui| {
                        ui.label(RichText::new(*axis).size(size + 1.0).strong());
                        ui.label(RichText::new(*joint).size(size - 3.0));
                    });
                    ui.label(value(columns[0], i));
                    ui.label(value(columns[1], i));
                    ui.label(value(columns[2], i));
                } else {
                    ui.label(RichText::new(*axis).size(size + 1.0).strong());
                    ui.label(value(columns[0], i));
                    ui.label(*unit);
                    ui.label(value(columns[1], i));
                    ui.label(*unit);
                    ui.horizontal(|ui| {
                        ui.label(RichText::new(*joint).size(size - 3.0));
                        ui.label(value(columns[2], i));
                    });
                    ui.label(*joint_unit);
                }
                ui.end_row();
            }
        });
    if compact {
        ui.label(RichText::new("mm; R and joints in deg; J3 (Z) in mm").small());
    }
    if let Some(w) = pendant.controller.work.map(|s| s.value) {
        ui.label(format!(
            "{}, work No. {}, tool No. {}",
            w.common.arm, w.work, w.tool
        ));
    }
}

/// The Position pane.
#[derive(Default)]
pub struct Readout;

impl Pane for Readout {
    fn ui(&mut self, ui: &mut Ui, cx: &mut PaneCx<'_>) {
        show(ui, cx.pendant, cx.now);
    }
}
