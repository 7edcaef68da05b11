//! The site of a station file as the ephemeris's observer.

use std::path::Path;

use anyhow::Result;
use campanile_config::Site;
use campanile_process::sun::Observer;

/// Reads a station file and returns its site.
pub fn station_site(path: &Path) -> Result<Site> {
    Ok(campanile_config::load_station(path)
        .map_err(|e| anyhow::anyhow!("{e}"))?
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
            return Err(super::exit::bad_input(format!(
                "{flag}: found {}; expected {expected}",
                super::exit::shown(value)
            )));
        }
    }
    let lon = if lon >= 180.0 { lon - 360.0 } else { lon };
    Ok(Observer::from_degrees(lat, lon, elevation_m, 1013.25, 12.0))
}
