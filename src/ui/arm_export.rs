//! "Export view as PNG": the arm view as it is on screen (same centre and zoom, scaled to
//! the picture), painted by tiny-skia and written on a worker thread, so the window never
//! waits for it.

use crossbeam_channel::{Receiver, bounded};
use egui::{ComboBox, RichText, Ui};

use crate::render::paint_png::PngPainter;
use crate::render::{Palette, Scene, View};

/// The picture sizes offered; `None` is the pane's own size.
const SIZES: [(&str, Option<[u32; 2]>); 4] = [
    ("as on screen", None),
    ("1280x800", Some([1280, 800])),
    ("1920x1080", Some([1920, 1080])),
    ("3840x2160", Some([3840, 2160])),
];

pub struct Export {
    path: String,
    size: usize,
    pending: Option<Receiver<Result<String, String>>>,
    /// The last export's outcome: ok, and the text.
    message: Option<(bool, String)>,
}

impl Default for Export {
    fn default() -> Self {
        Export {
            path: "arm-view.png".into(),
            size: 2,
            pending: None,
            message: None,
        }
    }
}

impl Export {
    pub fn controls(
        &mut self,
        ui: &mut Ui,
        scene: &Scene,
        palette: &Palette,
        view: &View,
        pane: [u32; 2],
    ) {
        let label = ui.label("PNG file");
        ui.add(egui::TextEdit::singleline(&mut self.path).desired_width(140.0))
            .labelled_by(label.id);
        let size = ui.label("size");
        ComboBox::from_id_salt("export-size")
            .selected_text(SIZES[self.size].0)
            .show_ui(ui, |ui| {
                for (i, (name, _)) in SIZES.iter().enumerate() {
                    ui.selectable_value(&mut self.size, i, *name);
                }
            })
            .response
            .labelled_by(size.id);
        let busy = self.pending.is_some();
        let clicked = ui
            .add_enabled(!busy, egui::Button::new("Export view as PNG"))
            .on_hover_text("Paints the view as shown (tiny-skia, no GPU) into the file")
            .clicked();
        if clicked {
            let [w, h] = SIZES[self.size].1.unwrap_or(pane);
            self.start(scene.clone(), *palette, *view, [w.max(16), h.max(16)]);
        }
    }

    fn start(&mut self, scene: Scene, palette: Palette, view: View, [w, h]: [u32; 2]) {
        let path = self.path.trim().to_string();
        if path.is_empty() {
            self.message = Some((false, "name a file to export to".into()));
            return;
        }
        let k = (f64::from(w) / f64::from(view.size[0].max(1.0)))
            .min(f64::from(h) / f64::from(view.size[1].max(1.0)));
        let view = View {
            scale: view.scale * k,
            ..view
        };
        let (tx, rx) = bounded(1);
        self.pending = Some(rx);
        self.message = None;
        std::thread::spawn(move || {
            let result = PngPainter::new()
                .render_view(&scene, &palette, &view, w, h)
                .map_err(|e| e.to_string())
                .and_then(|p| crate::render::paint_png::encode(&p).map_err(|e| e.to_string()))
                .and_then(|bytes| crate::files::write_whole(std::path::Path::new(&path), &bytes))
                .map(|()| {
                    let shown = std::path::absolute(&path)
                        .map_or(path.clone(), |p| p.display().to_string());
                    format!("saved {shown} ({w}x{h})")
                });
            let _ = tx.send(result);
        });
    }

    /// Picks up a finished export and shows its outcome.
    pub fn poll(&mut self, ui: &mut Ui) {
        if let Some(rx) = &self.pending {
            match rx.try_recv() {
                Ok(r) => {
                    self.message = Some(match r {
                        Ok(t) => (true, t),
                        Err(t) => (false, t),
                    });
                    self.pending = None;
                }
                Err(crossbeam_channel::TryRecvError::Empty) => {
                    ui.ctx()
                        .request_repaint_after(std::time::Duration::from_millis(50));
                }
                Err(crossbeam_channel::TryRecvError::Disconnected) => {
                    self.message = Some((false, "the export stopped unexpectedly".into()));
                    self.pending = None;
                }
            }
        }
        if self.pending.is_some() {
            ui.label("exporting...");
        } else if let Some((ok, text)) = &self.message {
            let colour = if *ok {
                ui.visuals().text_color()
            } else {
                ui.visuals().error_fg_color
            };
            ui.label(RichText::new(text).color(colour));
        }
    }
}
