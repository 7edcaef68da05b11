//! A fixed camera's calibration as `campanile sky calibrate` writes it:
//! the lens intrinsics and the mount calibration (its orientation) that a
//! station file takes, for the resolution they were fitted at.
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
    }
}
