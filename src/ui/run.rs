//! Opening the native window, with a plain one-line error where there is no display.

use super::app::{APP_ID, END_ASKED, PendantApp};
use super::start::StartOptions;
use crate::cli::Renderer;

/// Opens the window and runs until it closes, drawn by `renderer`.
pub fn run_window(options: StartOptions, renderer: Renderer) -> Result<(), String> {
    let renderer = eframe_renderer(renderer)?;
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
        Box::new(move |cc| {
            // Asked to end from outside: the window closes as on Ctrl+Q (STOP, files).
            let ctx = cc.egui_ctx.clone();
            if let Err(e) = ctrlc::set_handler(move || {
                END_ASKED.store(true, std::sync::atomic::Ordering::Relaxed);
                ctx.request_repaint();
            }) {
                eprintln!("xsel-pendant: a request to end (SIGTERM) will not close cleanly: {e}");
            }
            Ok(Box::new(PendantApp::new(cc, options)))
        }),
    )
    .map_err(|e| {
        let other = if renderer == eframe::Renderer::Glow {
            OTHER_THAN_GLOW
        } else {
            "--renderer glow"
        };
        format!("cannot open the window ({e}); try {other}, or --headless for text mode")
    })
}

/// What to try when OpenGL fails.
const OTHER_THAN_GLOW: &str = if cfg!(feature = "wgpu") {
    "--renderer wgpu"
} else {
    "a build with `--features wgpu` and --renderer wgpu"
};

/// eframe's renderer for `--renderer`; wgpu only in builds with the `wgpu` feature.
fn eframe_renderer(renderer: Renderer) -> Result<eframe::Renderer, String> {
    match renderer {
        Renderer::Glow => Ok(eframe::Renderer::Glow),
        #[cfg(feature = "wgpu")]
        Renderer::Wgpu => Ok(eframe::Renderer::Wgpu),
        #[cfg(not(feature = "wgpu"))]
        Renderer::Wgpu => Err("this build has no wgpu renderer (it is a cargo feature): \
             build with `cargo build --release --features wgpu`, or leave --renderer out for \
             OpenGL"
            .to_owned()),
    }
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
