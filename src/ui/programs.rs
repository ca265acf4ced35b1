//! The Programs view: the controller's programs with their state and step, run, pause,
//! one step, resume and end behind the model's checks and a confirmation, and a listing
//! opened from a file with the executing step highlighted.

use std::path::Path;
use std::time::{Duration, Instant};

use egui::{Button, DragValue, Key, RichText, Ui};
use egui_extras::{Column as Col, TableBuilder};

use super::file_field::{Browse, FieldSpec, FileAsk, Purpose};
use super::file_work::{Done, FileButton, FileWork, read_job};
use super::pane::{Pane, PaneCx};
use super::widgets::{AMBER, GREEN, GREY, RED, said_line};
use crate::files::job::Job;
use crate::pendant::programs::{
    Listing, MAX_FILE_BYTES, ProgramState, Programs, ProgramsIntent, Proposal,
};
use crate::pendant::{Intent, Pendant};
use crate::protocol::ProgramAction;

const ROW_HEIGHT: f32 = 20.0;
/// While the view is shown, drawn again this often (states and ages move on).
const REPAINT: Duration = Duration::from_millis(250);
/// The words every operator reads before running anything.
const SPEED_NOTE: &str = "A program moves the arm at its own speeds (VEL, ACC, DCL): the \
    pendant's reduced jog speed does not apply. STOP or Esc ends every program and stops \
    the arm.";

/// Below this width the listing goes above the table instead of beside it.
const SIDE_BY_SIDE: f32 = 760.0;

/// What the file field is for: opening a listing.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum ListingFile {
    Open,
}

static FILE_FIELD: FieldSpec<ListingFile> = FieldSpec {
    label: "Listing",
    hint: "programs.sel",
    width: 170.0,
    browse: &[Browse {
        label: "Open a program listing...",
        action: ListingFile::Open,
        purpose: Purpose::Open,
    }],
    filters: &[("SEL program text", &["sel", "txt"])],
};

static FILE_BUTTONS: [FileButton<ListingFile>; 1] = [(
    "Open",
    Some(
        "Show a program listing (the simulator's SEL text format) beside the step \
         pointer: Format B cannot read the controller's own program text",
    ),
    ListingFile::Open,
)];

/// The view's own state: the program chosen and the listing file; the programs and their
/// states are the pendant's.
pub struct ProgramsPanel {
    program: u8,
    file: FileWork<ListingFile, Done<Listing>>,
    drawn: bool,
    watching: bool,
    /// The step the listing last scrolled to.
    scrolled_to: Option<(u8, u16)>,
}

impl Default for ProgramsPanel {
    fn default() -> Self {
        Self {
            program: 1,
            file: FileWork::new(&FILE_FIELD),
            drawn: false,
            watching: false,
            scrolled_to: None,
        }
    }
}

fn start_job(ask: FileAsk<ListingFile>, now: Instant) -> Result<Job<Done<Listing>>, String> {
    read_job(ask.path, MAX_FILE_BYTES, now, |path, bytes| {
        Listing::from_bytes(&path.display().to_string(), bytes)
    })
}

fn state_color(state: ProgramState) -> egui::Color32 {
    match state {
        ProgramState::Running => GREEN,
        ProgramState::Paused => AMBER,
        ProgramState::Error { .. } => RED,
        ProgramState::Unknown | ProgramState::NotStarted => GREY,
    }
}

