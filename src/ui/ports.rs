//! The serial port list, read on a worker thread so listing never blocks a frame.

use crossbeam_channel::{Receiver, bounded};

use crate::line::ports::{PortEntry, list_ports};

/// The ports last found, and a listing in progress.
#[derive(Default)]
pub struct PortList {
    pub ports: Vec<PortEntry>,
    pub error: Option<String>,
    pending: Option<Receiver<Result<Vec<PortEntry>, String>>>,
    pub listed_once: bool,
}

impl PortList {
    /// Starts a listing unless one is running; `wake` is called when it is done.
    pub fn refresh(&mut self, wake: impl Fn() + Send + 'static) {
        if self.pending.is_some() {
            return;
        }
        let (tx, rx) = bounded(1);
        let spawned = std::thread::Builder::new()
            .name("xsel-port-list".into())
            .spawn(move || {
                let _ = tx.send(list_ports());
                wake();
            });
        match spawned {
            Ok(_) => self.pending = Some(rx),
            Err(e) => self.error = Some(format!("cannot list ports: {e}")),
        }
    }

    pub fn is_listing(&self) -> bool {
        self.pending.is_some()
    }

    /// Takes a finished listing, if any.
    pub fn poll(&mut self) {
        let Some(rx) = &self.pending else { return };
        if let Ok(result) = rx.try_recv() {
            self.pending = None;
            self.listed_once = true;
            match result {
                Ok(ports) => {
                    self.ports = ports;
                    self.error = None;
                }
                Err(e) => self.error = Some(e),
            }
        }
    }
}
