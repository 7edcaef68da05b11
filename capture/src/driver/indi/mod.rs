//! INDI: the Instrument Neutral Distributed Interface, the protocol of
//! astronomical and all-sky devices (`indiserver` and its drivers, as
//! indi-allsky and KStars use them). A client over tokio, and the
//! [`Camera`](crate::device::Camera) and
//! [`FilterWheel`](crate::device::FilterWheel) traits on an INDI `CCD` and
//! an INDI filter wheel.
//!
//! The protocol (INDI white paper, protocol version 1.7): XML elements over
//! TCP, with no enclosing document. The client asks `getProperties`; the
//! server defines each device's property vectors (`defNumberVector`,
//! `defSwitchVector`, `defTextVector`, `defLightVector`, `defBLOBVector`),
//! then reports changes (`set…Vector`, each with the vector's state Idle,
//! Ok, Busy or Alert); the client asks for changes (`new…Vector`).
//! Images arrive as BLOBs (base64 in `oneBLOB`) once `enableBLOB` asks for
//! them, as FITS files.
//!
//! Why a client of our own rather than the `indi` crate: that crate (5.x)
//! carries a websocket server (axum, tungstenite), ndarray and the
//! unmaintained `encoding` crate into every build; what a station needs is
//! the few hundred lines here on the `quick-xml` and `base64` crates the
//! workspace already builds.

pub mod camera;
pub mod client;
pub mod element;
pub mod local_server;
pub mod wheel;

pub use camera::{CcdSettings, IndiCamera};
pub use client::{Blob, IndiClient, Property, PropertyKind, PropertyState};
pub use local_server::LocalServer;
pub use wheel::IndiWheel;
