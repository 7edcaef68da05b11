//! Serial links to device controllers.

use serde::{Deserialize, Serialize};

use crate::validate::{Validate, Validator};

/// Baud rates a serial device may be configured with.
pub const STANDARD_BAUDS: [u32; 12] = [
    1200, 2400, 4800, 9600, 19200, 38400, 57600, 115_200, 230_400, 250_000, 460_800, 921_600,
];

/// A serial port and its speed.
///
/// A port named `sim:NAME` is a simulated device of the `sim` crate,
/// reached through the same byte protocol as the real one.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(test, derive(proptest_derive::Arbitrary))]
#[serde(deny_unknown_fields)]
pub struct SerialLink {
    /// Port path, e.g. "/dev/ttyUSB0", or `sim:head` for simulated firmware.
    pub port: String,
    /// Baud rate, one of [`STANDARD_BAUDS`].
    pub baud: u32,
}

impl SerialLink {
    /// Whether this link goes to simulated firmware.
    pub fn is_simulated(&self) -> bool {
        self.port.starts_with("sim:")
    }
}

impl Validate for SerialLink {
    fn validate(&self, v: &mut Validator) {
        v.non_empty("port", &self.port);
        if !STANDARD_BAUDS.contains(&self.baud) {
            v.invalid(
                "baud",
                self.baud.to_string(),
                "a standard baud rate: 1200, 2400, 4800, 9600, 19200, 38400, 57600, 115200, 230400, 250000, 460800 or 921600",
            );
        }
    }
}
