//! Solar positions for a table of instants and sites, in bulk: the CSV
//! format of `campanile sun --csv`.
//!
//! Input columns (a header row names them; order is free, extra columns are
//! kept and copied through):
//!
//! | column | unit | required |
//! | --- | --- | --- |
//! | `time_utc` | RFC 3339, e.g. `2026-08-28T20:30:00Z` | yes |
//! | `latitude_deg` | degrees, north positive | yes |
//! | `longitude_deg` | degrees, east positive | yes |
//! | `elevation_m` | metres above sea level | no (0) |
//! | `pressure_mbar` | millibars | no (1013.25) |
//! | `temperature_c` | °C | no (12) |
//! | `delta_t_s` | seconds, TT − UT | no (estimated) |
//!
//! Output appends `zenith_deg`, `azimuth_deg` (from north through east),
//! `elevation_deg` (all apparent, refraction included) and
//! `earth_sun_distance_au`.

use std::io::{Read, Write};

use chrono::{DateTime, Utc};
use rayon::prelude::*;

use super::position::{Ephemeris, Observer, SunError, SunPosition};
use crate::csv_cell::{CellError, TableError, column, number};

/// One row to compute.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SunRequest {
    /// The instant.
    pub time: DateTime<Utc>,
    /// The site.
    pub observer: Observer,
    /// ΔT if known.
    pub delta_t_s: Option<f64>,
}

/// A computed row.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SunAnswer {
    /// Apparent position.
    pub position: SunPosition,
    /// Earth–Sun distance, AU.
    pub earth_sun_distance_au: f64,
}

/// The ephemeris of the last instant and ΔT seen in a chunk.
type CachedEphemeris = (DateTime<Utc>, Option<f64>, Result<Ephemeris, SunError>);

/// Positions for many requests, in parallel. The time-dependent part is
/// computed once per run of consecutive requests at the same instant and ΔT.
pub fn sun_positions(requests: &[SunRequest]) -> Vec<Result<SunAnswer, SunError>> {
    const CHUNK: usize = 256;
    requests
        .par_chunks(CHUNK)
        .flat_map_iter(|chunk| {
            let mut cache: Option<CachedEphemeris> = None;
            chunk
                .iter()
                .map(|r| {
                    let fresh = !matches!(&cache, Some((t, dt, _)) if *t == r.time && *dt == r.delta_t_s);
                    if fresh {
                        cache = Some((r.time, r.delta_t_s, Ephemeris::at(r.time, r.delta_t_s)));
                    }
                    let eph = match &cache {
                        Some((_, _, Ok(e))) => e,
                        Some((_, _, Err(e))) => return Err(e.clone()),
                        None => unreachable!("cache was just filled"),
                    };
                    Ok(SunAnswer {
                        position: eph.position(&r.observer)?,
                        earth_sun_distance_au: eph.earth_sun_distance_au(),
                    })
                })
                .collect::<Vec<_>>()
        })
        .collect()
}

