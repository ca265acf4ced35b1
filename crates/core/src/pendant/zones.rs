//! The controller's simple interference-check zones (2A2H, PROTOCOL.md 3.46), read on
//! connect and on demand: the records as they came and the boxes the move checks and
//! the arm view use; a refusal or a lost reply is named, never shown as empty zones.

use crate::link::LinkEvent;
use crate::pendant::Level;
use crate::protocol::{Command, Reply, ZONE_NUMBERS, ZoneQuery, ZoneRecord};
use crate::robot::ZoneBox;

/// What the pendant knows of a zone's action on the controller. `[inferred]` The record's
/// tail, believed to name an output or flag and an error type, was not readable
/// (PROTOCOL.md 3.46): the zone may only set an output, and is not known to stop the arm.
pub const ZONE_ACTION: &str =
    "the controller's zone may only set an output: it is not known to stop the arm";

/// One zone as read.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ReadZone {
    pub number: u8,
    pub record: ZoneRecord,
}

impl ReadZone {
    /// What it does, where known: the unread tail raw, or [`ZONE_ACTION`].
    pub fn action(&self) -> String {
        if self.record.surplus.is_empty() {
            ZONE_ACTION.to_owned()
        } else {
            format!(
                "{ZONE_ACTION} (the record's unread tail: {})",
                self.record.surplus_text()
            )
        }
    }
}

/// The zones as last read and the read going on.
#[derive(Debug, Default)]
pub struct Zones {
    /// Every record read, defined or not, by number.
    read: Vec<ReadZone>,
    /// The defined zones' boxes (checks and drawing).
    boxes: Vec<ZoneBox>,
    /// The next zone number asked for, while a read runs.
    reading: Option<u8>,
    /// How the last read ended, for the view and Messages; a failure names its cause.
    pub outcome: Option<(Level, String)>,
    /// Whether the last read failed (the zones are then not known).
    failed: bool,
    commands: Vec<Command>,
    revision: u64,
}

impl Zones {
    /// The defined zones' boxes, base frame.
    pub fn boxes(&self) -> &[ZoneBox] {
        &self.boxes
    }

    /// Every record read.
    pub fn read(&self) -> &[ReadZone] {
        &self.read
    }

    /// Zone `n` as read.
    pub fn zone(&self, n: u8) -> Option<&ReadZone> {
        self.read.iter().find(|z| z.number == n)
    }

    /// Whether a read runs.
    pub fn reading(&self) -> bool {
        self.reading.is_some()
    }

    /// The last read failed: no zone is known (the checks cannot see any).
    pub fn failed(&self) -> bool {
        self.failed
    }

    /// Changes whenever the zones change.
    pub fn revision(&self) -> u64 {
        self.revision
    }

    /// Queries for the link, each in the line time the polls leave.
    pub fn take_commands(&mut self) -> Vec<Command> {
        std::mem::take(&mut self.commands)
    }

    /// Whether this model sent `command`.
    pub fn owns(command: &Command) -> bool {
        matches!(command, Command::ZoneQuery(_))
    }

    /// The line came up, or the operator asked: the zones are read from zone 1.
    pub fn start(&mut self, line_up: bool) -> Option<(Level, String)> {
        if !line_up {
            let said = (
                Level::Warning,
                "zones not read: the line is down".to_owned(),
            );
            self.outcome = Some(said.clone());
            return Some(said);
        }
        self.read.clear();
        self.outcome = Some((Level::Info, "reading the zones (2A2H)...".to_owned()));
        self.ask(*ZONE_NUMBERS.start());
        None
    }

    fn ask(&mut self, first: u8) {
        self.reading = Some(first);
        let count = ZONE_NUMBERS.end() - first + 1;
        self.commands
            .push(Command::ZoneQuery(ZoneQuery { first, count }));
    }

    /// The line went down: a read in progress ends (the zones read stay: the cell has not
    /// changed).
    pub fn line_gone(&mut self) {
        if self.reading.take().is_some() {
            self.outcome = Some((
                Level::Warning,
                "zones not read: the line went down".to_owned(),
            ));
        }
    }

    /// Ends the read with nothing known and why.
    fn fail(&mut self, why: String) -> Option<(Level, String)> {
        self.reading = None;
        self.failed = true;
        self.read.clear();
        self.boxes.clear();
        self.revision += 1;
        let said = (Level::Warning, format!("zones not read: {why}"));
        self.outcome = Some(said.clone());
        Some(said)
    }

