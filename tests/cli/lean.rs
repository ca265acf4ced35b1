//! The simulators link no UI: neither egui nor its renderers are in their executables, on
//! any platform (the Windows linker keeps what a Linux one drops, so this is checked on
//! the files, not taken on trust).

use std::path::Path;

/// Names that only UI code brings into an executable (its crates' source paths, which
/// panic locations and debug info carry).
const UI_CRATES: [&[u8]; 4] = [b"egui-0.", b"eframe-0.", b"glow-0.", b"winit-0."];

fn ui_crates_in(exe: &Path) -> Vec<String> {
    let bytes = std::fs::read(exe).expect("the executable is readable");
    UI_CRATES
        .iter()
        .filter(|name| memchr::memmem::find(&bytes, name).is_some())
        .map(|name| String::from_utf8_lossy(name).into_owned())
        .collect()
}

#[test]
fn the_simulators_link_no_ui() {
    for exe in [
        env!("CARGO_BIN_EXE_xsel-sim"),
        env!("CARGO_BIN_EXE_rmc-sim"),
    ] {
        let found = ui_crates_in(Path::new(exe));
        assert!(found.is_empty(), "{exe} links UI crates: {found:?}");
    }
}

#[test]
fn the_pendant_does_link_the_ui() {
    // The check above can fail: the pendant's own executable holds those names.
    let found = ui_crates_in(Path::new(env!("CARGO_BIN_EXE_xsel-pendant")));
    assert!(found.iter().any(|c| c == "egui-0."), "found {found:?}");
}
