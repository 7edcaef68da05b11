//! An Enttec DMX USB Pro as [`Lights`]: channel `n` here is DMX channel
//! `n + 1`; levels are scaled to 0..=255.

use crate::device::{DeviceError, Level, LightChannel, Lights};
use campanile_firmware_link::enttec::host::DmxUsbPro;
use std::time::Duration;
use tokio::io::{AsyncRead, AsyncWrite};

/// Dimmers on a DMX USB Pro.
#[derive(Debug)]
pub struct DmxLights<T> {
    widget: DmxUsbPro<T>,
    channels: u16,
}

impl<T: AsyncRead + AsyncWrite + Unpin + Send> DmxLights<T> {
    /// Dimmers on DMX channels 1..=`channels` (at most 512).
    pub fn new(io: T, channels: u16) -> Self {
        let channels = channels.clamp(1, 512);
        Self {
            widget: DmxUsbPro::new(io, usize::from(channels), Duration::from_millis(500)),
            channels,
        }
    }
}

impl<T: AsyncRead + AsyncWrite + Unpin + Send> DmxLights<T> {
    /// [`DmxLights::new`], then ask the widget for its serial number, which
    /// checks the link (sending DMX levels gets no answer).
    pub async fn connect(io: T, channels: u16) -> Result<Self, DeviceError> {
        let mut lights = Self::new(io, channels);
        let serial = lights.widget.serial_number().await?;
        tracing::debug!(serial, "DMX USB Pro connected");
        Ok(lights)
    }
}

impl<T: AsyncRead + AsyncWrite + Unpin + Send> Lights for DmxLights<T> {
    fn channels(&self) -> u16 {
        self.channels
    }

    async fn set_level(&mut self, channel: LightChannel, level: Level) -> Result<(), DeviceError> {
        if channel.0 >= self.channels {
            return Err(DeviceError::OutOfRange {
                what: "light channel",
                requested: f64::from(channel.0),
                min: 0.0,
                max: f64::from(self.channels) - 1.0,
            });
        }
        let v = (level.fraction() * 255.0).round() as u8;
        self.widget.set_level(channel.0 + 1, v).await?;
        Ok(())
    }

    async fn all_off(&mut self) -> Result<(), DeviceError> {
        self.widget.blackout().await?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use campanile_firmware_link::emulator::Emulator;
    use campanile_firmware_link::enttec::device::DmxDevice;
    use campanile_firmware_link::transport::memory::duplex;

    #[tokio::test(start_paused = true)]
    async fn levels_reach_the_universe() {
        let (host, dev) = duplex(4096);
        let emu = Emulator::spawn(DmxDevice::new(1), dev, Duration::from_millis(5));
        let mut l = DmxLights::new(host, 4);
        l.set_level(LightChannel(2), Level::new(0.5).unwrap()).await.unwrap();
        l.set_level(LightChannel(0), Level::FULL).await.unwrap();
        tokio::time::sleep(Duration::from_millis(20)).await;
        assert_eq!(&emu.firmware().universe()[..4], &[255, 0, 128, 0]);
        l.all_off().await.unwrap();
        tokio::time::sleep(Duration::from_millis(20)).await;
        assert_eq!(&emu.firmware().universe()[..4], &[0, 0, 0, 0]);
        assert!(matches!(
            l.set_level(LightChannel(4), Level::FULL).await,
            Err(DeviceError::OutOfRange { .. })
        ));
    }
}
