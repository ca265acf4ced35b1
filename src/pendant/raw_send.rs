//! Feeding the frame log from link events, and sending a raw frame typed by the user: it
//! becomes a typed command and goes through the link like any other, so STOP, the
//! one-outstanding rule and (for motion) the jog panel's readiness checks all hold.

use std::time::Instant;

use super::{Level, Pendant, Request, is_move, name};
use crate::link::LinkEvent;
use crate::protocol::{Command, Frame, checksum};

impl Pendant {
    /// Records traffic (frames, garbage, time-outs, left-out counts) in the frame log.
    pub(super) fn log_traffic(&mut self, now: Instant, event: &LinkEvent) {
        let log = &mut self.frame_log;
        match event {
            LinkEvent::FrameSent { bytes, at, .. } => log.sent(bytes, *at),
            LinkEvent::FrameReceived {
                bytes, first_byte, ..
            } => log.received(bytes, *first_byte),
            LinkEvent::Garbage { bytes, error, at } => log.garbage(bytes, &error.to_string(), *at),
            LinkEvent::Timeout {
                command, retrying, ..
            } => {
                let text = format!(
                    "no reply to {} ({}){}",
                    command.id(),
                    name(command),
                    if *retrying { ", sent again" } else { "" }
                );
                log.timeout(&text, now);
            }
            LinkEvent::Dropped { frames } => log.link_dropped(*frames),
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
                self.requests.push(Request::Submit(*c));
                self.say(
                    Level::Info,
                    format!("raw frame sent: {} ({})", c.id(), name(c)),
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
        let station = self.settings.connection.station();
        if parsed.station() != station {
            return Err(format!(
                "station {} is not the line's station {station}",
                parsed.station()
            ));
        }
        let command = Command::decode(&parsed).map_err(|e| e.to_string())?;
        if is_move(&command) {
            self.motion_ready(now)
                .map_err(|why| format!("{} is motion, and {why}", command.id()))?;
        }
        Ok(command)
    }
}
