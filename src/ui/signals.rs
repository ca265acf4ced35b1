//! The Signals view: the watch list of inputs, outputs, flags and variables with their
//! values as read, outputs and flags forced and variables edited behind a confirmation,
//! rows plotted, the list imported from and exported to CSV and JSON files.

use std::collections::HashMap;
use std::path::Path;
use std::time::{Duration, Instant};

use egui::{Button, ComboBox, Key, RichText, Sense, TextEdit, Ui};
use egui_extras::{Column as Col, TableBuilder};

use super::file_field::{Browse, FieldSpec, FileAsk, Purpose};
use super::file_work::{Done, FileButton, FileWork, is_json, read_job, write_job};
use super::pane::{Pane, PaneCx};
use super::plots::PlotsPanel;
use super::widgets::{AMBER, GREEN, GREY, RED, said_line};
use crate::files::job::Job;
use crate::pendant::signals::{
    HIGHLIGHT_FOR, MAX_ROWS, MAX_TEXT_CHARS, Proposal, Signal, SignalKind, Signals, SignalsIntent,
    Value, WatchRow, file,
};
use crate::pendant::{Intent, Level, Pendant};
use crate::protocol::RealEncoding;

const ROW_HEIGHT: f32 = 22.0;
/// While the view is shown, drawn again this often (the ages of the reads move on).
const AGES_REPAINT: Duration = Duration::from_millis(500);
/// The encoding selector's hover: PROTOCOL.md 3.40's words.
const ENCODING_HOVER: &str = "How this controller sends a real (double) variable, PROTOCOL.md \
    3.40: \"selected in accordance with the condition\". Word-swapped (lower 4 bytes, then \
    upper 4 bytes) on X-SEL J/K main application V0.41 or earlier, or when bits 0-3 of Other \
    parameter No. 46 are 0; plain (the 8 bytes most significant first) in any other case. A \
    host cannot read parameter 46: a value that looks absurd this way but ordinary the other \
    way is flagged at its row [inferred].";

/// What the file field is for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum SignalsFile {
    Import,
    ExportCsv,
    ExportJson,
}

static FILE_FIELD: FieldSpec<SignalsFile> = FieldSpec {
    label: "File",
    hint: "signals.csv or .json",
    width: 170.0,
    browse: &[
        Browse {
            label: "Import the watch list...",
            action: SignalsFile::Import,
            purpose: Purpose::Open,
        },
        Browse {
            label: "Export CSV as...",
            action: SignalsFile::ExportCsv,
            purpose: Purpose::Save,
        },
        Browse {
            label: "Export JSON as...",
            action: SignalsFile::ExportJson,
            purpose: Purpose::Save,
        },
    ],
    filters: &[("Watch list", &["csv", "json"])],
};

static FILE_BUTTONS: [FileButton<SignalsFile>; 3] = [
    (
        "Import",
        Some(
            "Replace the watch list with a CSV or JSON file's; a file with an error \
             anywhere changes nothing",
        ),
        SignalsFile::Import,
    ),
    (
        "Export CSV",
        Some("Write the whole watch list as CSV (.csv added when none is named)"),
        SignalsFile::ExportCsv,
    ),
    (
        "Export JSON",
        Some(
            "Write the whole watch list and the real encoding as JSON (.json added \
             when none is named)",
        ),
        SignalsFile::ExportJson,
    ),
];

/// A finished file job: the list (and the real encoding) read, or the rows written.
type SignalsDone = Done<(Vec<WatchRow>, Option<RealEncoding>)>;

/// The name being typed over a row's.
#[derive(Clone, Debug, PartialEq)]
struct NameEdit {
    signal: Signal,
    text: String,
    /// Focus was asked for (on the frame the edit began).
    focused: bool,
}

