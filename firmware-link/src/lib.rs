//! Byte links to Campanile device firmware.
//!
//! This crate holds both ends of every serial protocol the station speaks:
//!
//! | protocol | codec | device side (emulator) | host driver |
//! | --- | --- | --- | --- |
//! | campanile-link (ours) | [`link::frame`], [`link::message`] | [`link::device`] | [`link::host`] |
//! | Pelco-D (PTZ heads) | [`pelco_d`] | [`pelco_d::device`] | [`pelco_d::host`] |
//! | FLIR / Directed Perception PTU ASCII | [`flir_ptu`] | [`flir_ptu::device`] | [`flir_ptu::host`] |
//! | Enttec DMX USB Pro (lights) | [`enttec`] | [`enttec::device`] | [`enttec::host`] |
//! | Thorlabs FW102C (filter wheel) | [`fw102c`] | [`fw102c::device`] | [`fw102c::host`] |
//!
//! The codecs and device sides form a `no_std` core: no allocator, no tokio,
//! fixed-size buffers, and a pure state machine shape (bytes in, bytes out
//! plus effects; see [`firmware`]). Build with `--no-default-features` to get
//! only that core. The `std` feature (on by default) adds the host drivers,
//! the transports in [`transport`] (serial ports, in-memory duplex, a seeded
//! fault injector, a traffic log) and [`emulator`], which runs any device
//! side over a byte stream under tokio.
//!
//! What is **not** supported: Pelco-D zoom/focus/iris and auxiliary
//! commands are encoded as raw frames only; the FLIR binary protocol; the
//! Enttec RDM and DMX-input labels; FW102C settings other than the position
//! and the position count.
#![cfg_attr(not(feature = "std"), no_std)]
#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub mod cobs;
pub mod enttec;
pub mod firmware;
pub mod flir_ptu;
pub mod fw102c;
pub mod line;
pub mod link;
pub mod motion;
pub mod pelco_d;

#[cfg(feature = "std")]
pub mod driver_error;
#[cfg(feature = "std")]
pub mod emulator;
#[cfg(feature = "std")]
pub mod transport;
