//! The coordinate table itself: a virtualised egui_extras table (only visible rows are
//! laid out), one text cell per value, checked when the entry ends (Enter or leaving
//! the cell): the pendant checks it, and a refused entry stays in red with the draft
//! unchanged.

use egui::{Color32, Key, RichText, Role, TextEdit, Ui, WidgetInfo};
use egui_extras::{Column as Col, TableBuilder};

use super::coords::CoordsPanel;
use super::widgets::{AMBER, GREY, RED};
use crate::pendant::Pendant;
use crate::pendant::coords::cell::{self, Column};
use crate::pendant::coords::draft::cell_differs;
use crate::pendant::coords::{CellEntry, CoordsIntent};
use crate::robot::{CoordSystem, FrameKind};

const ROW_HEIGHT: f32 = 22.0;
/// The frozen No. column's width.
const NUMBER_WIDTH: f32 = 34.0;
/// The colour of a cell that differs from the controller's value.
const EDITED: Color32 = AMBER;

/// The cell being typed.
#[derive(Clone, Debug, PartialEq)]
pub struct CellEdit {
    pub kind: FrameKind,
    pub number: usize,
    pub column: Column,
    pub text: String,
}

impl CellEdit {
    fn is_at(&self, kind: FrameKind, number: usize, column: Column) -> bool {
        self.kind == kind && self.number == number && self.column == column
    }
}

/// The accessible name of a cell: `work 3 X mm`.
pub fn cell_label(kind: FrameKind, number: usize, column: Column) -> String {
    format!("{kind} {number} {}", column.heading())
}

pub fn table(
    ui: &mut Ui,
    panel: &mut CoordsPanel,
    pendant: &Pendant,
    ask: &mut impl FnMut(CoordsIntent),
) {
    let kind = panel.kind;
    let controller = pendant
        .read_table(kind)
        .map(|t| t.records.clone())
        .unwrap_or_default();
    let in_use = pendant.controller.frame_numbers().map(|(w, t)| match kind {
        FrameKind::Work => usize::from(w),
        FrameKind::Tool => usize::from(t),
    });
    let rows: Vec<usize> = {
        let draft = pendant.coords.draft(kind).rows();
        (0..draft.len())
            .filter(|&n| {
                !panel.only_differences || draft[n] != controller.get(n).copied().flatten()
            })
            .collect()
    };
    // The No. column stays put while a narrow pane scrolls the values sideways; the two
    // tables scroll down together, whichever the wheel or the bar moved.
    let offset = panel.rows_offset[kind_index(kind)];
    let whole = ui.available_rect_before_wrap();
    let (left, right) = whole.split_left_right_at_x(whole.left() + NUMBER_WIDTH + 8.0);
    let column = |rect| {
        egui::UiBuilder::new()
            .max_rect(rect)
            .layout(egui::Layout::top_down(egui::Align::Min))
    };
    let numbers = ui
        .scope_builder(column(left), |ui| {
            numbers_table(ui, kind, &rows, in_use, offset)
        })
        .inner;
    let values = ui
        .scope_builder(column(right), |ui| {
            egui::ScrollArea::horizontal()
                .id_salt(("coords-table-sideways", kind))
                .show(ui, |ui| {
                    let shown = Shown {
                        controller: &controller,
                        in_use,
                        rows: &rows,
                        offset,
                    };
                    rows_table(ui, panel, pendant, ask, &shown)
                })
                .inner
        })
        .inner;
    let moved = [values, numbers]
        .into_iter()
        .find(|o| (o - offset).abs() > 0.5);
    if let Some(to) = moved {
        panel.rows_offset[kind_index(kind)] = to;
        // The other table follows on the next frame.
        ui.ctx().request_repaint();
    }
}

fn kind_index(kind: FrameKind) -> usize {
    match kind {
        FrameKind::Work => 0,
        FrameKind::Tool => 1,
    }
}