/// The view's own state: what the operator typed and chose; the list and its values are
/// the pendant's.
pub struct SignalsPanel {
    kind: SignalKind,
    program: String,
    number: String,
    count: String,
    name: String,
    chars: String,
    filter: String,
    /// The values typed in the Set cells of variables, by row.
    typed: HashMap<Signal, String>,
    edit: Option<NameEdit>,
    /// The row a value was last proposed for (the model's refusal is shown there).
    proposed: Option<Signal>,
    /// "A program is running: I accept the risk", for the confirmation shown.
    take_the_risk: bool,
    file: FileWork<SignalsFile, SignalsDone>,
    /// The rows shown (indices into the list) and what they were filtered from.
    visible: Option<((u64, usize, String), Vec<usize>)>,
    /// Reads a round, worked out for the list's revision.
    reads: Option<(u64, usize)>,
    /// The view was drawn this frame.
    drawn: bool,
    /// What the model was last told of the view being shown.
    watching: bool,
    /// The traces this view put into the Plots pane: the signal and its series' name.
    placed: Vec<(Signal, String)>,
    /// Traces to put in on this frame's end: series' name, a bit.
    to_place: Vec<(Signal, String, bool)>,
}

impl Default for SignalsPanel {
    fn default() -> Self {
        Self {
            kind: SignalKind::Output,
            program: "0".into(),
            number: "300".into(),
            count: "1".into(),
            name: String::new(),
            chars: "16".into(),
            filter: String::new(),
            typed: HashMap::new(),
            edit: None,
            proposed: None,
            take_the_risk: false,
            file: FileWork::new(&FILE_FIELD),
            visible: None,
            reads: None,
            drawn: false,
            watching: false,
            placed: Vec::new(),
            to_place: Vec::new(),
        }
    }
}

/// A whole number typed in a field.
fn whole<T: std::str::FromStr>(text: &str, what: &str) -> Result<T, String> {
    text.trim()
        .parse::<T>()
        .map_err(|_| format!("type a whole number as the {what}"))
}

/// "0.2 s ago", "12 s ago", "3 min ago".
fn age(now: Instant, at: Instant) -> String {
    let s = now.saturating_duration_since(at).as_secs_f64();
    if s < 10.0 {
        format!("{s:.1} s ago")
    } else if s < 120.0 {
        format!("{s:.0} s ago")
    } else {
        format!("{:.0} min ago", s / 60.0)
    }
}

/// Rows whose label (kind, number, name) holds the filter's words, any case.
fn filtered(rows: &[WatchRow], filter: &str) -> Vec<usize> {
    let f = filter.trim().to_lowercase();
    if f.is_empty() {
        return (0..rows.len()).collect();
    }
    let number = f.parse::<u16>().ok();
    rows.iter()
        .enumerate()
        .filter(|(_, r)| {
            number.is_some_and(|n| r.numbers().contains(&n))
                || r.label().to_lowercase().contains(&f)
        })
        .map(|(i, _)| i)
        .collect()
}

/// Starts an import (read and parsed off the UI thread) or an export (the list written
/// off the UI thread, as the button says; a name without an extension gets its own).
fn start_job(
    mut ask: FileAsk<SignalsFile>,
    pendant: &Pendant,
    now: Instant,
) -> Result<Job<SignalsDone>, String> {
    if ask.action == SignalsFile::Import {
        return read_job(ask.path, file::MAX_FILE_BYTES, now, |_, b| file::parse(b));
    }
    let json = ask.action == SignalsFile::ExportJson;
    if ask.path.extension().is_none() {
        ask.path.set_extension(if json { "json" } else { "csv" });
    }
    let rows = pendant.signals.rows().to_vec();
    let encoding = pendant.signals.encoding;
    write_job("writing", ask, rows.len(), now, move || {
        if json {
            file::to_json(&rows, encoding)
        } else {
            file::to_csv(&rows)
        }
    })
}

