//! When a session's trigger fires on one plan day, or why it does not.
//!
//! - `Clock(time, day)`: at `time` UTC on the plan day's UTC date (the
//!   caller adds `day` to the date).
//! - `SolarElevation(e, Rising|Setting)`: the first instant of the plan day
//!   (the site's mean solar day, see [`sun_track`](super::sun_track)) at
//!   which the apparent elevation of the sun's centre crosses `e` upward or
//!   downward.
//! - `SolarAzimuth(a)`: the first instant of the plan day at which the sun's
//!   azimuth passes `a`, in either direction (it may do so below the horizon).
//! - `Face(F, Sunlit|Shadowed)`: the first instant of the plan day at which
//!   surface F turns sunlit (or shadowed), sunlit meaning the sun is above
//!   the horizon and in front of the plane of F's area-weighted mean normal
//!   ([`SurfaceOrientation::sunlit_margin`]). The moment is a crossing of the
//!   surface's plane or of the horizon. Self-shadowing by other geometry is
//!   not considered.
//!
//! Solar instants are found by bracketing on a 5-minute grid and bisecting
//! to 1 ms on the ephemeris.

use campanile_config::plan::{FaceState, SunMotion, Trigger};
use campanile_process::sun::SunPosition;
use chrono::{DateTime, NaiveDate, Utc};

use super::error::ScheduleError;
use super::scene_geometry::SurfaceOrientation;
use super::sun_track::{SunTrack, wrap_deg};

/// Whether a trigger fires on a plan day.
#[derive(Debug, Clone, PartialEq)]
pub enum Firing {
    /// It fires at this instant.
    At(DateTime<Utc>),
    /// It does not; the reason names the date, e.g. "the sun never reaches
    /// 80° on 2026-08-28 (highest 64.2°)".
    Never(String),
}

