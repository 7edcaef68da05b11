//! The neutral-density filter wheel used for sun shots (thesis §5.3.1).

use serde::{Deserialize, Serialize};

use crate::link::SerialLink;
use crate::validate::{Validate, Validator};

/// The protocol the wheel speaks.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(test, derive(proptest_derive::Arbitrary))]
pub enum WheelProtocol {
    /// Thorlabs FW102C/FW212C ASCII protocol (`pos=n`, `pos?`).
    Fw102c,
    /// Campanile's own framed protocol.
    CampanileLink,
    /// A filter wheel device on an INDI server (`indi: (server: …, device:
    /// …)`, no serial link).
    Indi,
}

/// A device on an INDI server.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(test, derive(proptest_derive::Arbitrary))]
#[serde(deny_unknown_fields)]
pub struct IndiDevice {
    /// The server, `host:port` (INDI's port is 7624).
    pub server: String,
    /// The device's INDI name, e.g. "Filter Simulator".
    pub device: String,
}

/// One slot of the wheel.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(test, derive(proptest_derive::Arbitrary))]
#[serde(deny_unknown_fields)]
pub struct FilterSlot {
    /// Name used by plan steps, e.g. "nd3".
    pub name: String,
    /// Optical density per channel `(r, g, b)`, each in [0, 10]: the
    /// transmittance is `10^-density`.
    pub optical_density: (f64, f64, f64),
}

impl FilterSlot {
    /// Transmittance per channel, `10^-OD`.
    pub fn transmittance(&self) -> [f64; 3] {
        let (r, g, b) = self.optical_density;
        [10f64.powf(-r), 10f64.powf(-g), 10f64.powf(-b)]
    }
}

/// The filter wheel. Slot `i` of `slots` is wheel position `i + 1`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(test, derive(proptest_derive::Arbitrary))]
#[serde(deny_unknown_fields)]
pub struct FilterWheel {
    /// Protocol on the wire.
    pub protocol: WheelProtocol,
    /// Serial link (serial protocols).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub link: Option<SerialLink>,
    /// The INDI device (protocol `Indi`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub indi: Option<IndiDevice>,
    /// The slots in wheel order, 1 to 12 of them.
    #[cfg_attr(test, proptest(strategy = "crate::arbitrary::small_vec()"))]
    pub slots: Vec<FilterSlot>,
}

impl FilterWheel {
    /// Where the wheel is reached: its serial port, or its INDI device.
    pub fn place(&self) -> String {
        match (&self.link, &self.indi) {
            (Some(l), _) => l.port.clone(),
            (None, Some(i)) => format!("INDI {:?} on {}", i.device, i.server),
            (None, None) => "nowhere".into(),
        }
    }

    /// Whether the wheel is a simulated serial device.
    pub fn is_simulated(&self) -> bool {
        self.link.as_ref().is_some_and(SerialLink::is_simulated)
    }

    /// The 1-based wheel position of the slot called `name`.
    pub fn position_of(&self, name: &str) -> Option<usize> {
        self.slots.iter().position(|s| s.name == name).map(|i| i + 1)
    }
}

impl Validate for FilterWheel {
    fn validate(&self, v: &mut Validator) {
        let found = match (&self.link, &self.indi) {
            (Some(l), Some(i)) => format!("a serial link on {} and INDI device {:?}", l.port, i.device),
            (Some(l), None) => format!("a serial link on {}", l.port),
            (None, Some(i)) => format!("INDI device {:?} on {}", i.device, i.server),
            (None, None) => "neither a serial link nor an INDI device".to_owned(),
        };
        match (self.protocol, &self.link, &self.indi) {
            (WheelProtocol::Indi, None, Some(i)) => v.at("indi", |v| crate::camera::validate_indi(v, &i.server, &i.device)),
            (WheelProtocol::Indi, _, _) => v.invalid(
                "indi",
                found,
                "for protocol Indi, an INDI device and no serial link, e.g. `indi: (server: \"127.0.0.1:7624\", device: \"Filter Simulator\")`",
            ),
            (_, Some(l), None) => v.at("link", |v| l.validate(v)),
            (_, _, _) => v.invalid(
                "link",
                found,
                "for a serial protocol, a serial link and no INDI device, e.g. `link: (port: \"/dev/ttyUSB1\", baud: 115200)`",
            ),
        }
        if self.slots.is_empty() || self.slots.len() > 12 {
            v.invalid("slots", format!("{} slots", self.slots.len()), "1 to 12 filter slots");
        }
        v.unique_names("slots", self.slots.iter().map(|s| s.name.as_str()));
        v.at("slots", |v| {
            for (i, slot) in self.slots.iter().enumerate() {
                v.at(i, |v| {
                    v.non_empty("name", &slot.name);
                    let (r, g, b) = slot.optical_density;
                    v.at("optical_density", |v| {
                        for (k, od) in [r, g, b].into_iter().enumerate() {
                            v.range(k, od, 0.0, 10.0, "an optical density");
                        }
                    });
                });
            }
        });
    }
}
