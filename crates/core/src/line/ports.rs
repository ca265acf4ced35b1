//! Lists the serial ports the system offers, with USB names where the OS gives them.

use std::fmt;

/// One port as the connection panel shows it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PortEntry {
    pub path: String,
    /// "USB: FTDI FT232R USB UART (SN A1B2C3) 0403:6001", "PCI", "Bluetooth" or empty.
    pub detail: String,
}

impl fmt::Display for PortEntry {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.detail.is_empty() {
            f.write_str(&self.path)
        } else {
            write!(f, "{} ({})", self.path, self.detail)
        }
    }
}

/// The ports found now, sorted by path; an error of the OS becomes its message.
pub fn list_ports() -> Result<Vec<PortEntry>, String> {
    let mut ports: Vec<PortEntry> = serialport::available_ports()
        .map_err(|e| format!("cannot list serial ports: {e}"))?
        .into_iter()
        .map(|info| PortEntry {
            detail: describe_port_type(&info.port_type),
            path: info.port_name,
        })
        .collect();
    ports.sort_by(|a, b| a.path.cmp(&b.path));
    Ok(ports)
}

fn describe_port_type(kind: &serialport::SerialPortType) -> String {
    match kind {
        serialport::SerialPortType::UsbPort(usb) => {
            let names: Vec<&str> = [usb.manufacturer.as_deref(), usb.product.as_deref()]
                .into_iter()
                .flatten()
                .filter(|s| !s.is_empty())
                .collect();
            let mut text = String::from("USB");
            if !names.is_empty() {
                text.push_str(": ");
                text.push_str(&names.join(" "));
            }
            if let Some(serial) = usb.serial_number.as_deref().filter(|s| !s.is_empty()) {
                text.push_str(&format!(" (SN {serial})"));
            }
            text.push_str(&format!(" {:04x}:{:04x}", usb.vid, usb.pid));
            text
        }
        serialport::SerialPortType::PciPort => "PCI".into(),
        serialport::SerialPortType::BluetoothPort => "Bluetooth".into(),
        serialport::SerialPortType::Unknown => String::new(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn usb_ports_show_maker_product_serial_and_ids() {
        let usb = serialport::SerialPortType::UsbPort(serialport::UsbPortInfo {
            vid: 0x0403,
            pid: 0x6001,
            serial_number: Some("A1B2C3".into()),
            manufacturer: Some("FTDI".into()),
            product: Some("FT232R USB UART".into()),
        });
        assert_eq!(
            describe_port_type(&usb),
            "USB: FTDI FT232R USB UART (SN A1B2C3) 0403:6001"
        );
        let entry = PortEntry {
            path: "/dev/ttyUSB0".into(),
            detail: describe_port_type(&usb),
        };
        assert!(entry.to_string().starts_with("/dev/ttyUSB0 (USB: FTDI"));
    }

    #[test]
    fn listing_does_not_fail_on_this_machine() {
        // Containers often have no serial ports at all: an empty list is a valid answer.
        assert!(list_ports().is_ok());
    }
}
