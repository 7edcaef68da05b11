//! Opening the station's camera with the driver its config names, as far
//! as this build has it (the V4L2 and nokhwa drivers are cargo features).

use crate::device::DeviceError;
use crate::driver::camera_thread::ThreadedCamera;
use campanile_config::camera::{Camera as CameraConfig, CameraDriver};

/// The camera `config` describes, open on its own thread; a clear error if
/// this build lacks its driver or the camera cannot be set up.
pub fn open_camera(config: &CameraConfig) -> Result<ThreadedCamera, DeviceError> {
    match config.driver {
        CameraDriver::Sim => Err(DeviceError::Camera(
            "the `Sim` camera exists only in the simulator; a real station names `V4l` or `Nokhwa`".into(),
        )),
        CameraDriver::V4l => open_v4l(config),
        CameraDriver::Nokhwa => open_nokhwa(config),
    }
}

#[cfg(feature = "v4l")]
fn open_v4l(config: &CameraConfig) -> Result<ThreadedCamera, DeviceError> {
    crate::driver::v4l2::open(config, crate::driver::v4l2::V4l2Options::default())
}

#[cfg(not(feature = "v4l"))]
fn open_v4l(_: &CameraConfig) -> Result<ThreadedCamera, DeviceError> {
    Err(DeviceError::Camera(
        "this campanile was built without the V4L2 camera driver; rebuild with `--features v4l` (needs libclang)"
            .into(),
    ))
}

#[cfg(feature = "nokhwa")]
fn open_nokhwa(config: &CameraConfig) -> Result<ThreadedCamera, DeviceError> {
    crate::driver::nokhwa_camera::open(config)
}

#[cfg(not(feature = "nokhwa"))]
fn open_nokhwa(_: &CameraConfig) -> Result<ThreadedCamera, DeviceError> {
    Err(DeviceError::Camera(
        "this campanile was built without the nokhwa camera driver; rebuild with `--features nokhwa` (needs libclang)"
            .into(),
    ))
}
