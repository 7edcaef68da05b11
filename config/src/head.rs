//! The pan-tilt head: protocol, limits, dynamics and mount calibration.

use serde::{Deserialize, Serialize};

use crate::link::SerialLink;
use crate::validate::{Validate, Validator};

/// The protocol the head speaks.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(test, derive(proptest_derive::Arbitrary))]
pub enum HeadProtocol {
    /// Pelco-D over RS-485/RS-232, with extended absolute-position commands.
    PelcoD,
    /// FLIR (Directed Perception) PTU ASCII protocol.
    FlirPtu,
    /// Campanile's own COBS + CRC framed protocol.
    CampanileLink,
}

/// Mechanical limits of the head, in its own pan and tilt angles.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[cfg_attr(test, derive(proptest_derive::Arbitrary))]
#[serde(deny_unknown_fields)]
pub struct HeadLimits {
    /// Lowest pan in degrees, in [-360, 360].
    pub pan_min_deg: f64,
    /// Highest pan in degrees, in (`pan_min_deg`, 360].
    pub pan_max_deg: f64,
    /// Lowest tilt in degrees, in [-90, 90].
    pub tilt_min_deg: f64,
    /// Highest tilt in degrees, in (`tilt_min_deg`, 90].
    pub tilt_max_deg: f64,
}

impl HeadLimits {
    /// Whether a pan/tilt (degrees) is reachable.
    pub fn contains(&self, pan_deg: f64, tilt_deg: f64) -> bool {
        (self.pan_min_deg..=self.pan_max_deg).contains(&pan_deg)
            && (self.tilt_min_deg..=self.tilt_max_deg).contains(&tilt_deg)
    }
}

/// Motion dynamics of the head.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[cfg_attr(test, derive(proptest_derive::Arbitrary))]
#[serde(deny_unknown_fields)]
pub struct HeadDynamics {
    /// Top pan speed in degrees per second, in (0, 1000].
    pub pan_speed_deg_s: f64,
    /// Top tilt speed in degrees per second, in (0, 1000].
    pub tilt_speed_deg_s: f64,
    /// Acceleration in degrees per second squared, in (0, 100000].
    pub acceleration_deg_s2: f64,
    /// Time to wait after a move before a frame is taken, in seconds, in [0, 60].
    #[serde(default)]
    pub settle_s: f64,
}

/// How the head sits in the world frame (z up, x east, y north; azimuth from
/// north through east).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[cfg_attr(test, derive(proptest_derive::Arbitrary))]
#[serde(deny_unknown_fields)]
pub struct MountCalibration {
    /// Azimuth the camera faces at pan 0, in degrees, in [0, 360).
    pub pan_zero_azimuth_deg: f64,
    /// Tilt reading at which the optical axis is horizontal, in degrees, in [-90, 90].
    pub tilt_zero_deg: f64,
    /// Rotation of the base about the north axis (roll), in degrees, in [-10, 10].
    #[serde(default)]
    pub level_roll_deg: f64,
    /// Rotation of the base about the east axis (pitch), in degrees, in [-10, 10].
    #[serde(default)]
    pub level_pitch_deg: f64,
}

/// The pan-tilt head.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(test, derive(proptest_derive::Arbitrary))]
#[serde(deny_unknown_fields)]
pub struct PanTiltHead {
    /// Protocol on the wire.
    pub protocol: HeadProtocol,
    /// Serial link.
    pub link: SerialLink,
    /// Device address on the bus (Pelco-D: 1–255; others: 0–255).
    #[serde(default = "default_address")]
    pub address: u8,
    /// Reachable angles.
    pub limits: HeadLimits,
    /// Speeds and acceleration.
    pub dynamics: HeadDynamics,
    /// Mount calibration.
    pub mount: MountCalibration,
}

impl PanTiltHead {
    /// Head angles `(pan, tilt)` in degrees that aim the optical axis at a
    /// world direction, with pan wrapped by whole turns into the head's
    /// limits; `None` if no turn of it is reachable. The level offsets
    /// (tenths of a degree) are left to the capture controller's exact
    /// kinematics: this is the reachability test plans are checked with.
    pub fn reach(&self, azimuth_deg: f64, elevation_deg: f64) -> Option<(f64, f64)> {
        let tilt = elevation_deg + self.mount.tilt_zero_deg;
        let pan0 = azimuth_deg - self.mount.pan_zero_azimuth_deg;
        [-720.0, -360.0, 0.0, 360.0, 720.0]
            .into_iter()
            .map(|turn| pan0 + turn)
            .find(|&pan| self.limits.contains(pan, tilt))
            .map(|pan| (pan, tilt))
    }
}

fn default_address() -> u8 {
    1
}

impl Validate for PanTiltHead {
    fn validate(&self, v: &mut Validator) {
        v.at("link", |v| self.link.validate(v));
        if self.protocol == HeadProtocol::PelcoD && self.address == 0 {
            v.invalid("address", "0".into(), "a Pelco-D address in 1–255 (0 is reserved)");
        }
        v.at("limits", |v| {
            let l = self.limits;
            v.range("pan_min_deg", l.pan_min_deg, -360.0, 360.0, "a pan angle in degrees");
            v.range_open_low(
                "pan_max_deg",
                l.pan_max_deg,
                l.pan_min_deg,
                360.0,
                "a pan angle in degrees (above pan_min_deg)",
            );
            v.range("tilt_min_deg", l.tilt_min_deg, -90.0, 90.0, "a tilt angle in degrees");
            v.range_open_low(
                "tilt_max_deg",
                l.tilt_max_deg,
                l.tilt_min_deg,
                90.0,
                "a tilt angle in degrees (above tilt_min_deg)",
            );
        });
        v.at("dynamics", |v| {
            let d = self.dynamics;
            v.range_open_low(
                "pan_speed_deg_s",
                d.pan_speed_deg_s,
                0.0,
                1000.0,
                "a speed in degrees per second",
            );
            v.range_open_low(
                "tilt_speed_deg_s",
                d.tilt_speed_deg_s,
                0.0,
                1000.0,
                "a speed in degrees per second",
            );
            v.range_open_low(
                "acceleration_deg_s2",
                d.acceleration_deg_s2,
                0.0,
                100_000.0,
                "an acceleration in degrees per second squared",
            );
            v.range("settle_s", d.settle_s, 0.0, 60.0, "a settle time in seconds");
        });
        v.at("mount", |v| self.mount.validate(v));
    }
}

impl Validate for MountCalibration {
    fn validate(&self, v: &mut Validator) {
        let m = self;
        v.range_open_high(
            "pan_zero_azimuth_deg",
            m.pan_zero_azimuth_deg,
            0.0,
            360.0,
            "an azimuth in degrees",
        );
        v.range("tilt_zero_deg", m.tilt_zero_deg, -90.0, 90.0, "a tilt angle in degrees");
        v.range(
            "level_roll_deg",
            m.level_roll_deg,
            -10.0,
            10.0,
            "a level offset in degrees",
        );
        v.range(
            "level_pitch_deg",
            m.level_pitch_deg,
            -10.0,
            10.0,
            "a level offset in degrees",
        );
    }
}