    /// Applies an event answering one of this model's queries.
    pub fn handle_event(&mut self, event: &LinkEvent) -> Option<(Level, String)> {
        let first = match event {
            LinkEvent::Reply { command, .. }
            | LinkEvent::ErrorReply { command, .. }
            | LinkEvent::Timeout { command, .. }
            | LinkEvent::Interrupted { command, .. }
            | LinkEvent::NotSent { command, .. } => match command {
                Command::ZoneQuery(q) => q.first,
                _ => return None,
            },
            _ => return None,
        };
        // An answer to a read begun again is not this read's.
        if self.reading != Some(first) {
            return None;
        }
        match event {
            LinkEvent::Reply {
                reply: Reply::ZoneTable(t),
                ..
            } if t.first == first && !t.records.is_empty() => {
                for (i, record) in t.records.iter().enumerate() {
                    let number = first.saturating_add(i as u8);
                    self.read.push(ReadZone {
                        number,
                        record: record.clone(),
                    });
                }
                let next = usize::from(first) + t.records.len();
                if next <= usize::from(*ZONE_NUMBERS.end()) {
                    // The reply was cut to the buffer: go on from the next number.
                    self.ask(next as u8);
                    return None;
                }
                self.finish()
            }
            // No record from this number on (a controller with fewer zones `[inferred]`):
            // what came so far is the whole list.
            LinkEvent::Reply {
                reply: Reply::ZoneTable(t),
                ..
            } if t.first == first => self.finish(),
            LinkEvent::Reply { .. } => self.fail(format!(
                "the 2A2H reply from zone {first} does not answer it (another zone number or message)"
            )),
            LinkEvent::ErrorReply { code, .. } => self.fail(format!(
                "the controller refused 2A2H from zone {first}: error {code}"
            )),
            LinkEvent::Timeout { retrying: true, .. } => None,
            LinkEvent::Timeout { .. } | LinkEvent::Interrupted { .. } => self.fail(format!(
                "no valid reply to 2A2H from zone {first} (the frame log shows what came)"
            )),
            LinkEvent::NotSent { reason, .. } => self.fail(format!("not sent: {reason}")),
            _ => None,
        }
    }

    /// The whole range is read: the defined zones become the boxes.
    fn finish(&mut self) -> Option<(Level, String)> {
        self.reading = None;
        self.failed = false;
        self.boxes = self
            .read
            .iter()
            .map(|z| crate::robot_wire::zone_box(z.number, &z.record))
            .filter(ZoneBox::is_defined)
            .collect();
        self.revision += 1;
        let numbers: Vec<String> = self.boxes.iter().map(|b| b.number.to_string()).collect();
        let text = match numbers.len() {
            0 => "zones: none defined".to_owned(),
            _ => format!("zones: {} defined ({})", numbers.len(), numbers.join(", ")),
        };
        self.outcome = Some((Level::Info, text.clone()));
        Some((Level::Info, text))
    }
}

#[cfg(test)]
mod tests {
    use std::time::{Duration, Instant};

    use super::*;
    use crate::link::{Origin, RequestId};
    use crate::protocol::{ErrorCode, Frame, ScMode, Station};
    use crate::sim::{Controller, SimSetup};

    /// Answers every query with the simulator, as the link would.
    fn run(z: &mut Zones, sim: &mut Controller) -> Vec<(Level, String)> {
        let mut said = Vec::new();
        while let Some(command) = z.take_commands().pop() {
            let bytes = command
                .to_bytes(Station::DEFAULT, ScMode::Computed)
                .unwrap();
            let out = sim.handle(&bytes, Duration::ZERO).unwrap();
            let reply = Reply::decode(&Frame::parse(&out).unwrap()).unwrap();
            let event = match reply {
                Reply::Error(code) => LinkEvent::ErrorReply {
                    id: RequestId(1),
                    origin: Origin::User,
                    command,
                    code,
                },
                reply => LinkEvent::Reply {
                    id: RequestId(1),
                    origin: Origin::User,
                    command,
                    reply,
                    round_trip: Duration::from_millis(2),
                },
            };
            said.extend(z.handle_event(&event));
        }
        said
    }

    #[test]
    fn the_built_in_zones_are_read_in_buffer_sized_pieces() {
        let mut setup = SimSetup::default();
        setup.config.reply_buffer = 200;
        let mut sim = Controller::new(setup);
        let mut z = Zones::default();
        assert_eq!(z.start(true), None);
        let said = run(&mut z, &mut sim);
        assert_eq!(z.read().len(), 10, "every number read, several queries");
        assert_eq!(
            z.boxes().iter().map(|b| b.number).collect::<Vec<_>>(),
            [1, 2]
        );
        assert_eq!(said, [(Level::Info, "zones: 2 defined (1, 2)".to_owned())]);
        assert!(!z.reading() && !z.failed());
        assert!(z.zone(1).unwrap().action().contains("only set an output"));
    }

