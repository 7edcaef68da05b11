//! Plain-file forms of the environment model, for `campanile env fit|predict`.
//!
//! **Observations** (CSV, header row), one row per region and time:
//! `region` (any label), `r,g,b` (the region's mean radiance),
//! `sky_r,sky_g,sky_b` (E_sky, the sky's flux), `sun_r,sun_g,sun_b` (E_sun,
//! solar irradiance normal to the sun), `sun_zenith_deg`, `sun_azimuth_deg`.
//!
//! **Fitted models** (RON, [`EnvironmentFile`]): per region, the model
//! chosen and why, ρ_sky, ρ_sun, the normal, the residual and the
//! conditioning figures.

use std::collections::BTreeMap;
use std::io::Read;

use serde::{Deserialize, Serialize};

use super::region_model::{EnvironmentObservation, RegionFit, RegionModelKind, region_radiance};
use crate::csv_cell::{CellError, number};

/// One region's fitted model.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RegionRecord {
    /// The region's label.
    pub region: String,
    /// "SkyAndSun" or "SkyOnly".
    pub model: String,
    /// Why.
    pub reason: String,
    /// ρ_sky per channel.
    pub rho_sky: [f64; 3],
    /// ρ_sun per channel.
    pub rho_sun: [f64; 3],
    /// Unit normal, for sky-and-sun regions.
    pub normal: Option<[f64; 3]>,
    /// RMS relative residual.
    pub rms_relative: f64,
    /// σ_min / σ_max of the sun directions.
    pub sun_track_condition: f64,
    /// Condition number of the fit's Jacobian.
    pub jacobian_condition: f64,
}

impl RegionRecord {
    /// The record of a fit.
    pub fn new(region: &str, fit: &RegionFit) -> Self {
        RegionRecord {
            region: region.to_owned(),
            model: match fit.kind {
                RegionModelKind::SkyAndSun => "SkyAndSun".into(),
                RegionModelKind::SkyOnly => "SkyOnly".into(),
            },
            reason: fit.reason.clone(),
            rho_sky: fit.rho_sky,
            rho_sun: fit.rho_sun,
            normal: fit.normal,
            rms_relative: fit.rms_relative,
            sun_track_condition: fit.sun_track_condition,
            jacobian_condition: fit.jacobian_condition,
        }
    }

    /// Predicted radiance under new light, eq. (5.13).
    pub fn radiance(&self, sky_irradiance: [f64; 3], sun_irradiance: [f64; 3], sun: [f64; 3]) -> [f64; 3] {
        region_radiance(
            self.rho_sky,
            self.rho_sun,
            self.normal,
            sky_irradiance,
            sun_irradiance,
            sun,
        )
    }
}

/// Every region's model.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EnvironmentFile {
    /// The regions, in label order.
    pub regions: Vec<RegionRecord>,
}

/// A problem in an observation table.
#[derive(Debug, thiserror::Error)]
pub enum ObservationTableError {
    /// Malformed CSV.
    #[error("row {row}: {message}")]
    Csv {
        /// Row (the header is row 1).
        row: u64,
        /// What the parser said.
        message: String,
    },
    /// A column is missing.
    #[error("the header has no `{column}` column (it has: {found})")]
    MissingColumn {
        /// The column.
        column: &'static str,
        /// The header.
        found: String,
    },
    /// A cell is not a number in range.
    #[error(transparent)]
    Cell(#[from] CellError),
}

const COLUMNS: [&str; 12] = [
    "r",
    "g",
    "b",
    "sky_r",
    "sky_g",
    "sky_b",
    "sun_r",
    "sun_g",
    "sun_b",
    "sun_zenith_deg",
    "sun_azimuth_deg",
    "region",
];

/// Reads observations, grouped by region label (in label order).
pub fn read_observations(
    input: impl Read,
) -> Result<BTreeMap<String, Vec<EnvironmentObservation>>, ObservationTableError> {
    let mut rd = csv::ReaderBuilder::new().trim(csv::Trim::All).from_reader(input);
    let header = rd
        .headers()
        .map_err(|e| ObservationTableError::Csv {
            row: 1,
            message: e.to_string(),
        })?
        .clone();
    let mut idx = [0usize; 12];
    for (slot, name) in idx.iter_mut().zip(COLUMNS) {
        *slot = header
            .iter()
            .position(|h| h == name)
            .ok_or_else(|| ObservationTableError::MissingColumn {
                column: name,
                found: header.iter().collect::<Vec<_>>().join(","),
            })?;
    }
    let mut out: BTreeMap<String, Vec<EnvironmentObservation>> = BTreeMap::new();
    for (k, rec) in rd.records().enumerate() {
        let row = k as u64 + 2;
        let rec = rec.map_err(|e| ObservationTableError::Csv {
            row,
            message: e.to_string(),
        })?;
        let v = |i: usize, lo: f64, hi: f64, what: &'static str| number(&rec, &header, idx[i], row, (lo, hi), what);
        let rgb = |base: usize, lo: f64, what: &'static str| -> Result<[f64; 3], CellError> {
            Ok([
                v(base, lo, f64::MAX, what)?,
                v(base + 1, lo, f64::MAX, what)?,
                v(base + 2, lo, f64::MAX, what)?,
            ])
        };
        let radiance = rgb(0, f64::MIN, "a radiance")?;
        let sky_irradiance = rgb(3, 0.0, "a sky irradiance ≥ 0")?;
        let sun_irradiance = rgb(6, 0.0, "a solar irradiance ≥ 0")?;
        let z = v(9, 0.0, 180.0, "a solar zenith angle in degrees in [0, 180]")?.to_radians();
        let a = v(10, -360.0, 360.0, "a solar azimuth in degrees")?.to_radians();
        let sun = [z.sin() * a.sin(), z.sin() * a.cos(), z.cos()];
        let region = rec.get(idx[11]).unwrap_or("").to_owned();
        out.entry(region).or_default().push(EnvironmentObservation {
            radiance,
            sky_irradiance,
            sun_irradiance,
            sun,
        });
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn observations_group_by_region_and_bad_cells_are_named() {
        let csv = "region,r,g,b,sky_r,sky_g,sky_b,sun_r,sun_g,sun_b,sun_zenith_deg,sun_azimuth_deg\n\
                   hill,1,2,3,10,10,10,900,900,900,30,180\n\
                   lake,1,1,1,10,10,10,900,900,900,30,180\n\
                   hill,2,3,4,12,12,12,800,800,800,50,250\n";
        let groups = read_observations(csv.as_bytes()).expect("valid");
        assert_eq!(groups.keys().collect::<Vec<_>>(), ["hill", "lake"]);
        assert_eq!(groups["hill"].len(), 2);
        assert!((groups["hill"][0].sun[2] - 30f64.to_radians().cos()).abs() < 1e-15);
        let bad = csv.replace("12,12,12", "12,-1,12");
        let e = read_observations(bad.as_bytes()).expect_err("negative irradiance");
        assert_eq!(
            e.to_string(),
            "row 4, column `sky_g`: found \"-1\"; expected a sky irradiance ≥ 0"
        );
    }
}
