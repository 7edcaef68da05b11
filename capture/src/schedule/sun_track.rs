//! The sun over the station's site as a function of UTC time, and the first
//! instant at which a function of its position changes sign: bracketed on a
//! 5-minute grid, then bisected on the real ephemeris to 1 ms.
//!
//! A plan day is the site's *mean solar day*: the 24 hours centred on local
//! mean noon of a UTC date, `12:00 UTC − longitude / (15°/h)`. Morning and
//! evening of one local day then fall in the same plan day, wherever the
//! site is (in Berkeley an evening at 19:00 PDT is 02:00 UTC the next date).

use campanile_config::Site;
use campanile_process::sun::{Ephemeris, Observer, SunPosition};
use chrono::{DateTime, NaiveDate, NaiveTime, TimeDelta, Utc};

use super::error::ScheduleError;

/// Spacing of the grid on which crossings are bracketed, seconds. A
/// crossing and its return within one step (a face lit for under five
/// minutes) can be missed.
pub const BRACKET_STEP_S: i64 = 300;

/// Width at which bisection stops, milliseconds.
pub const BISECTION_TOLERANCE_MS: i64 = 1;

/// The sun as the site sees it (apparent position, refraction included).
#[derive(Debug, Clone, Copy)]
pub struct SunTrack {
    observer: Observer,
    longitude_deg: f64,
    delta_t_s: Option<f64>,
}

/// One sample of the sun.
#[derive(Debug, Clone, Copy)]
pub struct SunSample {
    /// The instant.
    pub time: DateTime<Utc>,
    /// Where the sun is.
    pub position: SunPosition,
}

impl SunTrack {
    /// The sun over `site`.
    pub fn new(site: &Site) -> SunTrack {
        SunTrack {
            observer: Observer::from_degrees(
                site.latitude_deg,
                site.longitude_deg,
                site.elevation_m,
                site.pressure_mbar,
                site.temperature_c,
            ),
            longitude_deg: site.longitude_deg,
            delta_t_s: site.delta_t_s,
        }
    }

    /// The sun's apparent position at `time`.
    pub fn position(&self, time: DateTime<Utc>) -> Result<SunPosition, ScheduleError> {
        Ok(Ephemeris::at(time, self.delta_t_s)?.position(&self.observer)?)
    }

    /// The plan day of UTC date `date`: `[mean noon − 12 h, mean noon + 12 h)`.
    pub fn day_window(&self, date: NaiveDate) -> (DateTime<Utc>, DateTime<Utc>) {
        let noon = date.and_time(NaiveTime::MIN).and_utc() + TimeDelta::hours(12)
            - TimeDelta::seconds((self.longitude_deg * 240.0).round() as i64);
        (noon - TimeDelta::hours(12), noon + TimeDelta::hours(12))
    }

    /// The sun sampled every [`BRACKET_STEP_S`] over `[start, end]`.
    pub fn samples(&self, start: DateTime<Utc>, end: DateTime<Utc>) -> Result<Vec<SunSample>, ScheduleError> {
        let mut out = Vec::new();
        let mut t = start;
        loop {
            out.push(SunSample {
                time: t,
                position: self.position(t)?,
            });
            if t >= end {
                return Ok(out);
            }
            t = (t + TimeDelta::seconds(BRACKET_STEP_S)).min(end);
        }
    }

    /// The first instant in the sampled span at which `g` of the sun's
    /// position crosses zero in a way `accept(g_before, g_after)` allows,
    /// to [`BISECTION_TOLERANCE_MS`]. The instant returned is the first one
    /// (on the millisecond grid of the bisection) with `g`'s new sign.
    pub fn first_crossing(
        &self,
        samples: &[SunSample],
        g: impl Fn(&SunPosition) -> f64,
        accept: impl Fn(f64, f64) -> bool,
    ) -> Result<Option<DateTime<Utc>>, ScheduleError> {
        for pair in samples.windows(2) {
            let (ga, gb) = (g(&pair[0].position), g(&pair[1].position));
            if !accept(ga, gb) {
                continue;
            }
            let after_sign = gb >= 0.0;
            let (mut a, mut b) = (pair[0].time, pair[1].time);
            while (b - a).num_milliseconds() > BISECTION_TOLERANCE_MS {
                let mid = a + TimeDelta::milliseconds((b - a).num_milliseconds() / 2);
                if (g(&self.position(mid)?) >= 0.0) == after_sign {
                    b = mid;
                } else {
                    a = mid;
                }
            }
            return Ok(Some(b));
        }
        Ok(None)
    }
}

/// `a − b` wrapped into (−180°, 180°], degrees.
pub fn wrap_deg(d: f64) -> f64 {
    let w = d.rem_euclid(360.0);
    if w > 180.0 { w - 360.0 } else { w }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn berkeley() -> Site {
        Site {
            name: "Berkeley".into(),
            latitude_deg: 37.8721,
            longitude_deg: -122.2578,
            elevation_m: 90.0,
            pressure_mbar: 1010.0,
            temperature_c: 18.0,
            time_zone: "America/Los_Angeles".into(),
            delta_t_s: Some(69.2),
        }
    }

    /// Berkeley's mean noon is 12:00 + 122.2578° × 4 min/° = 20:09:02 UTC.
    #[test]
    fn the_plan_day_is_centred_on_local_mean_noon() {
        let track = SunTrack::new(&berkeley());
        let (start, end) = track.day_window(NaiveDate::from_ymd_opt(2026, 8, 28).expect("date"));
        assert_eq!(start.to_rfc3339(), "2026-08-28T08:09:02+00:00");
        assert_eq!(end.to_rfc3339(), "2026-08-29T08:09:02+00:00");
    }

    #[test]
    fn wrapping_keeps_differences_in_the_half_open_interval() {
        assert_eq!(wrap_deg(190.0), -170.0);
        assert_eq!(wrap_deg(-180.0), 180.0);
        assert_eq!(wrap_deg(360.0 + 5.0), 5.0);
    }
}
