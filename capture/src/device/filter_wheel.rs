//! The filter wheel trait.

use super::DeviceError;
use std::future::Future;

/// A filter wheel with numbered slots (0-based here, whatever the device
/// counts from).
pub trait FilterWheel: Send {
    /// Number of slots.
    fn slots(&self) -> u8;

    /// Turn to `slot` and return once it is in place.
    fn select(&mut self, slot: u8) -> impl Future<Output = Result<(), DeviceError>> + Send;

    /// The slot in place.
    fn current(&mut self) -> impl Future<Output = Result<u8, DeviceError>> + Send;
}
