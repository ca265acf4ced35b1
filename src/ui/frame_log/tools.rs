//! The frame log pane's tool rows: counts and view switches, the filter, files, and the
//! raw frame to send.

use std::path::{Path, PathBuf};
use std::time::Instant;

use egui::{RichText, Ui};

use super::FrameLogPanel;
use super::jobs::{self, Format};
use crate::files::Overwrite;
use crate::pendant::frame_log::Protocol;
use crate::pendant::frame_log::filter::DirFilter;
use crate::pendant::{Intent, Level, Pendant};
use crate::ui::file_field::{Browse, FieldSpec, FileAsk, Purpose, job_line};
use crate::ui::widgets::{AMBER, level_color, reserved_line};

/// Counts, pause, follow, clock, clear, and the way back from an opened file.
pub fn header(p: &mut FrameLogPanel, ui: &mut Ui, pendant: &Pendant, out: &mut Vec<Intent>) {
    // One wrapped row (two in the default layout): the pane's height goes to the rows
    // and the decode.
    ui.horizontal_wrapped(|ui| {
        let log = p.log(pendant);
        let (len, head_drops, link_drops, cap) =
            (log.len(), log.dropped_head(), log.dropped_link(), log.cap());
        let megabytes = log.memory_bytes() as f64 / 1e6;
        let shown = p.view_len(log);
        match &p.opened {
            Some(o) => ui.label(RichText::new(format!("File {} (read-only)", o.name)).strong()),
            None => ui.label(RichText::new("Live").strong()),
        };
        ui.label(format!("{shown} shown of {len} rows"))
            .on_hover_text(format!("Kept at most {cap} rows; {megabytes:.1} MB now"));
        if head_drops > 0 {
            ui.label(RichText::new(format!("{head_drops} dropped from the head")).color(AMBER));
        }
        if link_drops > 0 {
            ui.label(
                RichText::new(format!("{link_drops} left out by the link (reader behind)"))
                    .color(AMBER),
            );
        }
        let end = p.log(pendant).end();
        if p.paused_at.is_some() {
            let waiting = end.saturating_sub(p.paused_at.unwrap_or(end));
            if ui.button("Resume").clicked() {
                p.paused_at = None;
            }
            ui.label(RichText::new(format!("paused, {waiting} new rows waiting")).color(AMBER));
        } else if ui.button("Pause").clicked() {
            p.paused_at = Some(end);
            p.follow = false;
        }
        ui.checkbox(&mut p.follow, "Follow tail");
        ui.checkbox(&mut p.wall_clock, "Wall clock");
        let shown = p.tools_shown;
        if ui
            .selectable_label(shown, "Filter, files, raw")
            .on_hover_text("Show or hide the filter, file and raw-frame rows")
            .clicked()
        {
            p.set_tools_open(!shown);
        }
        if p.opened.is_some() {
            if ui.button("Back to live").clicked() {
                p.opened = None;
                p.reset_view();
                p.follow = true;
            }
        } else if ui.button("Clear").clicked() {
            out.push(Intent::ClearFrameLog);
            p.reset_view();
            p.say(Level::Info, "log cleared");
        }
        // Last in its row, so the buttons before it never move when it comes and goes.
        if p.job.is_some() {
            ui.spinner();
            ui.label("filtering...");
        }
    });
}

/// How many rows the live log keeps (a setting, with the files).
fn keep_rows(ui: &mut Ui, pendant: &Pendant, out: &mut Vec<Intent>) {
    let mut cap = pendant.frame_log.cap();
    let l = ui.label("Keep rows");
    let r = ui
        .add(
            egui::DragValue::new(&mut cap)
                .range(1_000..=5_000_000)
                .speed(1000),
        )
        .labelled_by(l.id);
    let dropped = pendant.frame_log.dropped_budget();
    let budget_mb = pendant.frame_log.budget() / (1024 * 1024);
    let r = r.on_hover_text(format!(
        "At most {cap} rows and {budget_mb} MB of them: the oldest go first. {} rows went for \
         the memory budget so far.",
        dropped
    ));
    if r.changed() {
        out.push(Intent::FrameLogCap(cap));
    }
    let mut mb = budget_mb;
    let l = ui.label("MB");
    let r = ui
        .add(egui::DragValue::new(&mut mb).range(8..=1024).speed(1))
        .labelled_by(l.id)
        .on_hover_text(
            "The most memory the log's rows take (a line of junk fills it in bytes, not rows)",
        );
    if r.changed() {
        out.push(Intent::FrameLogBudget(mb));
    }
}

