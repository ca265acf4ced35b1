//! Two snapshots compared: first whether they look like the same controller, then every
//! difference, table by table and row by row.

use std::collections::{BTreeMap, BTreeSet};
use std::fmt::Debug;

use super::{AlarmEntry, Frame, Position, Snapshot};

/// One difference: the table, the row, what it was and what it is.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Difference {
    pub table: &'static str,
    pub row: String,
    pub old: String,
    pub new: String,
}

/// The result of a compare: a warning said first (different controllers), then the
/// differences.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Comparison {
    pub old_taken: String,
    pub new_taken: String,
    /// Said before the differences: the versions differ (two controllers, or a firmware
    /// update).
    pub warning: Option<String>,
    pub differences: Vec<Difference>,
}

impl Comparison {
    pub fn summary(&self) -> String {
        let mut s = match self.differences.len() {
            0 => format!("{} and {}: no difference", self.old_taken, self.new_taken),
            n => format!(
                "{} -> {}: {n} difference(s)",
                self.old_taken, self.new_taken
            ),
        };
        if let Some(w) = &self.warning {
            s = format!("{w}; {s}");
        }
        s
    }
}

/// What changed from `old` to `new`.
pub fn compare(old: &Snapshot, new: &Snapshot) -> Comparison {
    let mut d = Vec::new();
    let warning = (!old.versions.is_empty()
        && !new.versions.is_empty()
        && old.versions != new.versions)
        .then(|| {
            "the versions differ: these may be two controllers (or a firmware update)".to_owned()
        });
    rows(
        &mut d,
        "versions",
        keyed(&old.versions, |v| format!("unit {}", v.unit)),
        keyed(&new.versions, |v| format!("unit {}", v.unit)),
        |v| {
            format!(
                "model {:02X}, code {:02X}, version {:04X}, {}",
                v.model, v.unit_code, v.version, v.built
            )
        },
    );
    rows(
        &mut d,
        "positions",
        keyed(&old.positions, |p| format!("No. {:05}", p.number)),
        keyed(&new.positions, |p| format!("No. {:05}", p.number)),
        position_text,
    );
    for (table, o, n) in [
        ("work", &old.work, &new.work),
        ("tool", &old.tool, &new.tool),
    ] {
        rows(
            &mut d,
            table,
            keyed(o, |f| format!("No. {:02}", f.number)),
            keyed(n, |f| format!("No. {:02}", f.number)),
            frame_text,
        );
    }
    let on = |f: &[u16]| {
        f.iter()
            .map(|n| (format!("{n}"), true))
            .collect::<BTreeMap<_, _>>()
    };
    rows(
        &mut d,
        "global flags",
        on(&old.flags_on),
        on(&new.flags_on),
        |_| "on".into(),
    );
    let vars = |m: &BTreeMap<u16, i32>| m.iter().map(|(n, v)| (format!("{n}"), *v)).collect();
    rows(
        &mut d,
        "integer variables",
        vars(&old.integers),
        vars(&new.integers),
        |v| v.to_string(),
    );
    let reals =
        |m: &BTreeMap<u16, String>| m.iter().map(|(n, v)| (format!("{n}"), v.clone())).collect();
    rows(
        &mut d,
        "real variables",
        reals(&old.reals),
        reals(&new.reals),
        |v| v.clone(),
    );
    rows(
        &mut d,
        "zones",
        keyed(&old.zones, |z| format!("zone {}", z.number)),
        keyed(&new.zones, |z| format!("zone {}", z.number)),
        zone_text,
    );
    alarms(&mut d, &old.alarms, &new.alarms);
    for (which, s) in [("old", old), ("new", new)] {
        if !s.missing.is_empty() {
            d.push(Difference {
                table: "not read",
                row: which.to_owned(),
                old: String::new(),
                new: s.missing.join("; "),
            });
        }
    }
    Comparison {
        old_taken: old.taken.clone(),
        new_taken: new.taken.clone(),
        warning,
        differences: d,
    }
}

fn keyed<T: Clone>(items: &[T], key: impl Fn(&T) -> String) -> BTreeMap<String, T> {
    items.iter().map(|i| (key(i), i.clone())).collect()
}

/// Rows only in one, and rows in both that differ (a missing row or value reads "-").
fn rows<T: PartialEq + Debug>(
    out: &mut Vec<Difference>,
    table: &'static str,
    old: BTreeMap<String, T>,
    new: BTreeMap<String, T>,
    text: impl Fn(&T) -> String,
) {
    let keys: BTreeSet<&String> = old.keys().chain(new.keys()).collect();
    for k in keys {
        let (o, n) = (old.get(k), new.get(k));
        if o == n {
            continue;
        }
        let show = |v: Option<&T>| v.map_or("-".to_owned(), &text);
        out.push(Difference {
            table,
            row: k.clone(),
            old: show(o),
            new: show(n),
        });
    }
}

fn position_text(p: &Position) -> String {
    let mut s: Vec<String> = p.axes.iter().map(|(a, v)| format!("{a} {v:.3}")).collect();
    if p.speed != 0 || p.accel != 0 || p.decel != 0 {
        s.push(format!("speed {} acc {} dcl {}", p.speed, p.accel, p.decel));
    }
    if !p.arm.is_empty() {
        s.push(format!("{} arm", p.arm));
    }
    s.join(", ")
}

fn frame_text(f: &Frame) -> String {
    format!("X {:.3} Y {:.3} Z {:.3} R {:.3}", f.x, f.y, f.z, f.r)
}

/// The history is newest first: the records the newer snapshot has on top of the older
/// one's list are new alarms; a list that does not end with the older one is said so.
fn alarms(out: &mut Vec<Difference>, old: &[AlarmEntry], new: &[AlarmEntry]) {
    let same = |a: &AlarmEntry, b: &AlarmEntry| {
        (a.code, a.details, &a.message) == (b.code, b.details, &b.message)
    };
    let added = new.len().saturating_sub(old.len());
    let continues = new.len() >= old.len() && new[added..].iter().zip(old).all(|(a, b)| same(a, b));
    if continues {
        for a in &new[..added] {
            out.push(Difference {
                table: "alarm history",
                row: format!("record {}", a.record),
                old: "-".into(),
                new: format!("{:03X} {}", a.code, a.message),
            });
        }
    } else {
        out.push(Difference {
            table: "alarm history",
            row: "the list".into(),
            old: format!("{} record(s)", old.len()),
            new: format!(
                "{} record(s), not the older list with new ones on top",
                new.len()
            ),
        });
    }
}

/// A zone's corners (and its unread tail) in a row of the differences.
fn zone_text(z: &super::Zone) -> String {
    let corner = |c: &BTreeMap<String, f64>| {
        c.iter()
            .map(|(a, v)| format!("{a} {v:.3}"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let mut s = format!("{} to {}", corner(&z.corner1), corner(&z.corner2));
    if !z.tail.is_empty() {
        s.push_str(&format!(" (tail {})", z.tail));
    }
    s
}
