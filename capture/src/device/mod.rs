//! Device traits: the few methods the controller needs from a camera, a
//! pan-tilt head, a filter wheel and a set of lights, with units in the
//! types.
//!
//! Like embedded-hal, drivers are generic over these small traits, so the
//! same controller code runs against real hardware (drivers in
//! [`crate::driver`] over a serial port) or against the simulator's
//! firmware emulators, and the conformance suites in [`crate::conformance`]
//! run against any of them.
//!
//! **Async, tokio-flavoured.** Every method that talks to a device returns
//! a `Send` future: the controller is a tokio program, and waiting on a
//! serial line must not block a thread. The traits do not name tokio, but
//! the drivers here use tokio's clock, so a test under paused time runs a
//! whole session in moments. Methods are generic (`impl PanTilt`), not
//! object-safe; wrap in an enum when a runtime choice is needed.
//!
//! The [`Camera`] trait takes manual exposure and gain and returns raw
//! frames with the exposure actually applied (cameras round it); the
//! simulator's camera implements it, and so do the V4L2 and nokhwa
//! drivers in [`crate::driver`] (cargo features `v4l` and `nokhwa`).

pub mod camera;
pub mod error;
pub mod filter_wheel;
pub mod frame_format;
pub mod lights;
pub mod pan_tilt;
pub mod units;

pub use camera::{Camera, CameraInfo, CaptureSettings, ExposureRange, ExposureTable, Frame, GainRange};
pub use error::DeviceError;
pub use filter_wheel::FilterWheel;
pub use frame_format::{FrameFile, FrameFormat};
pub use lights::{LightChannel, Lights};
pub use pan_tilt::{AxisRange, HeadStatus, PanTilt, PanTiltLimits};
pub use units::{Angle, AngularSpeed, ExposureTime, Gain, Level, Pose};
