//! The frame log pane: every byte on the line as virtualised rows over the pendant's
//! ring (or a log opened from a file, read-only), with filters computed off the UI
//! thread, pause, follow, jumps between request and reply, the decode of the selected
//! row, files, and a raw frame to send.

mod detail;
pub mod jobs;
mod table;
mod tools;

use std::collections::VecDeque;

use egui::Ui;

use crate::pendant::frame_log::FrameLog;
use crate::pendant::frame_log::Protocol;
use crate::pendant::frame_log::filter::{DirFilter, Filter};
use crate::pendant::{Intent, Level, Pendant};
use crate::protocol::Columns;
use jobs::{Filtered, Saved};

use super::pane::{Pane, PaneCx};
use crate::files::job::{Job, JobPoll};
use crate::ui::file_field::{FileField, take_done};

/// Rows matched per frame as new rows arrive under a filter (the rest wait a frame).
const INCREMENT: u64 = 20_000;

/// A log opened from a file.
pub struct Opened {
    pub log: FrameLog,
    pub name: String,
}

/// The filter as typed.
#[derive(Default)]
struct FilterInputs {
    id: String,
    text: String,
    from: String,
    to: String,
    dir: DirFilter,
    protocol: Option<Protocol>,
    problems_only: bool,
    decoded: bool,
}

impl FilterInputs {
    fn parse(&self) -> Result<Filter, String> {
        use crate::pendant::frame_log::filter::{parse_id, parse_seconds};
        Ok(Filter {
            id: parse_id(&self.id)?,
            protocol: self.protocol,
            dir: self.dir,
            problems_only: self.problems_only,
            from_s: parse_seconds(&self.from)?,
            to_s: parse_seconds(&self.to)?,
            text: self.text.clone(),
            decoded: self.decoded,
        })
    }
}

/// Rows that pass the filter in force.
struct FilteredRows {
    filter: Filter,
    seqs: VecDeque<u64>,
    /// Rows up to here were looked at.
    scanned: u64,
}

/// The pane's state (the rows themselves live in the pendant or in `opened`).
pub struct FrameLogPanel {
    pub(super) opened: Option<Opened>,
    inputs: FilterInputs,
    filter_error: Option<String>,
    /// The filter wanted (None: every row).
    wanted: Option<Filter>,
    rows: Option<FilteredRows>,
    job: Option<(Job<Filtered>, Filter)>,
    /// The view stops at this row while paused (new rows keep arriving).
    paused_at: Option<u64>,
    follow: bool,
    wall_clock: bool,
    selected: Option<u64>,
    scroll_to: Option<u64>,
    hovered: Option<Columns>,
    /// Rows drawn in the last frame, where (on screen) and which.
    drawn: Vec<(egui::Rect, u64)>,
    file: FileField<tools::LogFile>,
    only_filtered: bool,
    save_job: Option<Job<Saved>>,
    open_job: Option<Job<jobs::Opened>>,
    status: Option<(Level, String)>,
    raw_body: String,
    /// The filter, file and raw-frame rows: as the user chose, else shown only when the
    /// pane has room for them and rows below (the default layout at 1280x800 has not).
    tools_open: Option<bool>,
    pub(super) tools_shown: bool,
    /// How far the rows are scrolled sideways (the header follows).
    rows_x: f32,
    /// The rows' view height last frame (a horizontal scroll bar takes some of the
    /// pane), so the followed tail ends at its bottom edge.
    pub(super) rows_view_height: Option<f32>,
    /// Drawn this frame showing the live log (new rows are worth waking the window for).
    pub(crate) live_in_sight: bool,
    /// The decode's height as the splitter left it (None: 60% of the pane, or room for
    /// [`DECODE_LINES`] lines if that is more and the rows keep theirs).
    decode_height: Option<f32>,
    /// What the decode drew last frame: the height of its heading (the row's name and
    /// buttons, margins) and how many lines its fields had room for.
    pub(super) decode_drawn: DecodeDrawn,
}

