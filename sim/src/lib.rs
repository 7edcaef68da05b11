//! The simulated station. See the README table for what exists.
//!
//! - [`world`]: the scenes with their ground truth (geometry, materials, sun, sky) and the renderer's view of them.
//! - [`camera`]: a camera that photographs a [`camera::FrameSource`] through the `Camera` device trait.
//! - [`devices`]: device-side emulators of the head, filter wheel and lights over the firmware-link protocols.
//! - [`capture_hooks`]: the capture controller's clock and rig on a simulated station.
//! - [`clock`]: the simulated calendar, driven by tokio's (pausable) clock.
//! - [`faults`]: seeded fault injection for links, camera and devices.
//! - [`disk`]: a storage area that fills up.
//! - [`station`]: a whole simulated station assembled from a station config.
//! - [`seed`]: how per-frame and per-link seeds derive from the station's seed.
//! - [`error`]: what assembling a simulated station can fail with.

pub mod camera;
pub mod capture_hooks;
pub mod clock;
pub mod devices;
pub mod disk;
pub mod error;
pub mod faults;
pub mod seed;
pub mod station;
pub mod world;
