//! Image snapshots of the main window in both themes, rendered headlessly (wgpu on Mesa),
//! with the pendant fed scripted events of a ready controller so every run draws the same.
//! References live in `tests/snapshots/`; `UPDATE_SNAPSHOTS=1 cargo test` rewrites them.

use std::time::Instant;

use egui_kittest::Harness;
use xsel_pendant::link::LinkEvent;
use xsel_pendant::pendant::script::ready_controller;
use xsel_pendant::robot::Joints;
use xsel_pendant::ui::{PendantApp, StartOptions};

fn window(light: bool, pixels_per_point: f32) -> Harness<'static, PendantApp> {
    let mut h = Harness::builder()
        .with_size([1280.0, 800.0])
        .with_pixels_per_point(pixels_per_point)
        .wgpu()
        .build_eframe(|cc| PendantApp::new(cc, StartOptions::fresh_offline()));
    h.state_mut().pendant_mut().settings.light_theme = light;
    // The statuses are stamped just before each frame, so none is ever drawn as stale
    // however slow the machine; the one message is stamped at the start ("0.000 s").
    for frame in 0..4 {
        let app = h.state_mut();
        let started = app.started();
        let kin = *app.pendant().kinematics();
        let pendant = app.pendant_mut();
        for event in ready_controller(&kin, Joints::new(30.0, 60.0, 50.0, 0.0)) {
            match event {
                LinkEvent::Connected { .. } if frame > 0 => {}
                LinkEvent::Connected { .. } => pendant.handle_event(started, event),
                _ => pendant.handle_event(Instant::now(), event),
            }
        }
        pendant.take_requests();
        h.step();
    }
    h
}

#[test]
fn main_window_dark() {
    window(false, 1.0).snapshot("main_window_dark");
}

#[test]
fn main_window_light() {
    window(true, 1.0).snapshot("main_window_light");
}

/// A HiDPI screen (2 physical pixels per point): the same layout, sharper.
#[test]
fn main_window_hidpi() {
    window(false, 2.0).snapshot("main_window_hidpi");
}
