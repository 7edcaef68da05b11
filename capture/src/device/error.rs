//! What a device operation can fail with.

use campanile_firmware_link::driver_error::DriverError;
use thiserror::Error;

/// An error from a device trait method.
#[derive(Debug, Error)]
pub enum DeviceError {
    /// The request lies outside what the device can do; nothing was sent
    /// or the device refused it, and the device did not move.
    #[error("{what} = {requested} is outside {min}..={max}")]
    OutOfRange {
        /// The quantity and its unit, e.g. `"pan (deg)"`.
        what: &'static str,
        /// The requested value.
        requested: f64,
        /// Lowest allowed.
        min: f64,
        /// Highest allowed.
        max: f64,
    },
    /// The device has no such capability.
    #[error("this device cannot {0}")]
    Unsupported(&'static str),
    /// The device did not reach the requested state in time.
    #[error("timed out: {0}")]
    Timeout(String),
    /// The camera reported a failure (a bad frame, a driver error); the
    /// message is the camera's.
    #[error("camera failure: {0}")]
    Camera(String),
    /// The link to the device failed.
    #[error(transparent)]
    Link(#[from] DriverError),
}
