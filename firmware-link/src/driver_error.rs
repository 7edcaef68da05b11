//! What can go wrong when a host driver talks to a device.

use thiserror::Error;

/// An error from a host driver.
#[derive(Debug, Error)]
pub enum DriverError {
    /// The transport failed.
    #[error("I/O error on the device link: {0}")]
    Io(#[from] std::io::Error),
    /// The device did not answer in time, after every retry.
    #[error("no valid reply after {attempts} attempt(s)")]
    Timeout {
        /// Attempts made.
        attempts: u32,
    },
    /// The far end closed the link.
    #[error("the device link was closed")]
    Disconnected,
    /// The device refused the command.
    #[error("the device refused the command: {0}")]
    Rejected(String),
    /// The device answered something the protocol does not allow here.
    #[error("unexpected reply from the device: {0}")]
    Protocol(String),
    /// A requested value is outside what the device accepts.
    #[error("{what} = {value} is outside {min}..={max}")]
    OutOfRange {
        /// The quantity, with its unit.
        what: &'static str,
        /// The requested value.
        value: i64,
        /// Lowest allowed.
        min: i64,
        /// Highest allowed.
        max: i64,
    },
}
