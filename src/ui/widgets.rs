//! Small drawing helpers shared by the panels: lamps, coloured words, the disabled reason.

use egui::{Color32, RichText, Ui};

use crate::pendant::Level;

// Chosen to read on both themes: at least 3.6:1 against the light theme's near-white
// and 4.2:1 against the dark theme's near-black (WCAG contrast ratio).
pub const GREEN: Color32 = Color32::from_rgb(30, 145, 60);
pub const AMBER: Color32 = Color32::from_rgb(190, 110, 0);
pub const RED: Color32 = Color32::from_rgb(210, 40, 40);
pub const GREY: Color32 = Color32::from_gray(120);

/// A round lamp and its label.
pub fn lamp(ui: &mut Ui, on: bool, color: Color32, label: &str) {
    ui.horizontal(|ui| {
        let (rect, _) = ui.allocate_exact_size(egui::vec2(12.0, 12.0), egui::Sense::hover());
        let fill = if on { color } else { GREY.gamma_multiply(0.4) };
        ui.painter().circle_filled(rect.center(), 5.5, fill);
        ui.label(label);
    });
}

/// The colour of a message level.
pub fn level_color(level: Level) -> Color32 {
    match level {
        Level::Info => GREEN,
        Level::Warning => AMBER,
        Level::Error => RED,
    }
}

/// The reason beside a disabled control, in the warning colour.
pub fn reason(ui: &mut Ui, text: impl std::fmt::Display) {
    ui.label(RichText::new(format!("Not available: {text}")).color(AMBER));
}

/// One line of text in space that is always there: empty when `text` is `None`, cut to
/// the width when too long (the whole of it on hover), so nothing below it moves.
/// A view's last word (the model's level and text) on its reserved line, the whole of it
/// on hover; an empty line when there is none.
pub fn said_line(ui: &mut Ui, said: &Option<(crate::pendant::Level, String)>) {
    let text = said
        .as_ref()
        .map(|(level, text)| (level_color(*level), text.as_str()));
    reserved_line(ui, text, text.map(|(_, t)| t));
}

pub fn reserved_line(ui: &mut Ui, text: Option<(Color32, &str)>, hover: Option<&str>) {
    let height = ui.text_style_height(&egui::TextStyle::Body) + 2.0;
    let width = ui.available_width();
    let (rect, _) = ui.allocate_exact_size(egui::vec2(width, height), egui::Sense::hover());
    let Some((color, text)) = text else {
        return;
    };
    let label = egui::Label::new(RichText::new(text).color(color)).truncate();
    let layout = egui::Layout::left_to_right(egui::Align::Center);
    let resp = ui
        .scope_builder(egui::UiBuilder::new().max_rect(rect).layout(layout), |ui| {
            ui.add(label)
        })
        .inner;
    if let Some(hover) = hover {
        resp.on_hover_text(hover);
    }
}

/// `HH:MM:SS UTC` of a wall-clock time (the window has no time-zone table).
pub fn utc_time(t: std::time::SystemTime) -> String {
    let secs = t
        .duration_since(std::time::SystemTime::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs());
    let day = secs % 86_400;
    format!(
        "{:02}:{:02}:{:02} UTC",
        day / 3600,
        day % 3600 / 60,
        day % 60
    )
}

/// Now, as `HH:MM:SS UTC`: when a file was written.
pub fn clock_utc() -> String {
    utc_time(std::time::SystemTime::now())
}
