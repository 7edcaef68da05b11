//! Outdoor reflectance recovery and re-rendering at novel times (thesis ch. 5):
//! pseudo-albedos ρ_sun and ρ_se (eqs. 5.11–5.12) and radiance at any time.
//!
//! - [`photo`]: the inputs as plain data — posed radiance photos and the
//!   illumination (sun and sky) at each time.
//! - [`grid`]: cells on the target surfaces (§5.4's dense grid per triangle).
//! - [`observation`]: what each photo says about each cell, with the
//!   sun-visibility test, mirror exclusion and view weights.
//! - [`cell_irradiance`]: sun, sky (App. B) and one-bounce irradiance per cell.
//! - [`estimate`]: the robust N-photo fit of eqs. (5.11)–(5.12), photo outlier
//!   rejection, neighbour fill and per-cell conditioning and uncertainty.
//! - [`rerender`]: radiance images at any time and sky (§5.5, §5.6).
//! - [`atlas`]: pseudo-albedo texture atlases (EXR) and the materials file.
//! - [`photograph`]: renders through a response curve at a chosen shutter.
//! - [`scene_file`], [`photo_file`], [`light_file`]: the plain files of
//!   `campanile outdoor recover|render` (scene with known environment
//!   albedos, posed HDR photos, sun and sky per time), with [`sky_image`]
//!   fitting a sky from a fisheye picture of it.
//! - [`mod@zoom_albedo`]: pseudo-albedos at pixel resolution from a zoom
//!   photograph (§5.6.4, eq. 5.16) and the zoom view re-rendered with them.
//!
//! The environment is the scene's non-target surfaces (ground, landscape)
//! with their materials' albedo, lit by the same sun and sky: the lead sets
//! those albedos from the eq. (5.15) region fit ([`crate::environment`]).
//!
//! Usage: `let (refl, _) = recover_reflectance(&scene, &targets, &photos,
//! &lights, &ReflectanceSettings::default())?;` then
//! `rerender(&scene, &refl, &rig, &light, &RerenderSettings::default())`.
//!
//! Not done: specular pseudo-BRDFs (the surfaces are taken as
//! Lambertian); landscape radiance from an environment map.

// Channel loops index several arrays at once; they read better with an index.
#![allow(clippy::needless_range_loop)]

pub mod atlas;
pub mod cell_irradiance;
pub mod estimate;
pub mod grid;
pub mod light_file;
pub mod novel_view;
pub mod observation;
pub mod photo;
pub mod photo_file;
pub mod photograph;
pub mod rerender;
pub mod scene_file;
pub mod sky_image;
pub mod texture_transfer;
pub mod zoom_albedo;

use chrono::{DateTime, Utc};
use thiserror::Error;

pub use estimate::{CellEstimate, CellStatus, PhotoCheck, Reflectance, ReflectanceSettings, recover_reflectance};
pub use grid::Grid;
pub use photo::{Illumination, Photo};
pub use rerender::{RerenderSettings, rerender};
pub use zoom_albedo::{ZoomAlbedo, ZoomReport, ZoomSettings, rerender_zoom, zoom_albedo};

/// Why the outdoor reflectance could not be recovered or rendered.
#[derive(Debug, Error)]
pub enum OutdoorError {
    /// The grid spacing is not a positive length.
    #[error("grid spacing {spacing_m} m must be finite and > 0")]
    BadSpacing {
        /// The value given.
        spacing_m: f64,
    },
    /// A target names a surface the scene does not have.
    #[error("target surface {surface} does not exist: the scene has {count} surfaces")]
    UnknownSurface {
        /// The index given.
        surface: usize,
        /// Surfaces in the scene.
        count: usize,
    },
    /// No photograph was given.
    #[error("no photographs to recover reflectance from")]
    NoPhotos,
    /// A photo's buffer does not match its size.
    #[error("photo {photo:?}: {width}×{height} image holds {values} values, expected width·height·3")]
    ImageSize {
        /// The photo.
        photo: String,
        /// Width given.
        width: usize,
        /// Height given.
        height: usize,
        /// Values held.
        values: usize,
    },
    /// A photo's mask does not match its size.
    #[error("photo {photo:?}: mask has {got} entries, expected {expected}")]
    MaskSize {
        /// The photo.
        photo: String,
        /// width · height.
        expected: usize,
        /// Entries given.
        got: usize,
    },
    /// No illumination was given at a photo's time.
    #[error("photo {photo:?} was taken at {time}, but no illumination is given at that time")]
    NoIllumination {
        /// The photo.
        photo: String,
        /// Its time.
        time: DateTime<Utc>,
    },
    /// A knob of [`ZoomSettings`] is out of range.
    #[error("zoom settings: {field} = {value}, expected {expected}")]
    BadZoomSetting {
        /// The field.
        field: &'static str,
        /// The value given.
        value: f64,
        /// What it must be.
        expected: &'static str,
    },
    /// A zoom photograph sees none of the target surfaces.
    #[error(
        "photo {photo:?}: none of its {pixels} pixels sees a target surface (from its visible side); \
         aim the zoom photo at the solved surfaces or check its camera pose"
    )]
    NoTargetInView {
        /// The photo.
        photo: String,
        /// Pixels in it.
        pixels: usize,
    },
    /// An output file could not be written or read.
    #[error("{path}: {message}")]
    File {
        /// The file.
        path: std::path::PathBuf,
        /// What went wrong.
        message: String,
    },
}