impl SignalsPanel {
    /// Draws the view; what is asked for goes to `out`.
    pub fn show(
        &mut self,
        ui: &mut Ui,
        pendant: &Pendant,
        folder: &Path,
        now: Instant,
        out: &mut Vec<Intent>,
    ) {
        self.drawn = true;
        let signals = &pendant.signals;
        let mut ask = Vec::new();
        self.add_row(ui, &mut ask);
        self.list_row(ui, pendant, &mut ask);
        self.files(ui, pendant, folder, now, out);
        said_line(ui, &signals.feedback);
        let key = (
            signals.revision(),
            signals.rows().len(),
            self.filter.clone(),
        );
        if self.visible.as_ref().is_none_or(|(k, _)| *k != key) {
            self.visible = Some((key, filtered(signals.rows(), &self.filter)));
        }
        let visible = self.visible.take().unwrap_or_default();
        ui.horizontal_wrapped(|ui| {
            let l = ui.label("Filter");
            ui.add(
                TextEdit::singleline(&mut self.filter)
                    .desired_width(160.0)
                    .hint_text("number or name"),
            )
            .labelled_by(l.id)
            .on_hover_text("Show the rows whose number, kind or name holds these words");
            let total = signals.rows().len();
            let shown = visible.1.len();
            ui.label(if shown == total {
                format!("{total} rows")
            } else {
                format!("{shown} of {total} rows")
            });
        });
        ui.separator();
        self.table(ui, pendant, &visible.1, now, &mut ask);
        self.visible = Some(visible);
        if !signals.rows().is_empty() {
            ui.ctx().request_repaint_after(AGES_REPAINT);
        }
        out.extend(ask.into_iter().map(Intent::Signals));
    }

    /// Once a frame after the panes: the confirmation (whichever tab is in front, kept
    /// inside `centre`, never over the top bar's STOP or the jog column), the model told
    /// whether the view is shown, and the traces of rows ticked or unticked for plotting
    /// put into or taken out of the Plots pane.
    pub fn after_panes(
        &mut self,
        ctx: &egui::Context,
        centre: egui::Rect,
        pendant: &Pendant,
        plots: &mut PlotsPanel,
        out: &mut Vec<Intent>,
    ) {
        let mut ask = Vec::new();
        match &pendant.signals.proposal {
            Some(p) => self.confirmation(ctx, centre, p, pendant.signals.encoding, &mut ask),
            None => self.take_the_risk = false,
        }
        let drawn = std::mem::take(&mut self.drawn);
        if drawn != self.watching {
            self.watching = drawn;
            ask.push(SignalsIntent::Watch(drawn));
        }
        self.sync_plots(&pendant.signals, plots);
        out.extend(ask.into_iter().map(Intent::Signals));
    }

    /// Traces of rows no longer plotted (unticked, removed, refused) taken out; those
    /// ticked this frame put in.
    fn sync_plots(&mut self, signals: &Signals, plots: &mut PlotsPanel) {
        let rows = signals.rows();
        self.placed.retain(|(s, series)| {
            let still = rows.iter().any(|r| r.signal == *s && r.plot);
            if !still {
                plots.hide_signal(series);
            }
            still
        });
        for (s, series, bit) in std::mem::take(&mut self.to_place) {
            if self.placed.iter().any(|(p, _)| *p == s) {
                continue;
            }
            if plots.show_signal(&series, bit) {
                self.placed.push((s, series));
            }
        }
    }

