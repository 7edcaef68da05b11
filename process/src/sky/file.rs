//! Plain-file forms of sky data, for `campanile sky fit|predict`.
//!
//! **Samples** (CSV, header row): `zenith_deg`, `azimuth_deg` (from north
//! through east) of each sky element, and one column per camera channel
//! (any names, e.g. `r,g,b`), radiance in any one unit.
//!
//! **Fitted skies** (RON, [`SkyFile`]): the sun's position and, per channel,
//! the eq. (5.9) parameters, the model chosen and why, and the residual.

use std::io::Read;

use serde::{Deserialize, Serialize};

use crate::csv_cell::{CellError, TableError, column, number};

use super::fit::{Convergence, RobustSkyFit, SkyFit};
use super::seven_parameter::SkyModel;

/// One channel's fitted sky.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ChannelSky {
    /// The channel's column name.
    pub channel: String,
    /// Eq. (5.9) parameters.
    pub model: SkyModel,
    /// The model chosen: "Perez", "SevenParameter", "SevenParameterFixedAureole" or "Cie(N)".
    pub chosen: String,
    /// Why.
    pub reason: String,
    /// RMS relative residual over the samples.
    pub rms_relative: f64,
    /// Samples given.
    pub samples: usize,
    /// Fraction of them left out as not sky (occluders, glare).
    pub masked_fraction: f64,
    /// What was masked and why (absent in files written before it was
    /// recorded).
    #[serde(default)]
    pub masked: Option<String>,
    /// How the optimizer ended: criterion, iterations, parameters at a
    /// bound (absent for predicted skies and older files).
    #[serde(default)]
    pub convergence: Option<Convergence>,
}

impl ChannelSky {
    /// The record of a fit of `samples` samples of which `masked_fraction`
    /// were left out.
    pub fn new(channel: &str, fit: &SkyFit, samples: usize, masked_fraction: f64) -> Self {
        ChannelSky {
            channel: channel.to_owned(),
            model: fit.model,
            chosen: fit.kind.label(),
            reason: fit.reason.clone(),
            rms_relative: fit.rms_relative,
            samples,
            masked_fraction,
            masked: None,
            convergence: Some(fit.convergence.clone()),
        }
    }

    /// The record of a fit with outliers masked.
    pub fn of_robust(channel: &str, robust: &RobustSkyFit) -> Self {
        ChannelSky {
            masked: Some(robust.masked_summary()),
            ..ChannelSky::new(channel, &robust.fit, robust.kept.len(), robust.masked_fraction)
        }
    }
}

/// A fitted sky, every channel.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SkyFile {
    /// The sun's zenith angle when the samples were taken, degrees.
    pub sun_zenith_deg: f64,
    /// The sun's azimuth, degrees from north through east.
    pub sun_azimuth_deg: f64,
    /// One sky per channel.
    pub channels: Vec<ChannelSky>,
}

/// Sky samples read from CSV.
#[derive(Debug, Clone, PartialEq)]
pub struct SampleTable {
    /// Channel names, in column order.
    pub channels: Vec<String>,
    /// `(zenith, azimuth)` of each row, radians.
    pub directions: Vec<(f64, f64)>,
    /// `values[channel][row]`.
    pub values: Vec<Vec<f64>>,
}

/// A problem in a sample table.
#[derive(Debug, thiserror::Error)]
pub enum SampleTableError {
    /// The table or one of its cells.
    #[error(transparent)]
    Table(#[from] TableError),
    /// No column besides the directions.
    #[error("the header has no channel column besides zenith_deg and azimuth_deg (it has: {found})")]
    NoChannels {
        /// The header.
        found: String,
    },
}

impl From<CellError> for SampleTableError {
    fn from(e: CellError) -> Self {
        SampleTableError::Table(TableError::Cell(e))
    }
}

/// Reads sky samples from CSV: directions and at least one channel.
pub fn read_samples(input: impl Read) -> Result<SampleTable, SampleTableError> {
    read_table(input, true)
}

/// Reads directions from CSV (`zenith_deg`, `azimuth_deg`; any other
/// columns are read as channels, and none are needed).
pub fn read_directions(input: impl Read) -> Result<SampleTable, SampleTableError> {
    read_table(input, false)
}

fn read_table(input: impl Read, need_channels: bool) -> Result<SampleTable, SampleTableError> {
    let mut rd = csv::ReaderBuilder::new().trim(csv::Trim::All).from_reader(input);
    let header = rd.headers().map_err(|e| TableError::csv(1, &e))?.clone();
    let (cz, ca) = (column(&header, "zenith_deg")?, column(&header, "azimuth_deg")?);
    let chans: Vec<usize> = (0..header.len()).filter(|&i| i != cz && i != ca).collect();
    if need_channels && chans.is_empty() {
        return Err(SampleTableError::NoChannels {
            found: header.iter().collect::<Vec<_>>().join(","),
        });
    }
    let mut table = SampleTable {
        channels: chans.iter().map(|&i| header[i].to_owned()).collect(),
        directions: Vec::new(),
        values: vec![Vec::new(); chans.len()],
    };
    for (k, rec) in rd.records().enumerate() {
        let row = k as u64 + 2;
        let rec = rec.map_err(|e| TableError::csv(row, &e))?;
        let num =
            |i: usize, lo: f64, hi: f64, expected: &'static str| number(&rec, &header, i, row, (lo, hi), expected);
        let z = num(cz, 0.0, 90.0, "a zenith angle in degrees in [0, 90]")?;
        let a = num(ca, -360.0, 360.0, "an azimuth in degrees")?;
        table.directions.push((z.to_radians(), a.to_radians()));
        for (slot, &i) in chans.iter().enumerate() {
            table.values[slot].push(num(i, f64::MIN, f64::MAX, "a radiance (a finite number)")?);
        }
    }
    Ok(table)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn samples_and_directions_parse_and_bad_cells_are_named() {
        let t = read_samples("zenith_deg,azimuth_deg,r,g\n10,20,1.5,2\n0,0,3,4\n".as_bytes()).expect("valid");
        assert_eq!(t.channels, ["r", "g"]);
        assert_eq!(t.values[1], [2.0, 4.0]);
        assert!((t.directions[0].0 - 10f64.to_radians()).abs() < 1e-15);
        assert!(read_samples("zenith_deg,azimuth_deg\n10,20\n".as_bytes()).is_err());
        assert_eq!(
            read_directions("zenith_deg,azimuth_deg\n10,20\n".as_bytes())
                .expect("valid")
                .directions
                .len(),
            1
        );
        let e = read_samples("zenith_deg,azimuth_deg,r\n95,0,1\n".as_bytes()).expect_err("zenith 95");
        assert_eq!(
            e.to_string(),
            "row 2, column `zenith_deg`: found \"95\"; expected a zenith angle in degrees in [0, 90]"
        );
    }
}
