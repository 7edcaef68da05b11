//! Plain-file forms of sky data, for `campanile sky fit|predict`.
//!
//! **Samples** (CSV, header row): `zenith_deg` (in [0, 90]) and
//! `azimuth_deg` (from north through east) of each sky element, and the
//! channels' radiance in any one unit: the columns a [`ChannelSelection`]
//! names, by default `r,g,b` (or `red,green,blue`, any case), else a single
//! `y`, `luminance` or `radiance`. Other columns (ids, weights, notes) are
//! ignored and their cells are not read.
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

/// Which columns of a sample table are the channels.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub enum ChannelSelection {
    /// `r,g,b` (or `red,green,blue`; any case) when all three are present,
    /// else the one column named `y`, `luminance` or `radiance`.
    #[default]
    Auto,
    /// These columns, in this order (exact names, or any case when that is
    /// unambiguous).
    Named(Vec<String>),
    /// None: directions only.
    Directions,
}

/// The names [`ChannelSelection::Auto`] looks for, as the messages give them.
const AUTO_NAMES: &str = "r,g,b (or red,green,blue), or one of y, luminance, radiance";

/// A problem in a sample table.
#[derive(Debug, thiserror::Error)]
pub enum SampleTableError {
    /// The table or one of its cells.
    #[error(transparent)]
    Table(#[from] TableError),
    /// No columns the default selection takes as channels.
    #[error(
        "no channel columns: the header has {found}; expected {AUTO_NAMES} \
         (name the channel columns with --columns)"
    )]
    NoChannels {
        /// The header.
        found: String,
    },
    /// More than one column the default selection could take.
    #[error(
        "the channel column is ambiguous: the header has {candidates} (all of {found}); \
         name the channel columns with --columns"
    )]
    AmbiguousChannels {
        /// The columns that could be the channel.
        candidates: String,
        /// The header.
        found: String,
    },
    /// A channel asked for that is not in the header.
    #[error("channel column `{column}` is not in the header (it has: {found})")]
    UnknownChannel {
        /// The name asked for.
        column: String,
        /// The header.
        found: String,
    },
    /// A channel asked for twice, or a direction column asked for as a channel.
    #[error("channel column `{column}` cannot be a channel: {why} (the header has: {found})")]
    BadChannel {
        /// The name asked for.
        column: String,
        /// Why not.
        why: &'static str,
        /// The header.
        found: String,
    },
}

impl From<CellError> for SampleTableError {
    fn from(e: CellError) -> Self {
        SampleTableError::Table(TableError::Cell(e))
    }
}

