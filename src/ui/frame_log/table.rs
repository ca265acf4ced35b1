//! The frame log's rows, virtualised: only the rows in sight are formatted.

use egui::{Color32, RichText, TextStyle, Ui};

use super::FrameLogPanel;
use crate::pendant::Pendant;
use crate::pendant::frame_log::file::utc;
use crate::pendant::frame_log::{Dir, FrameLog, Row, Verdict};
use crate::ui::widgets::{AMBER, GREEN, RED};

const SENT: Color32 = Color32::from_rgb(90, 150, 230);

pub fn show(p: &mut FrameLogPanel, ui: &mut Ui, pendant: &Pendant) {
    let log = p.opened.as_ref().map_or(&pendant.frame_log, |o| &o.log);
    let total = p.view_len(log);
    let row_height = ui.text_style_height(&TextStyle::Monospace) + 4.0;
    ui.label(
        RichText::new(format!(
            "{:>12} {:>11}  {:<5} {:<34} {:>4} {:>9}  bytes",
            if p.wall_clock { "time (UTC)" } else { "s" },
            "+prev s",
            "dir",
            "message",
            "sc",
            "latency"
        ))
        .monospace()
        .weak(),
    );
    let mut area = egui::ScrollArea::both()
        .id_salt("frame-log-rows")
        .auto_shrink([false, false]);
    let target = p.scroll_to.take().and_then(|s| p.index_of(log, s));
    if let Some(i) = target {
        let half = ui.available_height() / 2.0;
        area = area.vertical_scroll_offset((i as f32 * row_height - half).max(0.0));
    } else if p.follow && p.paused_at.is_none() {
        area = area.vertical_scroll_offset(total as f32 * row_height);
    }
    let mut clicked = None;
    let mut scrolled_by_user = false;
    let out = area.show_rows(ui, row_height, total, |ui, range| {
        ui.spacing_mut().item_spacing.y = 0.0;
        for i in range {
            let Some(row) = p.seq_at(log, i).and_then(|s| log.row(s)) else {
                continue;
            };
            let text = line(log, &row, p.wall_clock);
            let color = color(&row);
            let selected = p.selected == Some(row.seq());
            let button =
                egui::Button::selectable(selected, RichText::new(text).monospace().color(color));
            let width = ui.available_width().max(900.0);
            if ui.add_sized([width, row_height], button).clicked() {
                clicked = Some(row.seq());
            }
        }
    });
    if ui.rect_contains_pointer(out.inner_rect) && ui.input(|i| i.smooth_scroll_delta.y > 0.0) {
        scrolled_by_user = true;
    }
    if scrolled_by_user {
        p.follow = false;
    }
    if let Some(seq) = clicked {
        p.selected = if p.selected == Some(seq) {
            None
        } else {
            Some(seq)
        };
        p.follow = false;
    }
}

/// One row as text, in the header's columns; the bytes last (they vary in length).
fn line(log: &FrameLog, row: &Row<'_>, wall: bool) -> String {
    let t = row.t_ns();
    let time = if wall {
        utc(log.wall(row)).get(11..).unwrap_or_default().to_string()
    } else {
        format!("{:.6}", t as f64 * 1e-9)
    };
    let prev = log
        .previous(row.seq())
        .map_or(0, |p| t.saturating_sub(p.t_ns()));
    let latency = row
        .latency_us()
        .map_or(String::new(), |us| format!("{:.2} ms", us as f64 / 1000.0));
    let mut name = row.name();
    if !row.note().is_empty() {
        name = format!("{name}: {}", row.note());
    }
    if name.chars().count() > 34 {
        name = name.chars().take(31).chain("...".chars()).collect();
    }
    format!(
        "{time:>12} {:>11.6}  {:<5} {name:<34} {:>4} {latency:>9}  {}",
        prev as f64 * 1e-9,
        row.dir().arrow(),
        row.verdict().label(),
        row.ascii()
    )
}

fn color(row: &Row<'_>) -> Color32 {
    if row.is_problem() {
        RED
    } else if row.verdict() == Verdict::AtAt {
        AMBER
    } else if row.dir() == Dir::Sent {
        SENT
    } else {
        GREEN
    }
}
