//! The time-series file: one row per scan, every column documented (name,
//! unit, meaning) in `#` comment lines above the header row, and the day's
//! extinction as a second small table.

use std::fmt::Write as _;

use super::condition::SkyCondition;
use super::day::SkySeries;
use super::scan::ScanProducts;

const CHANNELS: [&str; 3] = ["r", "g", "b"];

/// The per-scan columns: name, then unit and meaning. Per-channel columns
/// (`{c}`) repeat for r, g, b in that order.
pub const SERIES_COLUMNS: &[(&str, &str)] = &[
    ("occurrence", "text: the scan's occurrence id, {session}@{date}#{n}"),
    ("time_utc", "RFC 3339 UTC: mean time of the scan's sky tiles"),
    (
        "sun_zenith_deg",
        "degrees: apparent (refracted) solar zenith angle at time_utc",
    ),
    (
        "sun_azimuth_deg",
        "degrees from north through east: solar azimuth at time_utc",
    ),
    (
        "sun_air_mass",
        "unitless: Kasten–Young air mass at the sun frames' time (empty: no sun measured)",
    ),
    (
        "sun_e_{c}_w_m2",
        "W·m⁻² (full-well gauge): direct normal solar irradiance, channel {c}",
    ),
    (
        "sun_spread_{c}",
        "unitless: (max − min)/mean of the sun triplet, channel {c}",
    ),
    (
        "sky_model_{c}",
        "text: eq. (5.9) model chosen for channel {c} (Perez, SevenParameter, SevenParameterFixedAureole or Cie(N))",
    ),
    ("sky_lz_{c}_w_m2_sr", "W·m⁻²·sr⁻¹: eq. (5.9) scale Lz, channel {c}"),
    ("sky_a_{c}", "unitless: gradation coefficient a, channel {c}"),
    ("sky_b_{c}", "unitless: gradation exponent b, channel {c}"),
    ("sky_c_{c}", "unitless: aureole strength c, channel {c}"),
    ("sky_d_{c}", "1/radian^h: aureole decay d, channel {c}"),
    ("sky_e_{c}", "unitless: forward scattering e, channel {c}"),
    ("sky_h_{c}", "unitless: aureole exponent h of γ, channel {c}"),
    (
        "sky_rms_{c}",
        "unitless: RMS relative residual of the fit over the kept samples, channel {c}",
    ),
    (
        "sky_masked_{c}",
        "unitless 0–1: fraction of sky samples masked out as not sky, channel {c}",
    ),
    (
        "profile_rms_{c}",
        "unitless: RMS of fitted/measured − 1 over the sun's vertical-plane profile bins, channel {c}",
    ),
    (
        "flags",
        "text: raised quality flags, ;-separated (clouds_near_sun, poor_fit, high_masked_fraction)",
    ),
    (
        "clear_sky_index",
        "ratio: measured sky radiance over the day's clear sky at this sun position, solid-angle-weighted mean over the regions (channels summed; empty: not computed, see condition_note)",
    ),
    (
        "direct_clear_sky_index",
        "ratio: measured direct normal irradiance over the day's Langley fit E₀ exp(−β m) at the scan's air mass (channels summed)",
    ),
    (
        "cloud_cover",
        "fraction 0–1: solid-angle-weighted share of sky regions (3 zenith bands to 80° × 8 azimuth sectors, the sun's 15° left out) departing from the clear sky by more than 0.2 in |ln ratio| in a channel",
    ),
    (
        "clouds_near_sun_region",
        "0 or 1: the sky image's sun neighbourhood (3°–15° from the sun) departs from the clear sky (separate from the triplet flag clouds_near_sun)",
    ),
    (
        "sky_condition",
        "text: clear, partly-cloudy, cloudy or overcast (cloud_cover below 1.5, 4.5, 7.5 oktas, else overcast)",
    ),
    (
        "condition_note",
        "text: why a condition figure is missing (empty when all are there)",
    ),
];

/// The extinction columns (one row per day and channel).
pub const EXTINCTION_COLUMNS: &[(&str, &str)] = &[
    ("date", "YYYY-MM-DD: the day (from the occurrence ids)"),
    ("channel", "r, g or b"),
    (
        "beta",
        "per unit air mass: extinction coefficient β of ln E = ln E₀ − β m (empty: no fit)",
    ),
    (
        "e0_w_m2",
        "W·m⁻² (full-well gauge): irradiance outside the atmosphere E₀",
    ),
    ("rms_log", "unitless: RMS residual of ln E"),
    ("air_mass_span", "unitless: max − min air mass of the scans fitted"),
    ("scans_fitted", "count: scans whose sun triplet agreed"),
    ("scans_left_out", "count: scans with clouds near the sun or no sun"),
    ("note", "text: why there is no fit, if there is none"),
];

/// The columns with `{c}` expanded to r, g, b: (name, unit and meaning).
pub(crate) fn expand(columns: &[(&str, &str)]) -> Vec<(String, String)> {
    let mut out = Vec::new();
    for (name, doc) in columns {
        if name.contains("{c}") {
            for c in CHANNELS {
                out.push((name.replace("{c}", c), doc.replace("{c}", c)));
            }
        } else {
            out.push(((*name).to_owned(), (*doc).to_owned()));
        }
    }
    out
}

/// One cell of a series row, typed: what the CSV formats and the Parquet
/// file stores.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Cell {
    /// Text; `None` where there is nothing (an empty CSV cell, a Parquet null).
    Text(Option<String>),
    /// A number; `None` (or a non-finite value) where there is none.
    Number(Option<f64>),
    /// The scan's time.
    Time(chrono::DateTime<chrono::Utc>),
}

