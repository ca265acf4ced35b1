//! Why a probe could not go on, in words the connection panel can show as they are.

use std::fmt;
use std::io;

use crate::line::LineSettings;

/// What ended a probe before its candidates were done (other than a cancel).
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum ProbeError {
    /// The port does not exist.
    NotFound { port: String, detail: String },
    /// Another program (or this one's own link) holds the port.
    Busy { port: String, detail: String },
    /// The user may not open the port.
    PermissionDenied { port: String, detail: String },
    /// Opening failed for another reason.
    Open {
        port: String,
        line: LineSettings,
        detail: String,
    },
    /// The port failed while probing (unplugged, closed).
    Line {
        port: String,
        line: LineSettings,
        detail: String,
    },
    /// The plan cannot be run.
    Plan(String),
}

impl ProbeError {
    /// Sorts an error of opening `port` at `line` by its kind and, since the serial
    /// library's kinds are coarse (it reports a busy port as "not found"), its text.
    pub fn from_open(port: &str, line: LineSettings, err: io::Error) -> Self {
        let detail = err.to_string();
        let text = detail.to_ascii_lowercase();
        let has = |words: &[&str]| words.iter().any(|w| text.contains(w));
        let port_s = port.to_owned();
        if has(&["busy", "in use", "lock"]) || (cfg!(windows) && has(&["access is denied"])) {
            // A COM port another program holds says "Access is denied" [inferred].
            return ProbeError::Busy {
                port: port_s,
                detail,
            };
        }
        if has(&["permission denied", "access is denied"])
            || err.kind() == io::ErrorKind::PermissionDenied
        {
            return ProbeError::PermissionDenied {
                port: port_s,
                detail,
            };
        }
        if has(&["no such file", "no such device", "cannot find", "not found"])
            || err.kind() == io::ErrorKind::NotFound
            || missing_path(port)
        {
            return ProbeError::NotFound {
                port: port_s,
                detail,
            };
        }
        ProbeError::Open {
            port: port_s,
            line,
            detail,
        }
    }

    /// An error reading or writing `port` during the probe.
    pub fn from_line(port: &str, line: LineSettings, err: io::Error) -> Self {
        ProbeError::Line {
            port: port.to_owned(),
            line,
            detail: err.to_string(),
        }
    }
}

/// Whether a device path names nothing (Unix device files; COM names have no path).
#[cfg(unix)]
fn missing_path(port: &str) -> bool {
    !std::path::Path::new(port).exists()
}

#[cfg(not(unix))]
fn missing_path(_port: &str) -> bool {
    false
}

/// What to do about a denied port on this system.
fn permission_hint() -> &'static str {
    if cfg!(target_os = "linux") {
        "add your user to the `dialout` group (sudo usermod -aG dialout $USER), then log \
         out and in again"
    } else if cfg!(target_os = "macos") {
        "check the device's permissions"
    } else if cfg!(windows) {
        "check in Device Manager that the port is there and enabled, and that no other \
         program holds it"
    } else {
        "check that this user may use the port"
    }
}

impl fmt::Display for ProbeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ProbeError::NotFound { port, detail } => write!(
                f,
                "{port}: no such port; is the cable or USB adapter plugged in? ({detail})"
            ),
            ProbeError::Busy { port, detail } => write!(
                f,
                "{port} is in use by another program (or by this one's connection: \
                 disconnect first) ({detail})"
            ),
            ProbeError::PermissionDenied { port, detail } => write!(
                f,
                "{port}: permission denied; {} ({detail})",
                permission_hint()
            ),
            ProbeError::Open { port, line, detail } => {
                write!(f, "cannot open {port} at {line}: {detail}")
            }
            ProbeError::Line { port, line, detail } => {
                write!(f, "{port} failed while probing at {line}: {detail}")
            }
            ProbeError::Plan(why) => write!(f, "nothing to probe: {why}"),
        }
    }
}

impl std::error::Error for ProbeError {}

#[cfg(test)]
mod tests {
    use super::*;

    fn open_err(port: &str, kind: io::ErrorKind, text: &str) -> ProbeError {
        ProbeError::from_open(port, LineSettings::default(), io::Error::new(kind, text))
    }

    #[test]
    fn open_errors_are_sorted_by_what_the_user_can_do() {
        let e = open_err(
            "/dev/ttyUSB0",
            io::ErrorKind::Other,
            "cannot open /dev/ttyUSB0: Permission denied",
        );
        assert!(matches!(e, ProbeError::PermissionDenied { .. }), "{e:?}");
        if cfg!(target_os = "linux") {
            assert!(e.to_string().contains("dialout"), "{e}");
        }
        // The serial library reports EBUSY with the "not found" kind.
        let e = open_err(
            "/dev/ttyUSB0",
            io::ErrorKind::NotFound,
            "cannot open /dev/ttyUSB0: Device or resource busy",
        );
        assert!(matches!(e, ProbeError::Busy { .. }), "{e:?}");
        let e = open_err(
            "COM7",
            io::ErrorKind::Other,
            "The system cannot find the file specified.",
        );
        assert!(matches!(e, ProbeError::NotFound { .. }), "{e:?}");
        assert!(e.to_string().starts_with("COM7: no such port"), "{e}");
    }

    #[cfg(unix)]
    #[test]
    fn an_unexplained_error_on_a_missing_path_is_not_found() {
        let e = open_err(
            "/dev/no-such-xsel-port",
            io::ErrorKind::Other,
            "odd failure",
        );
        assert!(matches!(e, ProbeError::NotFound { .. }), "{e:?}");
        let e = open_err("/dev/null", io::ErrorKind::Other, "not a terminal");
        assert!(matches!(e, ProbeError::Open { .. }), "{e:?}");
        assert!(e.to_string().contains("/dev/null at 115200 8N1"), "{e}");
    }
}
