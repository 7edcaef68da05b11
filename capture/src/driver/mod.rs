//! Host drivers: the device traits of [`crate::device`] implemented over
//! the protocols of `campanile-firmware-link`. Each is generic over its
//! byte transport, so it does not know whether it talks to a real tty or a
//! simulated firmware.
//!
//! | driver | protocol | traits |
//! | --- | --- | --- |
//! | [`link::LinkController`] | campanile-link | `PanTilt`, `FilterWheel`, `Lights` |
//! | [`pelco_d::PelcoHead`] | Pelco-D | `PanTilt` |
//! | [`flir_ptu::FlirHead`] | FLIR PTU ASCII | `PanTilt` |
//! | [`fw102c::Fw102cWheel`] | Thorlabs FW102C | `FilterWheel` |
//! | [`enttec::DmxLights`] | Enttec DMX USB Pro | `Lights` |
//! | `v4l2::V4l2Camera` (feature `v4l`) | V4L2 | `Camera`, through [`camera_thread`] |
//! | `nokhwa_camera::NokhwaCamera` (feature `nokhwa`) | nokhwa (V4L2 backend) | `Camera`, through [`camera_thread`] |
//! | [`indi::IndiCamera`], [`indi::IndiWheel`] | INDI over TCP (`indiserver`) | `Camera`, `FilterWheel` |
//! | [`tethered_camera::TetheredCamera`] over `gphoto2_camera::Gphoto2Tether` (feature `gphoto2`) | libgphoto2 (tethered DSLRs); **has never met a camera** | `Camera`, through [`camera_thread`] |
//! | `aravis_camera::AravisCamera` (feature `aravis`) | GenICam (GigE Vision, USB3 Vision) through Aravis | `Camera`, through [`camera_thread`] |
//!
//! The V4L2 and nokhwa cameras share [`exposure_control`] (V4L2 exposure
//! and gain controls) and [`pixel_format`] (buffers to RGB codes); the
//! Aravis camera has [`genicam_format`] (GenICam pixel formats, Bayer
//! demosaicing, exposure and gain features); the gphoto2 camera
//! [`gphoto_settings`] (gphoto2's shutter, aperture, ISO and image-format
//! choices, bulb, and the exposure read from a delivered file's EXIF) and
//! [`tethered_camera`] (the stills-camera logic over a small
//! [`tethered_camera::Tether`] trait, tested against a scripted camera
//! delivering real JPEGs), of which the gphoto2 driver is only the
//! libgphoto2 calls. They need no camera and are tested in every build.
//!
//! A link that drops is reopened by [`backoff::reopen`] (exponential
//! backoff, capped, logged); [`crate::station`] does so for every serial
//! device of a real station.

#[cfg(feature = "aravis")]
pub mod aravis_camera;
pub mod backoff;
pub mod camera_thread;
pub mod enttec;
pub mod exposure_control;
pub mod flir_ptu;
pub mod fw102c;
pub mod genicam_format;
#[cfg(feature = "gphoto2")]
pub mod gphoto2_camera;
pub mod gphoto_settings;
pub mod indi;
pub mod link;
#[cfg(feature = "nokhwa")]
pub mod nokhwa_camera;
pub mod pelco_d;
pub mod pixel_format;
pub mod tethered_camera;
#[cfg(feature = "v4l")]
pub mod v4l2;

use std::time::Duration;

/// How often drivers poll a head that is still moving.
pub const POLL: Duration = Duration::from_millis(20);