impl Cell {
    fn csv(&self) -> String {
        match self {
            Cell::Text(t) => t.as_deref().map_or(String::new(), text_cell),
            Cell::Number(v) => v.map_or(String::new(), num),
            Cell::Time(t) => t.to_rfc3339_opts(chrono::SecondsFormat::Millis, true),
        }
    }
}

fn header(text: &mut String, title: &str, columns: &[(String, String)]) {
    let _ = writeln!(text, "# {title}");
    for (name, doc) in columns {
        let _ = writeln!(text, "# {name}: {doc}");
    }
    let names: Vec<&str> = columns.iter().map(|(n, _)| n.as_str()).collect();
    let _ = writeln!(text, "{}", names.join(","));
}

fn num(v: f64) -> String {
    if v.is_finite() { format!("{v}") } else { String::new() }
}

fn text_cell(s: &str) -> String {
    if s.contains([',', '"', '\n']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_owned()
    }
}

/// A scan's row with its condition, in [`SERIES_COLUMNS`]' order (expanded).
pub(crate) fn cells(s: &ScanProducts, cond: &SkyCondition) -> Vec<Cell> {
    let mut r = vec![
        Cell::Text(Some(s.occurrence.clone())),
        Cell::Time(s.time_utc),
        Cell::Number(Some(s.sun_zenith_deg)),
        Cell::Number(Some(s.sun_azimuth_deg)),
    ];
    let sun = s.sun.as_ref();
    r.push(Cell::Number(sun.map(|m| m.air_mass)));
    for c in 0..3 {
        r.push(Cell::Number(sun.map(|m| m.irradiance_w_m2[c])));
    }
    for c in 0..3 {
        r.push(Cell::Number(sun.map(|m| m.spread[c])));
    }
    let sky = s.sky.as_ref().filter(|k| k.len() == 3);
    let per = |f: &dyn Fn(&crate::sky::ChannelSky) -> f64| -> Vec<Cell> {
        (0..3).map(|c| Cell::Number(sky.map(|k| f(&k[c])))).collect()
    };
    r.extend((0..3).map(|c| Cell::Text(sky.map(|k| k[c].chosen.clone()))));
    r.extend(per(&|k| k.model.lz));
    r.extend(per(&|k| k.model.a));
    r.extend(per(&|k| k.model.b));
    r.extend(per(&|k| k.model.c));
    r.extend(per(&|k| k.model.d));
    r.extend(per(&|k| k.model.e));
    r.extend(per(&|k| k.model.h));
    r.extend(per(&|k| k.rms_relative));
    r.extend(per(&|k| k.masked_fraction));
    let prms = s.profile.rms_relative();
    for c in 0..3 {
        r.push(Cell::Number(prms.map(|p| p[c])));
    }
    r.push(Cell::Text(Some(s.quality.names())));
    r.push(Cell::Number(cond.clear_sky_index));
    r.push(Cell::Number(cond.direct_clear_sky_index));
    r.push(Cell::Number(cond.cloud_cover));
    r.push(Cell::Number(cond.clouds_near_sun_region.map(f64::from)));
    r.push(Cell::Text(cond.condition.map(|c| c.as_str().to_owned())));
    r.push(Cell::Text(Some(cond.note.clone())));
    r
}

/// The time series as CSV: documented header, one row per scan in time order.
pub fn series_csv(series: &SkySeries) -> String {
    let mut text = String::new();
    header(
        &mut text,
        "Campanile sky time series: one row per scan; columns, units and meaning:",
        &expand(SERIES_COLUMNS),
    );
    for (s, c) in series.scans.iter().zip(&series.conditions) {
        let row: Vec<String> = cells(s, c).iter().map(Cell::csv).collect();
        let _ = writeln!(text, "{}", row.join(","));
    }
    text
}

/// The day's extinction as CSV: documented header, one row per day and channel.
pub fn extinction_csv(series: &SkySeries) -> String {
    let mut text = String::new();
    header(
        &mut text,
        "Campanile extinction per day (Langley fit over the scans whose sun triplet agreed):",
        &expand(EXTINCTION_COLUMNS),
    );
    for d in &series.days {
        for (c, name) in CHANNELS.iter().enumerate() {
            let cells = match &d.fit[c] {
                Ok(e) => vec![
                    num(e.beta),
                    num(e.e0),
                    num(e.rms_log),
                    num(e.air_mass_span),
                    d.points.len().to_string(),
                    d.left_out.to_string(),
                    String::new(),
                ],
                Err(why) => vec![
                    String::new(),
                    String::new(),
                    String::new(),
                    String::new(),
                    d.points.len().to_string(),
                    d.left_out.to_string(),
                    text_cell(why),
                ],
            };
            let _ = writeln!(text, "{},{name},{}", d.date, cells.join(","));
        }
    }
    text
}

/// The number of cells per series row (for readers).
pub fn series_width() -> usize {
    expand(SERIES_COLUMNS).len()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_column_is_documented_and_rows_are_as_wide_as_the_header() {
        let series = SkySeries::new(Vec::new());
        let text = series_csv(&series);
        let header = text.lines().find(|l| !l.starts_with('#')).unwrap();
        let names: Vec<&str> = header.split(',').collect();
        assert_eq!(names.len(), series_width());
        // 5 + 3 + 3 + 10 × 3 + 3 + 1 + 6 = 51 columns, each with a comment line.
        assert_eq!(names.len(), 51);
        for n in &names {
            assert!(text.contains(&format!("# {n}: ")), "{n} undocumented");
        }
        let ext = extinction_csv(&series);
        assert_eq!(ext.lines().filter(|l| !l.starts_with('#')).count(), 1);
    }
}