    /// Kind, program, number, count, name, characters and Add.
    fn add_row(&mut self, ui: &mut Ui, ask: &mut Vec<SignalsIntent>) {
        ui.horizontal_wrapped(|ui| {
            let l = ui.label("Kind");
            ComboBox::from_id_salt("signals-kind")
                .selected_text(self.kind.label())
                .width(80.0)
                .show_ui(ui, |ui| {
                    for k in SignalKind::ALL {
                        ui.selectable_value(&mut self.kind, k, k.label());
                    }
                })
                .response
                .labelled_by(l.id);
            let has_program = self.kind.has_program();
            let l = ui.label("Program");
            ui.add_enabled(
                has_program,
                TextEdit::singleline(&mut self.program).desired_width(28.0),
            )
            .labelled_by(l.id)
            .on_hover_text("0: global; 1-64: that program's local flags or variables")
            .on_disabled_hover_text("inputs and outputs belong to no program");
            let l = ui.label("Number");
            ui.add(TextEdit::singleline(&mut self.number).desired_width(40.0))
                .labelled_by(l.id)
                .on_hover_text(
                    "Inputs 0-299, outputs 300-599, global flags 600-899, local flags \
                     900-999, integers 200-299 (local 1-99), reals 300-399 (local 100-199) \
                     [inferred numbering, PROTOCOL.md 3.34-3.43]",
                );
            let l = ui.label("Count");
            ui.add(TextEdit::singleline(&mut self.count).desired_width(32.0))
                .labelled_by(l.id)
                .on_hover_text("How many from the number on (a range)");
            let l = ui.label("Name");
            ui.add(
                TextEdit::singleline(&mut self.name)
                    .desired_width(110.0)
                    .hint_text("optional"),
            )
            .labelled_by(l.id)
            .on_hover_text("Your name for it (numbered 1, 2... when the count is more than 1)");
            let text = self.kind == SignalKind::Text;
            let l = ui.label("Characters");
            ui.add_enabled(
                text,
                TextEdit::singleline(&mut self.chars).desired_width(28.0),
            )
            .labelled_by(l.id)
            .on_hover_text(format!(
                "A string row reads this many characters (1-{MAX_TEXT_CHARS}), one variable \
                 number each"
            ))
            .on_disabled_hover_text("strings only");
            let parsed = self.parse_add();
            let why = parsed.as_ref().err().cloned().unwrap_or_default();
            if ui
                .add_enabled(parsed.is_ok(), Button::new("Add"))
                .on_hover_text("Watch these signals (the controller's numbering is checked)")
                .on_disabled_hover_text(why)
                .clicked()
                && let Ok(intent) = parsed
            {
                ask.push(intent);
            }
        });
    }

    /// The Add fields as an intent, or what to type.
    fn parse_add(&self) -> Result<SignalsIntent, String> {
        let program = if self.kind.has_program() {
            whole::<u8>(&self.program, "program (0-64)")?
        } else {
            0
        };
        let number = whole::<u16>(&self.number, "number")?;
        let count = whole::<u16>(&self.count, "count")?;
        if count == 0 || usize::from(count) > MAX_ROWS {
            return Err(format!("a count is 1-{MAX_ROWS}"));
        }
        let chars = if self.kind == SignalKind::Text {
            whole::<u8>(&self.chars, "characters")?
        } else {
            0
        };
        Ok(SignalsIntent::Add {
            signal: Signal::new(self.kind, program, number),
            count,
            name: self.name.clone(),
            chars,
        })
    }

    /// Defaults, Clear, the real encoding and the refresh line.
    fn list_row(&mut self, ui: &mut Ui, pendant: &Pendant, ask: &mut Vec<SignalsIntent>) {
        let signals = &pendant.signals;
        ui.horizontal_wrapped(|ui| {
            if ui
                .button("Defaults")
                .on_hover_text("Back to the first 32 inputs, outputs and global flags")
                .clicked()
            {
                ask.push(SignalsIntent::Defaults);
                self.edit = None;
            }
            if ui
                .add_enabled(!signals.rows().is_empty(), Button::new("Clear"))
                .on_hover_text("Watch nothing")
                .clicked()
            {
                ask.push(SignalsIntent::Clear);
                self.edit = None;
            }
            ui.separator();
            let l = ui.label("Real encoding");
            let mut encoding = signals.encoding;
            let words = |e: RealEncoding| match e {
                RealEncoding::Plain => "Plain",
                RealEncoding::WordSwapped => "Word-swapped",
            };
            ComboBox::from_id_salt("signals-encoding")
                .selected_text(words(encoding))
                .show_ui(ui, |ui| {
                    for e in [RealEncoding::Plain, RealEncoding::WordSwapped] {
                        ui.selectable_value(&mut encoding, e, words(e));
                    }
                })
                .response
                .labelled_by(l.id)
                .on_hover_text(ENCODING_HOVER);
            if encoding != signals.encoding {
                ask.push(SignalsIntent::RealEncoding(encoding));
            }
            ui.separator();
            let revision = signals.revision();
            let reads = match self.reads {
                Some((r, n)) if r == revision => n,
                _ => {
                    let n = signals.reads_per_round();
                    self.reads = Some((revision, n));
                    n
                }
            };
            let round = if reads == 1 {
                "1 read a round".to_owned()
            } else {
                format!("{reads} reads a round")
            };
            let line = match signals.refresh_rate() {
                _ if !pendant.line.is_up() => format!("{round}; not read: not connected"),
                None => format!("{round}; not read yet"),
                Some(rate) => format!("{round}, refreshed {rate:.1} times a second"),
            };
            ui.label(RichText::new(line).color(GREY)).on_hover_text(
                "Read in the line time the status polls leave, while this view is shown or a \
                 row is plotted",
            );
            if signals.change_pending() {
                ui.spinner();
                ui.label("a change is being sent and read back");
            }
        });
    }

