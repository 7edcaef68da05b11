//! The environment: the landscape around the scene as a light source
//! (thesis §5.3.3), and how each region of it will look at other times
//! (§5.5.2).

mod file;
mod map;
mod region_model;

pub use file::{EnvironmentFile, RegionRecord, read_observations};
pub use map::{EnvironmentMap, RegionStats};
pub use region_model::{
    EnvironmentObservation, RegionFit, RegionFitError, RegionModelKind, SUN_TRACK_MIN_CONDITION, fit_region,
};
