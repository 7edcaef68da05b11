//! The first stages of `campanile process` on a captured session, on plain
//! data (no files, no devices): frames grouped by shot, the camera response
//! (Debevec–Malik, the thesis's [11]), HDR radiance per group, and per
//! occurrence the sun (§5.3.1), the sky (§5.3.2, eq. 5.9) and the
//! environment map (§5.3.3); where the sky or the sun was not measured,
//! [`estimated_light`] makes them from a clear-sky model and the
//! photographs' sunlit/shadowed ratio.
//!
//! The binary reads a session directory, turns its journal and frames into
//! [`CapturedFrame`]s (through the plan, which says what each shot was for)
//! and calls [`calibrate_response`], [`merge_groups`] and
//! [`illumination`]. The outdoor reflectance solver then takes the merged
//! views and the per-time illumination.
//!
//! # Units
//!
//! Radiance comes out in W·m⁻²·sr⁻¹ under the *full-well gauge*: the
//! recovered curve's exposure at the top code is set to 1, i.e. a pixel at
//! full well in 1 s through no filter has radiance 1/k with the camera's
//! radiometric constant k = 1. Without an absolute calibration that is the
//! only physical choice; the solvers downstream (pseudo-albedos are ratios
//! of radiance to irradiance measured by the same camera) do not depend on
//! it. The sun's irradiance is measured in the same units.

mod estimated_light;
pub(crate) use estimated_light::median;
mod frames;
mod illumination;
mod measured_sky;
mod radiance;
mod response;
pub mod room_views;

pub use estimated_light::{
    EstimateSettings, EstimatedLight, KnownLight, MIN_PAIRS, MIN_SUN_TO_SKY, MODEL_GLOBAL_UNCERTAINTY, SPLIT_FLOOR,
    ScaleSource, SplitEstimate, estimated_light, predicted_estimated_light,
};
pub use frames::{CapturedFrame, FrameGroup, LOSSY_CLIP_MARGIN, Purpose, clip_lossy_top, group_frames, mean_time};
pub use illumination::{
    OccurrenceLight, SUN_MARGIN_RAD, SunMeasurement, TRIPLET_AGREEMENT, fisheye_average, illumination, sky_fisheye,
};
pub use measured_sky::{LightError, MeasuredSky, extinction, measured_sky, predicted_sky};
pub use radiance::{MergedGroup, merge_groups};
pub use response::{ResponseChoice, calibrate_response};

use crate::hdr::lens::RadialPolynomial;
use crate::pose::{Mount, Pinhole};
use crate::sun::Observer;

/// What processing needs to know of the station: the camera's geometry at
/// its full resolution, the lens falloff, the mount and the site.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StationOptics {
    /// The pinhole (with radial distortion) at `resolution`.
    pub pinhole: Pinhole,
    /// Width and height the pinhole is given for.
    pub resolution: (usize, usize),
    /// Relative illumination `1 + a ρ² + b ρ⁴` (ρ = 1 at the corners), thesis §4.7.2.
    pub falloff: RadialPolynomial,
    /// The head's mount calibration.
    pub mount: Mount,
    /// The site.
    pub observer: Observer,
    /// TT − UT, seconds, if the station gives it.
    pub delta_t_s: Option<f64>,
}

impl StationOptics {
    /// The optics of a configured station (camera at its configured
    /// resolution, falloff, mount calibration in radians, site).
    pub fn of_station(station: &campanile_config::Station) -> StationOptics {
        let camera = &station.camera;
        let (i, s) = (&camera.intrinsics, &station.site);
        StationOptics {
            pinhole: Pinhole::of_camera(camera),
            resolution: (camera.resolution.width as usize, camera.resolution.height as usize),
            falloff: RadialPolynomial {
                a: i.falloff.0,
                b: i.falloff.1,
            },
            mount: Mount::of_calibration(&station.head.mount),
            observer: Observer::from_degrees(
                s.latitude_deg,
                s.longitude_deg,
                s.elevation_m,
                s.pressure_mbar,
                s.temperature_c,
            ),
            delta_t_s: s.delta_t_s,
        }
    }

    /// The pinhole rescaled to a frame of `width` × `height`.
    pub fn pinhole_at(&self, width: usize, height: usize) -> Pinhole {
        self.pinhole.rescaled(self.resolution, width, height)
    }
}

/// Why a stage could not run.
#[derive(Debug, thiserror::Error)]
pub enum PipelineError {
    /// The response could not be recovered.
    #[error("camera response from {group}: {source}")]
    Response {
        /// The group used.
        group: String,
        /// Why.
        source: crate::hdr::HdrError,
    },
    /// No group can calibrate the response.
    #[error(
        "no bracket of two or more exposures without a filter in the session: the response needs one (take a view or a sky scan with brackets)"
    )]
    NoBracket,
    /// Some frames are RAW and some are not.
    #[error(
        "{linear} of the session's {total} frames are linear, RAW or FITS (e.g. {raw_example:?}), and the others are not (e.g. {other_example:?}): one response cannot serve both; process them as separate sessions"
    )]
    MixedFrames {
        /// RAW frames.
        linear: usize,
        /// All frames.
        total: usize,
        /// A RAW frame's key.
        raw_example: String,
        /// Another frame's key.
        other_example: String,
    },
    /// A group could not be merged.
    #[error("merging {group}: {source}")]
    Merge {
        /// The group.
        group: String,
        /// Why.
        source: crate::hdr::HdrError,
    },
    /// A group's frames were taken at different focal lengths.
    #[error(
        "group {group}: its frames were taken at different focal lengths ({} and {} for {other}): a bracket is one view through one lens",
        focal_text(*first),
        focal_text(*other_focal_px)
    )]
    MixedFocalLengths {
        /// The group.
        group: String,
        /// Its first frame's focal length, pixels (`None`: the station camera's).
        first: Option<f64>,
        /// A frame at another.
        other: String,
        /// That frame's focal length, pixels.
        other_focal_px: Option<f64>,
    },
    /// An occurrence has no sun or sky frames to process.
    #[error("occurrence {occurrence:?} has no sun shot and no sky scan")]
    NoScan {
        /// The occurrence.
        occurrence: String,
    },
    /// The sun's position could not be computed.
    #[error("sun position at {time}: {message}")]
    Sun {
        /// The time.
        time: chrono::DateTime<chrono::Utc>,
        /// Why.
        message: String,
    },
}

/// A frame's focal length as an error message says it.
fn focal_text(focal_px: Option<f64>) -> String {
    focal_px.map_or_else(|| "the station camera's".to_owned(), |f| format!("{f} px"))
}