/// Reads sky samples from CSV: the directions and the channels `channels`
/// selects (at least one, unless [`ChannelSelection::Directions`]). Cells
/// of the other columns are not read.
pub fn read_samples(input: impl Read, channels: &ChannelSelection) -> Result<SampleTable, SampleTableError> {
    let mut rd = csv::ReaderBuilder::new().trim(csv::Trim::All).from_reader(input);
    let header = rd.headers().map_err(|e| TableError::csv(1, &e))?.clone();
    let (cz, ca) = (column(&header, "zenith_deg")?, column(&header, "azimuth_deg")?);
    let chans = select(&header, channels, [cz, ca])?;
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

/// Reads directions from CSV (`zenith_deg`, `azimuth_deg`); any other
/// columns are ignored.
pub fn read_directions(input: impl Read) -> Result<SampleTable, SampleTableError> {
    read_samples(input, &ChannelSelection::Directions)
}

/// The indices of the channel columns `selection` picks from `header`,
/// whose direction columns are `directions`.
fn select(
    header: &csv::StringRecord,
    selection: &ChannelSelection,
    directions: [usize; 2],
) -> Result<Vec<usize>, SampleTableError> {
    let found = || header.iter().collect::<Vec<_>>().join(",");
    // The column named `name`: exactly, else the only one equal in any case.
    let find = |name: &str| {
        header.iter().position(|h| h == name).or_else(|| {
            let mut any_case = header
                .iter()
                .enumerate()
                .filter(|(_, h)| h.eq_ignore_ascii_case(name))
                .map(|(i, _)| i);
            match (any_case.next(), any_case.next()) {
                (Some(i), None) => Some(i),
                _ => None,
            }
        })
    };
    match selection {
        ChannelSelection::Directions => Ok(Vec::new()),
        ChannelSelection::Named(names) => {
            let mut chosen = Vec::with_capacity(names.len());
            for name in names {
                let i = find(name).ok_or_else(|| SampleTableError::UnknownChannel {
                    column: name.clone(),
                    found: found(),
                })?;
                let why = if directions.contains(&i) {
                    Some("it is a direction column")
                } else if chosen.contains(&i) {
                    Some("it is named twice")
                } else {
                    None
                };
                if let Some(why) = why {
                    return Err(SampleTableError::BadChannel {
                        column: name.clone(),
                        why,
                        found: found(),
                    });
                }
                chosen.push(i);
            }
            if chosen.is_empty() {
                return Err(SampleTableError::NoChannels { found: found() });
            }
            Ok(chosen)
        }
        ChannelSelection::Auto => {
            for names in [["r", "g", "b"], ["red", "green", "blue"]] {
                if let [Some(r), Some(g), Some(b)] = names.map(find) {
                    return Ok(vec![r, g, b]);
                }
            }
            let single: Vec<usize> = ["y", "luminance", "radiance"].iter().filter_map(|n| find(n)).collect();
            match single.as_slice() {
                [] => Err(SampleTableError::NoChannels { found: found() }),
                &[i] => Ok(vec![i]),
                more => Err(SampleTableError::AmbiguousChannels {
                    candidates: more.iter().map(|&i| &header[i]).collect::<Vec<_>>().join(", "),
                    found: found(),
                }),
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn samples_and_directions_parse_and_bad_cells_are_named() {
        let auto = &ChannelSelection::Auto;
        let t = read_samples(
            "zenith_deg,azimuth_deg,r,g,b\n10,20,1.5,2,3\n0,0,3,4,5\n".as_bytes(),
            auto,
        )
        .expect("valid");
        assert_eq!(t.channels, ["r", "g", "b"]);
        assert_eq!(t.values[1], [2.0, 4.0]);
        assert!((t.directions[0].0 - 10f64.to_radians()).abs() < 1e-15);
        assert!(read_samples("zenith_deg,azimuth_deg\n10,20\n".as_bytes(), auto).is_err());
        assert_eq!(
            read_directions("zenith_deg,azimuth_deg\n10,20\n".as_bytes())
                .expect("valid")
                .directions
                .len(),
            1
        );
        let e = read_samples("zenith_deg,azimuth_deg,r,g,b\n95,0,1,1,1\n".as_bytes(), auto).expect_err("zenith 95");
        assert_eq!(
            e.to_string(),
            "row 2, column `zenith_deg`: found \"95\"; expected a zenith angle in degrees in [0, 90]"
        );
    }

    /// A table with an id, a weight and a text note besides the channels.
    const MIXED: &str = "id,zenith_deg,azimuth_deg,weight,Red,GREEN,blue,y,note\n\
                         a7,10,20,0.5,1,2,3,9,clear\n\
                         b8,30,40,x,4,5,6,8,cloud edge\n";

    #[test]
    fn the_default_channels_are_r_g_b_in_any_case_and_other_columns_are_not_read() {
        let t = read_samples(MIXED.as_bytes(), &ChannelSelection::Auto).expect("valid");
        assert_eq!(t.channels, ["Red", "GREEN", "blue"]);
        assert_eq!(t.values, [[1.0, 4.0], [2.0, 5.0], [3.0, 6.0]]);
        // Directions only: neither the channels nor the text are read.
        let d = read_directions(MIXED.as_bytes()).expect("valid");
        assert!(d.channels.is_empty() && d.values.is_empty());
        assert!((d.directions[1].1 - 40f64.to_radians()).abs() < 1e-15);
        // Without r,g,b: the single luminance column.
        let t = read_samples(
            "zenith_deg,azimuth_deg,r,g,Luminance\n1,2,3,4,5\n".as_bytes(),
            &ChannelSelection::Auto,
        )
        .expect("valid");
        assert_eq!(
            (t.channels.as_slice(), t.values[0][0]),
            (&["Luminance".to_owned()][..], 5.0)
        );
    }

    #[test]
    fn named_channels_come_in_the_order_given() {
        let named = |names: &[&str]| ChannelSelection::Named(names.iter().map(|n| (*n).to_owned()).collect());
        let t = read_samples(MIXED.as_bytes(), &named(&["y", "red"])).expect("valid");
        assert_eq!(t.channels, ["y", "Red"]);
        assert_eq!(t.values, [[9.0, 8.0], [1.0, 4.0]]);
        // The weight column holds "x" on row 3: named, it is read and refused.
        let e = read_samples(MIXED.as_bytes(), &named(&["weight"])).expect_err("x");
        assert_eq!(
            e.to_string(),
            "row 3, column `weight`: found \"x\"; expected a radiance (a finite number)"
        );
    }

    #[test]
    fn channel_selections_that_cannot_be_met_name_the_header() {
        let named = |names: &[&str]| ChannelSelection::Named(names.iter().map(|n| (*n).to_owned()).collect());
        let header = "id,zenith_deg,azimuth_deg,weight,Red,GREEN,blue,y,note";
        let e = read_samples(MIXED.as_bytes(), &named(&["red", "q"])).expect_err("q");
        assert_eq!(
            e.to_string(),
            format!("channel column `q` is not in the header (it has: {header})")
        );
        let e = read_samples(MIXED.as_bytes(), &named(&["y", "Y"])).expect_err("twice");
        assert_eq!(
            e.to_string(),
            format!("channel column `Y` cannot be a channel: it is named twice (the header has: {header})")
        );
        let e = read_samples(MIXED.as_bytes(), &named(&["zenith_deg"])).expect_err("direction");
        assert!(e.to_string().contains("it is a direction column"), "{e}");
        let e = read_samples(
            "id,zenith_deg,azimuth_deg,r,g\n1,2,3,4,5\n".as_bytes(),
            &ChannelSelection::Auto,
        )
        .expect_err("no b");
        assert_eq!(
            e.to_string(),
            "no channel columns: the header has id,zenith_deg,azimuth_deg,r,g; expected r,g,b \
             (or red,green,blue), or one of y, luminance, radiance (name the channel columns with --columns)"
        );
        let e = read_samples(
            "zenith_deg,azimuth_deg,y,radiance\n1,2,3,4\n".as_bytes(),
            &ChannelSelection::Auto,
        )
        .expect_err("two");
        assert!(e.to_string().contains("ambiguous: the header has y, radiance"), "{e}");
    }
}
