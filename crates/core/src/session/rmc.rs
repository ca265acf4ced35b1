//! The RMC151's connection: a TCP connection to the controller named in the settings, or
//! to the built-in simulated RMC151 started for it on loopback; the RMC link on it.

use std::net::TcpListener;
use std::time::Duration;

use crossbeam_channel::Receiver;

use crate::link::Connector;
use crate::link::transport::{TcpTransport, Transport};
use crate::pendant::axes::RmcSettings;
use crate::rmc::{RmcEvent, RmcHandle, RmcLinkConfig, RmcRepaint};
use crate::session::LineOwner;
use crate::session::guardian::GuardianLine;
use crate::session::guardian::wire::RmcLine;
use crate::sim::rmc::{RmcConfig, RmcServer};

/// The Modbus/TCP port an address without one gets (RMC.md section 1: 502 [I]).
pub const MODBUS_PORT: u16 = 502;
/// Longest wait for a TCP connection (the link's thread waits; nothing moves meanwhile).
const CONNECT_TIMEOUT: Duration = Duration::from_secs(1);

/// The RMC link, and the simulator behind it when it is the built-in one.
pub struct RmcSession {
    pub link: RmcHandle,
    pub events: Receiver<RmcEvent>,
    /// The built-in simulated RMC151, served on loopback for this session.
    pub sim: Option<RmcServer>,
    /// Where the link connects.
    pub address: String,
}

/// `host:port` from what the user typed (502 when no port is given).
pub fn rmc_address(typed: &str) -> Result<String, String> {
    let typed = typed.trim();
    if typed.is_empty() {
        return Err("no address: name host:port, or leave it empty for the built-in RMC".into());
    }
    // Checked as the command line's `--rmc` is: a port out of range is refused here,
    // never taken as part of the host.
    crate::line::address(typed, Some(MODBUS_PORT))
}

impl RmcSession {
    /// Starts the RMC link on the controller in `settings` (or a built-in one).
    /// A real RMC's connection is owned by a guardian process when `owner` says so (the
    /// built-in one lives in the window's process and dies with it).
    pub fn open(
        settings: &RmcSettings,
        repaint: RmcRepaint,
        owner: &LineOwner,
    ) -> Result<Self, String> {
        let axes = settings.axis_count();
        let (address, sim) = if settings.address.trim().is_empty() {
            let listener = TcpListener::bind("127.0.0.1:0")
                .map_err(|e| format!("cannot start the built-in RMC: {e}"))?;
            let config = RmcConfig {
                axes,
                ..RmcConfig::default()
            };
            let server = RmcServer::start(listener, config)
                .map_err(|e| format!("cannot start the built-in RMC: {e}"))?;
            (server.local_addr().to_string(), Some(server))
        } else {
            (rmc_address(&settings.address)?, None)
        };
        let config = RmcLinkConfig {
            unit: settings.unit,
            axes,
            stop_decel: settings.stop_decel(),
            ..RmcLinkConfig::default()
        };
        let to = address.clone();
        let connector: Connector = match owner {
            LineOwner::Guardian { exe } if sim.is_none() => {
                let (exe, lease) = (exe.clone(), config.lease);
                let line = RmcLine {
                    address: to,
                    unit: settings.unit,
                    stop_decel: config.stop_decel,
                };
                Box::new(move |_| {
                    GuardianLine::open_rmc(&exe, line.clone(), lease)
                        .map(|t| Box::new(t) as Box<dyn Transport>)
                })
            }
            _ => Box::new(move |_| {
                TcpTransport::connect(&to, CONNECT_TIMEOUT)
                    .map(|t| Box::new(t) as Box<dyn Transport>)
            }),
        };
        let (link, events) = crate::rmc::spawn(connector, config, repaint)
            .map_err(|e| format!("cannot start the RMC link thread: {e}"))?;
        Ok(Self {
            link,
            events,
            sim,
            address,
        })
    }

    /// Whether it talks to the built-in simulated RMC151.
    pub fn is_simulated(&self) -> bool {
        self.sim.is_some()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_address_gets_the_modbus_port_when_it_has_none() {
        assert_eq!(rmc_address("192.168.0.10").unwrap(), "192.168.0.10:502");
        assert_eq!(rmc_address(" rmc.local:5020 ").unwrap(), "rmc.local:5020");
        assert!(rmc_address("").is_err());
        assert!(rmc_address("a b").is_err());
        assert!(
            rmc_address("127.0.0.1:99999")
                .unwrap_err()
                .contains("out of range")
        );
    }
}
