//! Device traits, drivers, the session controller and the session store. See the README table for what exists.
//!
//! - [`clock`]: UTC now and sleeping until an instant, on the wall clock or a simulated one.
//! - [`controller`]: runs a timeline's shots through the devices into the store.
//! - [`device`]: the traits the controller drives (camera, head, wheel, lights).
//! - [`driver`]: real drivers over serial links and camera APIs.
//! - [`import`]: a folder of hand-taken JPEG brackets made into a session.
//! - [`conformance`]: suites any driver or emulator must pass.
//! - [`schedule`]: when sessions run and what shots they take, as a pure function of plan, site and time.
//! - [`station`]: a real station's devices, built from its configuration, reconnecting with backoff.
//! - [`store`]: the session directory: frames written atomically and an append-only journal.
//! - [`unattended`]: the unattended station: days of scans, day sessions, storage budget, heartbeat, outages, damped exposure.

pub mod clock;
pub mod conformance;
pub mod controller;
pub mod device;
pub mod driver;
pub mod import;
pub mod schedule;
pub mod station;
pub mod store;
pub mod unattended;
