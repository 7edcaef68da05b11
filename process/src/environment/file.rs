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

use super::region_model::{EnvironmentObservation, RegionFit};
use crate::csv_cell::{CellError, TableError, column, number};
use crate::sky::direction;

/// One region's fitted model, under its label.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RegionRecord {
    /// The region's label.
    pub region: String,
    /// The fit.
    pub fit: RegionFit,
}

/// Every region's model.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EnvironmentFile {
    /// The regions, in label order.
    pub regions: Vec<RegionRecord>,
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
pub fn read_observations(input: impl Read) -> Result<BTreeMap<String, Vec<EnvironmentObservation>>, TableError> {
    let mut rd = csv::ReaderBuilder::new().trim(csv::Trim::All).from_reader(input);
    let header = rd.headers().map_err(|e| TableError::csv(1, &e))?.clone();
    let mut idx = [0usize; 12];
    for (slot, name) in idx.iter_mut().zip(COLUMNS) {
        *slot = column(&header, name)?;
    }
    let mut out: BTreeMap<String, Vec<EnvironmentObservation>> = BTreeMap::new();
    for (k, rec) in rd.records().enumerate() {
        let row = k as u64 + 2;
        let rec = rec.map_err(|e| TableError::csv(row, &e))?;
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
        let sun = direction(z, a);
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