/// Line, message ID, direction, problems only, time range, free text.
pub fn filter_bar(p: &mut FrameLogPanel, ui: &mut Ui) {
    let inputs = &mut p.inputs;
    ui.horizontal_wrapped(|ui| {
        let l = ui.label("Filter text");
        ui.add(
            egui::TextEdit::singleline(&mut inputs.text)
                .hint_text("raw, name or field")
                .desired_width(140.0),
        )
        .labelled_by(l.id);
        ui.checkbox(&mut inputs.decoded, "in decode");
        let l = ui.label("Line");
        egui::ComboBox::from_id_salt("frame-log-line")
            .selected_text(line_name(inputs.protocol))
            .show_ui(ui, |ui| {
                for p in [None, Some(Protocol::FormatB), Some(Protocol::Modbus)] {
                    ui.selectable_value(&mut inputs.protocol, p, line_name(p));
                }
            })
            .response
            .labelled_by(l.id);
        let l = ui.label("ID");
        ui.add(egui::TextEdit::singleline(&mut inputs.id).desired_width(40.0))
            .labelled_by(l.id);
        let l = ui.label("Direction");
        egui::ComboBox::from_id_salt("frame-log-dir")
            .selected_text(dir_name(inputs.dir))
            .show_ui(ui, |ui| {
                for d in [DirFilter::Both, DirFilter::Sent, DirFilter::Received] {
                    ui.selectable_value(&mut inputs.dir, d, dir_name(d));
                }
            })
            .response
            .labelled_by(l.id);
        ui.checkbox(&mut inputs.problems_only, "Errors only");
        let l = ui.label("From s");
        ui.add(egui::TextEdit::singleline(&mut inputs.from).desired_width(50.0))
            .labelled_by(l.id);
        let l = ui.label("to s");
        ui.add(egui::TextEdit::singleline(&mut inputs.to).desired_width(50.0))
            .labelled_by(l.id);
    });
    if let Some(e) = &p.filter_error {
        ui.label(RichText::new(e).color(level_color(Level::Warning)));
    }
}

fn line_name(p: Option<Protocol>) -> &'static str {
    match p {
        None => "Both lines",
        Some(Protocol::FormatB) => "X-SEL",
        Some(Protocol::Modbus) => "RMC151",
    }
}

fn dir_name(d: DirFilter) -> &'static str {
    match d {
        DirFilter::Both => "Both ways",
        DirFilter::Sent => "Sent",
        DirFilter::Received => "Received",
    }
}

/// What the file field is for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LogFile {
    Save(Format),
    Open,
}

pub static FILE_FIELD: FieldSpec<LogFile> = FieldSpec {
    label: "File",
    hint: "frame-log.jsonl",
    width: 180.0,
    browse: &[
        Browse {
            label: "Open a JSON Lines log...",
            action: LogFile::Open,
            purpose: Purpose::Open,
        },
        Browse {
            label: "Save as text...",
            action: LogFile::Save(Format::Text),
            purpose: Purpose::Save,
        },
        Browse {
            label: "Save as JSON Lines...",
            action: LogFile::Save(Format::JsonLines),
            purpose: Purpose::Save,
        },
    ],
    filters: &[("Frame log", &["jsonl", "txt", "log"])],
};

