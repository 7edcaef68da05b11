//! Topocentric solar position (thesis §5.3.1: "the solar position can be
//! obtained from the latitude and longitude of the site, and the time and
//! date").

use chrono::{DateTime, Datelike, Utc};
use solar_positioning::{Location, PreparedPositions, RefractionCorrection, SolarPositions};

/// Errors of the solar ephemeris.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SunError {
    /// The instant is outside the years SPA covers (−2000 to 6000).
    #[error("time {time} is outside the ephemeris's range (years -2000 to 6000): {reason}")]
    Time {
        /// The instant asked for.
        time: String,
        /// The library's reason.
        reason: String,
    },
    /// A site parameter is outside its domain.
    #[error("site {field} = {}: {reason}", shown(*.value))]
    Site {
        /// Which parameter.
        field: &'static str,
        /// Its value.
        value: f64,
        /// Why.
        reason: String,
    },
}

/// A number as an error shows it: shortest form, scientific when huge or tiny.
fn shown(x: f64) -> String {
    if x != 0.0 && x.is_finite() && !(1e-4..1e15).contains(&x.abs()) {
        format!("{x:e}")
    } else {
        format!("{x}")
    }
}

/// Where the observer stands. Angles in radians, as everywhere inside the code.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Observer {
    /// Geodetic latitude, north positive, in [−π/2, π/2].
    pub latitude_rad: f64,
    /// Longitude, east positive, in [−π, π].
    pub longitude_rad: f64,
    /// Height above sea level in metres (for parallax).
    pub elevation_m: f64,
    /// Local air pressure in millibars (for refraction).
    pub pressure_mbar: f64,
    /// Local air temperature in °C (for refraction).
    pub temperature_c: f64,
}

impl Observer {
    /// An observer from a site's degrees.
    pub fn from_degrees(
        latitude_deg: f64,
        longitude_deg: f64,
        elevation_m: f64,
        pressure_mbar: f64,
        temperature_c: f64,
    ) -> Self {
        Observer {
            latitude_rad: latitude_deg.to_radians(),
            longitude_rad: longitude_deg.to_radians(),
            elevation_m,
            pressure_mbar,
            temperature_c,
        }
    }

    pub(crate) fn location(&self) -> Location {
        Location {
            latitude: self.latitude_rad.to_degrees(),
            longitude: self.longitude_rad.to_degrees(),
        }
    }

    fn refraction(&self) -> Result<RefractionCorrection, SunError> {
        RefractionCorrection::new(self.pressure_mbar, self.temperature_c).map_err(|e| {
            let (field, value) = if self.pressure_mbar > 0.0 && self.pressure_mbar <= 2000.0 {
                ("temperature_c", self.temperature_c)
            } else {
                ("pressure_mbar", self.pressure_mbar)
            };
            SunError::Site {
                field,
                value,
                reason: e.to_string(),
            }
        })
    }
}

/// The sun's apparent topocentric position, refraction included.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SunPosition {
    /// Angle from the zenith, in [0, π].
    pub zenith_rad: f64,
    /// Azimuth from north through east, in [0, 2π).
    pub azimuth_rad: f64,
}

impl SunPosition {
    /// Elevation above the horizon.
    pub fn elevation_rad(&self) -> f64 {
        std::f64::consts::FRAC_PI_2 - self.zenith_rad
    }

    /// Unit vector toward the sun in the world frame (x east, y north, z up).
    pub fn direction(&self) -> [f64; 3] {
        crate::sky::direction(self.zenith_rad, self.azimuth_rad)
    }
}

/// ΔT = TT − UT in seconds, estimated for a date (Espenak & Meeus polynomials
/// with later fits), for when the site does not give it.
pub fn delta_t_estimate(time: DateTime<Utc>) -> Result<f64, SunError> {
    solar_positioning::delta_t::estimate_from_date(time.year(), time.month()).map_err(|e| SunError::Time {
        time: time.to_rfc3339(),
        reason: e.to_string(),
    })
}

/// The time-dependent part of the solar position at one instant (SPA steps
/// 1–11: heliocentric coordinates, nutation, aberration, sidereal time, the
/// sun's geocentric right ascension and declination). Compute it once per
/// instant and share it across every direction and site at that instant.
#[derive(Debug, Clone, Copy)]
pub struct Ephemeris {
    prepared: PreparedPositions,
    time: DateTime<Utc>,
}

impl Ephemeris {
    /// The ephemeris at `time`, with ΔT (TT − UT, seconds) given or estimated.
    pub fn at(time: DateTime<Utc>, delta_t_s: Option<f64>) -> Result<Ephemeris, SunError> {
        let dt = match delta_t_s {
            Some(dt) => dt,
            None => delta_t_estimate(time)?,
        };
        let prepared = SolarPositions::new().for_time(&time, dt).map_err(|e| SunError::Time {
            time: time.to_rfc3339(),
            reason: e.to_string(),
        })?;
        Ok(Ephemeris { prepared, time })
    }

    /// The instant.
    pub fn time(&self) -> DateTime<Utc> {
        self.time
    }

    /// Earth–Sun distance in astronomical units.
    pub fn earth_sun_distance_au(&self) -> f64 {
        self.prepared.earth_radius_vector().unwrap_or(1.0)
    }

    /// Geocentric declination of the sun.
    pub fn declination_rad(&self) -> f64 {
        self.prepared.declination().to_radians()
    }

    /// The sun as `observer` sees it (SPA steps 12–17: parallax, refraction).
    pub fn position(&self, observer: &Observer) -> Result<SunPosition, SunError> {
        self.topocentric(observer, Some(observer.refraction()?))
    }

