//! Whether a late reply may still be on its way, and the query that proves it is not.
//!
//! After a time-out the controller may still answer: its late reply (or `&` error, which
//! carries no message ID) would be taken for the answer to the next command. The
//! controller answers one command at a time, in order, so once a `#` reply arrives whose
//! ID no possibly-late command had, every late reply is behind us. Motion is sent only on
//! a line known to be in step; before it, the link sends such a proving query.
//!
//! A reply that has not come within the late-reply window is taken as never coming
//! ([inferred]: PROTOCOL.md 1.5 has the controller answer within its response delay or
//! not at all; the spec's time-out chapter was not retrievable).

use std::time::Instant;

use crate::protocol::{Axis, AxisPattern, Command, CoordKind, CoordQuery, MessageId, VersionQuery};

/// The message IDs whose late replies may still arrive, each until when.
#[derive(Debug, Default, Clone, PartialEq, Eq)]
pub struct LineSync {
    late: Vec<(MessageId, Instant)>,
}

impl LineSync {
    fn expire(&mut self, now: Instant) {
        self.late.retain(|&(_, until)| until > now);
    }

    fn may_be_late(&self, id: MessageId) -> bool {
        self.late.iter().any(|&(late, _)| late == id)
    }

    /// True when no late reply can be mistaken for the next answer.
    pub fn in_step(&mut self, now: Instant) -> bool {
        self.expire(now);
        self.late.is_empty()
    }

    /// A command's own reply may still come, until `until`: it timed out, or, on a line
    /// out of step, an `&` came that may have been another command's late error.
    pub fn may_answer_late(&mut self, id: MessageId, until: Instant) {
        match self.late.iter_mut().find(|(late, _)| *late == id) {
            Some(entry) => entry.1 = entry.1.max(until),
            None => self.late.push((id, until)),
        }
    }

    /// A reply with `id` arrived that answered nothing outstanding (late, unexpected or
    /// damaged): it is no longer on its way.
    pub fn late_reply_arrived(&mut self, id: MessageId) {
        if let Some(i) = self.late.iter().position(|&(late, _)| late == id) {
            self.late.swap_remove(i);
        }
    }

    /// A `#` reply with `id` arrived as an answer. If no possibly-late command had that
    /// ID, the controller has caught up and the line is in step again. An `&` proves
    /// nothing (it carries no ID) and is not reported here.
    pub fn reply_seen(&mut self, id: MessageId, now: Instant) {
        self.expire(now);
        if !self.may_be_late(id) {
            self.late.clear();
        }
    }

    /// A query that changes nothing and whose reply cannot be confused with a late one.
    pub fn proving_query(&mut self, now: Instant) -> Command {
        self.expire(now);
        let candidates = [
            Command::SystemStatus,
            Command::AxisStatus {
                axes: AxisPattern::single(Axis::A1),
            },
            Command::Version(VersionQuery::default()),
            Command::CoordQuery(CoordQuery {
                kind: CoordKind::Work,
                first: 0,
                count: 1,
            }),
        ];
        candidates
            .into_iter()
            .find(|c| !self.may_be_late(c.id()))
            .unwrap_or(Command::SystemStatus)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Duration;

    #[test]
    fn a_reply_of_another_id_puts_the_line_back_in_step() {
        let now = Instant::now();
        let until = now + Duration::from_secs(1);
        let mut sync = LineSync::default();
        assert!(sync.in_step(now));
        sync.may_answer_late(MessageId::SCARA_STATUS, until);
        assert!(!sync.in_step(now));
        // The same ID again may be the late reply itself: still unsure.
        sync.reply_seen(MessageId::SCARA_STATUS, now);
        assert!(!sync.in_step(now));
        sync.reply_seen(MessageId::SYSTEM_STATUS, now);
        assert!(sync.in_step(now));
    }

    #[test]
    fn a_late_reply_that_arrives_is_crossed_off() {
        let now = Instant::now();
        let mut sync = LineSync::default();
        sync.may_answer_late(MessageId::SYSTEM_STATUS, now + Duration::from_secs(1));
        sync.late_reply_arrived(MessageId::SYSTEM_STATUS);
        assert!(sync.in_step(now));
    }

    #[test]
    fn a_reply_that_never_came_stops_counting_after_its_window() {
        let now = Instant::now();
        let mut sync = LineSync::default();
        sync.may_answer_late(MessageId::SCARA_STATUS, now + Duration::from_millis(500));
        assert!(!sync.in_step(now + Duration::from_millis(499)));
        assert!(sync.in_step(now + Duration::from_millis(501)));
    }

    #[test]
    fn the_proving_query_avoids_the_ids_that_may_answer_late() {
        let now = Instant::now();
        let until = now + Duration::from_secs(1);
        let mut sync = LineSync::default();
        assert_eq!(sync.proving_query(now), Command::SystemStatus);
        sync.may_answer_late(MessageId::SYSTEM_STATUS, until);
        assert_eq!(sync.proving_query(now).id(), MessageId::AXIS_STATUS);
        sync.may_answer_late(MessageId::AXIS_STATUS, until);
        assert_eq!(sync.proving_query(now).id(), MessageId::VERSION);
        sync.may_answer_late(MessageId::VERSION, until);
        assert_eq!(sync.proving_query(now).id(), MessageId::COORD_QUERY);
        assert!(!sync.proving_query(now).is_motion());
    }
}