/// Save as text or JSON Lines (all, or the filtered rows); open a JSON Lines log.
pub fn file_bar(
    p: &mut FrameLogPanel,
    ui: &mut Ui,
    pendant: &Pendant,
    folder: &Path,
    now: Instant,
    out: &mut Vec<Intent>,
) {
    let busy = p.save_job.is_some() || p.open_job.is_some();
    ui.horizontal_wrapped(|ui| {
        if p.opened.is_none() {
            keep_rows(ui, pendant, out);
        }
        ui.add_enabled_ui(!busy, |ui| p.file.show(ui, folder, now));
        ui.checkbox(&mut p.only_filtered, "filtered rows only");
        for (label, action) in [
            ("Save text", LogFile::Save(Format::Text)),
            ("Save JSONL", LogFile::Save(Format::JsonLines)),
            ("Open JSONL", LogFile::Open),
        ] {
            if ui.add_enabled(!busy, egui::Button::new(label)).clicked() {
                p.file.ask(action, folder);
            }
        }
    });
    match p.file.take() {
        Some(Ok(ask)) => start(p, pendant, ask, now),
        Some(Err(why)) => p.say(Level::Warning, why),
        None => {}
    }
    p.file.confirm_line(ui);
    let cancelled = job_line(ui, &mut p.save_job).or_else(|| job_line(ui, &mut p.open_job));
    if let Some(said) = cancelled {
        p.say(Level::Warning, said);
    }
    if let Some((level, text)) = &p.status {
        ui.label(RichText::new(text).color(level_color(*level)));
    }
}

fn start(p: &mut FrameLogPanel, pendant: &Pendant, ask: FileAsk<LogFile>, now: Instant) {
    let FileAsk {
        action,
        path,
        overwrite,
    } = ask;
    match action {
        LogFile::Open => {
            let cap = pendant.frame_log.cap();
            match jobs::open(path, cap, now) {
                Ok(job) => p.open_job = Some(job),
                Err(e) => p.say(Level::Error, e),
            }
        }
        LogFile::Save(format) => start_save(p, pendant, format, path, overwrite, now),
    }
}

fn start_save(
    p: &mut FrameLogPanel,
    pendant: &Pendant,
    format: Format,
    path: PathBuf,
    overwrite: Overwrite,
    now: Instant,
) {
    let log = p.log(pendant);
    let only = if p.only_filtered {
        match &p.rows {
            Some(r) => Some(r.seqs.iter().copied().collect()),
            None if p.wanted.is_some() => {
                return p.say(
                    Level::Warning,
                    "the filter is still running; save again soon",
                );
            }
            None => None,
        }
    } else {
        None
    };
    match jobs::save(log.snapshot(), only, format, path, overwrite, now) {
        Ok(job) => p.save_job = Some(job),
        Err(e) => p.say(Level::Error, e),
    }
}

/// A raw frame body to send through the link, and what became of the last one.
pub fn raw_bar(p: &mut FrameLogPanel, ui: &mut Ui, pendant: &Pendant, out: &mut Vec<Intent>) {
    ui.horizontal_wrapped(|ui| {
        let l = ui.label("Raw frame");
        let edit = ui
            .add(
                egui::TextEdit::singleline(&mut p.raw_body)
                    .hint_text("e.g. 99215")
                    .desired_width(220.0),
            )
            .labelled_by(l.id);
        let enter = edit.lost_focus() && ui.input(|i| i.key_pressed(egui::Key::Enter));
        if ui.button("Send raw").clicked() || enter {
            out.push(Intent::SendRaw(p.raw_body.clone()));
            p.follow = true;
        }
        let mut connection = pendant.settings.connection.clone();
        if ui
            .checkbox(
                &mut connection.send_at_at,
                "Send @@ for the checksum (from the next connect)",
            )
            .changed()
        {
            out.push(Intent::ConnectionSettings(connection));
        }
    });
    let result = pendant.raw_sent.as_ref().map(|r| match r {
        Ok(id) => (
            level_color(Level::Info),
            format!("sent {id} through the link"),
        ),
        Err(e) => (level_color(Level::Warning), format!("Not sent: {e}")),
    });
    let shown = result.as_ref().map(|(c, t)| (*c, t.as_str()));
    reserved_line(ui, shown, shown.map(|(_, t)| t));
}