impl ProgramsPanel {
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
        let programs = &pendant.programs;
        let mut ask = Vec::new();
        if let Some(n) = programs.selected
            && n != self.program
            && !ui.memory(|m| m.focused().is_some())
        {
            self.program = n;
        }
        self.controls(ui, programs, &mut ask);
        ui.label(RichText::new(SPEED_NOTE).color(GREY).small());
        said_line(ui, &programs.feedback);
        self.poll_job(now, out);
        ui.horizontal(|ui| {
            if ui
                .button("Demo listing")
                .on_hover_text(
                    "Show the built-in simulator's demo (program 1, a pick and place between \
                     positions 1 and 2: assets/programs/demo.sel)",
                )
                .clicked()
            {
                out.push(Intent::Programs(ProgramsIntent::Listing {
                    path: Listing::DEMO.to_owned(),
                    read: Ok(Listing::demo()),
                }));
            }
            self.file
                .row(ui, folder, now, &FILE_BUTTONS, |ask| start_job(ask, now));
        });
        ui.separator();
        let listed = programs
            .listing
            .as_ref()
            .and_then(|l| l.program(self.program))
            .is_some();
        if listed && ui.available_width() >= SIDE_BY_SIDE {
            ui.columns(2, |cols| {
                self.table(&mut cols[0], programs, now, &mut ask);
                self.listing(&mut cols[1], programs);
            });
        } else if listed {
            // A narrow pane: the listing above, the table below it.
            let height = (ui.available_height() * 0.45).max(120.0);
            ui.allocate_ui(egui::vec2(ui.available_width(), height), |ui| {
                self.listing(ui, programs);
            });
            ui.separator();
            self.table(ui, programs, now, &mut ask);
        } else {
            self.table(ui, programs, now, &mut ask);
        }
        ui.ctx().request_repaint_after(REPAINT);
        out.extend(ask.into_iter().map(Intent::Programs));
    }

    /// The program number and the six buttons.
    fn controls(&mut self, ui: &mut Ui, programs: &Programs, ask: &mut Vec<ProgramsIntent>) {
        ui.horizontal_wrapped(|ui| {
            let l = ui.label("Program");
            let range = crate::protocol::PROGRAMS;
            let r = ui
                .add(DragValue::new(&mut self.program).range(range.start..=range.end - 1))
                .labelled_by(l.id)
                .on_hover_text("The program the buttons act on (click a row to choose it)");
            if r.changed() {
                ask.push(ProgramsIntent::Select(self.program));
            }
            let row = programs.row(self.program);
            let state = row.state();
            ui.label(
                RichText::new(state.text())
                    .color(state_color(state))
                    .strong(),
            );
            if let Some(step) = row.step() {
                ui.label(format!("step {step}"));
            }
            ui.separator();
            let n = self.program;
            let buttons: [(&str, ProgramAction, &str); 5] = [
                (
                    "Run",
                    ProgramAction::Run,
                    "Start the program from its first step (asks first)",
                ),
                (
                    "One step",
                    ProgramAction::Step,
                    "Run one step, then pause (asks first for this program)",
                ),
                (
                    "Pause",
                    ProgramAction::Pause,
                    "Pause the program between steps",
                ),
                (
                    "Resume",
                    ProgramAction::Resume,
                    "Go on from where it was paused here",
                ),
                ("End", ProgramAction::End, "End the program"),
            ];
            for (label, action, hover) in buttons {
                if ui.button(label).on_hover_text(hover).clicked() {
                    ask.push(ProgramsIntent::Ask(action, n));
                }
            }
            if ui
                .add(Button::new(RichText::new("End all").color(RED)))
                .on_hover_text("End every running program (254H 00)")
                .clicked()
            {
                ask.push(ProgramsIntent::EndAll);
            }
        });
    }

    /// Every program: number, state, step, error, age of the read; a click chooses it.
    fn table(
        &mut self,
        ui: &mut Ui,
        programs: &Programs,
        now: Instant,
        ask: &mut Vec<ProgramsIntent>,
    ) {
        let numbers: Vec<u8> = Programs::numbers().collect();
        let listing = programs.listing.as_ref();
        ui.push_id("programs-table", |ui| {
            TableBuilder::new(ui)
                .striped(true)
                .sense(egui::Sense::click())
                .column(Col::exact(40.0))
                .column(Col::initial(130.0).at_least(90.0))
                .column(Col::exact(50.0))
                .column(Col::remainder().at_least(80.0))
                .header(ROW_HEIGHT, |mut h| {
                    for title in ["No.", "State", "Step", "Name / last read"] {
                        h.col(|ui| {
                            ui.strong(title);
                        });
                    }
                })
                .body(|body| {
                    body.rows(ROW_HEIGHT, numbers.len(), |mut row| {
                        let n = numbers[row.index()];
                        let r = programs.row(n);
                        let state = r.state();
                        let stale = programs.is_stale(n, now);
                        row.set_selected(n == self.program);
                        row.col(|ui| {
                            ui.label(n.to_string());
                        });
                        row.col(|ui| {
                            let color = if stale && state != ProgramState::Unknown {
                                GREY
                            } else {
                                state_color(state)
                            };
                            let text = match &r.failed {
                                Some(why) => format!("{} ({why})", state.text()),
                                None => state.text(),
                            };
                            ui.label(RichText::new(text).color(color))
                                .on_hover_text(if stale { "not read for over 2 s" } else { "" });
                        });
                        row.col(|ui| {
                            ui.label(r.step().map_or(String::new(), |s| s.to_string()));
                        });
                        row.col(|ui| {
                            let name = listing.and_then(|l| l.name(n)).unwrap_or("");
                            let age = r
                                .status
                                .map(|(_, at)| {
                                    format!(
                                        "{:.1} s ago",
                                        now.saturating_duration_since(at).as_secs_f64()
                                    )
                                })
                                .unwrap_or_default();
                            ui.label(RichText::new(format!("{name}  {age}")).color(GREY));
                        });
                        if row.response().clicked() {
                            self.program = n;
                            ask.push(ProgramsIntent::Select(n));
                        }
                    });
                });
        });
    }

    /// The chosen program's listing, the executing step highlighted and kept in sight.
    fn listing(&mut self, ui: &mut Ui, programs: &Programs) {
        let Some(p) = programs
            .listing
            .as_ref()
            .and_then(|l| l.program(self.program))
        else {
            return;
        };
        let step = programs.row(self.program).step();
        ui.label(RichText::new(format!("Program {} {}", p.number, p.name)).strong());
        if p.errors > 0 {
            ui.colored_label(
                ui.visuals().error_fg_color,
                format!(
                    "{} line(s) not read (in red; point at one for why): the simulator \
                     would not load this program",
                    p.errors
                ),
            );
        }
        let follow = step.map(|s| (self.program, s));
        let scroll = follow.is_some() && follow != self.scrolled_to;
        egui::ScrollArea::vertical()
            .id_salt("programs-listing")
            .auto_shrink([false, false])
            .show(ui, |ui| {
                for s in &p.steps {
                    let here = step == Some(s.number);
                    let mut line =
                        RichText::new(format!("{:>4}  {}", s.number, s.text)).monospace();
                    if s.error.is_some() {
                        line = line.color(ui.visuals().error_fg_color);
                    }
                    if here {
                        line = line.background_color(AMBER.gamma_multiply(0.35)).strong();
                    }
                    // Long lines end in "…" (the whole line on hover): the step numbers
                    // stay in sight.
                    let mut r = ui.add(egui::Label::new(line).truncate());
                    if let Some(e) = &s.error {
                        r = r.on_hover_text(format!("Not read: {e}"));
                    }
                    if here && scroll {
                        r.scroll_to_me(Some(egui::Align::Center));
                    }
                }
            });
        if scroll {
            self.scrolled_to = follow;
        }
    }

    /// A finished read: the listing handed to the pendant.
    fn poll_job(&mut self, now: Instant, out: &mut Vec<Intent>) {
        let Some((path, read)) = self
            .file
            .poll(now, out, |_| String::new(), |_| ListingFile::Open)
        else {
            return;
        };
        self.file.message = None;
        out.push(Intent::Programs(ProgramsIntent::Listing {
            path: path.display().to_string(),
            read,
        }));
    }

    /// Once a frame after the panes: the confirmation (whichever tab is in front, kept
    /// inside `centre`), and the model told whether the view is shown.
    pub fn after_panes(
        &mut self,
        ctx: &egui::Context,
        centre: egui::Rect,
        pendant: &Pendant,
        out: &mut Vec<Intent>,
    ) {
        let mut ask = Vec::new();
        if let Some(p) = &pendant.programs.proposal {
            confirmation(ctx, centre, p, &mut ask);
        }
        let drawn = std::mem::take(&mut self.drawn);
        if drawn != self.watching {
            self.watching = drawn;
            ask.push(ProgramsIntent::Watch(drawn));
        }
        out.extend(ask.into_iter().map(Intent::Programs));
    }
}

