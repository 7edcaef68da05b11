//! The station: a site and the devices that stand on it.

use serde::{Deserialize, Serialize};

use crate::camera::Camera;
use crate::filter_wheel::FilterWheel;
use crate::head::PanTiltHead;
use crate::lights::Lights;
use crate::site::Site;
use crate::validate::{Validate, Validator};

/// Settings of the simulated world, for stations whose devices are simulated.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(test, derive(proptest_derive::Arbitrary))]
#[serde(deny_unknown_fields)]
pub struct Simulation {
    /// Seed of every random process in the simulated world.
    pub seed: u64,
    /// Chance that a byte on a simulated serial link is dropped, in [0, 0.5].
    #[serde(default)]
    pub link_drop_chance: f64,
    /// Chance that a byte on a simulated serial link is corrupted, in [0, 0.5].
    #[serde(default)]
    pub link_corrupt_chance: f64,
    /// The camera as it truly is, when it differs from the configured
    /// one: a lens and mount the station does not know (a mis-set
    /// orientation, a focal length a few percent off), which the simulated
    /// world renders with while the station and processing keep the
    /// configured camera, so that a calibration has something to find.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub true_camera: Option<crate::camera_calibration::CameraCalibration>,
}

/// A station: where it stands and what it drives.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(test, derive(proptest_derive::Arbitrary))]
#[serde(deny_unknown_fields)]
pub struct Station {
    /// A name for logs and reports.
    pub name: String,
    /// Where the station stands.
    pub site: Site,
    /// The camera.
    pub camera: Camera,
    /// The pan-tilt head.
    pub head: PanTiltHead,
    /// The ND filter wheel, if any (needed for sun shots).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub filter_wheel: Option<FilterWheel>,
    /// The light controller, if any (needed for indoor light sequences).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lights: Option<Lights>,
    /// The simulated world, when any device is simulated.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub simulation: Option<Simulation>,
}

impl Station {
    /// Whether any device of this station is simulated.
    pub fn uses_simulation(&self) -> bool {
        use crate::camera::CameraDriver;
        self.camera.driver == CameraDriver::Sim
            || self.head.link.is_simulated()
            || self.filter_wheel.as_ref().is_some_and(|w| w.is_simulated())
            || self.lights.as_ref().is_some_and(|l| l.link.is_simulated())
    }
}

impl Validate for Station {
    fn validate(&self, v: &mut Validator) {
        v.non_empty("name", &self.name);
        v.at("site", |v| self.site.validate(v));
        v.at("camera", |v| self.camera.validate(v));
        v.at("head", |v| self.head.validate(v));
        if let Some(w) = &self.filter_wheel {
            v.at("filter_wheel", |v| w.validate(v));
        }
        if let Some(l) = &self.lights {
            v.at("lights", |v| l.validate(v));
        }
        match &self.simulation {
            Some(s) => v.at("simulation", |v| {
                v.range("link_drop_chance", s.link_drop_chance, 0.0, 0.5, "a probability");
                v.range("link_corrupt_chance", s.link_corrupt_chance, 0.0, 0.5, "a probability");
                if let Some(t) = &s.true_camera {
                    v.at("true_camera", |v| {
                        t.validate(v);
                        if t.resolution != self.camera.resolution {
                            v.invalid(
                                "resolution",
                                format!("{}×{}", t.resolution.width, t.resolution.height),
                                &format!(
                                    "the configured camera's resolution, {}×{}",
                                    self.camera.resolution.width, self.camera.resolution.height
                                ),
                            );
                        }
                    });
                }
            }),
            None if self.uses_simulation() => v.invalid(
                "simulation",
                "nothing".into(),
                "a `simulation: Some((seed: N))` section, since a device is simulated (driver Sim or a `sim:` port)",
            ),
            None => {}
        }
        if self.uses_simulation() {
            self.validate_all_simulated(v);
        }
    }
}

impl Station {
    /// A station with any simulated device is simulated as a whole (the
    /// simulator stands in for every device, whatever its port says), so a
    /// real port or camera beside a simulated one is refused: otherwise a
    /// real head's conformance suite, or a capture, would silently run on
    /// the simulator's head instead.
    fn validate_all_simulated(&self, v: &mut Validator) {
        use crate::camera::CameraDriver;
        const WHY: &str = "since other devices of this station are simulated and the simulator then stands in \
                           for every device; a station is either all simulated or all real";
        if self.camera.driver != CameraDriver::Sim {
            v.at("camera", |v| {
                v.invalid("driver", format!("{:?}", self.camera.driver), &format!("Sim, {WHY}"))
            });
        }
        let links = [
            ("head", Some(&self.head.link)),
            ("filter_wheel", self.filter_wheel.as_ref().and_then(|w| w.link.as_ref())),
            ("lights", self.lights.as_ref().map(|l| &l.link)),
        ];
        if let Some(i) = self.filter_wheel.as_ref().and_then(|w| w.indi.as_ref()) {
            v.at("filter_wheel", |v| {
                v.invalid(
                    "indi",
                    format!("{:?} on {}", i.device, i.server),
                    &format!("a wheel on a `sim:` port, {WHY}"),
                )
            });
        }
        for (device, link) in links {
            if let Some(link) = link.filter(|l| !l.is_simulated()) {
                v.at(device, |v| {
                    v.at("link", |v| {
                        v.invalid("port", format!("{:?}", link.port), &format!("a `sim:` port, {WHY}"))
                    })
                });
            }
        }
    }
}
