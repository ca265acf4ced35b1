//! "Export view as PNG": the arm view as it is on screen (same centre and zoom, scaled to
//! the picture), painted by tiny-skia and written as a job, so the window never waits for
//! it; a file that is there is replaced only when the user says so.

use std::path::{Path, PathBuf};
use std::time::Instant;

use egui::{ComboBox, RichText, Ui};

use super::file_field::{Browse, FieldSpec, FileAsk, FileField, Purpose, job_line, take_done};
use super::widgets::clock_utc;
use crate::files::job::Job;
use crate::files::{WriteError, write_file};
use crate::pendant::Intent;
use crate::render::paint_png::PngPainter;
use crate::render::{Palette, Scene, View};

/// The picture sizes offered; `None` is the pane's own size.
const SIZES: [(&str, Option<[u32; 2]>); 4] = [
    ("as on screen", None),
    ("1280x800", Some([1280, 800])),
    ("1920x1080", Some([1920, 1080])),
    ("3840x2160", Some([3840, 2160])),
];

/// The only thing the field does: save a picture.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct SavePng;

static FILE_FIELD: FieldSpec<SavePng> = FieldSpec {
    label: "PNG file",
    hint: "arm-view.png",
    width: 140.0,
    browse: &[Browse {
        label: "Save as...",
        action: SavePng,
        purpose: Purpose::Save,
    }],
    filters: &[("PNG picture", &["png"])],
};

/// What the view shows now: the scene, its colours, the view and the pane's size.
pub type Shown<'a> = (&'a Scene, &'a Palette, &'a View, [u32; 2]);

/// What to paint: the scene, its colours, the view and the picture's size.
type Picture = (Scene, Palette, View, [u32; 2]);

/// What an export job hands back: the path, the size, and how the write went.
type Exported = (PathBuf, [u32; 2], Result<(), WriteError>);

pub struct Export {
    file: FileField<SavePng>,
    size: usize,
    job: Option<Job<Exported>>,
    /// The last export's outcome: ok, and the text.
    message: Option<(bool, String)>,
}

impl Default for Export {
    fn default() -> Self {
        Export {
            file: FileField::new(&FILE_FIELD, "arm-view.png"),
            size: 2,
            job: None,
            message: None,
        }
    }
}

impl Export {
    pub fn controls(&mut self, ui: &mut Ui, shown: Shown<'_>, folder: &Path, now: Instant) {
        let (scene, palette, view, pane) = shown;
        let idle = self.job.is_none();
        ui.add_enabled_ui(idle, |ui| self.file.show(ui, folder, now));
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
        let clicked = ui
            .add_enabled(idle, egui::Button::new("Export view as PNG"))
            .on_hover_text("Paints the view as shown (tiny-skia, no GPU) into the file")
            .clicked();
        if clicked {
            self.file.ask(SavePng, folder);
        }
        // The picture is the view as it is when the file is known (typed, or chosen in
        // the dialog).
        match self.file.take() {
            Some(Ok(ask)) => {
                let [w, h] = SIZES[self.size].1.unwrap_or(pane);
                let picture = (scene.clone(), *palette, *view, [w.max(16), h.max(16)]);
                self.start(ask, picture, now);
            }
            Some(Err(why)) => self.message = Some((false, why)),
            None => {}
        }
    }

    fn start(&mut self, ask: FileAsk<SavePng>, picture: Picture, now: Instant) {
        let (scene, palette, view, [w, h]) = picture;
        let FileAsk {
            path, overwrite, ..
        } = ask;
        let k = (f64::from(w) / f64::from(view.size[0].max(1.0)))
            .min(f64::from(h) / f64::from(view.size[1].max(1.0)));
        let view = View {
            scale: view.scale * k,
            ..view
        };
        self.message = None;
        let what = format!("exporting {}", path.display());
        let job = Job::spawn_opening(what, now, move |ctl| {
            let result = PngPainter::new()
                .render_view(&scene, &palette, &view, w, h)
                .map_err(|e| e.to_string())
                .and_then(|p| crate::render::paint_png::encode(&p).map_err(|e| e.to_string()))
                .map_err(WriteError::Failed)
                .and_then(|bytes| write_file(&path, &bytes, overwrite, ctl));
            (path, [w, h], result)
        });
        match job {
            Ok(job) => self.job = Some(job),
            Err(e) => self.message = Some((false, e)),
        }
    }

    /// Picks up a finished export and shows its outcome, or the job's line while it runs.
    pub fn poll(&mut self, ui: &mut Ui, now: Instant, intents: &mut Vec<Intent>) {
        self.file.confirm_line(ui);
        if let Some(said) = job_line(ui, &mut self.job) {
            self.message = Some((false, said));
        }
        match take_done(&mut self.job, now) {
            None => {}
            Some(Err(why)) => self.message = Some((false, why)),
            Some(Ok((path, [w, h], result))) => match result {
                Ok(()) => {
                    let at = clock_utc();
                    self.message =
                        Some((true, format!("saved {} ({w}x{h}) at {at}", path.display())));
                    intents.push(Intent::FileUsed(path));
                }
                Err(WriteError::Exists(what)) => self.file.exists(SavePng, path, what),
                Err(e) => self.message = Some((false, e.sentence(&path))),
            },
        }
        if let Some((ok, text)) = &self.message {
            let colour = if *ok {
                ui.visuals().text_color()
            } else {
                ui.visuals().error_fg_color
            };
            ui.label(RichText::new(text).color(colour));
        }
    }
}
