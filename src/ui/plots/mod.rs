//! The Plots pane: live traces of the polled channels that scroll (or stand still on
//! Pause), one plot per unit with its own value axis and the bits and phases as steps on
//! lanes beneath, all on one time axis; zoom and pan; cursors A and B with a readout; the
//! captures moves trigger, overlaid for comparison; CSV and PNG export.

mod captures;
mod export;

pub use export::picture;

use std::collections::BTreeSet;
use std::time::{Duration, Instant};

use egui::{Color32, ComboBox, RichText, Ui};
use egui_plot::{Line, Plot, PlotBounds, PlotPoints, Text, VLine};

use super::pane::{Pane, PaneCx};
use crate::pendant::samples::capture::Capture;
use crate::pendant::samples::view::{
    Trace, TraceCache, TraceChoice, capture_trace, capture_value_at, live_value_at,
};
use crate::pendant::{Intent, Pendant};
use crate::render::plot::TRACE_COLOURS;

/// Traces one plot shows at most.
pub const TRACES: usize = 4;
/// The time spans the live view offers, seconds.
const WINDOWS: [(f64, &str); 5] = [
    (5.0, "5 s"),
    (10.0, "10 s"),
    (60.0, "1 min"),
    (600.0, "10 min"),
    (3600.0, "1 h"),
];
/// How often a live view is drawn again while it scrolls.
const LIVE_REPAINT: Duration = Duration::from_millis(50);

/// What the plot shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Source {
    /// The sample store, scrolling or paused.
    Live,
    /// The captures ticked in the list, overlaid from their triggers.
    Captures,
}

/// The pane's state (the samples live in the pendant).
pub struct PlotsPanel {
    pub source: Source,
    pub traces: [Option<TraceChoice>; TRACES],
    /// Seconds shown while live.
    pub window_s: f64,
    /// Paused at this time (seconds since the store's origin); `None`: live.
    pub paused: Option<f64>,
    /// The time span drawn last frame, seconds.
    pub shown: (f64, f64),
    pub cursors: [Option<f64>; 2],
    next_cursor: usize,
    /// Captures overlaid (by number).
    pub overlaid: BTreeSet<u64>,
    /// The capture a Save acts on.
    pub selected: Option<u64>,
    pub(super) export: export::Export,
    /// The decimated traces of the last frame.
    cache: TraceCache,
    /// The captures the overlay's span was last fitted to.
    overlay_key: Vec<u64>,
    /// Where each plot was drawn last frame (its data area), top first.
    pub plot_rects: Vec<egui::Rect>,
    /// The capture and file rows shown: as the user chose, else when the pane has room.
    tools_open: Option<bool>,
    /// The plot was drawn with the defaults filled in once.
    defaulted: bool,
}

impl Default for PlotsPanel {
    fn default() -> Self {
        Self {
            source: Source::Live,
            traces: Default::default(),
            window_s: 10.0,
            paused: None,
            shown: (0.0, 10.0),
            cursors: [None; 2],
            next_cursor: 0,
            overlaid: BTreeSet::new(),
            selected: None,
            export: export::Export::default(),
            plot_rects: Vec::new(),
            overlay_key: Vec::new(),
            cache: TraceCache::default(),
            tools_open: None,
            defaulted: false,
        }
    }
}

impl PlotsPanel {
    /// The traces chosen.
    pub fn chosen(&self) -> Vec<TraceChoice> {
        self.traces.iter().flatten().cloned().collect()
    }

    /// A watched signal's trace (its series `series`, channel "state" for a bit, "value"
    /// for a number, as the samples name them) put into the first free slot, unless a
    /// slot shows it already; false when every slot is taken.
    pub fn show_signal(&mut self, series: &str, bit: bool) -> bool {
        let choice = TraceChoice::new(series, if bit { "state" } else { "value" });
        if self.traces.iter().flatten().any(|c| *c == choice) {
            return true;
        }
        match self.traces.iter_mut().find(|t| t.is_none()) {
            Some(slot) => {
                *slot = Some(choice);
                true
            }
            None => false,
        }
    }

    /// A watched signal's trace (series `series`) taken out of its slot.
    pub fn hide_signal(&mut self, series: &str) {
        for slot in &mut self.traces {
            if slot.as_ref().is_some_and(|c| c.series == series) {
                *slot = None;
            }
        }
    }

    /// Places the next cursor (A, then B, then A again) at `x`.
    pub fn place_cursor(&mut self, x: f64) {
        self.cursors[self.next_cursor] = Some(x);
        self.next_cursor = 1 - self.next_cursor;
    }