/// A problem in a table of sun requests.
#[derive(Debug, thiserror::Error)]
pub enum SunTableError {
    /// The table or one of its cells.
    #[error(transparent)]
    Table(#[from] TableError),
    /// The ephemeris refused a row. (Its reason is in the message, not a
    /// `source`, so that an error chain prints it once.)
    #[error("row {row}: {reason}")]
    Sun {
        /// Row.
        row: u64,
        /// Why.
        reason: SunError,
    },
    /// Writing failed; the `io::Error` is the source (printed by the chain;
    /// a closed pipe is `BrokenPipe`, so a caller can tell it).
    #[error("cannot write the output")]
    Write(#[source] std::io::Error),
}

impl From<CellError> for SunTableError {
    fn from(e: CellError) -> Self {
        SunTableError::Table(TableError::Cell(e))
    }
}

/// Reads requests from CSV, computes them, and writes the table with the
/// result columns appended. Returns the number of rows written.
pub fn sun_table(input: impl Read, output: impl Write) -> Result<usize, SunTableError> {
    let mut rd = csv::ReaderBuilder::new().trim(csv::Trim::All).from_reader(input);
    let header = rd.headers().map_err(|e| TableError::csv(1, &e))?.clone();
    let col = |name: &'static str| header.iter().position(|h| h == name);
    let need = |name: &'static str| column(&header, name);
    let (c_time, c_lat, c_lon) = (need("time_utc")?, need("latitude_deg")?, need("longitude_deg")?);
    let (c_elev, c_p, c_t, c_dt) = (
        col("elevation_m"),
        col("pressure_mbar"),
        col("temperature_c"),
        col("delta_t_s"),
    );
    let mut rows = Vec::new();
    let mut requests = Vec::new();
    for (k, rec) in rd.records().enumerate() {
        let row = k as u64 + 2;
        let rec = rec.map_err(|e| TableError::csv(row, &e))?;
        let cell = |c: usize| rec.get(c).unwrap_or("");
        let num = |c: usize, expected: &'static str| number(&rec, &header, c, row, (f64::MIN, f64::MAX), expected);
        let opt = |c: Option<usize>, default: Option<f64>, expected: &'static str| -> Result<Option<f64>, TableError> {
            match c {
                Some(c) if !cell(c).is_empty() => Ok(Some(num(c, expected)?)),
                _ => Ok(default),
            }
        };
        let time = DateTime::parse_from_rfc3339(cell(c_time))
            .map(|t| t.with_timezone(&Utc))
            .map_err(|_| CellError {
                row,
                column: "time_utc".into(),
                value: cell(c_time).to_owned(),
                expected: "an RFC 3339 time such as 2026-08-28T20:30:00Z",
            })?;
        let observer = Observer::from_degrees(
            num(c_lat, "a latitude in degrees")?,
            num(c_lon, "a longitude in degrees")?,
            opt(c_elev, Some(0.0), "an elevation in metres")?.unwrap_or(0.0),
            opt(c_p, Some(1013.25), "a pressure in millibars")?.unwrap_or(1013.25),
            opt(c_t, Some(12.0), "a temperature in °C")?.unwrap_or(12.0),
        );
        requests.push(SunRequest {
            time,
            observer,
            delta_t_s: opt(c_dt, None, "ΔT in seconds")?,
        });
        rows.push(rec);
    }
    let answers = sun_positions(&requests);
    let mut wr = csv::Writer::from_writer(output);
    let mut out_header = header.clone();
    for h in ["zenith_deg", "azimuth_deg", "elevation_deg", "earth_sun_distance_au"] {
        out_header.push_field(h);
    }
    wr.write_record(&out_header)
        .map_err(|e| SunTableError::Write(e.into()))?;
    for (k, (rec, ans)) in rows.iter().zip(answers).enumerate() {
        let a = ans.map_err(|reason| SunTableError::Sun {
            row: k as u64 + 2,
            reason,
        })?;
        let mut rec = rec.clone();
        rec.push_field(&format!("{:.7}", a.position.zenith_rad.to_degrees()));
        rec.push_field(&format!("{:.7}", a.position.azimuth_rad.to_degrees()));
        rec.push_field(&format!("{:.7}", a.position.elevation_rad().to_degrees()));
        rec.push_field(&format!("{:.10}", a.earth_sun_distance_au));
        wr.write_record(&rec).map_err(|e| SunTableError::Write(e.into()))?;
    }
    wr.flush().map_err(SunTableError::Write)?;
    Ok(rows.len())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table_reproduces_the_nrel_case_and_keeps_extra_columns() {
        let input = "id,time_utc,latitude_deg,longitude_deg,elevation_m,pressure_mbar,temperature_c,delta_t_s\n\
                     a,2003-10-17T19:30:30Z,39.742476,-105.1786,1830.14,820,11,67\n\
                     b,2003-10-17T19:30:30Z,39.742476,-105.1786,1830.14,820,11,67\n";
        let mut out = Vec::new();
        assert_eq!(sun_table(input.as_bytes(), &mut out).expect("valid"), 2);
        let text = String::from_utf8(out).expect("utf-8");
        let mut lines = text.lines();
        assert!(
            lines
                .next()
                .expect("header")
                .ends_with("zenith_deg,azimuth_deg,elevation_deg,earth_sun_distance_au")
        );
        let row: Vec<&str> = lines.next().expect("row").split(',').collect();
        assert_eq!(row[0], "a");
        let zenith: f64 = row[8].parse().expect("number");
        let azimuth: f64 = row[9].parse().expect("number");
        assert!(
            (zenith - 50.11162).abs() < 1e-5 && (azimuth - 194.34024).abs() < 1e-5,
            "{zenith} {azimuth}"
        );
    }

    #[test]
    fn bad_cells_are_named_by_row_and_column() {
        let input = "time_utc,latitude_deg,longitude_deg\n2026-08-28T20:30:00Z,37.9,-122.3\n2026-08-28T20:30:00Z,north,-122.3\n";
        let err = sun_table(input.as_bytes(), Vec::new()).expect_err("bad latitude");
        assert_eq!(
            err.to_string(),
            "row 3, column `latitude_deg`: found \"north\"; expected a latitude in degrees"
        );
        let err = sun_table("time,lat\n".as_bytes(), Vec::new()).expect_err("no columns");
        assert!(
            err.to_string().starts_with("the header has no `time_utc` column"),
            "{err}"
        );
        let input = "time_utc,latitude_deg,longitude_deg\n2026-08-28T20:30:00Z,95,0\n";
        let err = sun_table(input.as_bytes(), Vec::new()).expect_err("latitude 95");
        assert!(err.to_string().starts_with("row 2: site"), "{err}");
    }

    #[test]
    fn bulk_equals_one_by_one() {
        use chrono::TimeZone;
        let reqs: Vec<_> = (0..1000)
            .map(|k| SunRequest {
                time: Utc.with_ymd_and_hms(2026, 8, 28, 0, 0, 0).single().expect("t")
                    + chrono::Duration::minutes(k / 10 * 7),
                observer: Observer::from_degrees(
                    -80.0 + (k % 10) as f64 * 17.0,
                    -170.0 + (k % 7) as f64 * 50.0,
                    100.0,
                    1000.0,
                    10.0,
                ),
                delta_t_s: Some(69.0),
            })
            .collect();
        for (r, a) in reqs.iter().zip(sun_positions(&reqs)) {
            let single = super::super::sun_position(r.time, &r.observer, r.delta_t_s).expect("ok");
            assert_eq!(a.expect("ok").position, single);
        }
    }
}
