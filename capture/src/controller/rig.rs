//! The devices the controller drives, as one [`Rig`]: the camera, the head,
//! an optional filter wheel and optional lights, plus the hooks a station
//! offers beyond the device traits (reconnecting a device that dropped,
//! and, for the simulator only, moving the tripod and numbering frames).

use crate::device::{Camera, DeviceError, FilterWheel, LightChannel, Lights, PanTilt};
use std::fmt;
use std::future::Future;

/// Which device a failure came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum DeviceKind {
    /// The camera.
    Camera,
    /// The pan-tilt head.
    Head,
    /// The filter wheel.
    Wheel,
    /// The lights.
    Lights,
}

impl fmt::Display for DeviceKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            DeviceKind::Camera => "camera",
            DeviceKind::Head => "head",
            DeviceKind::Wheel => "filter wheel",
            DeviceKind::Lights => "lights",
        })
    }
}

/// A station's devices and hooks.
pub trait Rig: Send {
    /// The camera.
    type Camera: Camera;
    /// The head.
    type Head: PanTilt;
    /// The filter wheel.
    type Wheel: FilterWheel;
    /// The lights.
    type Lights: Lights;

    /// The camera.
    fn camera(&mut self) -> &mut Self::Camera;
    /// The head.
    fn head(&mut self) -> &mut Self::Head;
    /// The filter wheel, if the station has one.
    fn wheel(&mut self) -> Option<&mut Self::Wheel>;
    /// The lights, if the station has them.
    fn lights(&mut self) -> Option<&mut Self::Lights>;
    /// The trait channel of the station config's `index`-th light.
    fn light_channel(&self, index: usize) -> Option<LightChannel>;
    /// Open `device`'s link anew after it dropped (the link failed).
    fn reconnect(&mut self, device: DeviceKind) -> impl Future<Output = Result<(), DeviceError>> + Send;
    /// Carry the tripod to `position_m` (scene frame, metres) for a named
    /// pose, or back to the station's own place (`None`). Real stations
    /// stand where an operator puts them, so the default does nothing.
    fn place(&mut self, position_m: Option<[f64; 3]>) {
        let _ = position_m;
    }
    /// Number the camera's next frames from `first`. The simulator seeds
    /// render and sensor noise by frame number, so numbering each shot's
    /// frames from a value fixed by the timeline makes a resumed session's
    /// frames identical to an uninterrupted run's. Real cameras ignore it.
    fn number_frames_from(&mut self, first: u64) {
        let _ = first;
    }
}