/// The decode's heading height and lines shown, as last drawn.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct DecodeDrawn {
    /// All but the fields' lines: the row's name and buttons, margins.
    pub heading: f32,
    /// Lines of monospace text the fields' view had room for.
    pub lines: f32,
}

/// The decode's fields get room for this many lines where the pane has it.
const DECODE_LINES: f32 = 10.0;

/// The height of the bar between the rows and the decode (px).
const SPLITTER: f32 = 8.0;

/// The bar between the rows and the decode: dragged, it moves by the pointer's travel.
fn splitter(ui: &mut Ui) -> Option<f32> {
    let (rect, response) = ui.allocate_exact_size(
        egui::vec2(ui.available_width(), SPLITTER),
        egui::Sense::drag(),
    );
    response.widget_info(|| {
        egui::WidgetInfo::labeled(egui::Role::Splitter, true, "Rows and decode splitter")
    });
    let response = response
        .on_hover_cursor(egui::CursorIcon::ResizeVertical)
        .on_hover_text("Drag to share the pane between the rows and the decode");
    let stroke = if response.hovered() || response.dragged() {
        ui.visuals().widgets.active.fg_stroke
    } else {
        ui.visuals().widgets.noninteractive.bg_stroke
    };
    ui.painter().hline(rect.x_range(), rect.center().y, stroke);
    response.dragged().then(|| response.drag_delta().y)
}

/// A pane at least this tall shows the tools rows until the user hides them (px).
const ROOMY_PANE: f32 = 420.0;

impl Default for FrameLogPanel {
    fn default() -> Self {
        Self {
            opened: None,
            inputs: FilterInputs::default(),
            filter_error: None,
            wanted: None,
            rows: None,
            job: None,
            paused_at: None,
            follow: true,
            wall_clock: false,
            selected: None,
            scroll_to: None,
            hovered: None,
            drawn: Vec::new(),
            file: FileField::new(&tools::FILE_FIELD, "frame-log.jsonl"),
            only_filtered: false,
            save_job: None,
            open_job: None,
            status: None,
            raw_body: String::new(),
            tools_open: None,
            tools_shown: true,
            rows_x: 0.0,
            rows_view_height: None,
            live_in_sight: false,
            decode_height: None,
            decode_drawn: DecodeDrawn::default(),
        }
    }
}

impl FrameLogPanel {
    /// Shows or hides the filter, file and raw-frame rows (the user's choice from now on).
    pub(super) fn set_tools_open(&mut self, open: bool) {
        self.tools_open = Some(open);
    }

    /// Whether the filter, file and raw-frame rows are shown.
    pub fn tools_shown(&self) -> bool {
        self.tools_shown
    }

    /// The decode's height as the splitter left it (tests read it).
    pub fn decode_height(&self) -> Option<f32> {
        self.decode_height
    }

    /// How many lines of the decode's fields were in sight last frame (tests read it).
    pub fn decode_lines_shown(&self) -> f32 {
        self.decode_drawn.lines
    }

    /// Whether a filter job is still running (tests and benches wait for it).
    pub fn filtering(&self) -> bool {
        self.job.is_some()
    }

    /// Rows the view shows now.
    pub fn shown(&self, pendant: &Pendant) -> usize {
        let log = self.log(pendant);
        self.view_len(log)
    }

    /// The row whose decode is shown.
    pub fn selected(&self) -> Option<u64> {
        self.selected
    }

    /// Selects row `seq` and scrolls it into view (the jump buttons do this).
    pub fn reveal(&mut self, seq: u64) {
        self.selected = Some(seq);
        self.scroll_to = Some(seq);
        self.follow = false;
    }

    /// Whether the view is paused.
    pub fn paused(&self) -> bool {
        self.paused_at.is_some()
    }

