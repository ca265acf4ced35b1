//! Taught positions over the arm on the built-in simulator: a recorded point and the
//! position records read show as numbered markers; selecting a row highlights its marker,
//! and the arm view's "Select in the table" selects it in the teach list.

use egui_kittest::kittest::Queryable;
use xsel_pendant::render::{Role, Shape};
use xsel_pendant::ui::PendantApp;

use crate::kittest_common::{click, show_tab, step_until};
use crate::main_window::{app, ready};

fn texts(app: &PendantApp, role: Role) -> Vec<String> {
    app.arm_view()
        .scene()
        .map(|s| {
            s.with_role(role)
                .filter_map(|s| match s {
                    Shape::Text { text, .. } => Some(text.clone()),
                    _ => None,
                })
                .collect()
        })
        .unwrap_or_default()
}

#[test]
fn recorded_points_and_read_positions_show_as_numbered_markers() {
    let mut h = app();
    ready(&mut h);
    show_tab(&mut h, "Teach list");
    click(&mut h, "Record");
    step_until(&mut h, "the recorded point's marker", |a| {
        texts(a, Role::Marker).contains(&"T1".to_owned())
    });
    // The built-in simulator holds positions 1, 2 and 12.
    show_tab(&mut h, "Positions");
    click(&mut h, "Read");
    step_until(&mut h, "the position records' markers", |a| {
        let shown = texts(a, Role::Marker);
        ["2", "12"].iter().all(|n| shown.contains(&(*n).to_owned()))
    });
    // No. 1 is the No. field's number: the selected row, highlighted.
    step_until(&mut h, "No. 1 highlighted", |a| {
        texts(a, Role::MarkerSelected) == ["1"]
    });
    // Right-click on T1's marker: its row, Go to, and "Select in the table".
    let at = marker_on_screen(h.state(), "T1");
    h.event(egui::Event::PointerMoved(at));
    h.step();
    for pressed in [true, false] {
        h.event(egui::Event::PointerButton {
            pos: at,
            button: egui::PointerButton::Secondary,
            pressed,
            modifiers: egui::Modifiers::NONE,
        });
    }
    h.step();
    h.step();
    let _ = h.get_by_label("Go to \"P1\"");
    click(&mut h, "Select in the table");
    show_tab(&mut h, "Teach list");
    step_until(&mut h, "T1 selected", |a| {
        texts(a, Role::MarkerSelected).contains(&"T1".to_owned())
    });
}

/// Where the marker labelled `label` is on the screen.
fn marker_on_screen(app: &PendantApp, label: &str) -> egui::Pos2 {
    let (Some(scene), Some(view)) = (app.arm_view().scene(), app.arm_view().view()) else {
        panic!("the arm view is drawn")
    };
    let mut dots = scene
        .items
        .iter()
        .filter(|i| matches!(i.role, Role::Marker | Role::MarkerSelected));
    let mut last = None;
    for item in dots.by_ref() {
        match &item.shape {
            Shape::Dot { centre, .. } => last = Some(*centre),
            Shape::Text { text, .. } if text == label => {
                let c = last.expect("a dot before its label");
                let [x, y] = view.to_screen(c);
                return egui::pos2(x, y);
            }
            _ => {}
        }
    }
    panic!("no marker {label}")
}
