//! The interpreter on a virtual clock, driven by Format B frames as a host sends them:
//! the demo, every command, pause and one step as 213H reports them, and the bad inputs.

use std::time::Duration;

use crate::protocol::{
    BitSpace, Command, ErrorDetailQuery, Frame, ProgramAction, ProgramCall, ProgramStatus,
    ProgramStatusQuery, Reply, ScMode, Station,
};
use crate::sim::{Controller, SimSetup};

const TICK: Duration = Duration::from_millis(10);

/// A ready controller (servos on, homed) with the programs of `text` (or the demo).
fn sim(text: Option<&str>) -> Controller {
    let mut s = SimSetup::default();
    s.config.start_ready = true;
    if let Some(text) = text {
        let parsed = crate::sel::parse(text);
        assert!(parsed.errors.is_empty(), "{:?}", parsed.errors);
        s.programs = parsed.programs;
    }
    Controller::new(s)
}

/// A test's controller and its virtual clock.
struct Bench {
    c: Controller,
    t: Duration,
}

impl Bench {
    fn new(text: Option<&str>) -> Self {
        Bench {
            c: sim(text),
            t: Duration::ZERO,
        }
    }

    /// A frame body sent (SC computed); the reply without CR LF.
    fn raw(&mut self, body: &str) -> String {
        let sc = crate::protocol::checksum(body.as_bytes());
        let out = self
            .c
            .handle(format!("{body}{sc:02X}\r\n").as_bytes(), self.t)
            .expect("a reply");
        String::from_utf8(out).unwrap().trim_end().to_owned()
    }

    fn ask(&mut self, cmd: Command) -> Reply {
        let bytes = cmd.to_bytes(Station::DEFAULT, ScMode::Computed).unwrap();
        let out = self.c.handle(&bytes, self.t).expect("a reply");
        Reply::decode(&Frame::parse(&out).unwrap()).unwrap()
    }

    fn call(&mut self, action: ProgramAction, program: u8) -> Reply {
        self.ask(Command::Program(ProgramCall { action, program }))
    }

    /// The error code of a refusal, 0 for an acknowledge.
    fn refused(&mut self, action: ProgramAction, program: u8) -> u16 {
        match self.call(action, program) {
            Reply::Error(e) => e.0,
            Reply::Ack(_) => 0,
            r => panic!("{r:?}"),
        }
    }

    fn status(&mut self, program: u8) -> ProgramStatus {
        match self.ask(Command::ProgramStatus(ProgramStatusQuery { program })) {
            Reply::ProgramStatus(s) => s,
            r => panic!("{r:?}"),
        }
    }

    /// Advances the clock in ticks until `done` holds; panics past `limit` of simulated
    /// time.
    fn until(&mut self, limit: Duration, mut done: impl FnMut(&mut Controller) -> bool) {
        let end = self.t + limit;
        while !done(&mut self.c) {
            assert!(self.t < end, "not reached within {limit:?}");
            self.t += TICK;
            self.c.advance(self.t);
        }
    }

    fn wait(&mut self, d: Duration) {
        let end = self.t + d;
        while self.t < end {
            self.t += TICK;
            self.c.advance(self.t);
        }
    }

    fn int(&self, n: u16, program: u8) -> i32 {
        self.c.signals().int(n, program).unwrap()
    }

    fn bit(&self, space: BitSpace, program: u8, n: u16) -> bool {
        self.c.signals().bit(space, program, n).unwrap()
    }
}

fn started(c: &Controller, n: u8) -> bool {
    c.programs()
        .state(n)
        .is_some_and(|(s, ..)| s != super::TaskState::NotStarted)
}

