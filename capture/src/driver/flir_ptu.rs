//! A FLIR PTU as a [`PanTilt`]: limits and resolution are read from the
//! unit at connection (`PN`/`PX`/`TN`/`TX`, `PR`).

use crate::device::{Angle, AxisRange, DeviceError, HeadStatus, PanTilt, PanTiltLimits, Pose};
use campanile_firmware_link::driver_error::DriverError;
use campanile_firmware_link::flir_ptu::host::Ptu;
use campanile_firmware_link::flir_ptu::{Axis, Query, Setting};
use std::time::Duration;
use tokio::io::{AsyncRead, AsyncWrite};

/// A FLIR PTU. Home is position (0, 0).
#[derive(Debug)]
pub struct FlirHead<T> {
    ptu: Ptu<T>,
    limits: PanTiltLimits,
    /// Radians per step.
    step: f64,
    target: (i64, i64),
}

impl<T: AsyncRead + AsyncWrite + Unpin + Send> FlirHead<T> {
    /// Connect: echo off, terse mode, then read limits and resolution.
    pub async fn connect(io: T) -> Result<Self, DeviceError> {
        let mut ptu = Ptu::new(io, Duration::from_millis(500));
        ptu.init().await?;
        let res = ptu.resolution_milli_arcsec(Axis::Pan).await?;
        let step = Angle::from_degrees(res as f64 / 1000.0 / 3600.0).radians();
        let pan_min = ptu.get(Axis::Pan, Query::Min).await?;
        let pan_max = ptu.get(Axis::Pan, Query::Max).await?;
        let tilt_min = ptu.get(Axis::Tilt, Query::Min).await?;
        let tilt_max = ptu.get(Axis::Tilt, Query::Max).await?;
        let pan = ptu.get(Axis::Pan, Query::Position).await?;
        let tilt = ptu.get(Axis::Tilt, Query::Position).await?;
        let a = |s: i64| Angle::from_radians(s as f64 * step);
        Ok(Self {
            ptu,
            limits: PanTiltLimits {
                pan: AxisRange {
                    min: a(pan_min),
                    max: a(pan_max),
                },
                tilt: AxisRange {
                    min: a(tilt_min),
                    max: a(tilt_max),
                },
                resolution: Angle::from_radians(step),
                home: Pose::default(),
            },
            step,
            target: (pan, tilt),
        })
    }

    fn steps(&self, a: Angle) -> i64 {
        (a.radians() / self.step).round() as i64
    }

    fn pose(&self, p: i64, t: i64) -> Pose {
        Pose {
            pan: Angle::from_radians(p as f64 * self.step),
            tilt: Angle::from_radians(t as f64 * self.step),
        }
    }

    fn steps_i32(v: i64) -> Result<i32, DeviceError> {
        i32::try_from(v).map_err(|_| DeviceError::Link(DriverError::Protocol(format!("{v} steps"))))
    }
}

impl<T: AsyncRead + AsyncWrite + Unpin + Send> PanTilt for FlirHead<T> {
    fn limits(&self) -> PanTiltLimits {
        self.limits
    }

    async fn move_to(&mut self, pose: Pose) -> Result<(), DeviceError> {
        self.limits.check(&pose)?;
        let (p, t) = (self.steps(pose.pan), self.steps(pose.tilt));
        self.ptu.set(Axis::Pan, Setting::Position, Self::steps_i32(p)?).await?;
        self.ptu.set(Axis::Tilt, Setting::Position, Self::steps_i32(t)?).await?;
        self.target = (p, t);
        Ok(())
    }

    async fn status(&mut self) -> Result<HeadStatus, DeviceError> {
        let p = self.ptu.get(Axis::Pan, Query::Position).await?;
        let t = self.ptu.get(Axis::Tilt, Query::Position).await?;
        Ok(HeadStatus {
            pose: self.pose(p, t),
            moving: (p, t) != self.target,
        })
    }

    async fn wait_idle(&mut self, limit: Duration) -> Result<Pose, DeviceError> {
        match self.ptu.await_motion(limit).await {
            Ok(()) => Ok(self.status().await?.pose),
            Err(DriverError::Timeout { .. }) => Err(DeviceError::Timeout(format!("head still moving after {limit:?}"))),
            Err(e) => Err(e.into()),
        }
    }

    async fn home(&mut self) -> Result<(), DeviceError> {
        let home = self.limits.home;
        self.move_to(home).await
    }

    async fn stop(&mut self) -> Result<Pose, DeviceError> {
        self.ptu.halt().await?;
        let s = self.status().await?;
        self.target = (self.steps(s.pose.pan), self.steps(s.pose.tilt));
        Ok(s.pose)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::conformance::pan_tilt::{Options, run};
    use campanile_firmware_link::emulator::Emulator;
    use campanile_firmware_link::flir_ptu::device::{PtuConfig, PtuDevice};
    use campanile_firmware_link::transport::serial;

    /// The conformance suite through a real pseudo-terminal.
    #[tokio::test]
    async fn conforms_over_a_real_pty() {
        let (controller, device_end) = serial::pty_pair().unwrap();
        let port = serial::open(&serial::device_path(&device_end).unwrap(), 9600).unwrap();
        drop(device_end);
        let cfg = PtuConfig {
            speed: 16_000,
            ..PtuConfig::default()
        };
        let _emu = Emulator::spawn(PtuDevice::new(cfg), controller, Duration::from_millis(2));
        let mut head = FlirHead::connect(port).await.unwrap();
        let options = Options {
            move_limit: Duration::from_secs(5),
            settle: Duration::from_millis(100),
        };
        let report = run(&mut head, options).await;
        assert!(report.passed(), "{report}");
    }
}
