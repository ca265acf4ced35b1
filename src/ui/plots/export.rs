//! The plot's files: the shown channels as CSV (every poll in the span, exact values),
//! the plot as PNG (tiny-skia, as `--plot-png` paints it), and the selected capture as
//! CSV to read back later. Written off the UI thread, whole, asking before replacing.

use std::path::{Path, PathBuf};
use std::time::Instant;

use egui::{RichText, Ui};

use super::{PlotsPanel, Source};
use crate::files::job::Job;
use crate::files::{WriteError, write_file};
use crate::pendant::samples::csv::{write_capture, write_shown};
use crate::pendant::samples::view::{Trace, capture_trace, live_trace};
use crate::pendant::{Intent, Level, Pendant};
use crate::render::plot::{PlotLine, PlotPicture, plot_png};
use crate::ui::file_field::{Browse, FieldSpec, FileAsk, FileField, Purpose, job_line, take_done};
use crate::ui::widgets::level_color;

/// The PNG's size, pixels.
pub const PNG_SIZE: (u32, u32) = (1600, 900);

/// What a plot file is for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PlotFile {
    /// The shown channels over the shown span, as CSV.
    Csv,
    /// The plot as PNG.
    Png,
    /// The selected capture, as CSV.
    Capture,
}

static SPEC: FieldSpec<PlotFile> = FieldSpec {
    label: "File",
    hint: "plot.csv",
    width: 150.0,
    browse: &[
        Browse {
            label: "Save CSV...",
            action: PlotFile::Csv,
            purpose: Purpose::Save,
        },
        Browse {
            label: "Save PNG...",
            action: PlotFile::Png,
            purpose: Purpose::Save,
        },
        Browse {
            label: "Save capture...",
            action: PlotFile::Capture,
            purpose: Purpose::Save,
        },
    ],
    filters: &[("Plot", &["csv", "png"])],
};

/// The bytes a save writes and the words saying what they are, made off the UI thread.
type FileWork = dyn FnOnce() -> Result<(Vec<u8>, String), String> + Send;

/// A finished save: the path, what it was, and how it went.
pub struct Saved {
    path: PathBuf,
    what: PlotFile,
    result: Result<String, WriteError>,
}

/// The file field, the job writing and the last word about it.
pub struct Export {
    pub file: FileField<PlotFile>,
    job: Option<Job<Saved>>,
    pub status: Option<(Level, String)>,
}

impl Default for Export {
    fn default() -> Self {
        Self {
            file: FileField::new(&SPEC, "plot.csv"),
            job: None,
            status: None,
        }
    }
}

pub fn bar(
    p: &mut PlotsPanel,
    ui: &mut Ui,
    pendant: &Pendant,
    intents: &mut Vec<Intent>,
    folder: &Path,
    now: Instant,
) {
    let busy = p.export.job.is_some();
    ui.horizontal_wrapped(|ui| {
        ui.add_enabled_ui(!busy, |ui| p.export.file.show(ui, folder, now));
        for (label, action) in [
            ("Export CSV", PlotFile::Csv),
            ("Export PNG", PlotFile::Png),
            ("Save capture", PlotFile::Capture),
        ] {
            if ui.add_enabled(!busy, egui::Button::new(label)).clicked() {
                p.export.file.ask(action, folder);
            }
        }
    });
    match p.export.file.take() {
        Some(Ok(ask)) => start(p, pendant, ask, now),
        Some(Err(why)) => p.export.status = Some((Level::Warning, why)),
        None => {}
    }
    p.export.file.confirm_line(ui);
    if let Some(said) = job_line(ui, &mut p.export.job) {
        p.export.status = Some((Level::Warning, said));
    }
    match take_done(&mut p.export.job, now) {
        None => {}
        Some(Err(why)) => p.export.status = Some((Level::Error, why)),
        Some(Ok(Saved { path, what, result })) => match result {
            Ok(said) => {
                p.export.status = Some((Level::Info, said));
                intents.push(Intent::FileUsed(path));
            }
            Err(WriteError::Exists(size)) => p.export.file.exists(what, path, size),
            Err(e) => p.export.status = Some((Level::Error, e.sentence(&path))),
        },
    }
    if let Some((level, text)) = &p.export.status {
        ui.label(RichText::new(text).color(level_color(*level)));
    }
}

