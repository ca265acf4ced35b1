//! Opening the native window, with a plain one-line error where there is no display.

use super::app::{APP_ID, PendantApp, StartOptions};

/// Opens the window and runs until it closes, drawn by `renderer`.
pub fn run_window(options: StartOptions, renderer: eframe::Renderer) -> Result<(), String> {
    if let Some(why) = no_display() {
        return Err(why);
    }
    let native = eframe::NativeOptions {
        viewport: egui::ViewportBuilder::default()
            .with_title("xsel-pendant")
            .with_inner_size([1280.0, 800.0])
            .with_min_inner_size([900.0, 600.0])
            .with_app_id(APP_ID),
        renderer,
        ..eframe::NativeOptions::default()
    };
    eframe::run_native(
        APP_ID,
        native,
        Box::new(move |cc| Ok(Box::new(PendantApp::new(cc, options)))),
    )
    .map_err(|e| {
        let other = match renderer {
            eframe::Renderer::Glow => "--renderer wgpu",
            _ => "--renderer glow",
        };
        format!("cannot open the window ({e}); try {other}, or --headless for text mode")
    })
}

/// On Linux and the BSDs a window needs X11 or Wayland.
#[cfg(all(unix, not(target_os = "macos")))]
fn no_display() -> Option<String> {
    let set = |v: &str| std::env::var_os(v).is_some_and(|s| !s.is_empty());
    (!set("DISPLAY") && !set("WAYLAND_DISPLAY")).then(|| {
        "no display (neither DISPLAY nor WAYLAND_DISPLAY is set): use --headless for text mode"
            .to_owned()
    })
}

#[cfg(not(all(unix, not(target_os = "macos"))))]
fn no_display() -> Option<String> {
    None
}
