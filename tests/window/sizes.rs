//! The default layout at the sizes operators use: 1024x700 (the least supported),
//! 1280x800 (the default), 1920x1080, and 1280x800 at 2 pixels a point. The key widgets of
//! every pane lie inside the window and inside their pane, and no two widgets of the top
//! bar overlap.

use egui::Rect;
use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use xsel_pendant::ui::{PendantApp, StartOptions, Tab};

use crate::kittest_common::{show_tab, step_until};

/// Window sizes in points, with pixels a point.
const SIZES: [([f32; 2], f32); 4] = [
    ([1024.0, 700.0], 1.0),
    ([1280.0, 800.0], 1.0),
    ([1920.0, 1080.0], 1.0),
    ([1280.0, 800.0], 2.0),
];

/// With `XSEL_PENDANT_SHOTS=DIR` set (and the `wgpu` feature, which renders), the window
/// at each size is also rendered into DIR as a PNG, for a person to look at the layout.
#[cfg(feature = "wgpu")]
const SHOTS: &str = "XSEL_PENDANT_SHOTS";

fn app<'a>(size: [f32; 2], ppp: f32) -> Harness<'a, PendantApp> {
    let builder = Harness::builder()
        .with_size(size)
        .with_pixels_per_point(ppp);
    #[cfg(feature = "wgpu")]
    let builder = if std::env::var_os(SHOTS).is_some() {
        builder.wgpu()
    } else {
        builder
    };
    let mut h = builder.build_eframe(|cc| PendantApp::new(cc, StartOptions::fresh_simulator()));
    step_until(&mut h, "a position", |a| {
        a.pendant().controller.work.is_some()
    });
    h.run_steps(2);
    h
}

