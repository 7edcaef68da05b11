//! Seeded fault plans for the simulated station.
//!
//! - **Link faults**: bytes dropped or corrupted on a device's serial link,
//!   through firmware-link's [`FaultyStream`](campanile_firmware_link::transport::fault::FaultyStream)
//!   wrapped around the host end. By default the chances come from the
//!   station config's `simulation` section; [`FaultPlan::link`] overrides
//!   them. Each connection of each device draws from its own seed.
//! - **Camera faults** ([`CameraFaultPlan`]): a frame that never arrives
//!   (the capture call blocks for the exposure, the readout and the
//!   camera's frame timeout, then returns
//!   [`DeviceError::Timeout`](campanile_capture::device::DeviceError::Timeout))
//!   or a camera error (after the exposure and readout,
//!   [`DeviceError::Camera`](campanile_capture::device::DeviceError::Camera)).
//!   Faults are chosen per frame sequence number, by list or by seeded
//!   chance, so a retry (the next sequence number) draws anew.
//! - **Outages** ([`Outage`]): a device disappears (its host stream sees
//!   end of file, writes fail with `BrokenPipe`, and opening its port
//!   fails) for a simulated duration, then comes back; the host must
//!   reconnect (see [`crate::station::SimStation::reconnect_head`]).
//!
//! A disk that fills up is in [`crate::disk`].

use crate::seed::{Purpose, derive, uniform};
use campanile_firmware_link::transport::fault::FaultConfig;
use std::time::Duration;

/// What goes wrong with one frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CameraFault {
    /// The frame never arrives: the capture returns `DeviceError::Timeout`
    /// after the exposure, the readout and the frame timeout.
    Timeout,
    /// The camera reports an error after the exposure and readout.
    Error,
}

/// Which camera frames fail, and how.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct CameraFaultPlan {
    /// Seed of the chance draws.
    pub seed: u64,
    /// Chance that any one frame times out, in [0, 1].
    pub timeout_chance: f64,
    /// Chance that any one frame fails with a camera error, in [0, 1].
    pub error_chance: f64,
    /// Frame sequence numbers that time out.
    pub timeout_on: Vec<u64>,
    /// Frame sequence numbers that fail with a camera error.
    pub error_on: Vec<u64>,
}

impl CameraFaultPlan {
    /// No camera faults.
    pub fn none() -> Self {
        Self::default()
    }

    /// The fault, if any, of the frame with this sequence number.
    pub fn fault_for(&self, sequence: u64) -> Option<CameraFault> {
        if self.timeout_on.contains(&sequence) {
            return Some(CameraFault::Timeout);
        }
        if self.error_on.contains(&sequence) {
            return Some(CameraFault::Error);
        }
        let u = uniform(derive(self.seed, Purpose::CameraFaults, sequence));
        if u < self.timeout_chance {
            Some(CameraFault::Timeout)
        } else if u < self.timeout_chance + self.error_chance {
            Some(CameraFault::Error)
        } else {
            None
        }
    }
}

/// A simulated device.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Device {
    /// The pan-tilt head.
    Head,
    /// The filter wheel.
    Wheel,
    /// The light controller.
    Lights,
}

/// A device that disconnects `after` the station starts, for `duration`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Outage {
    /// Which device.
    pub device: Device,
    /// When, after the station starts.
    pub after: Duration,
    /// For how long it is absent.
    pub duration: Duration,
}

/// Byte-fault chances for the serial links.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct LinkFaults {
    /// Chance that a byte is dropped, in [0, 0.5].
    pub drop_chance: f64,
    /// Chance that a byte is corrupted, in [0, 0.5].
    pub corrupt_chance: f64,
}

impl LinkFaults {
    /// The firmware-link fault configuration with `seed`.
    pub fn config(&self, seed: u64) -> FaultConfig {
        FaultConfig {
            drop_chance: self.drop_chance.clamp(0.0, 0.5),
            corrupt_chance: self.corrupt_chance.clamp(0.0, 0.5),
            ..FaultConfig::none(seed)
        }
    }
}

/// Everything that will go wrong in a simulated station.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct FaultPlan {
    /// Camera faults.
    pub camera: CameraFaultPlan,
    /// Scheduled device outages.
    pub outages: Vec<Outage>,
    /// Link faults; `None` takes the station config's `simulation` chances.
    pub link: Option<LinkFaults>,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn listed_frames_fail_and_chances_match_within_3_sigma() {
        let plan = CameraFaultPlan {
            seed: 4,
            timeout_chance: 0.1,
            error_chance: 0.05,
            timeout_on: vec![3],
            error_on: vec![5],
        };
        assert_eq!(plan.fault_for(3), Some(CameraFault::Timeout));
        assert_eq!(plan.fault_for(5), Some(CameraFault::Error));
        let n = 20_000u64;
        let (mut t, mut e) = (0u64, 0u64);
        for s in 100..100 + n {
            match plan.fault_for(s) {
                Some(CameraFault::Timeout) => t += 1,
                Some(CameraFault::Error) => e += 1,
                None => {}
            }
        }
        // Binomial σ: √(n p (1−p)) ≈ 42 and 31 frames.
        assert!((t as f64 - 2000.0).abs() < 3.0 * 42.5, "{t}");
        assert!((e as f64 - 1000.0).abs() < 3.0 * 30.9, "{e}");
        assert_eq!(CameraFaultPlan::none().fault_for(3), None);
    }
}