    /// Fills empty trace slots with the first RMC axis's positions and In Position, or
    /// the X-SEL's X and Y when no RMC axis is polled.
    fn default_traces(&mut self, pendant: &Pendant) {
        if self.defaulted {
            return;
        }
        self.defaulted = true;
        if self.traces.iter().any(Option::is_some) {
            return;
        }
        let store = &pendant.samples.store;
        let rmc = store.all().iter().find(|s| s.name.starts_with("Axis"));
        let picks: Vec<TraceChoice> = match rmc {
            Some(s) => [
                "Target Position",
                "Actual Position",
                "In Position",
                "TG phase",
            ]
            .iter()
            .map(|c| TraceChoice::new(&s.name, *c))
            .collect(),
            None => store.choices().into_iter().take(2).collect(),
        };
        for (slot, pick) in self.traces.iter_mut().zip(picks) {
            *slot = Some(pick);
        }
    }

    /// The live view's time span now.
    fn live_span(&self, pendant: &Pendant, now: Instant) -> (f64, f64) {
        let end = self.paused.unwrap_or_else(|| {
            pendant
                .samples
                .store
                .origin()
                .map_or(0.0, |o| now.saturating_duration_since(o).as_secs_f64())
        });
        (end - self.window_s, end)
    }
}

/// Draws the pane; settings changes go to `intents`.
pub fn show(
    p: &mut PlotsPanel,
    ui: &mut Ui,
    pendant: &Pendant,
    intents: &mut Vec<Intent>,
    folder: &std::path::Path,
    now: Instant,
) {
    p.default_traces(pendant);
    let pane_height = ui.available_height();
    egui::ScrollArea::vertical()
        .id_salt("plots-pane")
        .auto_shrink([false, false])
        .show(ui, |ui| {
            pane(p, ui, pendant, intents, folder, now, pane_height)
        });
    if p.source == Source::Live && p.paused.is_none() {
        ui.ctx().request_repaint_after(LIVE_REPAINT);
    }
}

/// A pane shorter than this hides the capture and file rows until asked (px).
const ROOMY_PANE: f32 = 420.0;
/// The plots never get less than this (the pane scrolls instead), px.
const MIN_PLOTS: f32 = 180.0;

fn pane(
    p: &mut PlotsPanel,
    ui: &mut Ui,
    pendant: &Pendant,
    intents: &mut Vec<Intent>,
    folder: &std::path::Path,
    now: Instant,
    pane_height: f32,
) {
    let top = ui.cursor().top();
    let tools = *p.tools_open.get_or_insert(pane_height >= ROOMY_PANE);
    toolbar(p, ui, pendant, now);
    if tools {
        capture_choices(ui, pendant, intents);
    }
    trace_choosers(p, ui, pendant);
    if tools {
        export::bar(p, ui, pendant, intents, folder, now);
    }
    let used = ui.cursor().top() - top;
    let captures: Vec<&Capture> = pendant
        .samples
        .captures
        .list
        .iter()
        .filter(|c| p.overlaid.contains(&c.number))
        .collect();
    let left = pane_height - used;
    let list_height = if p.source == Source::Captures {
        (left * 0.35).clamp(80.0, 220.0)
    } else {
        0.0
    };
    let readout_height = 24.0 + 18.0 * (p.chosen().len() as f32 + 1.0);
    let plot_height = (left - list_height - readout_height).max(MIN_PLOTS);
    let traces = match p.source {
        Source::Live => live_traces(p, ui, pendant, now),
        Source::Captures => overlay_traces(p, &captures),
    };
    draw(p, ui, &traces, plot_height);
    readout(p, ui, pendant, &captures);
    if p.source == Source::Captures {
        captures::list(p, ui, pendant, intents);
    }
}

