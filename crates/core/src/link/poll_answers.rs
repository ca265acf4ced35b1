//! What each polled command answered last, to tell a change from a repeat.

use crate::protocol::{Command, Reply};

/// The latest answer to each polled command (a cycle holds a handful).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PollAnswers {
    last: Vec<(Command, Reply)>,
}

impl PollAnswers {
    /// Keeps `reply` as `command`'s latest answer: true when it differs from the one
    /// before (or is the first).
    pub fn changed(&mut self, command: &Command, reply: &Reply) -> bool {
        match self.last.iter_mut().find(|(c, _)| c == command) {
            Some((_, last)) if last == reply => false,
            Some((_, last)) => {
                *last = reply.clone();
                true
            }
            None => {
                self.last.push((command.clone(), reply.clone()));
                true
            }
        }
    }

    /// Forgets every answer (a new line: the first answers are news again).
    pub fn clear(&mut self) {
        self.last.clear();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::protocol::AxisPattern;

    #[test]
    fn the_first_answer_and_every_different_one_are_changes_and_repeats_are_not() {
        let mut answers = PollAnswers::default();
        let status = Command::SystemStatus;
        let axes = Command::AxisStatus {
            axes: AxisPattern::SCARA_1,
        };
        let a = Reply::Ack(status.id());
        let b = Reply::Ack(axes.id());
        assert!(answers.changed(&status, &a));
        assert!(answers.changed(&axes, &a), "each command has its own");
        assert!(!answers.changed(&status, &a));
        assert!(!answers.changed(&axes, &a));
        assert!(answers.changed(&status, &b));
        assert!(!answers.changed(&status, &b));
        answers.clear();
        assert!(answers.changed(&status, &b), "news again after a clear");
    }
}
