//! The lights trait.

use super::{DeviceError, Level};
use std::future::Future;

/// A light channel, 0-based.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct LightChannel(pub u16);

/// A set of dimmable lights.
pub trait Lights: Send {
    /// Number of channels.
    fn channels(&self) -> u16;

    /// Set one channel's level.
    fn set_level(
        &mut self,
        channel: LightChannel,
        level: Level,
    ) -> impl Future<Output = Result<(), DeviceError>> + Send;

    /// Turn every channel off.
    fn all_off(&mut self) -> impl Future<Output = Result<(), DeviceError>> + Send;
}