    fn files(
        &mut self,
        ui: &mut Ui,
        pendant: &Pendant,
        folder: &Path,
        now: Instant,
        out: &mut Vec<Intent>,
    ) {
        self.poll_job(now, out);
        let edit = &mut self.edit;
        self.file.row(ui, folder, now, &FILE_BUTTONS, |ask| {
            if ask.action == SignalsFile::Import {
                *edit = None;
            }
            start_job(ask, pendant, now)
        });
    }

    /// A finished job: a read handed to the pendant, a write said (or asked to replace).
    fn poll_job(&mut self, now: Instant, out: &mut Vec<Intent>) {
        let again = |path: &Path| {
            if is_json(path) {
                SignalsFile::ExportJson
            } else {
                SignalsFile::ExportCsv
            }
        };
        let words = |rows| format!("exported {rows} rows");
        let Some((path, read)) = self.file.poll(now, out, words, again) else {
            return;
        };
        self.file.message = None;
        let read = read.map(|(rows, encoding)| {
            if let Some(e) = encoding {
                out.push(Intent::Signals(SignalsIntent::RealEncoding(e)));
            }
            rows
        });
        out.push(Intent::Signals(SignalsIntent::Import {
            path: path.display().to_string(),
            read,
        }));
    }

    /// The table: only the rows in sight are laid out. What a narrow pane shows first:
    /// the signal, its name, its value and its Set; the rest scrolls in sideways.
    fn table(
        &mut self,
        ui: &mut Ui,
        pendant: &Pendant,
        visible: &[usize],
        now: Instant,
        ask: &mut Vec<SignalsIntent>,
    ) {
        let signals = &pendant.signals;
        if signals.rows().is_empty() {
            ui.label("Nothing watched: Add signals, or Defaults.");
            return;
        }
        if visible.is_empty() {
            ui.label("No rows under this filter.");
            return;
        }
        let blocked = signals.proposal.is_some();
        let scroll = ui.spacing().scroll;
        ui.spacing_mut().scroll = egui::style::ScrollStyle::solid();
        let height = ui.available_height();
        egui::ScrollArea::horizontal()
            .id_salt("signals-x")
            .show(ui, |ui| {
                TableBuilder::new(ui)
                    .id_salt("signals-table")
                    .striped(true)
                    .auto_shrink([false, false])
                    .max_scroll_height(height)
                    .cell_layout(egui::Layout::left_to_right(egui::Align::Center))
                    .column(Col::exact(110.0))
                    .column(Col::exact(100.0))
                    .column(Col::exact(84.0))
                    .column(Col::exact(130.0))
                    .column(Col::exact(34.0))
                    .column(Col::exact(70.0))
                    .column(Col::exact(56.0))
                    .column(Col::exact(62.0))
                    .column(Col::remainder().at_least(160.0))
                    .header(ROW_HEIGHT, |mut h| {
                        for title in [
                            "Signal",
                            "Name",
                            "Value",
                            "Set",
                            "Plot",
                            "Last read",
                            "Changes",
                            "",
                            "Note",
                        ] {
                            h.col(|ui| {
                                ui.strong(title);
                            });
                        }
                    })
                    .body(|body| {
                        body.rows(ROW_HEIGHT, visible.len(), |mut row| {
                            let Some(r) = visible
                                .get(row.index())
                                .and_then(|&i| signals.rows().get(i))
                            else {
                                return;
                            };
                            let s = r.signal;
                            let state = signals.state(&s);
                            let stale = signals.is_stale(&s, now);
                            let changed = state
                                .and_then(|st| st.changed_at)
                                .is_some_and(|t| now.saturating_duration_since(t) < HIGHLIGHT_FOR);
                            row.set_selected(changed);
                            let words = |text: String| {
                                let t = RichText::new(text);
                                if stale { t.color(GREY) } else { t }
                            };
                            row.col(|ui| {
                                ui.label(words(s.to_string()));
                            });
                            row.col(|ui| self.name_cell(ui, r, ask));
                            row.col(|ui| {
                                value_cell(
                                    ui,
                                    r,
                                    state.and_then(|st| st.value.as_ref()),
                                    signals,
                                    stale,
                                )
                            });
                            row.col(|ui| {
                                ui.add_enabled_ui(!blocked, |ui| {
                                    self.set_cell(
                                        ui,
                                        r,
                                        state.and_then(|st| st.value.as_ref()),
                                        ask,
                                    )
                                });
                            });
                            row.col(|ui| {
                                let mut on = r.plot;
                                let c = ui.add(egui::Checkbox::without_text(&mut on));
                                c.widget_info(|| {
                                    egui::WidgetInfo::selected(
                                        egui::Role::CheckBox,
                                        true,
                                        r.plot,
                                        format!("Plot: {s}"),
                                    )
                                });
                                let c = c.on_hover_ui(|ui| {
                                    ui.label(format!("Draw {} in the Plots pane", r.label()));
                                });
                                if c.changed() {
                                    ask.push(SignalsIntent::Plot(s, on));
                                    if on {
                                        // The series is named by the signal alone (a
                                        // rename leaves the trace where it is).
                                        self.to_place.push((s, s.to_string(), s.kind.is_bit()));
                                    }
                                }
                            });
                            row.col(|ui| {
                                let text = state
                                    .and_then(|st| st.read_at)
                                    .map_or_else(|| "not read".to_owned(), |t| age(now, t));
                                ui.label(words(text));
                            });
                            row.col(|ui| {
                                let n = state.map_or(0, |st| st.changes);
                                ui.label(words(n.to_string()))
                                    .on_hover_text("Changes seen since the row was added");
                            });
                            row.col(|ui| {
                                let b = ui.small_button("Remove");
                                b.widget_info(|| {
                                    egui::WidgetInfo::labeled(
                                        egui::Role::Button,
                                        true,
                                        format!("Remove: {s}"),
                                    )
                                });
                                if b.on_hover_ui(|ui| {
                                    ui.label(format!("Stop watching {}", r.label()));
                                })
                                .clicked()
                                {
                                    ask.push(SignalsIntent::Remove(s));
                                    self.typed.remove(&s);
                                }
                            });
                            row.col(|ui| {
                                let note = state
                                    .and_then(|st| st.error.clone())
                                    .or_else(|| self.refusal(signals, r));
                                if let Some(note) = note {
                                    let l = ui.add(
                                        egui::Label::new(RichText::new(&note).color(RED))
                                            .truncate(),
                                    );
                                    l.widget_info(|| {
                                        egui::WidgetInfo::labeled(
                                            egui::Role::Label,
                                            true,
                                            format!("{s} note: {note}"),
                                        )
                                    });
                                    l.on_hover_text(note);
                                }
                            });
                        });
                    });
            });
        ui.spacing_mut().scroll = scroll;
    }

