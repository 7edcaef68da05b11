//! Where the station stands: the site description used by the solar
//! ephemeris (thesis §5.3.1) and for display of local times.

use serde::{Deserialize, Serialize};

use crate::validate::{Validate, Validator};

/// A geographic site. Angles are in degrees, as everywhere in files.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(test, derive(proptest_derive::Arbitrary))]
#[serde(deny_unknown_fields)]
pub struct Site {
    /// A human-readable name, e.g. "Campanile, Berkeley".
    pub name: String,
    /// Geodetic latitude in degrees, north positive, in [-90, 90].
    pub latitude_deg: f64,
    /// Longitude in degrees, east positive, in [-180, 180].
    pub longitude_deg: f64,
    /// Height above mean sea level in metres, in [-500, 9000].
    pub elevation_m: f64,
    /// Mean annual local air pressure in millibars (hPa), in [300, 1100];
    /// used for atmospheric refraction.
    pub pressure_mbar: f64,
    /// Mean annual local temperature in °C, in [-90, 60]; used for refraction.
    pub temperature_c: f64,
    /// IANA time-zone name, e.g. "America/Los_Angeles". Used only to display
    /// local times: every time in files and in the code is UTC.
    pub time_zone: String,
    /// ΔT = TT − UT in seconds, if known; otherwise the ephemeris estimates it.
    /// In [-100, 300].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub delta_t_s: Option<f64>,
}

impl Validate for Site {
    fn validate(&self, v: &mut Validator) {
        v.non_empty("name", &self.name);
        v.range("latitude_deg", self.latitude_deg, -90.0, 90.0, "a latitude in degrees");
        v.range(
            "longitude_deg",
            self.longitude_deg,
            -180.0,
            180.0,
            "a longitude in degrees",
        );
        v.range(
            "elevation_m",
            self.elevation_m,
            -500.0,
            9000.0,
            "an elevation in metres",
        );
        v.range(
            "pressure_mbar",
            self.pressure_mbar,
            300.0,
            1100.0,
            "an air pressure in millibars",
        );
        v.range(
            "temperature_c",
            self.temperature_c,
            -90.0,
            60.0,
            "an air temperature in °C",
        );
        if self.time_zone.parse::<chrono_tz::Tz>().is_err() {
            v.invalid(
                "time_zone",
                format!("{:?}", self.time_zone),
                "an IANA time-zone name such as \"Europe/Rome\" or \"UTC\"",
            );
        }
        if let Some(dt) = self.delta_t_s {
            v.range("delta_t_s", dt, -100.0, 300.0, "ΔT in seconds");
        }
    }
}
