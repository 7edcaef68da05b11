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
    /// Serial link.
    pub link: SerialLink,
    /// The slots in wheel order, 1 to 12 of them.
    #[cfg_attr(test, proptest(strategy = "crate::arbitrary::small_vec()"))]
    pub slots: Vec<FilterSlot>,
}

impl FilterWheel {
    /// The 1-based wheel position of the slot called `name`.
    pub fn position_of(&self, name: &str) -> Option<usize> {
        self.slots.iter().position(|s| s.name == name).map(|i| i + 1)
    }
}

impl Validate for FilterWheel {
    fn validate(&self, v: &mut Validator) {
        v.at("link", |v| self.link.validate(v));
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