fn start(p: &mut PlotsPanel, pendant: &Pendant, ask: FileAsk<PlotFile>, now: Instant) {
    let FileAsk {
        action,
        path,
        overwrite,
    } = ask;
    let work: Box<FileWork> = match action {
        PlotFile::Csv if p.source == Source::Live => {
            // The store is copied for the job (an hour of samples is some megabytes).
            let store = pendant.samples.store.clone();
            let (choices, (from, to)) = (p.chosen(), p.shown);
            Box::new(move || {
                let mut out = Vec::new();
                let n =
                    write_shown(&mut out, &store, &choices, from, to).map_err(|e| e.to_string())?;
                Ok((out, format!("{n} samples")))
            })
        }
        PlotFile::Csv | PlotFile::Capture => {
            let number = match action {
                PlotFile::Capture => p.selected,
                _ => p.selected.or_else(|| p.overlaid.iter().next().copied()),
            };
            let Some(capture) = number.and_then(|n| {
                pendant
                    .samples
                    .captures
                    .list
                    .iter()
                    .find(|c| c.number == n)
                    .cloned()
            }) else {
                p.export.status = Some((
                    Level::Warning,
                    "select a capture in the list first (click its #)".into(),
                ));
                return;
            };
            Box::new(move || {
                let mut out = Vec::new();
                write_capture(&mut out, &capture).map_err(|e| e.to_string())?;
                Ok((
                    out,
                    format!(
                        "capture #{} ({} samples)",
                        capture.number,
                        capture.times.len()
                    ),
                ))
            })
        }
        PlotFile::Png => {
            let traces = png_traces(p, pendant);
            let (x_range, cursors) = (p.shown, p.cursors.iter().flatten().copied().collect());
            let light = pendant.settings.light_theme;
            let title = match p.source {
                Source::Live => "xsel-pendant: polled samples".to_string(),
                Source::Captures => "xsel-pendant: captures".to_string(),
            };
            let x_label = x_label(p.source);
            Box::new(move || {
                let picture = picture(&title, x_label, x_range, &traces, cursors, light);
                let png = plot_png(&picture, PNG_SIZE.0, PNG_SIZE.1).map_err(|e| e.to_string())?;
                Ok((png, format!("{}x{} plot", PNG_SIZE.0, PNG_SIZE.1)))
            })
        }
    };
    let what = match action {
        PlotFile::Csv => "save the plot as CSV",
        PlotFile::Png => "save the plot as PNG",
        PlotFile::Capture => "save the capture",
    };
    match Job::spawn_opening(what, now, move |ctl| {
        let result = work()
            .map_err(WriteError::Failed)
            .and_then(|(bytes, said)| {
                write_file(&path, &bytes, overwrite, ctl)?;
                Ok(format!("saved {said} to {}", path.display()))
            });
        Saved {
            path,
            what: action,
            result,
        }
    }) {
        Ok(job) => p.export.job = Some(job),
        Err(e) => p.export.status = Some((Level::Error, e)),
    }
}

pub fn x_label(source: Source) -> &'static str {
    match source {
        Source::Live => "seconds since the first poll",
        Source::Captures => "seconds from the trigger",
    }
}

/// The traces as the plot shows them, decimated to the PNG's width.
fn png_traces(p: &PlotsPanel, pendant: &Pendant) -> Vec<(usize, Trace)> {
    let (from, to) = p.shown;
    match p.source {
        Source::Live => p
            .traces
            .iter()
            .enumerate()
            .filter_map(|(i, c)| {
                live_trace(
                    &pendant.samples.store,
                    c.as_ref()?,
                    from,
                    to,
                    PNG_SIZE.0 as usize,
                )
                .map(|t| (i, t))
            })
            .collect(),
        Source::Captures => pendant
            .samples
            .captures
            .list
            .iter()
            .filter(|c| p.overlaid.contains(&c.number))
            .enumerate()
            .flat_map(|(k, c)| {
                p.traces.iter().enumerate().filter_map(move |(i, choice)| {
                    let choice = choice.as_ref()?;
                    let label = format!("#{} {}", c.number, choice.channel);
                    capture_trace(c, &choice.channel, label).map(|t| (i + k * super::TRACES, t))
                })
            })
            .collect(),
    }
}

/// The picture of `traces` for the PNG painter.
pub fn picture<'a>(
    title: &str,
    x_label: &'a str,
    x_range: (f64, f64),
    traces: &'a [(usize, Trace)],
    cursors: Vec<f64>,
    light: bool,
) -> PlotPicture<'a> {
    PlotPicture {
        title: title.to_string(),
        x_label,
        x_range,
        lines: traces
            .iter()
            .map(|(i, t)| PlotLine {
                label: &t.label,
                unit: &t.unit,
                step: t.step,
                top: t.top,
                points: &t.points,
                colour: *i,
            })
            .collect(),
        cursors,
        light,
    }
}