#[cfg(not(feature = "wgpu"))]
fn shot(_: &mut Harness<'_, PendantApp>, _: &str, _: [f32; 2], _: f32) {}

#[cfg(feature = "wgpu")]
fn shot(h: &mut Harness<'_, PendantApp>, what: &str, size: [f32; 2], ppp: f32) {
    if let Some(dir) = std::env::var_os(SHOTS) {
        let name = format!("{what}-{}x{}-x{ppp}.png", size[0], size[1]);
        let image = h.render().expect("a picture");
        image
            .save(std::path::Path::new(&dir).join(name))
            .expect("saved");
    }
}

fn within(inner: Rect, outer: Rect) -> bool {
    outer.expand(0.5).contains_rect(inner)
}

/// The widget labelled `label` (the first, if several) lies inside the window and, when
/// `pane` is given, inside that pane.
fn check(h: &Harness<'_, PendantApp>, label: &str, pane: Option<Tab>, size: [f32; 2], ppp: f32) {
    let window = Rect::from_min_size(egui::Pos2::ZERO, size.into());
    let node = h
        .query_all_by_label(label)
        .next()
        .unwrap_or_else(|| panic!("{label} is not in the window at {size:?} x{ppp}"));
    let rect = node.rect();
    assert!(
        within(rect, window),
        "{label} at {rect:?} leaves the {size:?} window (x{ppp})"
    );
    if let Some(tab) = pane {
        let pane_rect = h
            .state()
            .pane_rect(tab)
            .unwrap_or_else(|| panic!("the {tab:?} pane is not shown at {size:?}"));
        assert!(
            within(rect, pane_rect),
            "{label} at {rect:?} is cut by its {tab:?} pane {pane_rect:?} at {size:?} x{ppp}"
        );
    }
}

#[test]
fn key_widgets_lie_inside_the_window_and_their_pane_at_every_size() {
    for (size, ppp) in SIZES {
        let mut h = app(size, ppp);
        shot(&mut h, "window", size, ppp);
        for label in [
            "STOP", "X+", "X-", "Y+", "Y-", "Z up\nZ-", "R cw\nR-", "J4+",
        ] {
            check(&h, label, None, size, ppp);
        }
        for label in ["Servo ON", "Home"] {
            check(&h, label, None, size, ppp);
        }
        for label in ["Work", "Base", "Joints"] {
            check(&h, label, Some(Tab::Position), size, ppp);
        }
        // A narrow Status pane calls Completed "Done".
        for label in ["Axis", "Servo", "Home", "In use", "Completed|Done", "Error"] {
            let mut nodes = label.split('|').flat_map(|l| h.query_all_by_label(l));
            let node_in_status = nodes.any(|n| {
                h.state()
                    .pane_rect(Tab::Status)
                    .is_some_and(|p| within(n.rect(), p))
            });
            assert!(
                node_in_status,
                "the Status column {label} is not inside its pane at {size:?} x{ppp}"
            );
        }
        show_tab(&mut h, "Coordinate tables");
        shot(&mut h, "coords", size, ppp);
        // The files rows fold away in a short pane: the table's columns stay in sight.
        for label in ["No.", "X mm", "Y mm", "Z mm", "R deg"] {
            check(&h, label, Some(Tab::Coords), size, ppp);
        }
        // And its first rows too.
        for label in ["work 1 X mm", "work 1 R deg"] {
            check(&h, label, Some(Tab::Coords), size, ppp);
        }
        show_tab(&mut h, "Frame log");
        h.run_steps(3);
        shot(&mut h, "frame-log", size, ppp);
        shot(&mut h, "frame-log", size, ppp);
        check(&h, "Follow tail", Some(Tab::FrameLog), size, ppp);
        // Following the tail, the lowest row drawn is the newest, and it is whole in sight.
        let pane = h
            .state()
            .pane_rect(Tab::FrameLog)
            .expect("the frame log pane");
        let newest = h
            .query_all_by_label_contains(">>")
            .chain(h.query_all_by_label_contains("<<"))
            .map(|n| n.rect())
            .filter(|r| r.top() > pane.top() && r.left() >= pane.left() - 0.5)
            .max_by(|a, b| a.bottom().total_cmp(&b.bottom()))
            .expect("rows in the frame log");
        assert!(
            within(
                egui::Rect::from_x_y_ranges(pane.left()..=pane.left() + 10.0, newest.y_range()),
                pane
            ),
            "the newest row {newest:?} is cut by its pane {pane:?} at {size:?} x{ppp}"
        );
    }
}

#[test]
fn no_two_widgets_of_the_top_bar_overlap_at_any_size() {
    for (size, ppp) in SIZES {
        let h = app(size, ppp);
        let stop = h.get_by_label("STOP").rect();
        let bar_bottom = stop.max.y;
        let theme = h
            .query_all_by_label("Light theme")
            .chain(h.query_all_by_label("Dark theme"))
            .map(|n| n.rect())
            .next()
            .expect("the theme button");
        let mut rects: Vec<(String, Rect)> = vec![("STOP".into(), stop), ("theme".into(), theme)];
        // The top bar's own (the jog panel has a Reset alarm too).
        for label in ["Reset alarm", "No alarm", "Controller ready", "Mode "] {
            if let Some(n) = h
                .query_all_by_label_contains(label)
                .find(|n| n.rect().min.y < bar_bottom)
            {
                rects.push((label.into(), n.rect()));
            }
        }
        for (name, r) in &rects {
            assert!(r.min.y < bar_bottom, "{name} is not in the top bar: {r:?}");
        }
        for (i, (a, ra)) in rects.iter().enumerate() {
            for (b, rb) in &rects[i + 1..] {
                assert!(
                    !ra.shrink(0.5).intersects(rb.shrink(0.5)),
                    "{a} {ra:?} and {b} {rb:?} overlap at {size:?} x{ppp}"
                );
            }
        }
    }
}

#[test]
fn the_frame_log_decode_shows_ten_lines_in_the_default_layout_at_1280x800() {
    let (size, ppp) = ([1280.0, 800.0], 1.0);
    let mut h = app(size, ppp);
    show_tab(&mut h, "Frame log");
    step_until(&mut h, "a few rows", |a| a.pendant().frame_log.len() >= 6);
    // The newest sent row in view, selected as a user selects it.
    h.query_all_by_label_contains(">>")
        .last()
        .expect("a sent row in view")
        .click_accesskit();
    h.run_steps(3);
    assert!(h.state().frame_log_panel().selected().is_some());
    shot(&mut h, "frame-log-decode", size, ppp);
    let lines = h.state().frame_log_panel().decode_lines_shown();
    assert!(lines >= 10.0, "the decode shows {lines:.1} lines");
    // The rows keep theirs above it, the newest inside the pane.
    check(&h, "Close decode", Some(Tab::FrameLog), size, ppp);
    assert!(h.query_all_by_label_contains(">>").count() >= 1);
}

#[test]
fn the_decode_keeps_its_ten_lines_in_the_frame_its_rows_reply_arrives() {
    use std::time::{Duration, Instant};
    use xsel_pendant::pendant::script::ready_controller;
    use xsel_pendant::rmc::{AxisId, RmcEvent};
    use xsel_pendant::robot::Joints;

    let mut h = Harness::builder()
        .with_size([1280.0, 800.0])
        .build_eframe(|cc| PendantApp::new(cc, StartOptions::fresh_offline()));
    let feed = |h: &mut Harness<'_, PendantApp>, events: Vec<RmcEvent>| {
        let pendant = h.state_mut().pendant_mut();
        for event in events {
            pendant.handle_axes_event(Instant::now(), event);
        }
    };
    let kin = *h.state().pendant().kinematics();
    let pendant = h.state_mut().pendant_mut();
    for event in ready_controller(&kin, Joints::new(30.0, 60.0, 50.0, 0.0)) {
        pendant.handle_event(Instant::now(), event);
    }
    pendant.take_requests();
    // An RMC151 status read (FC3, 116 registers): its name is long, so the heading
    // wraps once the reply's latency and button join it.
    let [hi, lo] = AxisId::new(0).expect("axis 1").status_block().to_be_bytes();
    let request = vec![0, 7, 0, 0, 0, 6, 1, 3, hi, lo, 0, 116];
    let mut reply = vec![0, 7, 0, 0, 0, 235, 1, 3, 232];
    reply.resize(9 + 232, 0);
    let sent_at = Instant::now();
    feed(
        &mut h,
        vec![RmcEvent::FrameSent {
            bytes: request,
            at: sent_at,
        }],
    );
    h.run_steps(2);
    show_tab(&mut h, "Frame log");
    // The request selected while its reply is still to come: the decode's heading has
    // no reply to go to yet.
    h.query_all_by_label_contains(">>")
        .last()
        .expect("the request in view")
        .click_accesskit();
    h.run_steps(3);
    assert!(h.state().frame_log_panel().selected().is_some());
    let lines = h.state().frame_log_panel().decode_lines_shown();
    assert!(lines >= 10.0, "the decode shows {lines:.1} lines");
    // The reply comes: its latency and a Go to reply button join the heading, in the
    // same frame as the fields are drawn.
    feed(
        &mut h,
        vec![RmcEvent::FrameReceived {
            bytes: reply,
            at: sent_at + Duration::from_millis(2),
        }],
    );
    h.step();
    assert!(
        h.query_by_label("Go to reply").is_some(),
        "the heading grew"
    );
    let lines = h.state().frame_log_panel().decode_lines_shown();
    assert!(
        lines >= 10.0,
        "the decode shows {lines:.1} lines in the frame its reply arrived"
    );
}

