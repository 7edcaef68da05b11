//! Light controllers for indoor sequences (thesis §4.7.2): which channel
//! drives which lamp, where the lamp is and how bright it is.

use serde::{Deserialize, Serialize};

use crate::link::SerialLink;
use crate::validate::{Validate, Validator};

/// The protocol the light controller speaks.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(test, derive(proptest_derive::Arbitrary))]
pub enum LightProtocol {
    /// Enttec DMX USB Pro (DMX512 universe of 512 channels).
    DmxEnttec,
    /// Campanile's own framed protocol.
    CampanileLink,
}

/// The photometric calibration of one lamp.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(test, derive(proptest_derive::Arbitrary))]
#[serde(deny_unknown_fields)]
pub struct IntensityCalibration {
    /// Radiant intensity per camera channel `(r, g, b)` at full level, in
    /// W·sr⁻¹, each in [0, 1e6].
    pub radiant_intensity_w_sr: (f64, f64, f64),
    /// Output as a function of level: output fraction = level^gamma, gamma in (0, 10].
    #[serde(default = "default_gamma")]
    pub gamma: f64,
}

fn default_gamma() -> f64 {
    1.0
}

/// One lamp on one controller channel.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(test, derive(proptest_derive::Arbitrary))]
#[serde(deny_unknown_fields)]
pub struct LightChannel {
    /// Name used by plan steps, e.g. "lamp-left".
    pub name: String,
    /// Controller channel: DMX 1–512, or the campanile-link channel number.
    pub channel: u16,
    /// Centre of the lamp in the scene frame, metres `(x, y, z)`.
    pub position_m: (f64, f64, f64),
    /// Radius of the (spherical) lamp in metres, in [0, 1].
    #[serde(default)]
    pub radius_m: f64,
    /// Photometric calibration.
    pub intensity: IntensityCalibration,
}

/// A light controller and its lamps.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(test, derive(proptest_derive::Arbitrary))]
#[serde(deny_unknown_fields)]
pub struct Lights {
    /// Protocol on the wire.
    pub protocol: LightProtocol,
    /// Serial link.
    pub link: SerialLink,
    /// The lamps, at least one.
    #[cfg_attr(test, proptest(strategy = "crate::arbitrary::small_vec()"))]
    pub channels: Vec<LightChannel>,
}

impl Lights {
    /// The lamp called `name`.
    pub fn channel(&self, name: &str) -> Option<&LightChannel> {
        self.channels.iter().find(|c| c.name == name)
    }
}

impl Validate for Lights {
    fn validate(&self, v: &mut Validator) {
        v.at("link", |v| self.link.validate(v));
        if self.channels.is_empty() {
            v.invalid("channels", "an empty list".into(), "at least one light channel");
        }
        v.unique_names("channels", self.channels.iter().map(|c| c.name.as_str()));
        let max_channel = match self.protocol {
            LightProtocol::DmxEnttec => 512,
            LightProtocol::CampanileLink => 255,
        };
        let mut seen = std::collections::BTreeMap::new();
        v.at("channels", |v| {
            for (i, c) in self.channels.iter().enumerate() {
                v.at(i, |v| {
                    v.non_empty("name", &c.name);
                    v.range_u(
                        "channel",
                        c.channel.into(),
                        1,
                        max_channel,
                        "a controller channel number",
                    );
                    if let Some(first) = seen.insert(c.channel, i) {
                        v.invalid(
                            "channel",
                            c.channel.to_string(),
                            &format!("a channel not already used by channels[{first}]"),
                        );
                    }
                    let (x, y, z) = c.position_m;
                    v.at("position_m", |v| {
                        for (k, p) in [x, y, z].into_iter().enumerate() {
                            v.range(k, p, -1e4, 1e4, "a coordinate in metres");
                        }
                    });
                    v.range("radius_m", c.radius_m, 0.0, 1.0, "a lamp radius in metres");
                    v.at("intensity", |v| {
                        let (r, g, b) = c.intensity.radiant_intensity_w_sr;
                        v.at("radiant_intensity_w_sr", |v| {
                            for (k, p) in [r, g, b].into_iter().enumerate() {
                                v.range(k, p, 0.0, 1e6, "a radiant intensity in W/sr");
                            }
                        });
                        v.range_open_low("gamma", c.intensity.gamma, 0.0, 10.0, "a level-to-output exponent");
                    });
                });
            }
        });
    }
}
