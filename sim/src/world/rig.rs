//! The station's camera geometry in the processing crate's terms.

use campanile_config::head::MountCalibration;
use campanile_process::pose::{Mount, Pinhole};

/// The pinhole model of a configured camera at its configured resolution.
pub fn pinhole(camera: &campanile_config::Camera) -> Pinhole {
    let (w, h) = (camera.resolution.width, camera.resolution.height);
    let i = &camera.intrinsics;
    Pinhole {
        focal_px: i.focal.pixels(w),
        principal_px: i.principal_point_px.unwrap_or((f64::from(w) / 2.0, f64::from(h) / 2.0)),
        k1: i.distortion.0,
        k2: i.distortion.1,
    }
}

/// The same camera rendered at another resolution: focal length and
/// principal point scale with the width and height.
pub fn pinhole_at(camera: &campanile_config::Camera, width: usize, height: usize) -> Pinhole {
    let p = pinhole(camera);
    let sx = width as f64 / f64::from(camera.resolution.width);
    let sy = height as f64 / f64::from(camera.resolution.height);
    Pinhole {
        focal_px: p.focal_px * sx,
        principal_px: (p.principal_px.0 * sx, p.principal_px.1 * sy),
        ..p
    }
}

/// The mount calibration in radians.
pub fn mount(m: &MountCalibration) -> Mount {
    Mount {
        pan_zero_azimuth_rad: m.pan_zero_azimuth_deg.to_radians(),
        tilt_zero_rad: m.tilt_zero_deg.to_radians(),
        roll_rad: m.level_roll_deg.to_radians(),
        pitch_rad: m.level_pitch_deg.to_radians(),
    }
}