#[test]
fn the_pad_grows_with_the_window() {
    let pad_button = |size: [f32; 2]| {
        let h = app(size, 1.0);
        h.get_by_label("X+").rect()
    };
    let (small, default, large) = (
        pad_button([1024.0, 700.0]),
        pad_button([1280.0, 800.0]),
        pad_button([1920.0, 1080.0]),
    );
    // Never below the floor of 56x40 px.
    assert!(small.width() >= 56.0 && small.height() >= 40.0, "{small:?}");
    assert!(default.width() >= small.width(), "{default:?} {small:?}");
    assert!(
        large.width() >= 1.3 * default.width() && large.height() >= 1.3 * default.height(),
        "at 1920x1080 the pad's X+ is {large:?}, at 1280x800 {default:?}"
    );
}

/// The arm view's labels as painted (shortened and hidden ones too): no two placed boxes
/// overlap and each lies inside the view, with the zones, the taught positions and a ghost
/// drawn (the busiest the default start gets).
#[test]
fn no_two_labels_of_the_arm_view_overlap_at_any_size() {
    use xsel_pendant::render::labels::boxes_overlap;
    for (size, ppp) in SIZES {
        let mut h = app(size, ppp);
        step_until(&mut h, "the zones drawn", |a| {
            a.pendant().zones.boxes().len() == 2
        });
        show_tab(&mut h, "Positions");
        crate::kittest_common::click(&mut h, "Read");
        step_until(&mut h, "the positions read", |a| {
            a.pendant().positions.held().count() >= 3
        });
        h.get_by_role_and_label(egui::accesskit::Role::Button, "X+")
            .hover();
        h.run_steps(3);
        shot(&mut h, "arm-labels", size, ppp);
        let arm = h.state().arm_view();
        let view = arm.view().expect("the arm view is drawn");
        let labels = arm.labels();
        let placed: Vec<([f32; 4], &str)> = labels
            .iter()
            .filter_map(|l| l.rect.map(|r| (r, l.text.as_str())))
            .collect();
        assert!(
            placed.len() >= 10,
            "the labels are drawn at {size:?} x{ppp}: {labels:?}"
        );
        for (i, (a, ta)) in placed.iter().enumerate() {
            let inside = a[0] >= view.origin[0] - 0.5
                && a[1] >= view.origin[1] - 0.5
                && a[2] <= view.origin[0] + view.size[0] + 0.5
                && a[3] <= view.origin[1] + view.size[1] + 0.5;
            assert!(inside, "{ta} at {a:?} leaves the view at {size:?} x{ppp}");
            for (b, tb) in &placed[i + 1..] {
                assert!(
                    !boxes_overlap(*a, *b),
                    "\"{ta}\" {a:?} and \"{tb}\" {b:?} overlap at {size:?} x{ppp}"
                );
            }
        }
        for zone in ["zone 1", "zone 2"] {
            assert!(
                labels.iter().any(|l| l.text.starts_with(zone)),
                "{zone} labelled at {size:?} x{ppp}"
            );
        }
        // A 1920x1080 window takes the wide layout: the arm view has most of the height,
        // and the Plots are in sight beside the messages.
        if size[0] >= 1920.0 {
            let arm = h.state().pane_rect(Tab::Arm).expect("the arm view");
            assert!(arm.height() > 0.5 * size[1], "{arm:?} at {size:?}");
            assert!(
                h.state().pane_rect(Tab::Plots).is_some(),
                "the plots in sight at {size:?}"
            );
        }
    }
}