fn toolbar(p: &mut PlotsPanel, ui: &mut Ui, pendant: &Pendant, now: Instant) {
    ui.horizontal_wrapped(|ui| {
        ui.selectable_value(&mut p.source, Source::Live, "Live");
        let n = pendant.samples.captures.list.len();
        ui.selectable_value(&mut p.source, Source::Captures, format!("Captures ({n})"));
        ui.separator();
        if p.source == Source::Live {
            let label = if p.paused.is_some() {
                "Resume"
            } else {
                "Pause"
            };
            if ui.button(label).clicked() {
                p.paused = match p.paused {
                    Some(_) => None,
                    None => Some(p.live_span(pendant, now).1),
                };
            }
            let l = ui.label("Span");
            ComboBox::from_id_salt("plot-span")
                .selected_text(
                    WINDOWS
                        .iter()
                        .find(|(s, _)| *s == p.window_s)
                        .map_or("custom", |(_, t)| *t),
                )
                .show_ui(ui, |ui| {
                    for (s, text) in WINDOWS {
                        ui.selectable_value(&mut p.window_s, s, text);
                    }
                })
                .response
                .labelled_by(l.id);
        }
        if ui.button("Clear cursors").clicked() {
            p.cursors = [None; 2];
            p.next_cursor = 0;
        }
        let open = p.tools_open.unwrap_or(false);
        if ui
            .selectable_label(open, "Capture, files")
            .on_hover_text("Show or hide the capture choices and the CSV and PNG export")
            .clicked()
        {
            p.tools_open = Some(!open);
        }
    });
    ui.label(
        RichText::new(format!(
            "{}. Polled samples, not the controller's own loop: a value holds until the next poll.",
            poll_rates(pendant, now)
        ))
        .size(11.0)
        .color(crate::ui::widgets::GREY),
    );
}

/// Capture on or off, its length and its pre-trigger share.
fn capture_choices(ui: &mut Ui, pendant: &Pendant, intents: &mut Vec<Intent>) {
    ui.horizontal_wrapped(|ui| {
        let mut c = pendant.settings.captures;
        ui.checkbox(&mut c.on, "Capture moves");
        ui.add(
            egui::DragValue::new(&mut c.length_s)
                .range(0.5..=600.0)
                .speed(0.1)
                .suffix(" s"),
        )
        .on_hover_text("A capture's length");
        let mut pre = c.pre_share * 100.0;
        ui.add(
            egui::DragValue::new(&mut pre)
                .range(0.0..=90.0)
                .speed(1.0)
                .suffix(" % before"),
        )
        .on_hover_text("The share of a capture before the move's command (pre-trigger)");
        c.pre_share = pre / 100.0;
        if c != pendant.settings.captures {
            intents.push(Intent::CaptureSettings(c));
        }
    });
}

/// `Axis 1: 50 polls/s, X-SEL work position: 9 polls/s`, over the last 5 s.
fn poll_rates(pendant: &Pendant, now: Instant) -> String {
    let store = &pendant.samples.store;
    let Some(origin) = store.origin() else {
        return "No samples yet".into();
    };
    let end = now.saturating_duration_since(origin);
    let from = end.saturating_sub(Duration::from_secs(5));
    let span = (end - from).as_secs_f64().max(0.001);
    store
        .all()
        .iter()
        .map(|s| {
            let n = s.rows_between(from, end).len();
            format!("{}: {:.0} polls/s", s.name, n as f64 / span)
        })
        .collect::<Vec<_>>()
        .join(", ")
}

fn trace_choosers(p: &mut PlotsPanel, ui: &mut Ui, pendant: &Pendant) {
    let all = pendant.samples.store.choices();
    ui.horizontal_wrapped(|ui| {
        for (i, slot) in p.traces.iter_mut().enumerate() {
            let [r, g, b] = TRACE_COLOURS[i];
            let l = ui
                .label(RichText::new(format!("Trace {}", i + 1)).color(Color32::from_rgb(r, g, b)));
            let shown = slot.as_ref().map_or("none".to_string(), TraceChoice::label);
            ComboBox::from_id_salt(("plot-trace", i))
                .selected_text(shown)
                .width(190.0)
                .show_ui(ui, |ui| {
                    ui.selectable_value(slot, None, "none");
                    for c in &all {
                        let unit = pendant
                            .samples
                            .store
                            .find(c)
                            .map(|(s, ch)| s.channels[ch].unit.clone())
                            .unwrap_or_default();
                        let text = if unit.is_empty() {
                            c.label()
                        } else {
                            format!("{} ({unit})", c.label())
                        };
                        ui.selectable_value(slot, Some(c.clone()), text);
                    }
                })
                .response
                .labelled_by(l.id);
        }
    });
}

/// The chosen channels over the span shown, one min/max pair per pixel column. A live
/// span moves a column at a time, so only the newest columns are worked out each frame.
fn live_traces(
    p: &mut PlotsPanel,
    ui: &Ui,
    pendant: &Pendant,
    now: Instant,
) -> Vec<(usize, Trace)> {
    let columns = ui.available_width().max(50.0) as usize;
    let span = if p.paused.is_some() {
        p.shown
    } else {
        let (_, end) = p.live_span(pendant, now);
        let column = p.window_s / columns as f64;
        let end = (end / column).ceil() * column;
        (end - p.window_s, end)
    };
    p.shown = span;
    let chosen = p.chosen();
    p.cache.keep_only(&chosen);
    let store = &pendant.samples.store;
    p.traces
        .iter()
        .enumerate()
        .filter_map(|(i, c)| {
            let c = c.as_ref()?;
            p.cache
                .trace(store, c, span.0, span.1, columns)
                .map(|t| (i, t))
        })
        .collect()
}

