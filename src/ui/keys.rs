//! The keyboard map: arrows, PgUp/PgDn and , . jog by the physical direction (never with
//! Shift, Ctrl or Alt held); + and - walk the step ladder; Esc is STOP; F1 the help;
//! Ctrl+Q closes the window. The keys only report what is down: the pendant's
//! hold-to-run machine decides what a press does.

use std::time::{Duration, Instant};

use egui::{Context, Event, Key};

use crate::pendant::{Intent, JogInput, Pendant, PhysicalJog, Press, StopCause};

/// Every mapped jog key with the physical motion it asks for, and its name.
pub const MAP: [(Key, PhysicalJog, &str); 8] = [
    (Key::ArrowRight, PhysicalJog::XPlus, "Right"),
    (Key::ArrowLeft, PhysicalJog::XMinus, "Left"),
    (Key::ArrowUp, PhysicalJog::YPlus, "Up"),
    (Key::ArrowDown, PhysicalJog::YMinus, "Down"),
    (Key::PageUp, PhysicalJog::ZUp, "PgUp"),
    (Key::PageDown, PhysicalJog::ZDown, "PgDn"),
    (Key::Period, PhysicalJog::RCcw, "."),
    (Key::Comma, PhysicalJog::RCw, ","),
];

/// A key found down this soon after the window got its focus back is not a press: the
/// window cannot tell a key held through the focus change (whose auto-repeat arrives as
/// a first press) from a new one. [inferred] Auto-repeat delays are 200-600 ms.
const FOCUS_GRACE: Duration = Duration::from_millis(500);

/// What the keys remember between frames: which jog keys went down as a real press.
#[derive(Default)]
pub struct Keys {
    armed: [bool; MAP.len()],
    focus_gained: Option<Instant>,
}

/// What the keys asked for this frame beyond the pendant's intents.
#[derive(Default)]
pub struct KeyOutput {
    /// F1: show or hide the help overlay.
    pub toggle_help: bool,
    /// Ctrl+Q (Cmd+Q on a Mac): close the window (motion is stopped on the way out).
    pub quit: bool,
}

impl Keys {
    /// Reads this frame's keys: pushes a STOP for Esc, the step ladder for + and -, and
    /// every jog key's state.
    pub fn handle(
        &mut self,
        ctx: &Context,
        pendant: &Pendant,
        now: Instant,
        intents: &mut Vec<Intent>,
    ) -> KeyOutput {
        let mut out = KeyOutput::default();
        let typing = ctx.egui_wants_keyboard_input();
        let (events, down, modified): (Vec<Event>, Vec<bool>, bool) = ctx.input(|i| {
            (
                i.events.clone(),
                MAP.iter().map(|(k, ..)| i.key_down(*k)).collect(),
                jog_refused_with(i.modifiers),
            )
        });
        let mut jog = pendant.settings.jog.clone();
        for event in &events {
            match event {
                Event::WindowFocused(true) => self.focus_gained = Some(now),
                Event::Key {
                    key,
                    pressed: true,
                    repeat,
                    modifiers,
                    ..
                } => match key {
                    Key::Escape => intents.push(Intent::Stop(StopCause::Esc)),
                    Key::F1 => out.toggle_help = true,
                    Key::Q if modifiers.command => out.quit = true,
                    _ if typing || *repeat => {}
                    // Ctrl + and Ctrl - are the window's zoom (egui's), not the step.
                    Key::Plus | Key::Equals if !modifiers.command => jog.step_ladder(true),
                    Key::Minus if !modifiers.command => jog.step_ladder(false),
                    _ => {
                        let fresh = self
                            .focus_gained
                            .is_none_or(|at| now.saturating_duration_since(at) > FOCUS_GRACE);
                        if let Some(i) = MAP.iter().position(|(k, ..)| k == key) {
                            // Shift+PgDn, Ctrl+Left...: another command, never a jog.
                            self.armed[i] = fresh && !jog_refused_with(*modifiers);
                        }
                    }
                },
                _ => {}
            }
        }
        if jog != pendant.settings.jog {
            intents.push(Intent::JogSettings(jog));
        }
        for (i, ((_, physical, _), is_down)) in MAP.iter().zip(down).enumerate() {
            // A modifier pressed while a jog key is held ends that key's jog, and the key
            // jogs again only when pressed anew.
            if !is_down || modified {
                self.armed[i] = false;
            }
            let press = match (is_down, self.armed[i] && !typing) {
                (false, _) => Press::Up,
                (true, true) => Press::On(pendant.physical_jog(*physical)),
                (true, false) => Press::Aside,
            };
            // Up is reported every frame too: the pendant ignores an input it holds none of.
            intents.push(Intent::Jog(JogInput::Key(i as u8), press));
        }
        out
    }
}

/// Whether these modifiers make a jog key something else than a jog: Shift, Ctrl, Alt
/// (Option) or Cmd held.
fn jog_refused_with(m: egui::Modifiers) -> bool {
    m.shift || m.ctrl || m.alt || m.command || m.mac_cmd
}

/// The help overlay listing the map, at the bottom right (never over STOP).
pub fn help(ctx: &Context, pendant: &Pendant, open: &mut bool) {
    egui::Window::new("Keyboard")
        .open(open)
        .collapsible(false)
        .resizable(false)
        .anchor(egui::Align2::RIGHT_BOTTOM, [-12.0, -12.0])
        .show(ctx, |ui| {
            egui::Grid::new("key-map")
                .num_columns(2)
                .striped(true)
                .show(ui, |ui| {
                    ui.label("Esc");
                    ui.label("STOP (always)");
                    ui.end_row();
                    for (_, physical, name) in MAP {
                        ui.label(name);
                        let target = pendant.physical_jog(physical);
                        ui.label(format!("{} (sends {})", physical.name(), target.label()));
                        ui.end_row();
                    }
                    ui.label("+ / -");
                    ui.label("larger / smaller step");
                    ui.end_row();
                    ui.label("F1");
                    ui.label("this help");
                    ui.end_row();
                    ui.label("Ctrl + / Ctrl - / Ctrl 0");
                    ui.label("larger / smaller / normal size (kept)");
                    ui.end_row();
                    ui.label("Ctrl+Q");
                    ui.label("close the window (motion stops first)");
                    ui.end_row();
                });
            ui.label("Continuous mode: the jog runs while the key is held and stops on release.");
            ui.label("After STOP, release every jog key before the next jog.");
            ui.label("A jog key with Shift, Ctrl or Alt held does not jog.");
        });
}
