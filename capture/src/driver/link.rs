//! A campanile-link controller: head, filter wheel and lights on one line.

use crate::device::{
    Angle, AxisRange, DeviceError, FilterWheel, HeadStatus, Level, LightChannel, Lights, PanTilt, PanTiltLimits, Pose,
};
use campanile_firmware_link::driver_error::DriverError;
use campanile_firmware_link::link::host::{LinkClient, RetryPolicy};
use campanile_firmware_link::link::message::{DeviceInfo, HeadState};
use std::time::Duration;
use tokio::io::{AsyncRead, AsyncWrite};

/// One microradian, the protocol's angle unit.
const URAD: f64 = 1e-6;

fn to_urad(a: Angle) -> i32 {
    (a.radians() / URAD).round() as i32
}

fn pose_of(s: &HeadState) -> Pose {
    Pose {
        pan: Angle::from_radians(f64::from(s.pan) * URAD),
        tilt: Angle::from_radians(f64::from(s.tilt) * URAD),
    }
}

/// A campanile-link device. Its home pose is (0, 0).
#[derive(Debug)]
pub struct LinkController<T> {
    client: LinkClient<T>,
    info: DeviceInfo,
    limits: PanTiltLimits,
}

impl<T: AsyncRead + AsyncWrite + Unpin + Send> LinkController<T> {
    /// Connect: ask the device for its identity and limits.
    pub async fn connect(io: T, policy: RetryPolicy, initial_seq: u16) -> Result<Self, DeviceError> {
        let mut client = LinkClient::new(io, policy, initial_seq);
        let info = client.info().await?;
        let r = |lo: i32, hi: i32| AxisRange {
            min: Angle::from_radians(f64::from(lo) * URAD),
            max: Angle::from_radians(f64::from(hi) * URAD),
        };
        let limits = PanTiltLimits {
            pan: r(info.pan_min, info.pan_max),
            tilt: r(info.tilt_min, info.tilt_max),
            resolution: Angle::from_radians(URAD),
            home: Pose::default(),
        };
        Ok(Self { client, info, limits })
    }

    /// The device's identity.
    pub fn info(&self) -> DeviceInfo {
        self.info
    }

    /// The protocol client (statistics, events, raw requests).
    pub fn client(&mut self) -> &mut LinkClient<T> {
        &mut self.client
    }
}

impl<T: AsyncRead + AsyncWrite + Unpin + Send> PanTilt for LinkController<T> {
    fn limits(&self) -> PanTiltLimits {
        self.limits
    }

    async fn move_to(&mut self, pose: Pose) -> Result<(), DeviceError> {
        self.limits.check(&pose)?;
        self.client.move_to(to_urad(pose.pan), to_urad(pose.tilt)).await?;
        Ok(())
    }

    async fn status(&mut self) -> Result<HeadStatus, DeviceError> {
        let s = self.client.head().await?;
        Ok(HeadStatus {
            pose: pose_of(&s),
            moving: s.moving(),
        })
    }

    async fn wait_idle(&mut self, limit: Duration) -> Result<Pose, DeviceError> {
        match self.client.wait_idle(super::POLL, limit).await {
            Ok(s) => Ok(pose_of(&s)),
            Err(DriverError::Timeout { .. }) => Err(DeviceError::Timeout(format!("head still moving after {limit:?}"))),
            Err(e) => Err(e.into()),
        }
    }

    async fn home(&mut self) -> Result<(), DeviceError> {
        self.client.home().await?;
        Ok(())
    }

    async fn stop(&mut self) -> Result<Pose, DeviceError> {
        Ok(pose_of(&self.client.stop().await?))
    }
}

impl<T: AsyncRead + AsyncWrite + Unpin + Send> FilterWheel for LinkController<T> {
    fn slots(&self) -> u8 {
        self.info.filter_slots
    }