/// Each overlaid capture's chosen channels, against the time from its trigger.
fn overlay_traces(p: &mut PlotsPanel, captures: &[&Capture]) -> Vec<(usize, Trace)> {
    let mut out = Vec::new();
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for (k, c) in captures.iter().enumerate() {
        for (i, choice) in p.traces.iter().enumerate() {
            let Some(choice) = choice else { continue };
            let label = format!("#{} {}", c.number, choice.channel);
            // A plotted signal rides along in a capture as `series channel`.
            let found = capture_trace(c, &choice.channel, label.clone())
                .or_else(|| capture_trace(c, &choice.label(), label));
            if let Some(t) = found {
                lo = lo.min(c.times.first().copied().unwrap_or(0.0));
                hi = hi.max(c.times.last().copied().unwrap_or(0.0));
                out.push((i + k * TRACES, t));
            }
        }
    }
    // A new set of captures is shown whole; the user's zoom holds until it changes.
    let key: Vec<u64> = captures.iter().map(|c| c.number).collect();
    if lo < hi && p.overlay_key != key {
        p.shown = (lo, hi);
        p.overlay_key = key;
    }
    out
}

/// The plots: one per unit, then one for the lanes of bits and phases, on one time axis.
fn draw(p: &mut PlotsPanel, ui: &mut Ui, traces: &[(usize, Trace)], height: f32) {
    let mut units: Vec<&str> = Vec::new();
    for (_, t) in traces.iter().filter(|(_, t)| !t.step) {
        if !units.contains(&t.unit.as_str()) {
            units.push(&t.unit);
        }
    }
    let levels: Vec<&(usize, Trace)> = traces.iter().filter(|(_, t)| t.step).collect();
    let lanes_height = if levels.is_empty() {
        0.0
    } else {
        30.0 + 22.0 * levels.len() as f32
    };
    if units.is_empty() && levels.is_empty() {
        ui.allocate_space(egui::vec2(ui.available_width(), height));
        ui.label("Choose a trace above; samples come from the polls.");
        return;
    }
    let each = ((height - lanes_height) / units.len().max(1) as f32).max(60.0);
    let link = ui.make_persistent_id("plots-time");
    let x_label = export::x_label(p.source);
    p.plot_rects.clear();
    let mut clicked_at = None;
    let mut user_moved = false;
    let mut new_span = None;
    // Each plot: its unit (empty: the lanes), its traces, its height.
    type Stacked<'t> = (String, Vec<&'t (usize, Trace)>, f32);
    let plots: Vec<Stacked<'_>> = units
        .iter()
        .map(|u| {
            let ts: Vec<&(usize, Trace)> = traces
                .iter()
                .filter(|(_, t)| !t.step && t.unit == *u)
                .collect();
            (u.to_string(), ts, each)
        })
        .chain((!levels.is_empty()).then(|| (String::new(), levels.clone(), lanes_height)))
        .collect();
    let last = plots.len().saturating_sub(1);
    for (k, (unit, ts, h)) in plots.into_iter().enumerate() {
        let lanes = unit.is_empty();
        let mut plot = Plot::new(("plot", k, lanes))
            .height(h)
            .link_axis(link, [true, false])
            .link_cursor(link, [true, false])
            .y_axis_min_width(56.0)
            .allow_double_click_reset(false)
            .show_x(true)
            .show_y(!lanes);
        plot = if lanes {
            plot.y_axis_label("levels")
                .show_axes([k == last, false])
                .allow_zoom([true, false])
                .allow_drag([true, false])
        } else {
            // The lanes name themselves; the curves have a legend.
            plot.y_axis_label(unit.clone())
                .show_axes([k == last, true])
                .legend(egui_plot::Legend::default().position(egui_plot::Corner::LeftTop))
        };
        if k == last {
            plot = plot.x_axis_label(x_label);
        }
        let cursors = p.cursors;
        let shown = p.shown;
        let response = plot.show(ui, |pui| {
            // The span is the pane's; the user's pan and zoom apply on top of it and
            // are read back below.
            pui.set_plot_bounds_x(shown.0..=shown.1);
            if lanes {
                pui.set_plot_bounds_y(-0.2..=ts.len() as f64 + 0.2);
            }
            for (lane, (i, t)) in ts.iter().enumerate() {
                let [r, g, b] = TRACE_COLOURS[*i % TRACE_COLOURS.len()];
                let colour = Color32::from_rgb(r, g, b);
                let points: Vec<[f64; 2]> = if lanes {
                    steps(t, lane)
                } else {
                    t.points.clone()
                };
                pui.line(
                    Line::new(t.label.clone(), PlotPoints::new(points))
                        .color(colour)
                        .allow_band(!lanes)
                        .id((k, *i, lane)),
                );
                if lanes {
                    pui.text(
                        Text::new(
                            format!("lane {lane}"),
                            egui_plot::PlotPoint::new(shown.0, lane as f64 + 0.9),
                            RichText::new(&t.label).size(11.0).color(colour),
                        )
                        .anchor(egui::Align2::LEFT_TOP),
                    );
                }
            }
            for (c, x) in cursors.iter().enumerate() {
                if let Some(x) = x {
                    let name = if c == 0 { "cursor A" } else { "cursor B" };
                    pui.vline(VLine::new(name, *x).color(Color32::WHITE).id(("cursor", c)));
                }
            }
        });
        let r = &response.response;
        p.plot_rects.push(r.rect);
        if r.clicked()
            && let Some(pos) = r.interact_pointer_pos()
        {
            clicked_at = Some(response.transform.value_from_position(pos).x);
        }
        let scrolled = r.hovered()
            && ui.input(|i| i.smooth_scroll_delta != egui::Vec2::ZERO || i.zoom_delta() != 1.0);
        if r.dragged() || scrolled {
            user_moved = true;
            let b: &PlotBounds = response.transform.bounds();
            new_span = Some((b.min()[0], b.max()[0]));
        }
    }
    if let Some(x) = clicked_at {
        p.place_cursor(x);
    }
    if user_moved && p.source == Source::Live && p.paused.is_none() {
        // Zooming or panning a scrolling plot stops it where it is.
        p.paused = Some(p.shown.1);
    }
    if let Some(span) = new_span.filter(|(a, b)| b > a) {
        p.shown = span;
    }
}

