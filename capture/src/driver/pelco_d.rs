//! A Pelco-D head as a [`PanTilt`].
//!
//! Pelco-D reports neither limits nor motion, so the limits come from the
//! caller, and the head counts as moving until its queried position equals
//! the last commanded target. A lost motion command therefore shows up as a
//! [`DeviceError::Timeout`] in [`PanTilt::wait_idle`], never as a silent
//! wrong pose.

use crate::device::{Angle, AxisRange, DeviceError, HeadStatus, PanTilt, PanTiltLimits, Pose};
use campanile_firmware_link::pelco_d::host::PelcoD;
use std::time::Duration;
use tokio::io::{AsyncRead, AsyncWrite};
use tokio::time::Instant;

/// 1/100°, the protocol's angle unit, in degrees.
const CENTIDEG: f64 = 0.01;

fn to_cdeg(a: Angle) -> i32 {
    (a.degrees() / CENTIDEG).round() as i32
}

fn angle(cdeg: i32) -> Angle {
    Angle::from_degrees(f64::from(cdeg) * CENTIDEG)
}

/// `cdeg` or the same direction a turn away, whichever lies in `min..=max`
/// (`cdeg` itself if neither does).
fn into_range(cdeg: i32, min: Angle, max: Angle) -> i32 {
    let (lo, hi) = (to_cdeg(min), to_cdeg(max));
    [cdeg, cdeg + 36_000, cdeg - 36_000]
        .into_iter()
        .find(|v| (lo..=hi).contains(v))
        .unwrap_or(cdeg)
}

/// A Pelco-D head.
#[derive(Debug)]
pub struct PelcoHead<T> {
    driver: PelcoD<T>,
    limits: PanTiltLimits,
    target: (i32, i32),
}

impl<T: AsyncRead + AsyncWrite + Unpin + Send> PelcoHead<T> {
    /// A head at `address` with the given ranges (degrees) and home.
    pub fn new(io: T, address: u8, pan_deg: (f64, f64), tilt_deg: (f64, f64), home: Pose) -> Self {
        let r = |(lo, hi): (f64, f64)| AxisRange {
            min: Angle::from_degrees(lo),
            max: Angle::from_degrees(hi),
        };
        Self {
            driver: PelcoD::new(io, address, Duration::from_millis(200), 5),
            limits: PanTiltLimits {
                pan: r(pan_deg),
                tilt: r(tilt_deg),
                resolution: Angle::from_degrees(CENTIDEG),
                home,
            },
            target: (to_cdeg(home.pan), to_cdeg(home.tilt)),
        }
    }

    /// [`PelcoHead::new`], then ask the head where it is, which checks the
    /// link (Pelco-D has no handshake) and makes that pose the target, so
    /// a head reconnected mid-session does not count as moving.
    pub async fn connect(
        io: T,
        address: u8,
        pan_deg: (f64, f64),
        tilt_deg: (f64, f64),
        home: Pose,
    ) -> Result<Self, DeviceError> {
        let mut head = Self::new(io, address, pan_deg, tilt_deg, home);
        head.target = head.position().await?;
        Ok(head)
    }

    /// Where the head is, 1/100°. The wire carries angles modulo a turn
    /// (reported in −180°..180°); each is moved by a whole turn into the
    /// configured range where that puts it there, so a head whose pan runs
    /// 0°..360° reports 200°, not −160°.
    async fn position(&mut self) -> Result<(i32, i32), DeviceError> {
        let (p, t) = (self.driver.pan().await?, self.driver.tilt().await?);
        Ok((
            into_range(p, self.limits.pan.min, self.limits.pan.max),
            into_range(t, self.limits.tilt.min, self.limits.tilt.max),
        ))
    }
}

impl<T: AsyncRead + AsyncWrite + Unpin + Send> PanTilt for PelcoHead<T> {
    fn limits(&self) -> PanTiltLimits {
        self.limits
    }

    async fn move_to(&mut self, pose: Pose) -> Result<(), DeviceError> {
        self.limits.check(&pose)?;
        let (p, t) = (to_cdeg(pose.pan), to_cdeg(pose.tilt));
        self.driver.goto(p, t).await?;
        self.target = (p, t);
        Ok(())
    }

    async fn status(&mut self) -> Result<HeadStatus, DeviceError> {
        let (p, t) = self.position().await?;
        Ok(HeadStatus {
            pose: Pose {
                pan: angle(p),
                tilt: angle(t),
            },
            moving: (p, t) != self.target,
        })
    }

    async fn wait_idle(&mut self, limit: Duration) -> Result<Pose, DeviceError> {
        let end = Instant::now() + limit;
        loop {
            let s = self.status().await?;
            if !s.moving {
                return Ok(s.pose);
            }
            if Instant::now() >= end {
                return Err(DeviceError::Timeout(format!(
                    "head at {:?} has not reached its target within {limit:?}",
                    s.pose
                )));
            }
            tokio::time::sleep(super::POLL).await;
        }
    }

    async fn home(&mut self) -> Result<(), DeviceError> {
        let home = self.limits.home;
        self.move_to(home).await
    }

    async fn stop(&mut self) -> Result<Pose, DeviceError> {
        self.driver.stop().await?;
        let (p, t) = self.position().await?;
        self.target = (p, t);
        Ok(Pose {
            pan: angle(p),
            tilt: angle(t),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wire_angles_move_into_the_configured_range() {
        let a = Angle::from_degrees;
        // Pan 0..359.99°: −160° is 200°.
        assert_eq!(into_range(-16_000, a(0.0), a(359.99)), 20_000);
        assert_eq!(into_range(0, a(0.0), a(359.99)), 0);
        // Pan ±180°: unchanged.
        assert_eq!(into_range(-16_000, a(-180.0), a(180.0)), -16_000);
        // Outside any turn of the range: unchanged.
        assert_eq!(into_range(5_000, a(-10.0), a(10.0)), 5_000);
    }
    use crate::conformance::pan_tilt::{Options, run};
    use campanile_firmware_link::emulator::Emulator;
    use campanile_firmware_link::pelco_d::device::{PelcoConfig, PelcoDevice};
    use campanile_firmware_link::transport::serial;

    /// The conformance suite through a real pseudo-terminal.
    #[tokio::test]
    async fn conforms_over_a_real_pty() {
        let (controller, device_end) = serial::pty_pair().unwrap();
        let port = serial::open(&serial::device_path(&device_end).unwrap(), 9600).unwrap();
        drop(device_end);
        let cfg = PelcoConfig {
            speed: 90_000,
            ..PelcoConfig::default()
        };
        let _emu = Emulator::spawn(PelcoDevice::new(cfg), controller, Duration::from_millis(2));
        let mut head = PelcoHead::new(port, 1, (-179.99, 179.99), (-90.0, 90.0), Pose::default());
        let options = Options {
            move_limit: Duration::from_secs(5),
            settle: Duration::from_millis(100),
        };
        let report = run(&mut head, options).await;
        assert!(report.passed(), "{report}");
    }
}