#[test]
fn the_demo_picks_and_places_five_times_and_215h_says_a_program_runs() {
    let mut b = Bench::new(None);
    // PROTOCOL.md 3.45's example: run 1.
    assert_eq!(b.raw("!9925301"), "#992532F");
    let status = b.ask(Command::SystemStatus);
    let Reply::SystemStatus(s) = status else {
        panic!()
    };
    assert!(s.status2.program_running());
    let (p1, p2) = (b.c.positions()[&1].coords, b.c.positions()[&2].coords);
    let near = |c: &Controller, p: &crate::protocol::PerAxis<crate::protocol::Milli>| {
        let tip = c.tip_work();
        let [x, y] = [p.iter().next().unwrap().1.0, p.iter().nth(1).unwrap().1.0];
        (tip.x - f64::from(x) / 1000.0).abs() < 0.01 && (tip.y - f64::from(y) / 1000.0).abs() < 0.01
    };
    let (mut at1, mut at2) = (0, 0);
    let mut was = (false, false);
    let end = b.t + Duration::from_secs(120);
    while started(&b.c, 1) {
        assert!(b.t < end, "the demo never ends");
        b.t += TICK;
        b.c.advance(b.t);
        let now = (near(&b.c, &p1), near(&b.c, &p2));
        at1 += usize::from(now.0 && !was.0);
        at2 += usize::from(now.1 && !was.1);
        was = now;
    }
    assert_eq!((at1, at2), (5, 5), "five arrivals at each position");
    assert_eq!(b.int(1, 1), 5, "the cycle counter");
    assert!(
        !b.bit(BitSpace::Output, 0, 300),
        "the gripper open at the end"
    );
    assert_eq!(b.c.counters().motion_completed, 10);
    let s = b.status(1);
    assert_eq!((s.started(), s.step, s.error.0), (false, 0, 0));
    assert!(b.c.at_rest());
}

const TIMED: &str = "PROGRAM 3 timed\n\
                     TIMW 1\n\
                     BTON 301\n\
                     TIMW 1\n\
                     BTON 302\n\
                     TIMW 1\n\
                     EXIT\n";

#[test]
fn pause_holds_between_steps_and_one_step_runs_exactly_one() {
    let mut b = Bench::new(Some(TIMED));
    // One step on a program not started: it starts, runs step 1 (TIMW 1) and pauses.
    assert_eq!(b.refused(ProgramAction::Step, 3), 0);
    assert_eq!(b.status(3).step, 1);
    b.wait(Duration::from_millis(1500));
    let s = b.status(3);
    assert!(s.started(), "paused counts as started");
    assert_eq!(s.step, 2, "paused before step 2");
    assert!(!b.bit(BitSpace::Output, 0, 301));
    // One step again: BTON 301 only.
    assert_eq!(b.refused(ProgramAction::Step, 3), 0);
    b.wait(Duration::from_millis(100));
    assert!(b.bit(BitSpace::Output, 0, 301));
    assert_eq!(b.status(3).step, 3);
    // Resume: it runs on; pause while it waits in step 3 takes hold after that step.
    assert_eq!(b.refused(ProgramAction::Resume, 3), 0);
    b.wait(Duration::from_millis(300));
    assert_eq!(b.status(3).step, 3);
    assert_eq!(b.refused(ProgramAction::Pause, 3), 0);
    // One step on a program that is running freely, even with a pause asked: refused.
    assert_eq!(b.refused(ProgramAction::Step, 3), 0xB0C);
    b.wait(Duration::from_secs(2));
    assert_eq!(b.status(3).step, 4, "paused after step 3, before step 4");
    assert!(!b.bit(BitSpace::Output, 0, 302));
    // Resume all (00), then it ends by itself.
    assert_eq!(b.raw("!9925700"), "#9925733");
    b.until(Duration::from_secs(3), |c| !started(c, 3));
    assert!(b.bit(BitSpace::Output, 0, 302));
    assert_eq!(b.status(3).error.0, 0);
}

