//! The keyboard map: arrows, PgUp/PgDn and , . jog; + and - walk the step ladder; Esc is
//! STOP. Jog keys act only when no text field has the keyboard.

use std::time::Instant;

use egui::{Context, Event, Key};

use crate::pendant::{HoldSource, JogAxis, JogMode, Pendant};
use crate::protocol::Direction;

/// Every mapped key with what it does, for the help overlay.
pub const MAP: [(Key, JogAxis, Direction, &str); 8] = [
    (Key::ArrowRight, JogAxis::X, Direction::Positive, "Right"),
    (Key::ArrowLeft, JogAxis::X, Direction::Negative, "Left"),
    (Key::ArrowUp, JogAxis::Y, Direction::Positive, "Up"),
    (Key::ArrowDown, JogAxis::Y, Direction::Negative, "Down"),
    (Key::PageUp, JogAxis::Z, Direction::Positive, "PgUp"),
    (Key::PageDown, JogAxis::Z, Direction::Negative, "PgDn"),
    (Key::Period, JogAxis::R, Direction::Positive, "."),
    (Key::Comma, JogAxis::R, Direction::Negative, ","),
];

/// What the keys asked for this frame.
#[derive(Default)]
pub struct KeyOutput {
    /// Esc: STOP, run at once.
    pub stop: bool,
    /// F1: show or hide the help overlay.
    pub toggle_help: bool,
}

/// Reads this frame's keys and turns them into pendant calls.
pub fn handle(ctx: &Context, pendant: &mut Pendant, now: Instant) -> KeyOutput {
    let mut out = KeyOutput::default();
    let typing = ctx.egui_wants_keyboard_input();
    let (events, down): (Vec<Event>, Vec<bool>) = ctx.input(|i| {
        (
            i.events.clone(),
            MAP.iter().map(|(k, ..)| i.key_down(*k)).collect(),
        )
    });
    for event in &events {
        let Event::Key {
            key,
            pressed: true,
            repeat,
            ..
        } = event
        else {
            continue;
        };
        match key {
            Key::Escape => out.stop = true,
            Key::F1 => out.toggle_help = true,
            _ if typing => {}
            Key::Plus | Key::Equals if !repeat => pendant.settings.jog.step_ladder(true),
            Key::Minus if !repeat => pendant.settings.jog.step_ladder(false),
            _ if *repeat || pendant.settings.jog.mode != JogMode::Step => {}
            _ => {
                if let Some((_, axis, dir, _)) = MAP.iter().find(|(k, ..)| k == key) {
                    pendant.jog_step(*axis, *dir, now);
                }
            }
        }
    }
    if pendant.settings.jog.mode == JogMode::Continuous {
        continuous(pendant, &down, typing, now);
    }
    out
}

/// Holds a continuous jog while its key is down; releases it when the key comes up.
fn continuous(pendant: &mut Pendant, down: &[bool], typing: bool, now: Instant) {
    let held = pendant.held_jog().filter(|h| h.source == HoldSource::Key);
    if let Some(h) = held {
        let still = MAP
            .iter()
            .zip(down)
            .any(|((_, a, d, _), &is_down)| is_down && *a == h.axis && *d == h.direction);
        if still && !typing {
            pendant.jog_held();
        } else {
            pendant.jog_release(now);
        }
        return;
    }
    if typing || pendant.held_jog().is_some() {
        return;
    }
    if let Some(((_, axis, dir, _), _)) = MAP.iter().zip(down).find(|(_, d)| **d) {
        pendant.jog_press(*axis, *dir, HoldSource::Key, now);
    }
}

/// The help overlay listing the map.
pub fn help(ctx: &Context, open: &mut bool) {
    egui::Window::new("Keyboard")
        .open(open)
        .collapsible(false)
        .resizable(false)
        .show(ctx, |ui| {
            egui::Grid::new("key-map")
                .num_columns(2)
                .striped(true)
                .show(ui, |ui| {
                    ui.label("Esc");
                    ui.label("STOP (always)");
                    ui.end_row();
                    for (_, axis, dir, name) in MAP {
                        ui.label(name);
                        let sign = if dir == Direction::Positive { "+" } else { "-" };
                        ui.label(format!("jog {}{sign}", axis.name()));
                        ui.end_row();
                    }
                    ui.label("+ / -");
                    ui.label("larger / smaller step");
                    ui.end_row();
                    ui.label("F1");
                    ui.label("this help");
                    ui.end_row();
                });
            ui.label("Continuous mode: the jog runs while the key is held and stops on release.");
        });
}
