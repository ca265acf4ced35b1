//! An image snapshot of the frame log pane with scripted rows (fixed times, so every run
//! draws the same): sent, received, `@@`, an error reply, garbage with a bad checksum and
//! a time-out, one row selected with its decode. `UPDATE_SNAPSHOTS=1` rewrites it.

use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use xsel_pendant::ui::{PendantApp, StartOptions};

use crate::wire::frame as framed;

#[test]
fn frame_log_pane() {
    let mut h = Harness::builder()
        .with_size([1280.0, 800.0])
        .wgpu()
        .build_eframe(|cc| PendantApp::new(cc, StartOptions::fresh_offline()));
    let log = &mut h.state_mut().pendant_mut().frame_log;
    let ms = 1_000_000;
    log.push_sent(&framed("!99215"), 100 * ms);
    log.push_received(&framed("#99215000000"), 103 * ms);
    log.push_sent(b"!992A101@@\r\n", 200 * ms);
    log.push_received(&framed("#992A10000040F000000000003D09"), 204 * ms);
    log.push_sent(&framed("!992D501001E001E00140200002710"), 300 * ms);
    log.push_received(b"&99C1F00\r\n", 302 * ms);
    log.push_sent(&framed("!99212"), 400 * ms);
    log.push_garbage(b"#99212000000FF\r\n", "checksum error", 404 * ms);
    log.push_sent(&framed("!99215"), 500 * ms);
    log.push_timeout("no reply to 215H (system status query)", 600 * ms);
    h.step();
    h.get_by_label("Frame log").click();
    h.step();
    h.step();
    h.state_mut().frame_log_panel_mut().reveal(4);
    h.run_steps(3);
    h.snapshot("frame_log_pane");
}
