//! A camera's calibration as `campanile sky calibrate` (from the sun) and
//! `campanile station calibrate-mount` (from registered photographs of
//! targets) write it: the lens intrinsics and the mount calibration (its
//! orientation) that a station file takes, for the resolution they were
//! fitted at, and where the head stood when that is measured too.
//!
//! ```ron
//! CameraCalibration(
//!     resolution: (width: 512, height: 512),
//!     intrinsics: (focal: Pixels(163.2), projection: Equidistant,
//!                  principal_point_px: Some((256.0, 256.0)), distortion: (0.021, 0.0)),
//!     mount: (pan_zero_azimuth_deg: 3.01, tilt_zero_deg: 0.0,
//!             level_roll_deg: 1.06, level_pitch_deg: -1.05),
//! )
//! ```

use serde::{Deserialize, Serialize};

use crate::camera::{Camera, Intrinsics, Resolution};
use crate::head::MountCalibration;
use crate::station::Station;
use crate::validate::{Validate, Validator};

/// A calibrated camera: what replaces a station's `camera.intrinsics` and
/// `head.mount`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(test, derive(proptest_derive::Arbitrary))]
#[serde(deny_unknown_fields)]
pub struct CameraCalibration {
    /// The resolution the intrinsics are given for (the station camera's).
    pub resolution: Resolution,
    /// The calibrated lens.
    pub intrinsics: Intrinsics,
    /// The calibrated orientation, as the head's mount calibration.
    pub mount: MountCalibration,
    /// Where the head stood, world frame (x east, y north, z up), metres,
    /// when it was measured (from registered photographs): a tripod set up
    /// away from the scene's poses. Views processed through this
    /// calibration are taken from here rather than from their poses'
    /// positions.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[cfg_attr(test, proptest(strategy = "crate::arbitrary::position()"))]
    pub head_position_m: Option<(f64, f64, f64)>,
}

impl CameraCalibration {
    /// `station` with this calibration's lens and mount; an error naming
    /// both resolutions when the station's camera has another.
    pub fn apply_to(&self, station: &Station) -> Result<Station, String> {
        let r = station.camera.resolution;
        if r != self.resolution {
            return Err(format!(
                "the calibration is for {}×{} px, the station's camera is {}×{} px",
                self.resolution.width, self.resolution.height, r.width, r.height
            ));
        }
        let mut s = station.clone();
        s.camera.intrinsics = self.intrinsics.clone();
        s.head.mount = self.mount;
        Ok(s)
    }
}

impl Validate for CameraCalibration {
    fn validate(&self, v: &mut Validator) {
        // The intrinsics are checked as a camera's, at this resolution.
        let camera = Camera {
            driver: crate::camera::CameraDriver::Sim,
            device: None,
            resolution: self.resolution,
            intrinsics: self.intrinsics.clone(),
            bit_depth: 12,
            exposure: crate::camera::ExposureLimits {
                min_s: 1e-3,
                max_s: 1.0,
                steps: Default::default(),
            },
            gain: crate::camera::GainLimits {
                min_db: 0.0,
                max_db: 0.0,
            },
            response_curve: None,
            file_format: Default::default(),
        };
        camera.validate(v);
        v.at("mount", |v| self.mount.validate(v));
        if let Some((x, y, z)) = self.head_position_m {
            v.at("head_position_m", |v| {
                let what = "a position in metres within 10 000 km of the scene's origin";
                for (axis, value) in [("0", x), ("1", y), ("2", z)] {
                    v.range(axis, value, -1e7, 1e7, what);
                }
            });
        }
    }
}