    /// The log shown: the opened file's, or the live one.
    pub fn log<'a>(&'a self, pendant: &'a Pendant) -> &'a FrameLog {
        self.opened.as_ref().map_or(&pendant.frame_log, |o| &o.log)
    }

    fn view_end(&self, log: &FrameLog) -> u64 {
        self.paused_at.map_or(log.end(), |p| p.min(log.end()))
    }

    fn view_len(&self, log: &FrameLog) -> usize {
        let end = self.view_end(log);
        match &self.rows {
            Some(r) => r.seqs.partition_point(|&s| s < end),
            None => end.saturating_sub(log.head()) as usize,
        }
    }

    /// The sequence number of the `i`-th row shown.
    fn seq_at(&self, log: &FrameLog, i: usize) -> Option<u64> {
        match &self.rows {
            Some(r) => r.seqs.get(i).copied(),
            None => Some(log.head() + i as u64),
        }
    }

    /// Where row `seq` is in the view.
    fn index_of(&self, log: &FrameLog, seq: u64) -> Option<usize> {
        match &self.rows {
            Some(r) => r.seqs.binary_search(&seq).ok(),
            None => seq.checked_sub(log.head()).map(|i| i as usize),
        }
    }

    fn say(&mut self, level: Level, text: impl Into<String>) {
        self.status = Some((level, plain(&text.into())));
    }

    /// Starts, finishes and extends the filtering of the log shown.
    fn update_filter(&mut self, pendant: &Pendant, now: std::time::Instant) {
        let log = self.opened.as_ref().map_or(&pendant.frame_log, |o| &o.log);
        match self.inputs.parse() {
            Ok(f) => {
                self.filter_error = None;
                self.wanted = (!f.is_empty()).then_some(f);
            }
            Err(e) => self.filter_error = Some(e),
        }
        let Some(wanted) = self.wanted.clone() else {
            self.rows = None;
            self.job = None;
            return;
        };
        if let Some((job, filter)) = &self.job
            && let JobPoll::Done(done) = job.poll(now)
        {
            if *filter == wanted {
                self.rows = Some(FilteredRows {
                    filter: filter.clone(),
                    seqs: done.seqs.into(),
                    scanned: done.end,
                });
            }
            self.job = None;
        }
        let current = self.rows.as_ref().is_some_and(|r| r.filter == wanted);
        let running = self.job.as_ref().is_some_and(|(_, f)| *f == wanted);
        if !current && !running {
            match jobs::filter(log.snapshot(), wanted.matcher(), now) {
                Ok(job) => self.job = Some((job, wanted.clone())),
                Err(e) => self.filter_error = Some(e),
            }
        }
        if let Some(rows) = self.rows.as_mut().filter(|r| r.filter == wanted) {
            while rows.seqs.front().is_some_and(|&s| s < log.head()) {
                rows.seqs.pop_front();
            }
            if rows.scanned < log.head() {
                rows.scanned = log.head();
            }
            let matcher = wanted.matcher();
            let until = log.end().min(rows.scanned + INCREMENT);
            for seq in rows.scanned..until {
                if let Some(r) = log.row(seq)
                    && matcher.matches(&r)
                {
                    rows.seqs.push_back(seq);
                }
            }
            rows.scanned = until;
        }
    }

    /// Forgets the filter results (the rows they point at are gone).
    fn reset_view(&mut self) {
        self.rows = None;
        self.job = None;
        self.selected = None;
        self.paused_at = None;
    }