    /// The model's refusal of the value last proposed for this row, while it is the last
    /// word.
    fn refusal(&self, signals: &Signals, r: &WatchRow) -> Option<String> {
        if self.proposed != Some(r.signal) {
            return None;
        }
        let (level, text) = signals.feedback.as_ref()?;
        let label = r.label();
        (*level != Level::Info
            && signals.proposal.is_none()
            && text.strip_prefix(&label)?.starts_with(':'))
        .then(|| text.clone())
    }

    /// A click on the name begins its edit; Enter or leaving renames, Esc forgets.
    fn name_cell(&mut self, ui: &mut Ui, r: &WatchRow, ask: &mut Vec<SignalsIntent>) {
        let s = r.signal;
        if let Some(edit) = self.edit.as_mut().filter(|e| e.signal == s) {
            let field = ui.add(
                TextEdit::singleline(&mut edit.text)
                    .id_salt(("signal-name", s))
                    .desired_width(f32::INFINITY)
                    .margin(egui::vec2(2.0, 1.0)),
            );
            field.widget_info(|| named_field(&edit.text, format!("{s} name")));
            if !edit.focused {
                field.request_focus();
                edit.focused = true;
            } else if field.lost_focus() {
                let text = std::mem::take(&mut edit.text);
                self.edit = None;
                if !ui.input(|i| i.key_pressed(Key::Escape)) && text != r.name {
                    ask.push(SignalsIntent::Rename(s, text));
                }
            } else if !field.has_focus() {
                self.edit = None;
            }
            return;
        }
        let l = ui.add(
            egui::Label::new(r.name.as_str())
                .truncate()
                .sense(Sense::click()),
        );
        l.widget_info(|| {
            egui::WidgetInfo::labeled(
                egui::Role::Label,
                true,
                if r.name.is_empty() {
                    format!("{s} name, empty")
                } else {
                    format!("{s} name: {}", r.name)
                },
            )
        });
        let l = l.on_hover_ui(|ui| {
            ui.label(format!("{s}: your name for it; click to edit"));
        });
        if l.clicked() {
            self.edit = Some(NameEdit {
                signal: s,
                text: r.name.clone(),
                focused: false,
            });
        }
    }

