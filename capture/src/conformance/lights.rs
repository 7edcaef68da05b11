//! Conformance suite for any [`Lights`]: every listed channel takes a
//! level and off, all off works, and a channel past the last is refused.
//! (The trait cannot read levels back; a person watching the lamps sees
//! each come on at half and go off, in order.)

use super::Report;
use crate::device::{DeviceError, Level, LightChannel, Lights};

async fn check_channels<L: Lights>(lights: &mut L, channels: &[LightChannel]) -> Result<(), String> {
    if channels.is_empty() {
        return Err("no channels to check".into());
    }
    let half = Level::new(0.5).ok_or("0.5 is a level")?;
    for &c in channels {
        lights
            .set_level(c, half)
            .await
            .map_err(|e| format!("channel {} at half: {e}", c.0))?;
        lights
            .set_level(c, Level::OFF)
            .await
            .map_err(|e| format!("channel {} off: {e}", c.0))?;
    }
    lights.all_off().await.map_err(|e| format!("all off: {e}"))
}

async fn check_out_of_range<L: Lights>(lights: &mut L) -> Result<(), String> {
    let n = lights.channels();
    match lights.set_level(LightChannel(n), Level::FULL).await {
        Err(DeviceError::OutOfRange { .. }) => Ok(()),
        Ok(()) => Err(format!("channel {n} of {n} channels was accepted")),
        Err(e) => Err(format!("channel {n}: expected OutOfRange, got {e}")),
    }
}

/// Run every check on `lights`, exercising `channels` (the station's lamps).
pub async fn run<L: Lights>(lights: &mut L, channels: &[LightChannel]) -> Report {
    let mut r = Report::default();
    r.record(
        "channels: each at half, then off; all off",
        check_channels(lights, channels).await,
    );
    r.record(
        "out of range: refused with OutOfRange",
        check_out_of_range(lights).await,
    );
    r
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::driver::enttec::DmxLights;
    use campanile_firmware_link::emulator::Emulator;
    use campanile_firmware_link::enttec::device::DmxDevice;
    use campanile_firmware_link::transport::memory::duplex;
    use std::time::Duration;

    #[tokio::test(start_paused = true)]
    async fn dmx_usb_pro_conforms_and_ends_dark() {
        let (host, dev) = duplex(4096);
        let emu = Emulator::spawn(DmxDevice::new(7), dev, Duration::from_millis(5));
        let mut l = DmxLights::connect(host, 3).await.unwrap();
        let report = run(&mut l, &[LightChannel(0), LightChannel(1), LightChannel(2)]).await;
        assert!(report.passed(), "{report}");
        tokio::time::sleep(Duration::from_millis(20)).await;
        assert_eq!(&emu.firmware().universe()[..3], &[0, 0, 0]);
    }
}
