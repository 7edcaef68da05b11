//! The sky time series (issue 12): per scan of a sky-only session, the
//! sun's irradiance, the sky per channel (eq. 5.9, model chosen and why,
//! residuals), a zenith-to-horizon profile and quality flags
//! ([`scan_products`]); per day, recomputed from the per-scan products
//! alone, the extinction β per channel against air mass (Langley), a CSV
//! with one row per scan, plots and a keogram ([`write_day`]).
//!
//! Scans are independent: [`Shard`] picks a deterministic share of them by
//! a stable hash of the occurrence id, and shard outputs merge by the union
//! of their `scans/` directories ([`store`]).

mod condition;
mod day;
mod keogram;
mod plots;
mod profile;
mod quality;
mod regions;
mod report;
mod scan;
mod series_csv;
mod series_parquet;
mod shard;
mod sky_pixels;
pub mod store;

use std::path::PathBuf;

pub use condition::{
    CLEAR_SCAN_COVER, CLEAR_SCAN_RMS, CLOUDY_DEPARTURE, ClearReference, Condition, MIN_MEASURED_SHARE, SkyCondition,
    day_conditions,
};
pub use day::{DayExtinction, SkySeries, day_of};
pub use keogram::{keogram_png, keogram_residual_png};
pub use plots::{conditions_svg, irradiance_svg, langley_svg, shape_parameters_svg, zenith_scale_svg};
pub use profile::{MeridianProfile, PROFILE_BIN_DEG, PROFILE_BINS, meridian_profile, plane_direction};
pub use quality::{HIGH_MASKED_FRACTION, POOR_FIT_RMS, QualityFlags};
pub use regions::{
    BAND_EDGES_DEG, MIN_REGION_PIXELS, NEAR_SUN_DEG, REGION_COUNT, RegionSums, SECTORS, SkyRegions,
    in_sun_neighbourhood, region_grid, region_of, region_solid_angle, sun_neighbourhood_grid,
};
pub use report::sky_series_sections;
pub use scan::{ScanProducts, SunRecord, scan_file_stem, scan_products};
pub use series_csv::{EXTINCTION_COLUMNS, SERIES_COLUMNS, extinction_csv, series_csv, series_width};
pub use series_parquet::{PARQUET_FORMAT, series_parquet, unit_key};
pub use shard::{Shard, ShardParseError, stable_hash};
pub use store::{read_scans, scan_path, write_day, write_scan};

/// Why the series could not be read or written.
#[derive(Debug, thiserror::Error)]
pub enum SkySeriesError {
    /// A file could not be read or written.
    #[error("{action} {}: {source}", path.display())]
    Io {
        /// What was being done.
        action: &'static str,
        /// The file.
        path: PathBuf,
        /// Why.
        #[source]
        source: std::io::Error,
    },
    /// A per-scan file is not one.
    #[error("{}: {message}", path.display())]
    Parse {
        /// The file.
        path: PathBuf,
        /// The parser's message.
        message: String,
    },
    /// A directory given as a shard output has no `scans/`.
    #[error("{}: not a shard output directory (it has no scans/ directory)", dir.display())]
    NotAShard {
        /// The directory.
        dir: PathBuf,
    },
    /// Two shards wrote different products for the same scan.
    #[error("{} and {} hold different products for the same scan: were they processed with different responses or versions?", first.display(), second.display())]
    Conflict {
        /// The file already merged.
        first: PathBuf,
        /// The other shard's file.
        second: PathBuf,
    },
    /// A figure could not be made.
    #[error(transparent)]
    Report(#[from] crate::report::ReportError),
}