    /// Bits: a toggle; integers and reals: a field and Set; inputs and strings: nothing.
    fn set_cell(
        &mut self,
        ui: &mut Ui,
        r: &WatchRow,
        value: Option<&Value>,
        ask: &mut Vec<SignalsIntent>,
    ) {
        let s = r.signal;
        if !s.kind.writable() {
            return;
        }
        if s.kind.is_bit() {
            let choices: &[(&str, &str)] = match value {
                Some(Value::Bit(true)) => &[("Set OFF", "off")],
                Some(Value::Bit(false)) => &[("Set ON", "on")],
                _ => &[("Set ON", "on"), ("Set OFF", "off")],
            };
            for (words, text) in choices {
                let b = ui.small_button(*words);
                b.widget_info(|| {
                    egui::WidgetInfo::labeled(
                        egui::Role::Button,
                        ui.is_enabled(),
                        format!("{words}: {s}"),
                    )
                });
                if b.on_hover_ui(|ui| {
                    ui.label(format!("{words} {} (asks to confirm first)", r.label()));
                })
                .clicked()
                {
                    self.proposed = Some(s);
                    ask.push(SignalsIntent::Propose {
                        signal: s,
                        text: (*text).to_owned(),
                    });
                }
            }
            return;
        }
        let text = self.typed.entry(s).or_default();
        let field = ui.add(
            TextEdit::singleline(text)
                .id_salt(("signal-set", s))
                .desired_width(86.0)
                .hint_text("new value")
                .margin(egui::vec2(2.0, 1.0)),
        );
        field.widget_info(|| named_field(text, format!("{s} new value")));
        let entered = field.lost_focus() && ui.input(|i| i.key_pressed(Key::Enter));
        let b = ui.small_button("Set");
        b.widget_info(|| {
            egui::WidgetInfo::labeled(egui::Role::Button, ui.is_enabled(), format!("Set: {s}"))
        });
        let clicked = b
            .on_hover_ui(|ui| {
                ui.label(format!("Change {} (asks to confirm first)", r.label()));
            })
            .clicked();
        if (entered || clicked) && !text.trim().is_empty() {
            self.proposed = Some(s);
            ask.push(SignalsIntent::Propose {
                signal: s,
                text: text.clone(),
            });
        }
        if text.is_empty() {
            self.typed.remove(&s);
        }
    }

