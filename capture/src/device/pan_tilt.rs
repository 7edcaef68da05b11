//! The pan-tilt head trait.

use super::{Angle, DeviceError, Pose};
use std::future::Future;
use std::time::Duration;

/// The range of one axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AxisRange {
    /// Lowest reachable angle.
    pub min: Angle,
    /// Highest reachable angle.
    pub max: Angle,
}

impl AxisRange {
    /// Whether `a` is within the range.
    pub fn contains(&self, a: Angle) -> bool {
        a >= self.min && a <= self.max
    }
}

/// What a head can reach, how finely, and where home is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PanTiltLimits {
    /// Pan range.
    pub pan: AxisRange,
    /// Tilt range.
    pub tilt: AxisRange,
    /// Smallest step either axis makes (positions are reported to within
    /// half of it).
    pub resolution: Angle,
    /// Where [`PanTilt::home`] goes.
    pub home: Pose,
}

impl PanTiltLimits {
    /// Whether `pose` is reachable.
    pub fn contains(&self, pose: &Pose) -> bool {
        self.pan.contains(pose.pan) && self.tilt.contains(pose.tilt)
    }

    /// `Ok` if `pose` is reachable, else the [`DeviceError::OutOfRange`]
    /// naming the first axis that is not.
    pub fn check(&self, pose: &Pose) -> Result<(), DeviceError> {
        for (what, a, r) in [("pan (deg)", pose.pan, self.pan), ("tilt (deg)", pose.tilt, self.tilt)] {
            if !r.contains(a) {
                return Err(DeviceError::OutOfRange {
                    what,
                    requested: a.degrees(),
                    min: r.min.degrees(),
                    max: r.max.degrees(),
                });
            }
        }
        Ok(())
    }
}

/// Where the head is and whether it is moving.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HeadStatus {
    /// Current pose.
    pub pose: Pose,
    /// Whether either axis is travelling.
    pub moving: bool,
}

/// A pan-tilt head.
///
/// Moves start and return at once; [`PanTilt::wait_idle`] waits for the head
/// to come to rest. A move outside [`PanTilt::limits`] fails with
/// [`DeviceError::OutOfRange`] and leaves the head where it was.
pub trait PanTilt: Send {
    /// Reachable ranges, resolution and home (known after connecting).
    fn limits(&self) -> PanTiltLimits;

    /// Start moving to `pose`.
    fn move_to(&mut self, pose: Pose) -> impl Future<Output = Result<(), DeviceError>> + Send;

    /// Where the head is now.
    fn status(&mut self) -> impl Future<Output = Result<HeadStatus, DeviceError>> + Send;

    /// Wait until the head is at rest (at most `limit`); returns its pose.
    fn wait_idle(&mut self, limit: Duration) -> impl Future<Output = Result<Pose, DeviceError>> + Send;

    /// Start moving to the home pose.
    fn home(&mut self) -> impl Future<Output = Result<(), DeviceError>> + Send;

    /// Halt at once; returns the pose where the head stopped.
    fn stop(&mut self) -> impl Future<Output = Result<Pose, DeviceError>> + Send;
}
