//! What assembling or reconnecting simulated devices can fail with.

use campanile_capture::device::DeviceError;
use thiserror::Error;

/// An error from the simulator.
#[derive(Debug, Error)]
pub enum SimError {
    /// The station config asks for something the simulator cannot emulate.
    #[error("the simulator cannot emulate {0}")]
    Unsupported(String),
    /// A simulated device's port cannot be opened (it is disconnected).
    #[error("cannot open {port}: {error}")]
    Open {
        /// The port, e.g. `sim:head`.
        port: String,
        /// Why (in the message, so not also a source to print twice).
        error: std::io::Error,
    },
    /// The host driver failed to connect to a simulated device.
    #[error("connecting to {port}: {error}")]
    Connect {
        /// The port, e.g. `sim:head`.
        port: String,
        /// Why (in the message, so not also a source to print twice).
        error: DeviceError,
    },
}