/// A level trace as steps on `lane`: each value held until the next.
fn steps(t: &Trace, lane: usize) -> Vec<[f64; 2]> {
    let mut out = Vec::with_capacity(t.points.len() * 2);
    for pair in t.points.windows(2) {
        let ([xa, va], [xb, _]) = (pair[0], pair[1]);
        out.push([xa, t.on_lane(lane, va)]);
        out.push([xb, t.on_lane(lane, va)]);
    }
    if let Some([x, v]) = t.points.last() {
        out.push([*x, t.on_lane(lane, *v)]);
    }
    out
}

/// Cursors A and B: their times, each trace's value there and the difference.
fn readout(p: &PlotsPanel, ui: &mut Ui, pendant: &Pendant, captures: &[&Capture]) {
    let [a, b] = p.cursors;
    if a.is_none() && b.is_none() {
        ui.label(
            RichText::new("Click the plot to place cursor A, again for B. Drag to pan, wheel to zoom (either stops a live plot).")
                .size(11.0)
                .color(crate::ui::widgets::GREY),
        );
        return;
    }
    let value = |choice: &TraceChoice, x: Option<f64>| -> Option<f64> {
        let x = x?;
        match p.source {
            Source::Live => live_value_at(&pendant.samples.store, choice, x),
            Source::Captures => captures
                .first()
                .and_then(|c| capture_value_at(c, &choice.channel, x)),
        }
    };
    let text = |v: Option<f64>| v.map_or("—".to_string(), |v| format!("{v:.4}"));
    egui::Grid::new("plot-readout")
        .num_columns(4)
        .spacing([16.0, 2.0])
        .show(ui, |ui| {
            for h in ["", "A", "B", "B − A"] {
                ui.label(RichText::new(h).strong());
            }
            ui.end_row();
            ui.label("time (s)");
            ui.label(text(a));
            ui.label(text(b));
            ui.label(text(a.zip(b).map(|(a, b)| b - a)));
            ui.end_row();
            for choice in p.chosen() {
                let (va, vb) = (value(&choice, a), value(&choice, b));
                ui.label(choice.label());
                ui.label(text(va));
                ui.label(text(vb));
                ui.label(text(va.zip(vb).map(|(a, b)| b - a)));
                ui.end_row();
            }
        });
}

impl Pane for PlotsPanel {
    fn ui(&mut self, ui: &mut Ui, cx: &mut PaneCx<'_>) {
        show(self, ui, cx.pendant, cx.intents, cx.folder, cx.now);
    }
}