/// The frozen No. column, scrolled to `offset`; returns where it was scrolled to.
fn numbers_table(
    ui: &mut Ui,
    kind: FrameKind,
    rows: &[usize],
    in_use: Option<usize>,
    offset: f32,
) -> f32 {
    TableBuilder::new(ui)
        .id_salt(("coords-numbers", kind))
        .striped(true)
        .vertical_scroll_offset(offset)
        .scroll_bar_visibility(egui::scroll_area::ScrollBarVisibility::AlwaysHidden)
        .auto_shrink([true, false])
        .cell_layout(egui::Layout::left_to_right(egui::Align::Center))
        .column(Col::exact(NUMBER_WIDTH))
        .header(ROW_HEIGHT, |mut h| {
            h.col(|ui| {
                ui.strong("No.");
            });
        })
        .body(|body| {
            body.rows(ROW_HEIGHT, rows.len(), |mut row| {
                let n = rows[row.index()];
                row.set_selected(in_use == Some(n));
                row.col(|ui| {
                    ui.label(n.to_string());
                });
            });
        })
        .state
        .clamped_offset()
        .y
}

/// What one frame of the values table shows.
struct Shown<'a> {
    /// The controller's records as read.
    controller: &'a [Option<CoordSystem>],
    /// The record the controller uses now.
    in_use: Option<usize>,
    /// The record numbers shown (all, or those that differ).
    rows: &'a [usize],
    /// How far down the table is scrolled.
    offset: f32,
}

/// The values table scrolled to `shown.offset`; returns where it was scrolled to.
fn rows_table(
    ui: &mut Ui,
    panel: &mut CoordsPanel,
    pendant: &Pendant,
    ask: &mut impl FnMut(CoordsIntent),
    shown: &Shown<'_>,
) -> f32 {
    let &Shown {
        controller,
        in_use,
        rows,
        offset,
    } = shown;
    let kind = panel.kind;
    // X to R share the width in sight (54 to 100 px each), so they fit a narrow pane; the
    // Arm toggle, the state and the diff's columns come after them, sideways.
    ui.spacing_mut().item_spacing.x = 4.0;
    let share = (ui.available_width() - 8.0) / Column::ALL.len() as f32 - 4.0;
    let value = Col::exact(share.clamp(54.0, 100.0));
    // With the diff shown, each controller column sits beside its draft column.
    let per_value = if panel.show_diff { 2 } else { 1 };
    TableBuilder::new(ui)
        .id_salt(("coords-table", kind))
        .striped(true)
        .vertical_scroll_offset(offset)
        .cell_layout(egui::Layout::left_to_right(egui::Align::Center))
        .columns(value, Column::ALL.len() * per_value)
        .column(Col::exact(34.0))
        .column(Col::auto().at_least(90.0))
        .header(ROW_HEIGHT, |mut h| {
            for c in Column::ALL {
                h.col(|ui| {
                    ui.strong(c.heading());
                });
                if panel.show_diff {
                    h.col(|ui| {
                        ui.strong(format!("ctrl {}", c.heading()))
                            .on_hover_text("The controller's value, beside the draft's");
                    });
                }
            }
            h.col(|ui| {
                ui.strong("Arm")
                    .on_hover_text("Show this frame over the arm view");
            });
            h.col(|ui| {
                ui.strong("State");
            });
        })
        .body(|body| {
            body.rows(ROW_HEIGHT, rows.len(), |mut row| {
                let n = rows[row.index()];
                let draft = pendant.coords.draft(kind).get(n);
                let theirs = controller.get(n).copied().flatten();
                let read = controller.get(n).is_some_and(|r| r.is_some());
                row.set_selected(in_use == Some(n));
                for column in Column::ALL {
                    row.col(|ui| value_cell(ui, panel, pendant, ask, controller, n, column));
                    if panel.show_diff {
                        row.col(|ui| {
                            let differs = cell_differs(draft, theirs, column);
                            let text = theirs
                                .map_or("unread".to_owned(), |cs| cell::show(column.get(&cs)));
                            let color = if differs { EDITED } else { GREY };
                            ui.label(RichText::new(text).color(color));
                        });
                    }
                }
                row.col(|ui| {
                    let mut on = pendant.coords.is_over_arm(kind, n as u8);
                    let r = ui.checkbox(&mut on, "");
                    r.widget_info(|| {
                        WidgetInfo::selected(
                            Role::CheckBox,
                            true,
                            on,
                            format!("{kind} {n} over the arm"),
                        )
                    });
                    if r.changed() {
                        ask(CoordsIntent::OverArm {
                            kind,
                            number: n as u8,
                            on,
                        });
                    }
                });
                row.col(|ui| {
                    let mut words = Vec::new();
                    if in_use == Some(n) {
                        words.push("in use");
                    }
                    if controller.is_empty() || !read {
                        words.push("unread");
                    }
                    if draft != theirs && draft.is_some() {
                        words.push("edited");
                    }
                    if cell::read_only(kind, n) {
                        words.push("base frame");
                    }
                    ui.label(words.join(", "));
                });
            });
        })
        .state
        .clamped_offset()
        .y
}

