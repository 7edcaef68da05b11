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
