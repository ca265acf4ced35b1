//! The message list: what the pendant told the operator, newest last, with the time.

use std::time::Instant;

use egui::{RichText, Ui};

use super::pane::{Pane, PaneCx};
use super::widgets::level_color;
use crate::pendant::Pendant;

pub fn show(ui: &mut Ui, pendant: &Pendant, started: Instant) {
    egui::ScrollArea::vertical()
        .stick_to_bottom(true)
        .auto_shrink([false, false])
        .show(ui, |ui| {
            for m in &pendant.messages {
                let t = m.at.saturating_duration_since(started).as_secs_f64();
                ui.label(
                    RichText::new(format!("{t:>9.3} s  {}", m.text))
                        .monospace()
                        .color(level_color(m.level)),
                );
            }
        });
}

/// The Messages pane.
#[derive(Default)]
pub struct MessagesPane;

impl Pane for MessagesPane {
    fn ui(&mut self, ui: &mut Ui, cx: &mut PaneCx<'_>) {
        show(ui, cx.pendant, cx.started);
    }
}
