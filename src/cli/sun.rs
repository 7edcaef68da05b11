//! `campanile sun`: where the sun is, for one instant or a CSV table.

use std::path::PathBuf;

use anyhow::Result;

use super::exit::bad_input;
use campanile_session::sun_files::{self, SunAt};
use chrono::{DateTime, Utc};
use clap::Args;

/// Solar position (NREL SPA, ±0.0003°) for one instant, or for a table.
///
/// One instant: give --time and a site, either --station FILE or --lat and
/// --lon (plus optional --elevation-m, --pressure-mbar, --temperature-c,
/// --delta-t-s). Prints the apparent (refracted) zenith, azimuth (from north
/// through east) and elevation, the Earth–Sun distance, and that date's
/// sunrise, transit and sunset.
///
/// A table: --csv IN.csv [--out OUT.csv]. Columns time_utc, latitude_deg,
/// longitude_deg, and optionally elevation_m, pressure_mbar, temperature_c,
/// delta_t_s; other columns are copied through. The output adds zenith_deg,
/// azimuth_deg, elevation_deg and earth_sun_distance_au.
///
/// Examples:
///   campanile sun --time 2026-08-28T20:30:00Z --station examples/sim-station.ron
///   campanile sun --time 2003-10-17T19:30:30Z --lat 39.742476 --lon -105.1786 \
///       --elevation-m 1830.14 --pressure-mbar 820 --temperature-c 11 --delta-t-s 67
///   campanile sun --csv times.csv --out positions.csv
#[derive(Debug, Args)]
#[command(verbatim_doc_comment)]
pub struct SunArgs {
    /// The instant, RFC 3339 (e.g. 2026-08-28T20:30:00Z).
    #[arg(long, conflicts_with = "csv", required_unless_present = "csv")]
    time: Option<DateTime<Utc>>,
    /// Take the site from this station file.
    #[arg(long, conflicts_with_all = ["lat", "lon", "csv"])]
    station: Option<PathBuf>,
    /// Latitude in degrees, north positive.
    #[arg(long, allow_negative_numbers = true, requires = "lon")]
    lat: Option<f64>,
    /// Longitude in degrees, east positive.
    #[arg(long, allow_negative_numbers = true, requires = "lat")]
    lon: Option<f64>,
    /// Height above sea level in metres.
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    elevation_m: f64,
    /// Air pressure in millibars (for refraction).
    #[arg(long, default_value_t = 1013.25, allow_negative_numbers = true)]
    pressure_mbar: f64,
    /// Air temperature in °C (for refraction).
    #[arg(long, default_value_t = 12.0, allow_negative_numbers = true)]
    temperature_c: f64,
    /// IANA time zone for the local date and display (with --lat/--lon).
    #[arg(long, default_value = "UTC", conflicts_with = "station")]
    time_zone: chrono_tz::Tz,
    /// ΔT = TT − UT in seconds; estimated from the date when absent.
    #[arg(long, allow_negative_numbers = true)]
    delta_t_s: Option<f64>,
    /// Compute a CSV table of instants and sites instead.
    #[arg(long, value_name = "IN.csv")]
    csv: Option<PathBuf>,
    /// Where to write the table (standard output when absent).
    #[arg(long, value_name = "OUT.csv", requires = "csv")]
    out: Option<PathBuf>,
}

pub fn run(args: SunArgs) -> Result<()> {
    if let Some(input) = &args.csv {
        let n = sun_files::table(input, args.out.as_deref(), &mut std::io::stdout().lock())?;
        tracing::info!(rows = n, "solar positions written");
        return Ok(());
    }
    let Some(time) = args.time else {
        return Err(bad_input("--time is required without --csv"));
    };
    let instant = SunAt {
        time,
        station: args.station,
        lat: args.lat,
        lon: args.lon,
        elevation_m: args.elevation_m,
        pressure_mbar: args.pressure_mbar,
        temperature_c: args.temperature_c,
        time_zone: args.time_zone,
        delta_t_s: args.delta_t_s,
    };
    Ok(sun_files::instant(&instant, &mut std::io::stdout().lock())?)
}
