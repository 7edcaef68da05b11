//! Solar positions as `campanile sun` gives them: a CSV table of instants
//! and sites, or one instant at a site with that date's sunrise, transit
//! and sunset (NREL SPA through `campanile_process::sun`).

use std::fs::File;
use std::io::{BufReader, Write};
use std::path::{Path, PathBuf};

use anyhow::Context;
use campanile_process::sun::{Ephemeris, Observer, SolarDay, solar_day, sun_table};
use chrono::{DateTime, Utc};

use crate::error::{Error, Result, shown};
use crate::site::{observer, station_site};

/// Where and when, for one instant.
#[derive(Debug, Clone)]
pub struct SunAt {
    /// The instant.
    pub time: DateTime<Utc>,
    /// A station file whose site is used.
    pub station: Option<PathBuf>,
    /// The latitude, degrees north (without a station).
    pub lat: Option<f64>,
    /// The longitude, degrees east (without a station).
    pub lon: Option<f64>,
    /// Height above sea level, metres.
    pub elevation_m: f64,
    /// Air pressure, millibars (refraction).
    pub pressure_mbar: f64,
    /// Air temperature, °C (refraction).
    pub temperature_c: f64,
    /// The time zone for the local date and display (with lat and lon).
    pub time_zone: chrono_tz::Tz,
    /// ΔT = TT − UT, seconds; estimated from the date when absent.
    pub delta_t_s: Option<f64>,
}

/// Solar positions for the CSV table `input`, written to the file `out`
/// (through a partial file and a rename) or else to `stdout`; returns the
/// rows written.
pub fn table(input: &Path, out: Option<&Path>, stdout: &mut dyn Write) -> Result<usize> {
    let file = File::open(input).with_context(|| format!("{}: cannot open", input.display()))?;
    let n = match out {
        Some(out) => crate::partial_file::write_with(out, |w| {
            Ok(sun_table(BufReader::new(file), w).with_context(|| format!("{}", input.display()))?)
        })?,
        None => sun_table(BufReader::new(file), stdout).with_context(|| format!("{}", input.display()))?,
    };
    Ok(n)
}

/// Writes the sun's apparent position at `a`'s instant and site, the
/// Earth–Sun distance, and the local date's sunrise, transit and sunset
/// (or polar day or night) to `out`.
pub fn instant(a: &SunAt, out: &mut dyn Write) -> Result<()> {
    let time = a.time;
    let (observer, delta_t, zone, site_name) = match (&a.station, a.lat, a.lon) {
        (Some(path), _, _) => {
            let s = station_site(path)?;
            let zone: chrono_tz::Tz = s.time_zone.parse().unwrap_or(chrono_tz::UTC);
            (observer(&s), s.delta_t_s, zone, s.name)
        }
        (None, Some(lat), Some(lon)) => (
            check_site(a, lat, lon)
                .map(|()| Observer::from_degrees(lat, lon, a.elevation_m, a.pressure_mbar, a.temperature_c))?,
            a.delta_t_s,
            a.time_zone,
            format!("{lat}°, {lon}°"),
        ),
        _ => return Err(Error::input("give a site: --station FILE, or --lat and --lon")),
    };
    let delta_t = a.delta_t_s.or(delta_t);
    let eph = Ephemeris::at(time, delta_t)?;
    let p = eph.position(&observer)?;
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
fn check_site(args: &SunAt, lat: f64, lon: f64) -> Result<()> {
    let checks = [
        ("--lat", lat, -90.0, 90.0, "degrees from -90 to 90"),
        ("--lon", lon, -180.0, 180.0, "degrees from -180 to 180"),
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
            return Err(Error::input(format!(
                "{flag}: found {}; expected {expected}",
                shown(value)
            )));
        }
    }
    Ok(())
}