    /// The geometric position (no refraction) for `observer` at height
    /// `elevation_m`: the direction of the sun's centre in space.
    pub fn position_unrefracted(&self, observer: &Observer) -> Result<SunPosition, SunError> {
        self.topocentric(observer, None)
    }

    fn topocentric(
        &self,
        observer: &Observer,
        refraction: Option<RefractionCorrection>,
    ) -> Result<SunPosition, SunError> {
        let p = self
            .prepared
            .at(observer.location(), observer.elevation_m, refraction)
            .map_err(|e| {
                let (lat, lon) = (observer.latitude_rad.to_degrees(), observer.longitude_rad.to_degrees());
                let (field, value) = if !(-90.0..=90.0).contains(&lat) {
                    ("latitude_deg", lat)
                } else if !(-180.0..=180.0).contains(&lon) {
                    ("longitude_deg", lon)
                } else {
                    ("elevation_m", observer.elevation_m)
                };
                SunError::Site {
                    field,
                    value,
                    reason: e.to_string(),
                }
            })?;
        Ok(SunPosition {
            zenith_rad: p.zenith_angle().to_radians(),
            azimuth_rad: p.azimuth().to_radians(),
        })
    }
}

/// The sun's position for one observer at one instant.
pub fn sun_position(time: DateTime<Utc>, observer: &Observer, delta_t_s: Option<f64>) -> Result<SunPosition, SunError> {
    Ephemeris::at(time, delta_t_s)?.position(observer)
}

#[cfg(test)]
mod tests {
    use super::*;
    use chrono::{FixedOffset, NaiveDate, TimeZone};

    /// NREL SPA's published test case (Reda & Andreas 2004, Table A5.1):
    /// 2003-10-17 12:30:30 local time (UTC−7), 39.742476°N, 105.1786°W,
    /// 1830.14 m, 820 mbar, 11 °C, ΔT = 67 s → zenith 50.11162°,
    /// azimuth 194.34024°, Earth–Sun distance 0.9965422974 AU.
    #[test]
    fn nrel_spa_published_test_case_to_1e5_degrees() {
        let local = FixedOffset::west_opt(7 * 3600).expect("offset");
        let time = local
            .with_ymd_and_hms(2003, 10, 17, 12, 30, 30)
            .single()
            .expect("valid")
            .with_timezone(&Utc);
        let obs = Observer::from_degrees(39.742476, -105.1786, 1830.14, 820.0, 11.0);
        let eph = Ephemeris::at(time, Some(67.0)).expect("in range");
        let p = eph.position(&obs).expect("valid site");
        assert!(
            (p.zenith_rad.to_degrees() - 50.11162).abs() < 1e-5,
            "zenith {}",
            p.zenith_rad.to_degrees()
        );
        assert!(
            (p.azimuth_rad.to_degrees() - 194.34024).abs() < 1e-5,
            "azimuth {}",
            p.azimuth_rad.to_degrees()
        );
        assert!(
            (eph.earth_sun_distance_au() - 0.9965422974).abs() < 1e-9,
            "R {}",
            eph.earth_sun_distance_au()
        );
    }

    /// Meeus, Astronomical Algorithms (2nd ed.), Example 25.b: 1992 October
    /// 13.0 TD, full VSOP87 → apparent α = 13h13m30.749s, δ = −7°47′01.74″.
    /// SPA truncates VSOP87, so agreement is to its stated ±0.0003°.
    #[test]
    fn meeus_example_25b_apparent_declination() {
        let time = NaiveDate::from_ymd_opt(1992, 10, 13)
            .expect("date")
            .and_hms_opt(0, 0, 0)
            .expect("time")
            .and_utc();
        let eph = Ephemeris::at(time, Some(0.0)).expect("in range");
        let want = -(7.0 + 47.0 / 60.0 + 1.74 / 3600.0);
        assert!(
            (eph.declination_rad().to_degrees() - want).abs() < 3e-4,
            "δ {}",
            eph.declination_rad().to_degrees()
        );
    }

    #[test]
    fn direction_is_a_unit_vector_in_the_world_frame() {
        // Sun due east at 30° elevation: x east, z up.
        let p = SunPosition {
            zenith_rad: 60f64.to_radians(),
            azimuth_rad: 90f64.to_radians(),
        };
        let d = p.direction();
        assert!((d[0] - 60f64.to_radians().sin()).abs() < 1e-15 && d[1].abs() < 1e-15 && (d[2] - 0.5).abs() < 1e-15);
        assert!((p.elevation_rad() - 30f64.to_radians()).abs() < 1e-15);
    }

    #[test]
    fn out_of_range_inputs_are_errors_not_nans() {
        let t = Utc.with_ymd_and_hms(2026, 8, 28, 20, 0, 0).single().expect("valid");
        let bad_lat = Observer::from_degrees(91.0, 0.0, 0.0, 1013.0, 15.0);
        assert!(matches!(sun_position(t, &bad_lat, None), Err(SunError::Site { .. })));
        let bad_p = Observer::from_degrees(10.0, 0.0, 0.0, -5.0, 15.0);
        assert!(matches!(sun_position(t, &bad_p, None), Err(SunError::Site { .. })));
        let far = Utc.with_ymd_and_hms(7000, 1, 1, 0, 0, 0).single().expect("valid");
        assert!(matches!(Ephemeris::at(far, Some(0.0)), Err(SunError::Time { .. })));
    }

    #[test]
    fn sun_solid_angle_at_one_au_is_6_8e_minus_5_sr() {
        // π ρ² with ρ = 959.63″ = 4.6524e-3 rad → 6.7999e-5 sr.
        let omega = super::super::sun_solid_angle_sr(1.0);
        assert!((omega - 6.7999e-5).abs() < 2e-9, "{omega}");
    }
}