#[test]
fn conditions_waits_variables_and_jumps_do_what_sel_says() {
    let text = "PROGRAM 4 logic\n\
                LET 1 0\n\
                LET 200 7\n\
                TAG 1\n\
                ADD 1 1\n\
                CPLT 1 *200 901\n\
                901 GOTO 1\n\
                CPEQ 1 7 610\n\
                WTON 16 0.5 611\n\
                WTON 16 - 612\n\
                LD 16\n\
                A N17\n\
                O 620 BTON 303 305\n\
                N16 BTON 306\n\
                SUB 1 7 613\n\
                EXIT\n";
    let mut b = Bench::new(Some(text));
    assert_eq!(b.refused(ProgramAction::Run, 4), 0);
    // Seven rounds of the loop, then the first WTON times out after 0.5 s.
    b.wait(Duration::from_millis(200));
    assert_eq!(b.int(1, 4), 7);
    assert_eq!(b.int(200, 0), 7, "a global variable");
    assert!(b.bit(BitSpace::Flag, 0, 610), "CPEQ 1 7 turned 610 on");
    assert!(
        !b.bit(BitSpace::Flag, 4, 901),
        "the last CPLT turned 901 off"
    );
    b.wait(Duration::from_millis(500));
    assert!(
        b.bit(BitSpace::Flag, 0, 611),
        "time-out turns the output on"
    );
    // The second WTON waits for input 16 with no time-out.
    b.wait(Duration::from_secs(5));
    assert!(started(&b.c, 4) && !b.bit(BitSpace::Flag, 0, 612));
    b.c.signals_mut().set_input(16, true).unwrap();
    b.until(Duration::from_secs(1), |c| !started(c, 4));
    assert!(
        !b.bit(BitSpace::Flag, 0, 612),
        "no time-out: output stays off"
    );
    // 16 on and 17 off: 303-305 on; N16 false: 306 stays off.
    for n in 303..=305 {
        assert!(b.bit(BitSpace::Output, 0, n), "output {n}");
    }
    assert!(!b.bit(BitSpace::Output, 0, 306));
    assert_eq!(b.int(1, 4), 0);
    assert!(
        b.bit(BitSpace::Flag, 0, 613),
        "SUB to zero turns its output on"
    );
}

#[test]
fn a_position_not_taught_or_out_of_reach_ends_the_program_with_the_alarm() {
    let text = "PROGRAM 5 bad moves\nVEL 100\nMOVP 1\nMOVP 77\nEXIT\n\
                PROGRAM 6 too far\nMOVL 1\nMOVL 78\n";
    let mut b = Bench::new(Some(text));
    let mut far = b.c.positions()[&1];
    far.number = 78;
    far.coords = crate::protocol::PerAxis::from_fn(far.coords.pattern(), |a| match a.index() {
        0 => crate::protocol::Milli(2_000_000),
        _ => crate::protocol::Milli(0),
    });
    b.c.positions_mut().insert(78, far);
    assert_eq!(b.refused(ProgramAction::Run, 5), 0);
    b.until(Duration::from_secs(30), |c| !started(c, 5));
    let s = b.status(5);
    assert_eq!((s.error.0, s.error_step, s.step), (0xB0A, 3, 0));
    let Reply::SystemStatus(sys) = b.ask(Command::SystemStatus) else {
        panic!()
    };
    assert_eq!(sys.critical_error.0, 0xB0A);
    assert!(!sys.status2.program_running());
    // The alarm history names program and step (216H details 1 and 2).
    let Reply::ErrorDetail(d) = b.ask(Command::ErrorDetail(ErrorDetailQuery::ListRecord {
        record: 1,
    })) else {
        panic!()
    };
    assert_eq!((d.error.0, d.details[0], d.details[1]), (0xB0A, 5, 3));
    // Acting is refused until 252H; then the second program fails out of reach.
    assert_eq!(b.refused(ProgramAction::Run, 6), 0xB07);
    assert_eq!(b.raw("!99252"), "#992522E");
    assert_eq!(b.refused(ProgramAction::Run, 6), 0);
    b.until(Duration::from_secs(30), |c| !started(c, 6));
    let s = b.status(6);
    assert_eq!((s.error.0, s.error_step), (0xB08, 2));
    // A new run clears the error.
    assert_eq!(b.raw("!99252"), "#992522E");
    assert_eq!(b.refused(ProgramAction::Run, 5), 0);
    assert_eq!(b.status(5).error.0, 0);
}