    #[test]
    fn a_reply_with_no_record_ends_the_list_and_one_for_another_zone_is_named() {
        let table = |first, records| LinkEvent::Reply {
            id: RequestId(4),
            origin: Origin::User,
            command: Command::ZoneQuery(ZoneQuery {
                first: 1,
                count: 10,
            }),
            reply: Reply::ZoneTable(crate::protocol::ZoneTable { first, records }),
            round_trip: Duration::from_millis(2),
        };
        let mut z = Zones::default();
        z.start(true);
        z.take_commands();
        let said = z.handle_event(&table(1, Vec::new()));
        assert_eq!(said.unwrap().1, "zones: none defined");
        assert!(!z.failed() && z.boxes().is_empty());
        z.start(true);
        let said = z.handle_event(&table(3, Vec::new())).unwrap().1;
        assert!(said.contains("does not answer it"), "{said}");
        assert!(z.failed());
    }

    #[test]
    fn a_refusal_or_a_lost_reply_is_named_and_no_zone_is_kept() {
        let mut sim = Controller::new(SimSetup::default());
        let mut z = Zones::default();
        z.start(true);
        run(&mut z, &mut sim);
        assert_eq!(z.boxes().len(), 2);
        z.start(true);
        let command = z.take_commands().pop().unwrap();
        let said = z.handle_event(&LinkEvent::ErrorReply {
            id: RequestId(2),
            origin: Origin::User,
            command,
            code: ErrorCode(0xA01),
        });
        let (level, text) = said.unwrap();
        assert_eq!(level, Level::Warning);
        assert!(
            text.contains("refused 2A2H") && text.contains("A01"),
            "{text}"
        );
        assert!(z.boxes().is_empty() && z.failed());

        z.start(true);
        let command = z.take_commands().pop().unwrap();
        let timeout = |retrying| LinkEvent::Timeout {
            id: RequestId(3),
            origin: Origin::User,
            command: command.clone(),
            retrying,
            recheck: None,
            at: Instant::now(),
        };
        let retry = timeout(true);
        assert_eq!(z.handle_event(&retry), None, "the link tries again first");
        let said = z.handle_event(&timeout(false));
        assert!(said.unwrap().1.contains("no valid reply"));
        assert_eq!(
            z.start(false).unwrap().1,
            "zones not read: the line is down"
        );
    }

    /// A ready pendant at `joints` that has read the built-in simulator's zones.
    fn ready_with_zones(joints: crate::robot::Joints, now: Instant) -> crate::pendant::Pendant {
        use crate::pendant::{Pendant, Settings};
        let mut p = Pendant::new(
            Settings::default(),
            crate::robot::RobotModel::default_model(),
        );
        let kin = crate::robot::Scara::new(&p.model);
        for event in crate::pendant::script::ready_controller(&kin, joints) {
            p.handle_event(now, event);
        }
        p.take_requests();
        let mut sim = Controller::new(SimSetup::default());
        p.zones.start(true);
        run(&mut p.zones, &mut sim);
        assert_eq!(p.zones.boxes().len(), 2);
        p
    }

    #[test]
    fn a_step_into_a_zone_is_shown_with_its_number_and_goes_only_on_the_second_press() {
        use crate::pendant::jog::JogAxis;
        use crate::pendant::tests::submitted;
        use crate::protocol::Direction::Positive;
        let now = Instant::now();
        // Tip at X 250, Y 250; zone 1 spans X 330-420, Y 180-320.
        let mut p = ready_with_zones(crate::robot::Joints::new(0.0, 90.0, 0.0, 0.0), now);
        p.settings.jog.step = 50.0;
        let preview = p.preview_jog(JogAxis::X, Positive, now).unwrap();
        assert!(
            preview.plan.unwrap().path.zones.is_empty(),
            "X+ 50 stays out"
        );
        p.settings.jog.step = 100.0;
        let plan = p
            .preview_jog(JogAxis::X, Positive, now)
            .unwrap()
            .plan
            .unwrap();
        assert_eq!(plan.path.zones, [1]);
        assert_eq!(plan.second_press().as_deref(), Some("enters zone 1"));
        let mark = plan.path.first.clone().unwrap();
        assert!(mark.tip.x >= 330.0 && mark.tip.x < 332.0, "{mark:?}");

        p.jog_step(JogAxis::X, Positive, now);
        assert!(
            submitted(&mut p).is_empty(),
            "nothing moves on the first press"
        );
        let said = p.jog.feedback.as_ref().map(|m| m.text.clone()).unwrap();
        assert!(
            said.starts_with("X+ enters zone 1 (the controller's zone may only set an output")
                && said.ends_with("press again within 5 s to confirm"),
            "{said}"
        );
        // STOP takes the armed press back.
        p.stop(now);
        p.take_requests();
        p.jog_step(JogAxis::X, Positive, now + Duration::from_millis(100));
        assert!(submitted(&mut p).is_empty(), "asked again after STOP");
        p.jog_step(JogAxis::X, Positive, now + Duration::from_millis(600));
        let sent = submitted(&mut p);
        assert!(
            matches!(sent.as_slice(), [Command::ScaraMoveRelative(_)]),
            "{sent:?}"
        );
    }