    async fn select(&mut self, slot: u8) -> Result<(), DeviceError> {
        if slot >= self.info.filter_slots {
            return Err(DeviceError::OutOfRange {
                what: "filter slot",
                requested: f64::from(slot),
                min: 0.0,
                max: f64::from(self.info.filter_slots) - 1.0,
            });
        }
        self.client.select_filter(slot).await?;
        Ok(())
    }

    async fn current(&mut self) -> Result<u8, DeviceError> {
        Ok(self.client.filter().await?.slot)
    }
}

impl<T: AsyncRead + AsyncWrite + Unpin + Send> Lights for LinkController<T> {
    fn channels(&self) -> u16 {
        u16::from(self.info.light_channels)
    }

    async fn set_level(&mut self, channel: LightChannel, level: Level) -> Result<(), DeviceError> {
        let n = self.channels();
        let Some(ch) = u8::try_from(channel.0).ok().filter(|_| channel.0 < n) else {
            return Err(DeviceError::OutOfRange {
                what: "light channel",
                requested: f64::from(channel.0),
                min: 0.0,
                max: f64::from(n) - 1.0,
            });
        };
        let raw = (level.fraction() * 65_535.0).round() as u16;
        self.client.set_light(ch, raw).await?;
        Ok(())
    }

    async fn all_off(&mut self) -> Result<(), DeviceError> {
        self.client.all_lights_off().await?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use campanile_firmware_link::emulator::Emulator;
    use campanile_firmware_link::link::device::{DeviceConfig, Effect, LinkDevice};
    use campanile_firmware_link::transport::memory::duplex;

    #[tokio::test(start_paused = true)]
    async fn wheel_and_lights_through_the_traits() {
        let (host, dev) = duplex(4096);
        let emu = Emulator::spawn(LinkDevice::new(DeviceConfig::default()), dev, Duration::from_millis(5));
        let mut c = LinkController::connect(host, RetryPolicy::default(), 1).await.unwrap();
        assert_eq!((c.slots(), c.channels()), (6, 4));
        c.select(4).await.unwrap();
        assert_eq!(c.current().await.unwrap(), 4);
        assert!(matches!(c.select(6).await, Err(DeviceError::OutOfRange { .. })));
        c.set_level(LightChannel(1), Level::new(0.5).unwrap()).await.unwrap();
        assert!(matches!(
            c.set_level(LightChannel(4), Level::FULL).await,
            Err(DeviceError::OutOfRange { .. })
        ));
        assert_eq!(emu.firmware().light_levels(), &[0, 32_768, 0, 0]);
        c.all_off().await.unwrap();
        assert_eq!(emu.firmware().light_levels(), &[0, 0, 0, 0]);
        assert_eq!(
            emu.effects().as_slice(),
            &[
                Effect::FilterSelect(4),
                Effect::LightLevel {
                    channel: 1,
                    level: 32_768
                },
                Effect::LightsAllOff
            ]
        );
    }

    /// The conformance suite through a real pseudo-terminal: the emulator on
    /// the controlling end, the driver on the device end opened by path.
    #[tokio::test]
    async fn conforms_over_a_real_pty() {
        use crate::conformance::pan_tilt::{Options, run};
        use campanile_firmware_link::transport::serial;
        let (controller, device_end) = serial::pty_pair().unwrap();
        let path = serial::device_path(&device_end).unwrap();
        let port = serial::open(&path, 115_200).unwrap();
        drop(device_end);
        let cfg = DeviceConfig {
            speed: 16_000_000,
            ..DeviceConfig::default()
        };
        let _emu = Emulator::spawn(LinkDevice::new(cfg), controller, Duration::from_millis(2));
        let mut head = LinkController::connect(port, RetryPolicy::default(), 5).await.unwrap();
        let options = Options {
            move_limit: Duration::from_secs(5),
            settle: Duration::from_millis(100),
        };
        let report = run(&mut head, options).await;
        assert!(report.passed(), "{report}");
    }
}