#[test]
fn bad_numbers_states_and_held_axes_are_refused() {
    let text = "PROGRAM 1 mover\nTAG 1\nMOVP 1\nMOVP 2\nGOTO 1\n\
                PROGRAM 2 mover too\nMOVP 2\n\
                PROGRAM 3 no moves\nTIMW 100\n";
    let mut b = Bench::new(Some(text));
    // 00 for run and one step, numbers beyond 64, a number with no program.
    assert!(b.raw("!9925300").starts_with("&99A03"), "run 00");
    assert!(b.raw("!9925600").starts_with("&99A03"), "one step 00");
    assert_eq!(b.refused(ProgramAction::Run, 65), 0xA03);
    assert_eq!(b.refused(ProgramAction::Run, 9), 0xB0B);
    assert_eq!(b.refused(ProgramAction::End, 9), 0xB0B);
    assert_eq!(b.raw("!9921300"), "&99A033C", "213H names a program");
    assert_eq!(b.status(9).step, 0, "an empty slot reads as not started");
    // Pause and resume need a started program.
    assert_eq!(b.refused(ProgramAction::Pause, 1), 0xB0C);
    assert_eq!(b.refused(ProgramAction::Resume, 1), 0xB0C);
    assert_eq!(
        b.refused(ProgramAction::End, 1),
        0,
        "ending an ended program"
    );
    assert_eq!(b.refused(ProgramAction::Run, 1), 0);
    assert_eq!(b.refused(ProgramAction::Run, 1), 0xB0C, "already started");
    // Program 1 holds the arm: program 2 and the host's moves are refused; 3 runs.
    assert_eq!(b.refused(ProgramAction::Run, 2), 0xB03);
    b.wait(Duration::from_millis(50));
    let mut targets = crate::protocol::PerAxis::new();
    targets.set(
        crate::protocol::Axis::from_index(0).unwrap(),
        crate::protocol::Milli(1000),
    );
    let jog = Command::ScaraMoveRelative(crate::protocol::ScaraMove {
        motion: crate::protocol::ScaraMotion::default(),
        targets,
    });
    assert!(matches!(b.ask(jog), Reply::Error(e) if e.0 == 0xB03));
    assert_eq!(b.refused(ProgramAction::Run, 3), 0);
    // End all (PROTOCOL.md 3.45's example): both end; the arm's move brakes.
    assert_eq!(b.raw("!9925400"), "#9925430");
    assert!(!started(&b.c, 1) && !started(&b.c, 3));
    b.until(Duration::from_secs(5), |c| c.at_rest());
    assert_eq!(b.refused(ProgramAction::Run, 2), 0, "the arm is free again");
}

#[test]
fn a_program_that_never_ends_is_bounded_per_advance_and_ends_on_254h() {
    let mut b = Bench::new(Some("PROGRAM 8 forever\nTAG 1\nADD 1 1\nGOTO 1\n"));
    assert_eq!(b.refused(ProgramAction::Run, 8), 0);
    b.t += Duration::from_secs(3600);
    b.c.advance(b.t);
    let ran = b.int(1, 8);
    assert!(
        ran > 0 && ran as u32 <= super::MAX_STEPS_PER_ADVANCE,
        "{ran} rounds in one advance"
    );
    // Simulated time goes on at one step a millisecond.
    b.wait(Duration::from_secs(1));
    let later = b.int(1, 8) - ran;
    assert!((300..=400).contains(&later), "{later} rounds in 1 s");
    assert!(!b.c.at_rest());
    assert_eq!(b.raw("!9925408"), "#9925430");
    assert!(b.c.at_rest());
}

#[test]
fn stop_238h_brakes_the_move_but_the_program_goes_on_and_e_stop_ends_it() {
    let text = "PROGRAM 2 two moves\nMOVP 1 - 640\nMOVP 2\nTIMW 50\n";
    let mut b = Bench::new(Some(text));
    assert_eq!(b.refused(ProgramAction::Run, 2), 0);
    b.wait(Duration::from_millis(100));
    assert_eq!(b.status(2).step, 1);
    assert_eq!(b.raw("!99238FF00"), "#9923832", "238H all axes");
    b.until(Duration::from_secs(5), |c| {
        c.programs().state(2).is_some_and(|(_, step, _)| step >= 2)
    });
    assert!(
        !b.bit(BitSpace::Flag, 0, 640),
        "a stopped move leaves its output off"
    );
    // Pause (PROTOCOL.md 3.45's example) holds after the move in progress ends.
    assert_eq!(b.raw("!9925502"), "#9925531");
    b.until(Duration::from_secs(30), |c| c.at_rest());
    assert_eq!(b.status(2).step, 3);
    b.c.set_emergency_stop(true);
    let s = b.status(2);
    assert_eq!((s.started(), s.error.0, s.error_step), (false, 0xB04, 3));
}
