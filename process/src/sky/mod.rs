//! Sky radiance models (thesis §5.3.2): the seven-parameter all-weather
//! model the station fits (eq. 5.9), and the fifteen CIE standard general
//! skies (CIE S 011/E:2003, ISO 15469) the fit is tested against and may
//! choose between.
//!
//! Angles: ξ is a sky element's zenith angle, γ its angular distance from
//! the sun, both in radians.

mod cie;
mod compare;
mod daylight;
mod file;
mod fit;
mod frame_samples;
mod geometry;
mod latlong;
mod perez;
mod predict;
mod seven_parameter;

pub use cie::{CieSky, CieSkyType};
pub use compare::{ChannelComparison, compare_with_samples};
pub use daylight::{Atmosphere, Daylight, REDDENING_ONSET_AIR_MASS, SUN_ANGULAR_RADIUS_RAD};
pub use file::{ChannelSelection, ChannelSky, SampleTable, SampleTableError, SkyFile, read_directions, read_samples};
pub use fit::{
    Candidate, Convergence, MAX_MASKED_FRACTION, OUTLIER_FLOOR, PARAMETER_NAMES, PARAMETER_RANGES, RCOND_FLOOR,
    RobustSkyFit, SkyFit, SkyFitError, SkyFitOptions, SkyModelKind, SkySample, Termination, WEIGHT_FLOOR,
    fit_perez_from, fit_sky, fit_sky_robust, fit_sky_with,
};
pub use frame_samples::{FrameSampleError, MIN_ELEVATION_RAD, SkyFrame, sky_samples};
pub use geometry::{angle_between, direction};
pub use latlong::{latlong_direction, render_latlong};
pub use perez::{BRIGHTNESS_RANGE, CLEARNESS_BIN_EDGES, PerezSky, table_extremes};
pub use predict::{KnownSky, OvercastSky, PredictError, predict_sky, redden};
pub use seven_parameter::{COS_XI_FLOOR, SkyAngles, SkyModel};
