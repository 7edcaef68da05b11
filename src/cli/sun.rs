//! `campanile sun`: where the sun is, for one instant or a CSV table.

use std::fs::File;
use std::io::{BufReader, Write};
use std::path::PathBuf;

use anyhow::{Context, Result};

use super::exit::{bad_input, shown};
use campanile_process::sun::{Ephemeris, Observer, SolarDay, solar_day, sun_table};
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
        let file = File::open(input).with_context(|| format!("{}: cannot open", input.display()))?;
        let n = match &args.out {
            Some(out) => campanile_session::partial_file::write_with(out, |w| {
                Ok(sun_table(BufReader::new(file), w).with_context(|| format!("{}", input.display()))?)
            })?,
            None => sun_table(BufReader::new(file), std::io::stdout().lock())
                .with_context(|| format!("{}", input.display()))?,
        };
        tracing::info!(rows = n, "solar positions written");
        return Ok(());
    }
    let Some(time) = args.time else {
        return Err(bad_input("--time is required without --csv"));
    };
    let (observer, delta_t, zone, site_name) = match (&args.station, args.lat, args.lon) {
        (Some(path), _, _) => {
            let s = super::site::station_site(path)?;
            let zone: chrono_tz::Tz = s.time_zone.parse().unwrap_or(chrono_tz::UTC);
            (super::site::observer(&s), s.delta_t_s, zone, s.name)
        }
        (None, Some(lat), Some(lon)) => (
            check_site(&args)
                .map(|()| Observer::from_degrees(lat, lon, args.elevation_m, args.pressure_mbar, args.temperature_c))?,
            args.delta_t_s,
            args.time_zone,
            format!("{lat}°, {lon}°"),
        ),
        _ => return Err(bad_input("give a site: --station FILE, or --lat and --lon")),
    };
    let delta_t = args.delta_t_s.or(delta_t);
    let eph = Ephemeris::at(time, delta_t)?;
    let p = eph.position(&observer)?;
    let mut out = std::io::stdout().lock();
    writeln!(out, "site            {site_name}")?;
    writeln!(
        out,
        "time            {} ({})",
        time.to_rfc3339(),
        time.with_timezone(&zone).format("%Y-%m-%d %H:%M:%S %Z")
    )?;
    writeln!(out, "zenith_deg      {:.5}", p.zenith_rad.to_degrees())?;
    writeln!(out, "azimuth_deg     {:.5}", p.azimuth_rad.to_degrees())?;
    writeln!(out, "elevation_deg   {:.5}", p.elevation_rad().to_degrees())?;
    writeln!(out, "earth_sun_au    {:.7}", eph.earth_sun_distance_au())?;
    let local_date = time.with_timezone(&zone).date_naive();
    let show = |t: Option<DateTime<Utc>>| match t {
        Some(t) => format!(
            "{} ({})",
            t.format("%Y-%m-%d %H:%M:%S UTC"),
            t.with_timezone(&zone).format("%H:%M:%S %Z")
        ),
        None => "none".into(),
    };
    match solar_day(local_date, &zone, &observer, delta_t)? {
        SolarDay::Normal {
            sunrise,
            transit,
            sunset,
        } => {
            writeln!(out, "sunrise         {}", show(sunrise))?;
            writeln!(out, "transit         {}", show(transit))?;
            writeln!(out, "sunset          {}", show(sunset))?;
        }
        SolarDay::PolarDay { transit } => writeln!(out, "polar day       the sun stays up; transit {}", show(transit))?,
        SolarDay::PolarNight { transit } => {
            writeln!(out, "polar night     the sun stays down; transit {}", show(transit))?
        }
    }
    Ok(())
}

/// The site's arguments against their domains (those of the NREL SPA).
fn check_site(args: &SunArgs) -> Result<()> {
    let checks = [
        ("--lat", args.lat.unwrap_or(0.0), -90.0, 90.0, "degrees from -90 to 90"),
        (
            "--lon",
            args.lon.unwrap_or(0.0),
            -180.0,
            180.0,
            "degrees from -180 to 180",
        ),
        (
            "--elevation-m",
            args.elevation_m,
            -6_500_000.0,
            1e7,
            "metres above sea level, -6500000 to 10000000",
        ),
        (
            "--pressure-mbar",
            args.pressure_mbar,
            f64::MIN_POSITIVE,
            2000.0,
            "more than 0 and at most 2000 mbar",
        ),
        (
            "--temperature-c",
            args.temperature_c,
            -273.0 + 1e-9,
            100.0,
            "more than -273 and at most 100 °C",
        ),
    ];
    for (flag, value, low, high, expected) in checks {
        if !(low..=high).contains(&value) {
            return Err(bad_input(format!(
                "{flag}: found {}; expected {expected}",
                shown(value)
            )));
        }
    }
    Ok(())
}
