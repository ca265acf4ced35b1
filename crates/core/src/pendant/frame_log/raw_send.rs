//! Feeding the frame log from link events, and sending a raw frame typed by the user: it
//! becomes a typed command and goes through the link like any other, so STOP, the
//! one-outstanding rule and (for motion) the jog panel's readiness checks all hold.

use std::time::Instant;

use crate::link::LinkEvent;
use crate::pendant::{Level, Pendant, Request, name};
use crate::protocol::{Command, Frame, ScMode, checksum};

impl Pendant {
    /// Records traffic (frames, garbage, time-outs, left-out counts) in the frame log.
    pub(in crate::pendant) fn log_traffic(&mut self, event: &LinkEvent) {
        let log = &mut self.frame_log;
        match event {
            LinkEvent::FrameSent { bytes, at, .. } => log.sent(bytes, *at),
            LinkEvent::FrameReceived {
                bytes, first_byte, ..
            } => log.received(bytes, *first_byte),
            LinkEvent::Garbage {
                bytes,
                more,
                error,
                at,
            } => match more {
                0 => log.garbage(bytes, &error.to_string(), *at),
                n => log.garbage(bytes, &format!("{error} (+{n} bytes not kept)"), *at),
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
                log.timeout(&text, *at);
            }
            LinkEvent::Dropped { frames } => log.link_dropped(*frames),
            LinkEvent::Interrupted { .. } | LinkEvent::Disconnected { .. } => log.line_lost(),
            _ => {}
        }
    }

    /// Sends a frame typed as its body: station, message ID and data, e.g. `99215`
    /// (no header, SC or CR LF: the link adds them, with the checksum or `@@` as the
    /// connection settings say). Returns what was sent, or why not.
    pub fn send_raw(&mut self, body: &str, now: Instant) -> Result<Command, String> {
        let result = self.raw_command(body.trim(), now);
        match &result {
            Ok(c) => {
                self.requests.push(Request::Submit(c.clone()));
                let station = crate::protocol::Station(self.settings.connection.station);
                let canonical = c.to_bytes(station, ScMode::Computed).unwrap_or_default();
                let typed = format!("!{}", body.trim());
                let note = if canonical.starts_with(typed.as_bytes()) {
                    String::new()
                } else {
                    // Lower-case hex, say: the link encodes the command its own way.
                    format!(", written as {}", canonical.escape_ascii())
                };
                self.say(
                    Level::Info,
                    format!("raw frame sent: {} ({}){note}", c.id(), name(c)),
                    now,
                );
            }
            Err(why) => self.say(Level::Warning, format!("raw frame not sent: {why}"), now),
        }
        result
    }

    fn raw_command(&self, body: &str, now: Instant) -> Result<Command, String> {
        if body.is_empty() {
            return Err("type the frame's body, e.g. 99215".into());
        }
        if !body.is_ascii() || body.bytes().any(|b| b.is_ascii_control()) {
            return Err("the body must be printable ASCII".into());
        }
        if !self.line.is_up() {
            return Err("the line is down".into());
        }
        let mut frame = Vec::with_capacity(body.len() + 5);
        frame.push(b'!');
        frame.extend_from_slice(body.as_bytes());
        let sc = checksum(&frame);
        frame.extend_from_slice(format!("{sc:02X}\r\n").as_bytes());
        let parsed = Frame::parse(&frame).map_err(|e| e.to_string())?;
        let station = crate::protocol::Station(self.settings.connection.station);
        if parsed.station() != station {
            return Err(format!(
                "station {} is not the line's station {station}",
                parsed.station()
            ));
        }
        let command = Command::decode(&parsed).map_err(|e| e.to_string())?;
        if command.moves_arm() {
            self.motion_ready(now)
                .map_err(|why| format!("{} is motion, and {why}", command.id()))?;
        }
        Ok(command)
    }
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
