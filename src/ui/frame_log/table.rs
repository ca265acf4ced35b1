//! The frame log's rows, virtualised: only the rows in sight are formatted.

use egui::{Color32, Response, RichText, Sense, TextStyle, Ui, Widget, WidgetInfo, pos2, vec2};

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
    // The header scrolls sideways with the rows (their offset of the last frame), and
    // never by itself.
    egui::ScrollArea::horizontal()
        .id_salt("frame-log-header")
        .horizontal_scroll_offset(p.rows_x)
        .scroll_bar_visibility(egui::scroll_area::ScrollBarVisibility::AlwaysHidden)
        .scroll_source(egui::scroll_area::ScrollSource::NONE)
        .show(ui, |ui| {
            egui::Label::new(
                RichText::new(format!(
                    "{:>10} {:>8}  {:<5} {:<3} {:>6}  {:<NAME_WIDTH$}  bytes",
                    if p.wall_clock { "UTC" } else { "s" },
                    "+prev ms",
                    "dir",
                    "sc",
                    "lat ms",
                    "message",
                ))
                .monospace()
                .weak(),
            )
            .extend()
            .ui(ui);
        });
    let mut area = egui::ScrollArea::both()
        .id_salt("frame-log-rows")
        .auto_shrink([false, false]);
    let target = p.scroll_to.take().and_then(|s| p.index_of(log, s));
    if let Some(i) = target {
        let half = ui.available_height() / 2.0;
        area = area.vertical_scroll_offset((i as f32 * row_height - half).max(0.0));
    } else if p.follow && p.paused_at.is_none() {
        // The last row at the bottom of the view: an offset past the end would leave
        // the view showing the last row or two of a short (filtered) list.
        let view = p
            .rows_view_height
            .unwrap_or(ui.available_height())
            .min(ui.available_height());
        let bottom = total as f32 * row_height - view;
        area = area.vertical_scroll_offset(bottom.max(0.0));
    }
    // While the tail is followed the rows move under the pointer between frames, and
    // a click (press and release on one widget) may never land: a press selects the row
    // that was drawn under it in the frame the user saw.
    let press = ui.input(|i| {
        i.pointer
            .primary_pressed()
            .then(|| i.pointer.interact_pos())
            .flatten()
    });
    let mut clicked = press.and_then(|pos| {
        p.drawn
            .iter()
            .find(|(rect, _)| rect.contains(pos))
            .map(|&(_, seq)| seq)
    });
    let mut drawn = Vec::new();
    let mut scrolled_by_user = false;
    // Rows touch: the scroll area's pitch (row height plus this spacing) must be the
    // pitch they are drawn at, or the followed tail drifts off the bottom edge.
    ui.spacing_mut().item_spacing.y = 0.0;
    let out = area.show_rows(ui, row_height, total, |ui, range| {
        ui.spacing_mut().item_spacing.y = 0.0;
        for i in range {
            let Some(row) = p.seq_at(log, i).and_then(|s| log.row(s)) else {
                continue;
            };
            let text = line(log, &row, p.wall_clock);
            let selected = p.selected == Some(row.seq());
            let r = row_ui(ui, text, color(&row), selected, row_height);
            if r.clicked() {
                clicked = Some(row.seq());
            }
            drawn.push((r.rect.intersect(ui.clip_rect()), row.seq()));
        }
    });
    p.drawn = drawn;
    p.rows_x = out.state.clamped_offset().x;
    p.rows_view_height = Some(out.inner_rect.height());
    if ui.rect_contains_pointer(out.inner_rect) && ui.input(|i| i.smooth_scroll_delta.y > 0.0) {
        scrolled_by_user = true;
    }
    if scrolled_by_user {
        p.follow = false;
    }
    if let Some(seq) = clicked {
        p.selected = Some(seq);
        p.follow = false;
    }
}

/// One row: one line of monospace text, never wrapped (wider rows scroll sideways),
/// clickable, and named for assistive technology (and tests) by its text.
fn row_ui(ui: &mut Ui, text: String, color: Color32, selected: bool, height: f32) -> Response {
    let font = TextStyle::Monospace.resolve(ui.style());
    let galley = ui.painter().layout_no_wrap(text.clone(), font, color);
    let width = ui.available_width().max(galley.size().x + 4.0);
    let (rect, response) = ui.allocate_exact_size(vec2(width, height), Sense::click());
    response.widget_info(|| {
        WidgetInfo::selected(egui::Role::Button, ui.is_enabled(), selected, text.clone())
    });
    if ui.is_rect_visible(rect) {
        let visuals = ui.visuals();
        if selected {
            ui.painter()
                .rect_filled(rect, 2.0, visuals.selection.bg_fill);
        } else if response.hovered() {
            ui.painter()
                .rect_filled(rect, 2.0, visuals.widgets.hovered.weak_bg_fill);
        }
        let pos = pos2(rect.left(), rect.center().y - galley.size().y / 2.0);
        ui.painter().galley(pos, galley, color);
    }
    response
}

/// The message name's column (longer names are cut; the decode has them whole).
const NAME_WIDTH: usize = 44;

/// One row as text, in the header's columns: the message name before the bytes (so it
/// is always in sight), the bytes, then the link's note (why garbage, what timed out).
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
        .map_or(String::new(), |us| format!("{:.2}", us as f64 / 1000.0));
    let name = row.name();
    let note = row.note();
    let note = if note.is_empty() {
        String::new()
    } else {
        format!("  {note}")
    };
    format!(
        "{time:>10} {:>8.3}  {:<5} {:<3} {latency:>6}  {name:<NAME_WIDTH$.NAME_WIDTH$}  {}{note}",
        prev as f64 * 1e-6,
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
