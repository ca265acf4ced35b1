//! What changed between two polls that an operator must hear of: E-stop, alarm, drive
//! source, mode, servo and homing. Each change becomes one line in Messages.

use crate::pendant::Level;
use crate::protocol::{AxisState, HomeState, PerAxis, SystemMode, SystemStatus};

/// The lines for a new 215H after `old` (none for the first one read).
pub fn system(old: Option<&SystemStatus>, new: &SystemStatus) -> Vec<(Level, String)> {
    let Some(old) = old else {
        return Vec::new();
    };
    let mut out = Vec::new();
    let estop = |s: &SystemStatus| s.status1.emergency_stop();
    match (estop(old), estop(new)) {
        (false, true) => out.push((Level::Error, "E-stop pressed: motion is held".into())),
        (true, false) => out.push((Level::Info, "E-stop released".into())),
        _ => {}
    }
    let cut = |s: &SystemStatus| s.status3.drive_cut_off();
    match (cut(old), cut(new)) {
        (false, true) => out.push((Level::Error, "drive source cut off".into())),
        (true, false) => out.push((Level::Info, "drive source restored".into())),
        _ => {}
    }
    if old.critical_error != new.critical_error {
        if new.critical_error.0 != 0 {
            out.push((
                Level::Error,
                format!(
                    "alarm {:03X}: {}",
                    new.critical_error.0,
                    new.critical_error.describe()
                ),
            ));
        } else {
            out.push((
                Level::Info,
                format!("alarm {:03X} reset", old.critical_error.0),
            ));
        }
    }
    if old.mode != new.mode {
        let name = |m: SystemMode| m.name().unwrap_or("unknown");
        out.push((
            Level::Warning,
            format!("mode {} -> {}", name(old.mode), name(new.mode)),
        ));
    }
    out
}

/// The lines for a new 2A1H's axis blocks after `old`: servo and homing.
pub fn axes(old: Option<&PerAxis<AxisState>>, new: &PerAxis<AxisState>) -> Vec<(Level, String)> {
    let Some(old) = old else {
        return Vec::new();
    };
    let all = |axes: &PerAxis<AxisState>, f: &dyn Fn(&AxisState) -> bool| {
        let mut any = false;
        let every = axes.iter().all(|(_, a)| {
            any = true;
            f(&a)
        });
        any && every
    };
    let mut out = Vec::new();
    let servo = |a: &AxisState| a.status.servo_on();
    let none_on = |axes: &PerAxis<AxisState>| !axes.iter().any(|(_, a)| servo(&a));
    match (all(old, &servo), all(new, &servo)) {
        (false, true) => out.push((Level::Info, "servo on".into())),
        (true, false) if none_on(new) => out.push((Level::Warning, "servo off".into())),
        (true, false) => out.push((Level::Warning, "servo off on some axes".into())),
        _ => {}
    }
    let homing = |a: &AxisState| a.status.home_state() == HomeState::Homing;
    let homed = |a: &AxisState| a.status.home_state() == HomeState::Done;
    let any_homing = |axes: &PerAxis<AxisState>| axes.iter().any(|(_, a)| homing(&a));
    match (any_homing(old), any_homing(new)) {
        (false, true) => out.push((Level::Info, "homing started".into())),
        (true, false) if all(new, &homed) => out.push((Level::Info, "homing done".into())),
        (true, false) => out.push((
            Level::Warning,
            "homing ended without homing every axis".into(),
        )),
        _ => {}
    }
    out
}
