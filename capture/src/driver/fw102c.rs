//! A Thorlabs FW102C as a [`FilterWheel`] (slots 0-based here, 1-based on
//! the wire).

use crate::device::{DeviceError, FilterWheel};
use campanile_firmware_link::fw102c::host::Fw102c;
use std::time::Duration;
use tokio::io::{AsyncRead, AsyncWrite};

/// An FW102C filter wheel.
#[derive(Debug)]
pub struct Fw102cWheel<T> {
    wheel: Fw102c<T>,
    slots: u8,
}

impl<T: AsyncRead + AsyncWrite + Unpin + Send> Fw102cWheel<T> {
    /// Connect: ask the wheel how many positions it has.
    pub async fn connect(io: T) -> Result<Self, DeviceError> {
        let mut wheel = Fw102c::new(io, Duration::from_secs(2));
        let slots = wheel.count().await?;
        Ok(Self { wheel, slots })
    }
}

impl<T: AsyncRead + AsyncWrite + Unpin + Send> FilterWheel for Fw102cWheel<T> {
    fn slots(&self) -> u8 {
        self.slots
    }

    async fn select(&mut self, slot: u8) -> Result<(), DeviceError> {
        if slot >= self.slots {
            return Err(DeviceError::OutOfRange {
                what: "filter slot",
                requested: f64::from(slot),
                min: 0.0,
                max: f64::from(self.slots) - 1.0,
            });
        }
        self.wheel.set_position(slot + 1).await?;
        Ok(())
    }

    async fn current(&mut self) -> Result<u8, DeviceError> {
        Ok(self.wheel.position().await?.saturating_sub(1))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use campanile_firmware_link::emulator::Emulator;
    use campanile_firmware_link::fw102c::device::WheelDevice;
    use campanile_firmware_link::transport::memory::duplex;

    #[tokio::test(start_paused = true)]
    async fn selects_through_the_trait() {
        let (host, dev) = duplex(1024);
        let emu = Emulator::spawn(WheelDevice::new(12), dev, Duration::from_millis(5));
        let mut w = Fw102cWheel::connect(host).await.unwrap();
        assert_eq!(w.slots(), 12);
        w.select(11).await.unwrap();
        assert_eq!(w.current().await.unwrap(), 11);
        assert_eq!(emu.firmware().position(), 12);
        assert!(matches!(w.select(12).await, Err(DeviceError::OutOfRange { .. })));
    }
}