/// "Run program 1?" with Run and Cancel; Esc cancels (and the STOP it also is ends all).
fn confirmation(
    ctx: &egui::Context,
    area: egui::Rect,
    p: &Proposal,
    ask: &mut Vec<ProgramsIntent>,
) {
    let mut open = true;
    let verb = match p.call.action {
        ProgramAction::Run => "Run",
        ProgramAction::Step => "One step",
        _ => "Resume",
    };
    egui::Window::new("Automatic operation")
        .collapsible(false)
        .resizable(false)
        .constrain_to(area)
        .default_pos(area.center() - egui::vec2(200.0, 70.0))
        .default_width(400.0)
        .open(&mut open)
        .show(ctx, |ui| {
            ui.label(RichText::new(&p.text).strong().size(15.0));
            ui.label(
                RichText::new("Sent once (never repeated by the link); what the controller does goes to Messages.")
                    .color(GREY),
            );
            ui.horizontal(|ui| {
                if ui.button(RichText::new(verb).strong()).clicked() {
                    ask.push(ProgramsIntent::Confirm);
                }
                if ui.button("Cancel").clicked() {
                    ask.push(ProgramsIntent::Cancel);
                }
            });
        });
    if !open || ctx.input(|i| i.key_pressed(Key::Escape)) {
        ask.push(ProgramsIntent::Cancel);
    }
}

impl Pane for ProgramsPanel {
    fn ui(&mut self, ui: &mut Ui, cx: &mut PaneCx<'_>) {
        self.show(ui, cx.pendant, cx.folder, cx.now, cx.intents);
    }
}
