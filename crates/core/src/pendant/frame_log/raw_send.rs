//! Feeding the frame log from both links' events, and reading a raw frame typed by the user: it
//! becomes a typed command that goes through the link like any other, so STOP, the
//! one-outstanding rule and (for motion) the jog panel's readiness checks all hold.

use crate::link::LinkEvent;
use crate::pendant::controller::readiness::NotReady;
use crate::pendant::{Level, name};
use crate::protocol::{Command, Frame, ScMode, Station, checksum};
use crate::rmc::RmcEvent;

use super::{Dir, FrameLog};

impl FrameLog {
    /// Records traffic (frames, garbage, time-outs, left-out counts) from a link event.
    pub fn record_event(&mut self, event: &LinkEvent) {
        match event {
            LinkEvent::FrameSent { bytes, at, .. } => self.sent(bytes, *at),
            LinkEvent::FrameReceived {
                bytes, first_byte, ..
            } => self.received(bytes, *first_byte),
            LinkEvent::Garbage {
                bytes,
                more,
                error,
                at,
            } => match more {
                0 => self.garbage(bytes, &error.to_string(), *at),
                n => self.garbage(bytes, &format!("{error} (+{n} bytes not kept)"), *at),
            },
            LinkEvent::Timeout {
                command,
                retrying,
                at,
                ..
            } => {
                let text = format!(
                    "no reply to {} ({}){}",
                    command.id(),
                    name(command),
                    if *retrying { ", sent again" } else { "" }
                );
                self.timeout(&text, *at);
            }
            LinkEvent::Dropped { frames } => self.link_dropped(*frames),
            LinkEvent::Interrupted { .. } | LinkEvent::Disconnected { .. } => self.line_lost(),
            _ => {}
        }
    }

    /// Records the RMC151 link's traffic (Modbus/TCP frames, garbage, time-outs,
    /// left-out counts).
    pub fn record_rmc_event(&mut self, event: &RmcEvent) {
        match event {
            RmcEvent::FrameSent { bytes, at } => self.modbus(Dir::Sent, bytes, "", *at),
            RmcEvent::FrameReceived { bytes, at } => self.modbus(Dir::Received, bytes, "", *at),
            RmcEvent::Garbage { bytes, error, at } => self.modbus(Dir::Garbage, bytes, error, *at),
            RmcEvent::Timeout { what, at } => self.modbus(Dir::Timeout, b"", what, *at),
            RmcEvent::LineDown { .. } => self.modbus_line_lost(),
            RmcEvent::Dropped(n) => self.link_dropped(*n),
            _ => {}
        }
    }
}

/// What a raw frame's checks need to know of the line and the controller.
pub struct RawCx {
    /// The line's station.
    pub station: Station,
    pub line_up: bool,
    /// Whether the controller may be asked to move now.
    pub motion: Result<(), NotReady>,
}

/// Reads a frame typed as its body: station, message ID and data, e.g. `99215` (no
/// header, SC or CR LF: the link adds them, with the checksum or `@@` as the connection
/// settings say). The command to send and the operator's word on it, or why not (said
/// too).
pub fn raw_command(body: &str, cx: &RawCx) -> (Result<Command, String>, (Level, String)) {
    let body = body.trim();
    let result = parse(body, cx);
    let said = match &result {
        Ok(c) => {
            let canonical = c.to_bytes(cx.station, ScMode::Computed).unwrap_or_default();
            let typed = format!("!{body}");
            let note = if canonical.starts_with(typed.as_bytes()) {
                String::new()
            } else {
                // Lower-case hex, say: the link encodes the command its own way.
                format!(", written as {}", canonical.escape_ascii())
            };
            (
                Level::Info,
                format!("raw frame sent: {} ({}){note}", c.id(), name(c)),
            )
        }
        Err(why) => (Level::Warning, format!("raw frame not sent: {why}")),
    };
    (result, said)
}

fn parse(body: &str, cx: &RawCx) -> Result<Command, String> {
    if body.is_empty() {
        return Err("type the frame's body, e.g. 99215".into());
    }
    if !body.is_ascii() || body.bytes().any(|b| b.is_ascii_control()) {
        return Err("the body must be printable ASCII".into());
    }
    if !cx.line_up {
        return Err("the line is down".into());
    }
    let mut frame = Vec::with_capacity(body.len() + 5);
    frame.push(b'!');
    frame.extend_from_slice(body.as_bytes());
    let sc = checksum(&frame);
    frame.extend_from_slice(format!("{sc:02X}\r\n").as_bytes());
    let parsed = Frame::parse(&frame).map_err(|e| e.to_string())?;
    let station = cx.station;
    if parsed.station() != station {
        return Err(format!(
            "station {} is not the line's station {station}",
            parsed.station()
        ));
    }
    let command = Command::decode(&parsed).map_err(|e| e.to_string())?;
    if command.moves_arm() {
        cx.motion
            .map_err(|why| format!("{} is motion, and {why}", command.id()))?;
    }
    Ok(command)
}

#[cfg(test)]
mod tests {
    use std::time::Instant;

    use crate::link::LinkEvent;
    use crate::pendant::{Pendant, Request, Settings, script};
    use crate::protocol::Command;
    use crate::robot::{Joints, RobotModel, Scara};

    fn connected() -> Pendant {
        let mut p = Pendant::new(Settings::default(), RobotModel::default_model());
        p.handle_event(
            Instant::now(),
            LinkEvent::Connected {
                line: "test".into(),
            },
        );
        p.take_requests();
        p
    }

    const STEP: &str = "992D501001E001E00140200002710";

    #[test]
    fn a_query_body_becomes_a_command_for_the_link() {
        let mut p = connected();
        assert_eq!(
            p.send_raw(" 99215 ", Instant::now()),
            Ok(Command::SystemStatus)
        );
        assert_eq!(
            p.take_requests(),
            vec![Request::Submit(Command::SystemStatus)]
        );
    }

    #[test]
    fn bad_bodies_are_refused_with_a_reason_and_nothing_is_sent() {
        let mut p = connected();
        let now = Instant::now();
        for (body, why) in [
            ("", "type the frame's body"),
            ("98215", "station 98"),
            ("99ZZZ", ""),
            ("99\x02215", "printable"),
        ] {
            let err = p.send_raw(body, now).unwrap_err();
            assert!(err.contains(why), "{body:?}: {err}");
        }
        assert!(p.take_requests().is_empty());
        assert!(
            p.messages
                .back()
                .unwrap()
                .text
                .starts_with("raw frame not sent")
        );
    }

    #[test]
    fn motion_needs_the_same_readiness_as_the_jog_panel() {
        let mut p = connected();
        let now = Instant::now();
        let err = p.send_raw(STEP, now).unwrap_err();
        assert!(err.contains("is motion"), "{err}");
        assert!(p.take_requests().is_empty());

        let mut p = Pendant::new(Settings::default(), RobotModel::default_model());
        let kin = Scara::new(&p.model);
        for event in script::ready_controller(&kin, Joints::new(30.0, 60.0, 50.0, 0.0)) {
            p.handle_event(now, event);
        }
        p.take_requests();
        let sent = p.send_raw(STEP, now).unwrap();
        assert!(matches!(sent, Command::ScaraMoveRelative(_)));
        assert_eq!(p.take_requests(), vec![Request::Submit(sent)]);
    }
}
