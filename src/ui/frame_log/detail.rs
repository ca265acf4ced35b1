//! The selected row, decoded field by field; the bytes of the field under the pointer are
//! marked in the raw text. Jumps between request and reply, and copy.

use egui::text::{LayoutJob, TextFormat};
use egui::{Color32, FontId, RichText, Ui};

use super::{FrameLogPanel, plain};
use crate::pendant::Pendant;
use crate::pendant::frame_log::{Protocol, Row};
use crate::protocol::Columns;

const MARK: Color32 = Color32::from_rgb(120, 90, 10);

pub fn show(p: &mut FrameLogPanel, ui: &mut Ui, pendant: &Pendant) {
    let log = p.opened.as_ref().map_or(&pendant.frame_log, |o| &o.log);
    let Some(seq) = p.selected else { return };
    let Some(row) = log.row(seq) else {
        p.selected = None;
        return;
    };
    let d = row.describe();
    let modbus = row.protocol() == Protocol::Modbus;
    let request = log.request_of(seq);
    let reply = log.reply_of(seq);
    let mut goto = None;
    let mut copy = false;
    let mut close = false;
    // One line whatever the row: the buttons on the right, the row's name cut to the
    // room left (whole on hover), so the fields below keep their lines.
    egui::Sides::new().shrink_left().truncate().show(
        ui,
        |ui| {
            ui.label(RichText::new(format!("Row {seq}: {}", plain(&row.name()))).strong());
        },
        |ui| {
            close = ui.button("Close decode").clicked();
            copy = ui.button("Copy").clicked();
            if let Some(r) = request
                && ui.button("Go to request").clicked()
            {
                goto = Some(r);
            }
            if let Some(r) = reply
                && ui.button("Go to reply").clicked()
            {
                goto = Some(r);
            }
            if let Some(us) = row.latency_us() {
                ui.label(format!("latency {:.3} ms", us as f64 / 1000.0));
            }
        },
    );
    let hovered = p.hovered.take();
    let fields = egui::ScrollArea::vertical()
        .id_salt("frame-log-decode")
        .auto_shrink([false, false])
        .show(ui, |ui| {
            // The raw text first, scrolling with the fields (the pane's height goes to the
            // decode, not to a heading that stays); lines stacked without gaps.
            ui.spacing_mut().item_spacing.y = 0.0;
            raw_text(ui, &row, modbus, hovered);
            ui.label(RichText::new(plain(&d.title)).monospace());
            for f in &d.fields {
                let cols = if f.columns.last > f.columns.first {
                    format!("{}-{}", f.columns.first, f.columns.last)
                } else {
                    f.columns.first.to_string()
                };
                let text = format!(
                    "  {cols:<7} {:<12} {}: {}",
                    plain(&f.raw),
                    f.name,
                    plain(&f.value)
                );
                let r = ui.label(RichText::new(text).monospace());
                if r.hovered() {
                    p.hovered = Some(f.columns);
                }
                for b in &f.bits {
                    ui.label(
                        RichText::new(format!("          {}", plain(&b.to_string()))).monospace(),
                    );
                }
            }
            ui.label(RichText::new(format!("  {}", plain(&d.checksum.to_string()))).monospace());
            for pr in &d.problems {
                ui.label(
                    RichText::new(format!(
                        "  problem at column {}: {}",
                        pr.column,
                        plain(&pr.message)
                    ))
                    .monospace()
                    .color(crate::ui::widgets::RED),
                );
            }
        });
    p.decode_drawn.lines =
        fields.inner_rect.height() / ui.text_style_height(&egui::TextStyle::Monospace);
    if p.hovered != hovered {
        // The raw text above was drawn with the old mark: draw again with the new one.
        ui.ctx().request_repaint();
    }
    if copy {
        ui.ctx()
            .copy_text(format!("{}\n{}", row.ascii(), plain(&d.to_string())));
    }
    if let Some(s) = goto {
        p.selected = Some(s);
        p.scroll_to = Some(s);
        p.follow = false;
    }
    if close {
        p.selected = None;
    }
}

/// The row's raw text, the hovered field's bytes marked.
fn raw_text(ui: &mut Ui, row: &Row<'_>, modbus: bool, hovered: Option<Columns>) {
    let mut job = LayoutJob::default();
    // Long replies wrap at any byte (they have no spaces to wrap at).
    job.wrap.max_width = ui.available_width();
    job.wrap.break_anywhere = true;
    let font = FontId::monospace(14.0);
    for (i, b) in row.bytes().iter().enumerate() {
        let column = i + 1;
        let marked = hovered.is_some_and(|c| c.first <= column && column <= c.last);
        let format = TextFormat {
            font_id: font.clone(),
            color: ui.visuals().text_color(),
            background: if marked { MARK } else { Color32::TRANSPARENT },
            ..TextFormat::default()
        };
        let text = if modbus {
            // Binary: each byte as a hex pair, its column its place in the frame.
            format!("{b:02X} ")
        } else {
            [*b].escape_ascii().to_string()
        };
        job.append(&text, 0.0, format);
    }
    if row.bytes().is_empty() {
        job.append(
            row.note(),
            0.0,
            TextFormat::simple(font, ui.visuals().text_color()),
        );
    }
    ui.label(job);
    if !row.note().is_empty() && !row.bytes().is_empty() {
        ui.label(RichText::new(plain(row.note())).color(crate::ui::widgets::RED));
    }
}
