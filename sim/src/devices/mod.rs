//! Device-side emulators of the head, filter wheel and lights, built from
//! the station config for whichever protocol it names, each behind a
//! simulated port ([`port::DevicePort`]) and reached by `capture`'s host
//! driver through an in-memory link (with the config's seeded byte faults).
//!
//! [`DeviceTruth`] reads the emulators' ground truth (true head angles,
//! wheel slot, light levels), which the camera renders with.

pub mod head;
pub mod lights;
pub mod port;
pub mod wheel;

use campanile_process::pose::HeadPose;

/// Ground truth of the simulated devices, shared with the camera. Absent
/// devices read as: head at (0, 0), no filter (slot `None`), no lights.
#[derive(Debug, Clone, Default)]
pub struct DeviceTruth {
    /// The head.
    pub head: Option<head::HeadPort>,
    /// The filter wheel.
    pub wheel: Option<wheel::WheelPort>,
    /// The lights.
    pub lights: Option<lights::LightsPort>,
}

impl DeviceTruth {
    /// The head's true mechanical angles.
    pub fn head_pose(&self) -> HeadPose {
        self.head.as_ref().map_or(
            HeadPose {
                pan_rad: 0.0,
                tilt_rad: 0.0,
            },
            head::HeadPort::true_pose,
        )
    }

    /// The filter slot in place, 0-based.
    pub fn wheel_slot(&self) -> Option<usize> {
        self.wheel.as_ref().map(wheel::WheelPort::slot)
    }

    /// Light levels in the config's channel order.
    pub fn light_levels(&self) -> Vec<f64> {
        self.lights.as_ref().map(lights::LightsPort::levels).unwrap_or_default()
    }
}
