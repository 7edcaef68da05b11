//! Processing a captured session end to end, and its report.
//!
//! What `campanile process` and `campanile demo` do, as a library that
//! tests and other programs can call (the binary parses arguments, prints
//! and maps [`Error`]s to exit statuses):
//!
//! - [`run`]: a whole `process` run: the kind of session, its stages in
//!   order, its products and report page;
//! - [`process`]: a session's response and HDR, sun, sky and environment
//!   (stages 1–2), the outdoor stages (pseudo-albedos, held-out views) and
//!   the room stage (inverse global illumination), their products on disk
//!   and their report sections;
//! - [`sky_series`]: a sky-only session as a time series of scans;
//! - [`scan_processor`]: the [`ScanProcessor`](scan_processor::ScanProcessor)
//!   the station calls after each scan, and the sky series' one;
//! - [`station_run`]: the unattended station's run, simulated or real;
//! - [`station_status`]: the station's heartbeat read back;
//! - [`station_page`]: the station's live web page and JSON API;
//! - [`igi`]: inverse global illumination on a scene file and its products;
//! - [`outdoor_files`]: outdoor reflectance on plain files (recover, render);
//! - [`env_files`]: environment regions on plain files (fit, predict);
//! - [`sun_files`]: solar positions for an instant or a table;
//! - [`texture_files`]: texture maps from registered photographs on plain files;
//! - [`hdr_files`]: the camera response, HDR merges and lens models on
//!   plain files;
//! - [`site`]: the sun given as angles or from the ephemeris at a site;
//! - [`sky_files`]: sky models on plain files (fit, predict, map);
//! - [`scene_render`]: the scene at new times from recovered pseudo-albedos;
//! - [`capture_inputs`]: a capture's plan, station, scene and timeline, and
//!   a simulated station's world;
//! - [`capture_run`]: a capture's timeline run on the simulated or the real
//!   station, and the session's tally;
//! - [`device_checks`]: the devices a computer offers, and the
//!   conformance suites run against a station's;
//! - [`plan_check`]: a plan simulated forward on a station;
//! - [`photo_import`]: sessions from hand-taken photographs, and
//!   checking a session's frames;
//! - [`demo`]: the simulated station's day, cube and room, with every
//!   figure beside the simulator's truth;
//! - [`report_summary`]: the summary at the top of every report page;
//! - [`verdicts`], [`partial_file`], [`progress`], [`error`].

/// Returns early with an `anyhow` error made from a message (this crate's
/// `bail!`: the error converts into [`Error::Work`]).
macro_rules! bail {
    ($($arg:tt)*) => {
        return Err(anyhow::anyhow!($($arg)*).into())
    };
}

pub mod capture_inputs;
pub mod capture_run;
pub mod condition_hook;
pub mod demo;
pub mod device_checks;
pub mod env_files;
pub mod error;
pub mod hdr_files;
pub mod igi;
pub mod mount_files;
pub mod mount_session;
pub mod outdoor_files;
pub mod partial_file;
pub mod photo_import;
pub mod plan_check;
pub mod process;
pub mod progress;
pub mod register_files;
pub mod report_summary;
pub mod run;
pub mod scan_processor;
pub mod scene_render;
pub mod site;
pub mod sky_camera_files;
pub mod sky_files;
pub mod sky_series;
pub mod station_page;
pub mod station_run;
pub mod station_status;
pub mod sun_files;
pub mod texture_files;
pub mod verdicts;

pub use error::{Error, Result};
