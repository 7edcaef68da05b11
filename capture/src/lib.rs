//! Device traits, drivers, the session controller and the session store. See the README table for what exists.

pub mod conformance;
pub mod device;
pub mod driver;