    #[test]
    fn go_to_a_target_or_a_taught_point_in_a_zone_asks_twice_too() {
        use crate::pendant::tests::submitted;
        use crate::robot::Pose;
        let now = Instant::now();
        let mut p = ready_with_zones(crate::robot::Joints::new(0.0, 90.0, 0.0, 0.0), now);
        p.set_step_target(Pose::new(370.0, 250.0, 0.0, 90.0), now);
        p.take_requests();
        p.go_to_target(now);
        assert!(submitted(&mut p).is_empty());
        let said = p.jog.feedback.as_ref().map(|m| m.text.clone()).unwrap();
        assert!(said.starts_with("the target enters zone 1"), "{said}");
        p.go_to_target(now + Duration::from_secs(1));
        assert!(matches!(
            submitted(&mut p).as_slice(),
            [Command::ScaraMoveAbsolute(_)]
        ));

        // A taught point inside zone 1 (work 0, right arm): Go asks, Go again sends.
        let mut p = ready_with_zones(crate::robot::Joints::new(0.0, 90.0, 0.0, 0.0), now);
        let at = crate::pendant::teach::TaughtPose {
            pose: [370_000, 250_000, 0, 90_000],
            arm: crate::protocol::ArmSystem::Right,
            work: 0,
            tool: 0,
        };
        p.teach.edit(|l| l.record("feeder", at)).unwrap();
        p.teach_go(0, now);
        assert!(submitted(&mut p).is_empty());
        let said = p.jog.feedback.as_ref().map(|m| m.text.clone()).unwrap();
        assert!(said.starts_with("Go to \"feeder\" enters zone 1"), "{said}");
        assert!(said.contains("press Go again"), "{said}");
        p.teach_go(0, now + Duration::from_secs(1));
        assert!(matches!(
            submitted(&mut p).as_slice(),
            [Command::ScaraMoveAbsolute(_)]
        ));
    }

    #[test]
    fn zones_read_again_take_an_armed_second_press_back() {
        use crate::pendant::Request;
        use crate::pendant::jog::JogAxis;
        use crate::pendant::tests::submitted;
        use crate::protocol::Direction::Positive;
        let now = Instant::now();
        let mut p = ready_with_zones(crate::robot::Joints::new(0.0, 90.0, 0.0, 0.0), now);
        p.settings.jog.step = 100.0;
        p.jog_step(JogAxis::X, Positive, now);
        assert!(submitted(&mut p).is_empty());
        // Read again through the pendant, answered by the simulator.
        let mut sim = Controller::new(SimSetup::default());
        p.read_zones(now);
        for r in p.take_requests() {
            let Request::Spare(command @ Command::ZoneQuery(_)) = r else {
                continue;
            };
            let bytes = command
                .to_bytes(Station::DEFAULT, ScMode::Computed)
                .unwrap();
            let out = sim.handle(&bytes, Duration::ZERO).unwrap();
            let reply = Reply::decode(&Frame::parse(&out).unwrap()).unwrap();
            let event = LinkEvent::Reply {
                id: RequestId(9),
                origin: Origin::User,
                command,
                reply,
                round_trip: Duration::from_millis(2),
            };
            p.handle_event(now, event);
        }
        assert_eq!(p.zones.boxes().len(), 2);
        p.jog_step(JogAxis::X, Positive, now + Duration::from_millis(300));
        assert!(
            submitted(&mut p).is_empty(),
            "the press armed before the new read is asked again"
        );
        p.jog_step(JogAxis::X, Positive, now + Duration::from_millis(600));
        assert_eq!(submitted(&mut p).len(), 1);
    }
}
