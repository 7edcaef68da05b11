//! The simulated station as the capture controller sees it: the
//! controller's [`Clock`] on the simulated calendar, and its [`Rig`]
//! (devices plus hooks) on a [`SimStation`]. The hooks are the only
//! simulation-specific things the controller calls: reconnecting a device
//! ([`SimStation::reconnect_head`] and friends), carrying the tripod to a
//! named pose ([`SimCamera::set_position`](crate::camera::SimCamera::set_position)),
//! and numbering frames per shot ([`SimCamera::set_sequence`](crate::camera::SimCamera::set_sequence)),
//! which makes a resumed session's frames identical to an uninterrupted run's.

use crate::camera::{FrameSource, SimCamera};
use crate::clock::SimClock;
use crate::devices::head::SimHead;
use crate::devices::lights::SimLights;
use crate::devices::wheel::SimWheel;
use crate::error::SimError;
use crate::station::SimStation;
use campanile_capture::clock::Clock;
use campanile_capture::controller::{DeviceKind, Rig};
use campanile_capture::device::{DeviceError, LightChannel};
use campanile_firmware_link::driver_error::DriverError;
use chrono::{DateTime, Utc};

impl Clock for SimClock {
    fn now(&self) -> DateTime<Utc> {
        SimClock::now(self)
    }

    async fn sleep_until(&self, t: DateTime<Utc>) {
        SimClock::sleep_until(self, t).await;
    }
}

fn device_error(e: SimError) -> DeviceError {
    match e {
        SimError::Connect { error, .. } => error,
        SimError::Open { error, .. } => DeviceError::Link(DriverError::Io(error)),
        SimError::Unsupported(what) => DeviceError::Camera(format!("the simulator cannot emulate {what}")),
    }
}

impl<S: FrameSource> Rig for SimStation<S> {
    type Camera = SimCamera<S>;
    type Head = SimHead;
    type Wheel = SimWheel;
    type Lights = SimLights;

    fn camera(&mut self) -> &mut SimCamera<S> {
        &mut self.camera
    }

    fn head(&mut self) -> &mut SimHead {
        &mut self.head
    }

    fn wheel(&mut self) -> Option<&mut SimWheel> {
        self.wheel.as_mut()
    }

    fn lights(&mut self) -> Option<&mut SimLights> {
        self.lights.as_mut()
    }

    fn light_channel(&self, index: usize) -> Option<LightChannel> {
        SimStation::light_channel(self, index)
    }

    async fn reconnect(&mut self, device: DeviceKind) -> Result<(), DeviceError> {
        match device {
            DeviceKind::Camera => Ok(()),
            DeviceKind::Head => self.reconnect_head().await.map_err(device_error),
            DeviceKind::Wheel => self.reconnect_wheel().await.map_err(device_error),
            DeviceKind::Lights => self.reconnect_lights().await.map_err(device_error),
        }
    }

    fn place(&mut self, position_m: Option<[f64; 3]>) {
        let at = self.position_for(position_m);
        self.camera.set_position(at);
    }

    fn number_frames_from(&mut self, first: u64) {
        self.camera.set_sequence(first);
    }
}
