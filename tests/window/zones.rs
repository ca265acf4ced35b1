//! Zones on the built-in simulator: read on connect, drawn over the arm, and a step into
//! one shown red with its number before anything moves, sent only on a second press.

use std::time::Instant;

use egui_kittest::kittest::Queryable;
use xsel_pendant::pendant::MotionPhase;
use xsel_pendant::render::{Role, Shape};
use xsel_pendant::ui::PendantApp;

use crate::kittest_common::{click, step_until};
use crate::main_window::{app, ready, sim_busy, sim_in_frames};

/// The texts of `role` in the scene the arm view painted last.
fn texts(app: &PendantApp, role: Role) -> Vec<String> {
    app.arm_view()
        .scene()
        .map(|s| {
            s.with_role(role)
                .filter_map(|s| match s {
                    Shape::Text { text, .. } => Some(text.clone()),
                    _ => None,
                })
                .collect()
        })
        .unwrap_or_default()
}

fn steps_sent(app: &PendantApp) -> usize {
    sim_in_frames(app, "2D5").len()
}

fn step_done(n: usize) -> impl Fn(&PendantApp) -> bool {
    move |a| {
        steps_sent(a) == n
            && !sim_busy(a)
            && a.pendant().motion_phase(Instant::now()) == MotionPhase::Done
            && a.pendant().motion_ready(Instant::now()).is_ok()
    }
}

#[test]
fn a_step_toward_a_zone_is_red_with_its_number_before_anything_moves() {
    let mut h = app();
    ready(&mut h);
    step_until(&mut h, "the built-in zones to be read and drawn", |a| {
        a.pendant().zones.boxes().len() == 2 && texts(a, Role::Zone).len() == 2
    });
    let mut drawn = texts(h.state(), Role::Zone);
    drawn.sort();
    assert_eq!(drawn, ["zone 1 Z 0..150", "zone 2 Z 0..200"]);
    assert_eq!(
        sim_in_frames(h.state(), "2A2").len(),
        1,
        "one query for all"
    );

    // From the home pose (tip X 250, Y 250) one 50 mm X+ step is clear of zone 1
    // (X 330-420, Y 180-320); the next would end in it.
    click(&mut h, "50");
    click(&mut h, "X+");
    step_until(&mut h, "the first step to end", step_done(1));
    h.get_by_role_and_label(egui::accesskit::Role::Button, "X+")
        .hover();
    step_until(&mut h, "the ghost of the next step to show the zone", |a| {
        texts(a, Role::ZoneEntered) == ["zone 1 Z 0..150"]
            && texts(a, Role::GhostRefused).contains(&"enters zone 1: press twice".to_owned())
            && texts(a, Role::GhostRefused).contains(&"enters zone 1 here".to_owned())
    });
    click(&mut h, "X+");
    let said = h
        .state()
        .pendant()
        .jog
        .feedback
        .as_ref()
        .map(|m| m.text.clone())
        .unwrap_or_default();
    assert!(
        said.starts_with("X+ enters zone 1") && said.contains("press again"),
        "{said}"
    );
    assert_eq!(steps_sent(h.state()), 1, "nothing left for the line");
    // The second press sends it: exactly one more 2D5H reaches the simulator.
    click(&mut h, "X+");
    step_until(&mut h, "the confirmed step to end", step_done(2));
}