fn value_cell(
    ui: &mut Ui,
    panel: &mut CoordsPanel,
    pendant: &Pendant,
    ask: &mut impl FnMut(CoordsIntent),
    controller: &[Option<CoordSystem>],
    n: usize,
    column: Column,
) {
    let kind = panel.kind;
    let draft = pendant.coords.draft(kind).get(n);
    let theirs = controller.get(n).copied().flatten();
    let editing = panel.edit.as_ref().filter(|e| e.is_at(kind, n, column));
    // A refused entry stays in its cell until it is typed over, dismissed or replaced.
    let refusal = pendant
        .coords
        .refused
        .as_ref()
        .filter(|r| r.is_at(kind, n, column));
    let refused = editing.is_none() && refusal.is_some();
    let mut text = match (editing, refusal) {
        (Some(e), _) => e.text.clone(),
        (None, Some(r)) => r.entry.text.clone(),
        (None, None) => draft.map_or_else(String::new, |cs| cell::show(column.get(&cs))),
    };
    let color = if refused {
        RED
    } else if cell_differs(draft, theirs, column) && draft.is_some() {
        EDITED
    } else {
        ui.visuals().text_color()
    };
    let read_only = cell::read_only(kind, n);
    // The base frame's row is drawn as text, not as fields: it cannot be typed into.
    let color = if read_only { GREY } else { color };
    let label = cell_label(kind, n, column);
    let mut field = TextEdit::singleline(&mut text)
        .id_salt(("coord-cell", kind, n, column.index()))
        .desired_width(f32::INFINITY)
        .margin(egui::vec2(2.0, 2.0))
        .text_color(color)
        .interactive(!read_only)
        .hint_text(RichText::new("unread").color(GREY));
    if read_only {
        field = field.frame(egui::Frame::NONE);
    }
    let r = ui.add(field);
    // The tooltip is also the cell's accessible name (screen readers, tests).
    let r = if read_only {
        r.on_hover_text(format!("{label}: {}", cell::READ_ONLY))
    } else {
        r.on_hover_text(label)
    };
    if r.changed() || (r.gained_focus() && editing.is_none()) {
        panel.edit = Some(CellEdit {
            kind,
            number: n,
            column,
            text: text.clone(),
        });
    }
    if r.lost_focus()
        && panel
            .edit
            .as_ref()
            .is_some_and(|e| e.is_at(kind, n, column))
    {
        panel.edit = None;
        if ui.input(|i| i.key_pressed(Key::Escape)) {
            if refusal.is_some() {
                ask(CoordsIntent::DismissRefusal);
            }
        } else {
            ask(CoordsIntent::SetCell(CellEntry {
                kind,
                number: n,
                column,
                text,
            }));
        }
    }
    r.context_menu(|ui| {
        let can = theirs.is_some() && !read_only;
        if ui
            .add_enabled(can, egui::Button::new("Reset to the controller's value"))
            .clicked()
        {
            ask(CoordsIntent::ResetCell {
                kind,
                number: n,
                column,
            });
            panel.edit = None;
            ui.close();
        }
    });
}
