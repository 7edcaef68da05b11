//! Where the sun is for a command: given as angles, or from the ephemeris
//! (NREL SPA) for an instant at a station's site or at a latitude and
//! longitude.

use std::path::{Path, PathBuf};

use campanile_config::Site;
use campanile_process::sun::{Ephemeris, Observer};
use chrono::{DateTime, Utc};

use crate::error::{Error, Result, shown};

/// Reads a station file and returns its site.
pub fn station_site(path: &Path) -> Result<Site> {
    Ok(campanile_config::load_station(path)
        .map_err(|e| Error::input(e.to_string()))?
        .value
        .site)
}

/// The observer standing at `site`.
pub fn observer(site: &Site) -> Observer {
    Observer::from_degrees(
        site.latitude_deg,
        site.longitude_deg,
        site.elevation_m,
        site.pressure_mbar,
        site.temperature_c,
    )
}

/// The observer at `--lat`, `--lon` (north and east positive; a longitude
/// from 180 up to 360 is taken as east of Greenwich the long way round)
/// and `--elevation-m`, with refraction for 1013.25 mbar and 12 °C (as
/// `campanile sun` assumes). Values outside their domains are bad input.
pub fn observer_at(lat: f64, lon: f64, elevation_m: f64) -> Result<Observer> {
    let checks = [
        (
            "--lat",
            lat,
            (-90.0..=90.0).contains(&lat),
            "degrees from -90 to 90, north positive",
        ),
        (
            "--lon",
            lon,
            (-180.0..360.0).contains(&lon),
            "degrees from -180 up to (not including) 360, east positive",
        ),
        (
            "--elevation-m",
            elevation_m,
            (-6_500_000.0..=1e7).contains(&elevation_m),
            "metres above sea level, -6500000 to 10000000",
        ),
    ];
    for (flag, value, ok, expected) in checks {
        if !ok {
            return Err(Error::input(format!(
                "{flag}: found {}; expected {expected}",
                shown(value)
            )));
        }
    }
    let lon = if lon >= 180.0 { lon - 360.0 } else { lon };
    Ok(Observer::from_degrees(lat, lon, elevation_m, 1013.25, 12.0))
}

/// The sun as a command is given it: angles, or an instant with a station
/// file or with a latitude and longitude.
#[derive(Debug, Clone, Default)]
pub struct SunGiven {
    /// The sun's zenith angle, degrees.
    pub zenith_deg: Option<f64>,
    /// The sun's azimuth, degrees from north through east.
    pub azimuth_deg: Option<f64>,
    /// The instant, for the ephemeris.
    pub time: Option<DateTime<Utc>>,
    /// The station file whose site the ephemeris uses.
    pub station: Option<PathBuf>,
    /// The site's latitude, degrees, north positive.
    pub lat: Option<f64>,
    /// The site's longitude, degrees, east positive.
    pub lon: Option<f64>,
    /// The site's height above sea level, metres.
    pub elevation_m: Option<f64>,
}

impl SunGiven {
    /// (zenith, azimuth) in radians, for a sun that may be below the
    /// horizon (the environment is lit by the sky alone then).
    pub fn resolve_any(&self) -> Result<(f64, f64)> {
        let site = (&self.station, self.lat, self.lon);
        match (self.zenith_deg, self.azimuth_deg, self.time, site) {
            (Some(z), Some(a), _, _) if (0.0..=180.0).contains(&z) => Ok((z.to_radians(), a.to_radians())),
            (Some(z), Some(_), _, _) => Err(Error::input(format!(
                "--sun-zenith-deg: found {}; expected a zenith angle from 0 to 180 degrees",
                shown(z)
            ))),
            (_, _, Some(t), (Some(path), _, _)) => {
                let s = station_site(path)?;
                let p = Ephemeris::at(t, s.delta_t_s)?.position(&observer(&s))?;
                Ok((p.zenith_rad, p.azimuth_rad))
            }
            (_, _, Some(t), (None, Some(lat), Some(lon))) => {
                let obs = observer_at(lat, lon, self.elevation_m.unwrap_or(0.0))?;
                let p = Ephemeris::at(t, None)?.position(&obs)?;
                Ok((p.zenith_rad, p.azimuth_rad))
            }
            _ => Err(Error::input(
                "give the sun: --sun-zenith-deg and --sun-azimuth-deg, or --time with --station or with --lat and --lon",
            )),
        }
    }

    /// (zenith, azimuth) in radians, for a sun above the horizon.
    pub fn resolve(&self) -> Result<(f64, f64)> {
        let (z, a) = self.resolve_any()?;
        if z > std::f64::consts::FRAC_PI_2 {
            return Err(Error::input(format!(
                "the sun is {:.2}° below the horizon then: no daylight sky to fit or predict",
                (z - std::f64::consts::FRAC_PI_2).to_degrees()
            )));
        }
        Ok((z, a))
    }
}
