//! The first-contact report from the connection panel on the built-in simulator, driven
//! headlessly with egui_kittest: the button runs the read-only questions on a thread of
//! its own, the report lands as a new file in the files folder, and Show report opens
//! it. Waits are bounded by a deadline; nothing sleeps.

use std::time::Instant;

use xsel_pendant::pendant::Intent;

use crate::kittest_common::{click_button, step_until_shown};
use crate::main_window::app;

#[test]
fn the_report_is_taken_written_to_a_new_file_and_shown() {
    let folder = std::env::temp_dir().join(format!("xsel-fc-window-{}", std::process::id()));
    std::fs::create_dir_all(&folder).expect("a folder of the test");
    let mut h = app();
    h.state_mut()
        .pendant_mut()
        .apply(Intent::FileUsed(folder.join("any")), Instant::now());
    h.step();
    click_button(&mut h, "First-contact report");
    step_until_shown(&mut h, "report written");
    let written: Vec<_> = std::fs::read_dir(&folder)
        .expect("the folder")
        .filter_map(|e| e.ok())
        .map(|e| e.path())
        .collect();
    assert_eq!(written.len(), 1, "{written:?}");
    let text = std::fs::read_to_string(&written[0]).expect("the report");
    assert!(text.contains("- 215H: 5 of 5 answered"), "{text}");
    assert!(text.contains("Only queries were sent"));
    click_button(&mut h, "Show report");
    step_until_shown(&mut h, "Every frame, in order");
    // The window's own line went on polling throughout: the report used a line of
    // its own (a second built-in simulator).
    assert!(h.state().pendant().line.is_up());
    let _ = std::fs::remove_dir_all(&folder);
}