    /// The change in words, Send and Cancel; a running program's risk ticked first.
    fn confirmation(
        &mut self,
        ctx: &egui::Context,
        area: egui::Rect,
        p: &Proposal,
        encoding: RealEncoding,
        ask: &mut Vec<SignalsIntent>,
    ) {
        let mut open = true;
        egui::Window::new("Confirm the change")
            .collapsible(false)
            .resizable(false)
            .constrain_to(area)
            .default_pos(area.center() - egui::vec2(180.0, 60.0))
            .default_width(360.0)
            .open(&mut open)
            .show(ctx, |ui| {
                ui.label(RichText::new(p.text(encoding)).strong().size(15.0));
                ui.label(
                    RichText::new(
                        "Sent once (never repeated by the link), then read back; the result \
                         goes to Messages.",
                    )
                    .color(GREY),
                );
                if p.program_running {
                    ui.label(
                        RichText::new("215H reports a program running: it may drive this too")
                            .color(RED)
                            .strong(),
                    );
                    ui.checkbox(
                        &mut self.take_the_risk,
                        "A program is running: I accept the risk",
                    );
                }
                ui.horizontal(|ui| {
                    let can = !p.program_running || self.take_the_risk;
                    if ui
                        .add_enabled(can, Button::new("Send"))
                        .on_disabled_hover_text("a program is running: tick the risk first")
                        .clicked()
                    {
                        ask.push(SignalsIntent::Confirm {
                            take_the_risk: p.program_running && self.take_the_risk,
                        });
                    }
                    if ui.button("Cancel").clicked() {
                        ask.push(SignalsIntent::Cancel);
                    }
                });
            });
        if !open || ctx.input(|i| i.key_pressed(Key::Escape)) {
            ask.push(SignalsIntent::Cancel);
        }
    }
}

/// Bits: a lamp and ON/OFF; numbers and strings: their text; greyed when stale.
fn value_cell(ui: &mut Ui, r: &WatchRow, value: Option<&Value>, signals: &Signals, stale: bool) {
    let s = r.signal;
    let shown = value.map(|v| v.show(signals.encoding));
    let words = shown.as_deref().unwrap_or("?");
    let color = if stale {
        GREY
    } else {
        ui.visuals().text_color()
    };
    if let Some(Value::Bit(on)) = value {
        let (rect, _) = ui.allocate_exact_size(egui::vec2(12.0, 12.0), Sense::hover());
        let fill = match (on, stale) {
            (true, false) => GREEN,
            (true, true) => GREEN.gamma_multiply(0.45),
            (false, _) => GREY.gamma_multiply(0.4),
        };
        ui.painter().circle_filled(rect.center(), 5.5, fill);
    }
    let warn = matches!(value, Some(Value::Real(_))) && words.contains("check the real encoding");
    let l = ui.add(
        egui::Label::new(RichText::new(words).color(if warn { AMBER } else { color })).truncate(),
    );
    l.widget_info(|| {
        egui::WidgetInfo::labeled(egui::Role::Label, true, format!("{s} value: {words}"))
    });
    l.on_hover_ui(|ui| {
        ui.label(match (&shown, stale) {
            (None, _) => format!("{s}: not read yet"),
            (Some(v), true) => format!("{s}: {v} (stale: not read for a while)"),
            (Some(v), false) => format!("{s}: {v}"),
        });
    });
}

/// A text field's accessible description: its name and what it holds.
fn named_field(text: &str, name: String) -> egui::WidgetInfo {
    let mut info = egui::WidgetInfo::text_edit(true, text, text, "");
    info.label = Some(name);
    info
}

impl Pane for SignalsPanel {
    fn ui(&mut self, ui: &mut Ui, cx: &mut PaneCx<'_>) {
        self.show(ui, cx.pendant, cx.folder, cx.now, cx.intents);
    }
}
