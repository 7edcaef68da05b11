//! The station's camera geometry in the processing crate's terms.

use campanile_config::head::MountCalibration;
use campanile_process::pose::{Mount, Pinhole};

/// The pinhole model of a configured camera at its configured resolution.
pub fn pinhole(camera: &campanile_config::Camera) -> Pinhole {
    Pinhole::of_camera(camera)
}

/// The same camera rendered at another resolution: focal length and
/// principal point scale with the width and height.
pub fn pinhole_at(camera: &campanile_config::Camera, width: usize, height: usize) -> Pinhole {
    let full = (camera.resolution.width as usize, camera.resolution.height as usize);
    Pinhole::of_camera(camera).rescaled(full, width, height)
}

/// The mount calibration in radians.
pub fn mount(m: &MountCalibration) -> Mount {
    Mount::of_calibration(m)
}