/// When `trigger` fires on plan day `date`. For `Face` triggers `face` is
/// the surface's orientation (looked up by the caller).
pub fn fire(
    trigger: &Trigger,
    date: NaiveDate,
    track: &SunTrack,
    face: Option<&SurfaceOrientation>,
) -> Result<Firing, ScheduleError> {
    let day_samples = || {
        let (start, end) = track.day_window(date);
        track.samples(start, end)
    };
    match trigger {
        Trigger::Clock { time, .. } => Ok(Firing::At(date.and_time(*time).and_utc())),
        Trigger::SolarElevation { elevation_deg, motion } => {
            let samples = day_samples()?;
            let elevations = samples.iter().map(|s| s.position.elevation_rad().to_degrees());
            let highest = elevations.clone().fold(f64::NEG_INFINITY, f64::max);
            let lowest = elevations.fold(f64::INFINITY, f64::min);
            let target = *elevation_deg;
            let g = |p: &SunPosition| p.elevation_rad().to_degrees() - target;
            let found = match motion {
                SunMotion::Rising => track.first_crossing(&samples, g, |a, b| a < 0.0 && b >= 0.0)?,
                SunMotion::Setting => track.first_crossing(&samples, g, |a, b| a >= 0.0 && b < 0.0)?,
            };
            Ok(match found {
                Some(t) => Firing::At(t),
                None if highest < target => Firing::Never(format!(
                    "the sun never reaches {}° on {date} (highest {highest:.1}°)",
                    target
                )),
                None if lowest >= target => Firing::Never(format!(
                    "the sun never goes below {}° on {date} (lowest {lowest:.1}°)",
                    target
                )),
                None => Firing::Never(format!(
                    "the sun does not cross {}° {} within the plan day of {date}",
                    target,
                    match motion {
                        SunMotion::Rising => "rising",
                        SunMotion::Setting => "setting",
                    }
                )),
            })
        }
        Trigger::SolarAzimuth { azimuth_deg } => {
            let samples = day_samples()?;
            let target = *azimuth_deg;
            let g = |p: &SunPosition| wrap_deg(p.azimuth_rad.to_degrees() - target);
            // A sign change of the wrapped difference is a crossing of the
            // target unless it is the jump at ±180° (the opposite azimuth).
            let found = track.first_crossing(&samples, g, |a, b| (a < 0.0) != (b < 0.0) && (a - b).abs() < 180.0)?;
            Ok(match found {
                Some(t) => Firing::At(t),
                None => Firing::Never(format!("the sun never passes azimuth {}° on {date}", target)),
            })
        }
        Trigger::Face { face: name, becomes } => {
            let Some(surface) = face else {
                return Ok(Firing::Never(format!("face {name:?} is not a surface of the scene")));
            };
            let Some(_) = surface.normal else {
                return Ok(Firing::Never(format!(
                    "face {name:?} has no net orientation (its triangles face every way), so it never turns sunlit or shadowed as a whole"
                )));
            };
            let samples = day_samples()?;
            let g = |p: &SunPosition| surface.sunlit_margin(p.direction(), p.elevation_rad()).unwrap_or(-1.0);
            let found = match becomes {
                FaceState::Sunlit => track.first_crossing(&samples, g, |a, b| a <= 0.0 && b > 0.0)?,
                FaceState::Shadowed => track.first_crossing(&samples, g, |a, b| a > 0.0 && b <= 0.0)?,
            };
            let lit = samples
                .iter()
                .filter(|s| surface.is_sunlit(s.position.direction(), s.position.elevation_rad()))
                .count();
            let state = match becomes {
                FaceState::Sunlit => "sunlit",
                FaceState::Shadowed => "shadowed",
            };
            Ok(match found {
                Some(t) => Firing::At(t),
                None if lit == 0 => Firing::Never(format!(
                    "face {name:?} never becomes {state} on {date}: it is never sunlit that day"
                )),
                None if lit == samples.len() => Firing::Never(format!(
                    "face {name:?} never becomes {state} on {date}: it is sunlit all day"
                )),
                None => Firing::Never(format!("face {name:?} never becomes {state} on {date}")),
            })
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::schedule::scene_geometry::SurfaceOrientation;
    use campanile_config::Site;
    use chrono::{NaiveTime, TimeDelta};

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

    fn date() -> NaiveDate {
        NaiveDate::from_ymd_opt(2026, 8, 28).expect("date")
    }

    fn at(f: Firing) -> DateTime<Utc> {
        match f {
            Firing::At(t) => t,
            Firing::Never(r) => panic!("expected a firing, got: {r}"),
        }
    }

    /// The azimuth in degrees at `t`.
    fn azimuth(track: &SunTrack, t: DateTime<Utc>) -> f64 {
        track.position(t).expect("ephemeris").azimuth_rad.to_degrees()
    }

    /// A clock trigger fires at exactly its UTC time on the day.
    #[test]
    fn a_clock_trigger_fires_at_the_exact_instant() {
        let track = SunTrack::new(&berkeley());
        let trigger = Trigger::Clock {
            time: NaiveTime::from_hms_opt(20, 30, 0).expect("time"),
            day: 0,
        };
        let t = at(fire(&trigger, date(), &track, None).expect("ok"));
        assert_eq!(t.to_rfc3339(), "2026-08-28T20:30:00+00:00");
    }

    /// The sun cannot reach 80° at 37.9°N in late August (it culminates at
    /// 90° − 37.87° + 9.5° ≈ 61.6°): reported with the day's highest.
    #[test]
    fn an_unreachable_elevation_never_fires_and_says_why() {
        let track = SunTrack::new(&berkeley());
        let trigger = Trigger::SolarElevation {
            elevation_deg: 80.0,
            motion: SunMotion::Rising,
        };
        let Firing::Never(reason) = fire(&trigger, date(), &track, None).expect("ok") else {
            panic!("80° must not fire")
        };
        assert!(
            reason.starts_with("the sun never reaches 80° on 2026-08-28 (highest 61."),
            "{reason}"
        );
    }

    /// An axis-aligned south face (normal −y) is sunlit while the sun's
    /// azimuth is between 90° and 270°: it becomes sunlit when the azimuth
    /// crosses 90° and shadowed when it crosses 270°, both with the sun up
    /// on this date. Checked against the ephemeris to 1 s.
    #[test]
    fn a_south_face_turns_at_azimuths_90_and_270() {
        let track = SunTrack::new(&berkeley());
        let south = SurfaceOrientation::from_area_vectors("south", [0.0, -770.0, 0.0], 770.0);
        for (becomes, crossing) in [(FaceState::Sunlit, 90.0), (FaceState::Shadowed, 270.0)] {
            let trigger = Trigger::Face {
                face: "south".into(),
                becomes,
            };
            let t = at(fire(&trigger, date(), &track, Some(&south)).expect("ok"));
            let (before, after) = (t - TimeDelta::seconds(1), t + TimeDelta::seconds(1));
            assert!(
                azimuth(&track, before) < crossing && azimuth(&track, after) > crossing,
                "{becomes:?} at {t}: azimuth {} .. {}",
                azimuth(&track, before),
                azimuth(&track, after)
            );
            assert!(
                track.position(t).expect("ok").elevation_rad() > 0.0,
                "the sun is up at {t}"
            );
        }
    }

    /// A face whose normal points down is never sunlit.
    #[test]
    fn a_face_never_sunlit_is_reported() {
        let track = SunTrack::new(&berkeley());
        let floor = SurfaceOrientation::from_area_vectors("underside", [0.0, 0.0, -1.0], 1.0);
        let trigger = Trigger::Face {
            face: "underside".into(),
            becomes: FaceState::Sunlit,
        };
        let Firing::Never(reason) = fire(&trigger, date(), &track, Some(&floor)).expect("ok") else {
            panic!("must not fire")
        };
        assert!(reason.contains("never sunlit that day"), "{reason}");
    }
}
