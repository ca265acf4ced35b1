//! The panes' arrangement in a file of its own: written whole after a change, an
//! unreadable one set aside with a message and the default layout used.

use egui_kittest::Harness;
use xsel_pendant::ui::{PendantApp, StartOptions, Tab};

use crate::kittest_common::*;

fn start_in(dir: &std::path::Path) -> Harness<'static, PendantApp> {
    let options = StartOptions {
        data_dir: Some(dir.to_path_buf()),
        fresh: false,
        ..StartOptions::fresh_offline()
    };
    Harness::builder()
        .with_size([1280.0, 800.0])
        .build_eframe(move |cc| PendantApp::new(cc, options))
}

#[test]
fn an_unreadable_layout_file_is_set_aside_said_and_written_again_whole() {
    let dir = std::env::temp_dir().join(format!("xsel-pendant-layout-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("layout.json");
    std::fs::write(&file, b"{\"root\": garbage").unwrap();
    let mut h = start_in(&dir);
    let said =
        h.state().pendant().messages.iter().any(|m| {
            m.text.contains("window layout could not be read") && m.text.contains("kept as")
        });
    assert!(said, "{:?}", h.state().pendant().messages);
    let aside = std::fs::read_dir(&dir)
        .unwrap()
        .flatten()
        .find(|e| {
            e.file_name()
                .to_string_lossy()
                .contains("layout.json.unreadable")
        })
        .expect("the unreadable file kept");
    assert_eq!(std::fs::read(aside.path()).unwrap(), b"{\"root\": garbage");
    // The default layout is drawn, and written to its file.
    h.run_steps(2);
    assert!(h.state().pane_rect(Tab::Status).is_some());
    step_until(&mut h, "the layout written", |_| {
        std::fs::read(&file).is_ok_and(|b| {
            serde_json::from_slice::<egui_tiles::Tree<Tab>>(&b)
                .is_ok_and(|t| t.tiles.find_pane(&Tab::Signals).is_some())
        })
    });
    drop(h);
    let _ = std::fs::remove_dir_all(&dir);
}