    pub fn show(
        &mut self,
        ui: &mut Ui,
        pendant: &Pendant,
        folder: &std::path::Path,
        now: std::time::Instant,
        out: &mut Vec<Intent>,
    ) {
        self.poll_files(now, out);
        self.update_filter(pendant, now);
        self.live_in_sight = self.opened.is_none() && self.paused_at.is_none();
        if self.job.is_some() {
            ui.ctx().request_repaint();
        }
        self.tools_shown = self
            .tools_open
            .unwrap_or(ui.available_height() >= ROOMY_PANE);
        tools::header(self, ui, pendant, out);
        if self.tools_shown {
            tools::filter_bar(self, ui);
            tools::file_bar(self, ui, pendant, folder, now, out);
            tools::raw_bar(self, ui, pendant, out);
        }
        ui.separator();
        let available = ui.available_height();
        if self.selected.is_none() {
            ui.allocate_ui(
                egui::vec2(ui.available_width(), available.max(80.0)),
                |ui| {
                    table::show(self, ui, pendant);
                },
            );
            return;
        }
        // The decode below the rows: 60% of the pane, or room for its heading and ten
        // lines of fields if more, unless the splitter was dragged; the rows keep at least
        // three lines.
        let line = ui.text_style_height(&egui::TextStyle::Monospace);
        let rows_min = 3.0 * line + 30.0;
        let ten_lines = self.decode_drawn.heading + DECODE_LINES * line;
        let decode = self
            .decode_height
            .unwrap_or((available * 0.6).max(ten_lines))
            .clamp(60.0, (available - rows_min - SPLITTER).max(60.0));
        let table_height = (available - decode - SPLITTER).max(rows_min);
        ui.allocate_ui(egui::vec2(ui.available_width(), table_height), |ui| {
            table::show(self, ui, pendant);
        });
        if let Some(dy) = splitter(ui) {
            self.decode_height = Some(decode - dy);
        }
        detail::show(self, ui, pendant);
        let heading = decode - self.decode_drawn.lines * line;
        let heading_changed = (heading - self.decode_drawn.heading).abs() > 0.5;
        self.decode_drawn.heading = heading;
        if heading_changed && self.decode_height.is_none() {
            // Sized for last frame's heading (a row selected anew, or a reply that adds
            // its buttons and wraps the heading): lay the pane out again before it is
            // painted, so the fields keep their ten lines in this very frame.
            ui.ctx()
                .request_discard("the frame log decode's heading changed height");
        }
    }

    fn poll_files(&mut self, now: std::time::Instant, out: &mut Vec<Intent>) {
        match take_done(&mut self.save_job, now) {
            None => {}
            Some(Err(why)) => self.say(Level::Error, why),
            Some(Ok(Saved {
                path,
                format,
                result,
            })) => match result {
                Ok(n) => {
                    let at = crate::ui::widgets::clock_utc();
                    self.say(
                        Level::Info,
                        format!("saved {n} rows to {} at {at}", path.display()),
                    );
                    out.push(Intent::FileUsed(path));
                }
                Err(crate::files::WriteError::Exists(what)) => {
                    self.file.exists(tools::LogFile::Save(format), path, what);
                }
                Err(e) => self.say(Level::Error, e.sentence(&path)),
            },
        }
        match take_done(&mut self.open_job, now) {
            None => {}
            Some(Err(why)) => self.say(Level::Error, why),
            Some(Ok((_, Err(e)))) => self.say(Level::Error, e),
            Some(Ok((path, Ok(log)))) => {
                let n = log.len();
                let name = path.display().to_string();
                self.opened = Some(Opened {
                    log,
                    name: name.clone(),
                });
                self.reset_view();
                self.follow = false;
                self.say(Level::Info, format!("opened {name} ({n} rows, read-only)"));
                out.push(Intent::FileUsed(path));
            }
        }
    }
}

/// Text with the few non-ASCII marks of the decoder spelled in ASCII (the window's fonts
/// and its tests stay ASCII).
pub(crate) fn plain(s: &str) -> String {
    s.replace('\u{2014}', "-")
        .replace('\u{2026}', "...")
        .chars()
        .map(|c| if c.is_ascii() { c } else { '?' })
        .collect()
}

impl Pane for FrameLogPanel {
    fn ui(&mut self, ui: &mut Ui, cx: &mut PaneCx<'_>) {
        self.show(ui, cx.pendant, cx.folder, cx.now, cx.intents);
    }
}
