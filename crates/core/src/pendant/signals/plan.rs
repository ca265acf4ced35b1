//! A round of reads planned from the watch list: ports and flags by groups of 8 on their
//! category's grid, variables by runs, neighbours merged, each read within the reply
//! buffer, so a round takes as few requests as the buffer allows.

use std::collections::BTreeMap;

use super::WatchRow;
use crate::protocol::{BitQuery, BitSpace, Command, REPLY_BUFFER, VarKind, VarQuery};

/// Merge two runs when the characters between them cost less than a request of its own
/// (a request's frames and gap are some 40 characters and a reply delay).
const MERGE_GAP_CHARS: usize = 32;

/// One read of a round.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ReadPlan {
    pub command: Command,
}

/// The reads that cover every row, in the list's kinds' order.
pub fn plan_reads(rows: &[WatchRow]) -> Vec<ReadPlan> {
    let mut bits: BTreeMap<(u8, u8, u16), Vec<u16>> = BTreeMap::new();
    let mut vars: BTreeMap<(u8, u8), Vec<(u16, u16)>> = BTreeMap::new();
    for r in rows {
        let s = r.signal;
        if let Some(space) = s.kind.space() {
            let Some(cat) = space.category(s.number) else {
                continue;
            };
            let program = if space == BitSpace::Flag {
                s.program
            } else {
                0
            };
            bits.entry((space_order(space), program, cat.head()))
                .or_default()
                .push(cat.group_start(s.number));
        } else if let Some(kind) = s.kind.var() {
            let n = r.numbers();
            vars.entry((var_order(kind), s.program))
                .or_default()
                .push((n.start, n.end));
        }
    }
    let mut out = Vec::new();
    for ((space, program, head), mut starts) in bits {
        let space = SPACES[usize::from(space)];
        let Some(cat) = space.category(head) else {
            continue;
        };
        starts.sort_unstable();
        starts.dedup();
        let max = space.max_count(REPLY_BUFFER);
        let gap = (MERGE_GAP_CHARS / 2) as u16 * crate::protocol::messages::signals::GROUP;
        let runs = runs(
            starts
                .iter()
                .map(|&g| (g, g.saturating_add(8).min(cat.numbers.end))),
            gap,
            max,
        );
        out.extend(runs.into_iter().map(|(start, end)| ReadPlan {
            command: Command::BitQuery(BitQuery {
                space,
                program,
                start,
                count: end - start,
            }),
        }));
    }
    for ((kind, program), mut spans) in vars {
        let kind = KINDS[usize::from(kind)];
        spans.sort_unstable();
        let max = u16::from(kind.max_count(REPLY_BUFFER));
        let gap = (MERGE_GAP_CHARS / kind.width()) as u16;
        for (start, end) in runs(spans.into_iter(), gap, max) {
            out.push(ReadPlan {
                command: Command::VarQuery(VarQuery {
                    kind,
                    program,
                    start,
                    count: (end - start) as u8,
                }),
            });
        }
    }
    out
}

const SPACES: [BitSpace; 3] = [BitSpace::Input, BitSpace::Output, BitSpace::Flag];
const KINDS: [VarKind; 3] = [VarKind::Integer, VarKind::Real, VarKind::Text];

fn space_order(s: BitSpace) -> u8 {
    SPACES.iter().position(|&x| x == s).unwrap_or(0) as u8
}

fn var_order(k: VarKind) -> u8 {
    KINDS.iter().position(|&x| x == k).unwrap_or(0) as u8
}

/// Sorted spans merged when at most `gap` apart, each run at most `max` long (a span
/// longer than `max` is split).
fn runs(spans: impl Iterator<Item = (u16, u16)>, gap: u16, max: u16) -> Vec<(u16, u16)> {
    let max = max.max(1);
    let mut out: Vec<(u16, u16)> = Vec::new();
    for (start, end) in spans {
        match out.last_mut() {
            Some((s, e)) if start <= e.saturating_add(gap) && end.max(*e) - *s <= max => {
                *e = end.max(*e);
            }
            _ => {
                let mut s = start;
                while end - s > max {
                    out.push((s, s + max));
                    s += max;
                }
                out.push((s, end));
            }
        }
    }
    out
}

/// Whether `command` (a round's read) carries `row`'s value.
pub(super) fn covers(command: &Command, row: &WatchRow) -> bool {
    let s = row.signal;
    match command {
        Command::BitQuery(q) => {
            s.kind.space() == Some(q.space)
                && (q.space != BitSpace::Flag || q.program == s.program)
                && (q.start..q.start.saturating_add(q.count)).contains(&s.number)
        }
        Command::VarQuery(q) => {
            let n = row.numbers();
            s.kind.var() == Some(q.kind)
                && q.program == s.program
                && n.start >= q.start
                && n.end <= q.start + u16::from(q.count)
        }
        _ => false,
    }
}
