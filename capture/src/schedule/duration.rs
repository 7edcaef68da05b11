//! How long an occurrence takes, estimated from its shots: head slews,
//! exposures, readout and filter changes.
//!
//! - Slews: pan and tilt move at once, each with a trapezoidal speed profile
//!   (the configured acceleration up to the axis's top speed, cruise,
//!   deceleration), then the head settles; the slew lasts as long as the
//!   slower axis plus the settle time. Each occurrence starts with the head
//!   at pan 0, tilt 0. An aim the head cannot reach costs no slew.
//! - Exposures: `Fixed` as given; `Metered` and `Auto` assume a typical
//!   metered exposure times `2^stops`: [`TYPICAL_SUN_EXPOSURE_S`] at the sun,
//!   [`TYPICAL_SKY_EXPOSURE_S`] on sky and environment tiles,
//!   [`TYPICAL_VIEW_EXPOSURE_S`] at poses and head angles; all clamped into
//!   the camera's limits.
//! - Readout: [`READOUT_S`] per frame.
//! - Filters: [`FILTER_CHANGE_S`] whenever a shot's filter differs from the
//!   previous one; a runtime choice among slots is assumed to be the densest.
//!
//! Every planned shot counts, including auto-bracket frames that are not
//! promised, so the estimate is an upper bound for auto-brackets.

use std::time::Duration;

use campanile_config::head::HeadDynamics;
use campanile_config::station::Station;

use super::shot::{FilterChoice, PlannedAim, PlannedExposure, PlannedShot};

/// Readout time of one frame, seconds.
pub const READOUT_S: f64 = 0.030;
/// Time to turn the filter wheel to another slot, seconds.
pub const FILTER_CHANGE_S: f64 = 1.0;
/// Assumed metered exposure at the sun (through its ND filter), seconds.
pub const TYPICAL_SUN_EXPOSURE_S: f64 = 0.001;
/// Assumed metered exposure of a sky or environment tile, seconds.
pub const TYPICAL_SKY_EXPOSURE_S: f64 = 0.010;
/// Assumed metered exposure of a view of the target, seconds.
pub const TYPICAL_VIEW_EXPOSURE_S: f64 = 0.030;

/// Time for one axis to move `distance_deg` from rest to rest with top
/// speed `speed_deg_s` and acceleration `accel_deg_s2`, seconds:
/// `d/v + v/a` when it reaches top speed (`d ≥ v²/a`), else `2 √(d/a)`.
pub fn axis_move_s(distance_deg: f64, speed_deg_s: f64, accel_deg_s2: f64) -> f64 {
    let d = distance_deg.abs();
    if d == 0.0 || speed_deg_s <= 0.0 || accel_deg_s2 <= 0.0 {
        return 0.0;
    }
    if d >= speed_deg_s * speed_deg_s / accel_deg_s2 {
        d / speed_deg_s + speed_deg_s / accel_deg_s2
    } else {
        2.0 * (d / accel_deg_s2).sqrt()
    }
}

/// Time to slew the head from `(pan, tilt)` to `(pan, tilt)` (degrees) and
/// settle, seconds; zero when it does not move.
pub fn slew_s(from: (f64, f64), to: (f64, f64), dynamics: &HeadDynamics) -> f64 {
    if from == to {
        return 0.0;
    }
    let pan = axis_move_s(to.0 - from.0, dynamics.pan_speed_deg_s, dynamics.acceleration_deg_s2);
    let tilt = axis_move_s(to.1 - from.1, dynamics.tilt_speed_deg_s, dynamics.acceleration_deg_s2);
    pan.max(tilt) + dynamics.settle_s
}

/// The assumed exposure of a shot, seconds.
pub fn exposure_s(shot: &PlannedShot, station: &Station) -> f64 {
    let typical = match shot.aim {
        PlannedAim::Sun => TYPICAL_SUN_EXPOSURE_S,
        PlannedAim::Sky { .. } => TYPICAL_SKY_EXPOSURE_S,
        PlannedAim::Pose { .. } | PlannedAim::Head { .. } => TYPICAL_VIEW_EXPOSURE_S,
    };
    let t = match shot.exposure {
        PlannedExposure::Fixed { seconds } => seconds,
        PlannedExposure::Metered { stops } => typical * stops.exp2(),
        PlannedExposure::Auto => typical,
    };
    let limits = station.camera.exposure;
    t.clamp(limits.min_s, limits.max_s.max(limits.min_s))
}

fn slot(filter: &FilterChoice) -> Option<&str> {
    match filter {
        FilterChoice::None => None,
        FilterChoice::Slot(s) => Some(s),
        FilterChoice::LightestUnsaturated(list) => list.last().map(String::as_str),
    }
}

/// The estimated duration of `shots` taken in order, with the sun at `sun`
/// (azimuth, elevation in degrees) for shots aimed at it.
pub fn estimate(shots: &[PlannedShot], station: &Station, sun: (f64, f64)) -> Duration {
    seconds(walk(shots, station, sun).1)
}

/// When each of `shots`, taken in order from the occurrence's start, is
/// planned to begin (its slew and filter change), as an offset from the
/// start: the estimate of the shots before it.
pub fn start_offsets(shots: &[PlannedShot], station: &Station, sun: (f64, f64)) -> Vec<Duration> {
    walk(shots, station, sun).0.into_iter().map(seconds).collect()
}

fn seconds(s: f64) -> Duration {
    Duration::from_millis((s * 1000.0).round() as u64)
}

/// The start of each shot and the end of the last, seconds from the start.
fn walk(shots: &[PlannedShot], station: &Station, sun: (f64, f64)) -> (Vec<f64>, f64) {
    let mut head = (0.0, 0.0);
    let mut filter: Option<&str> = None;
    let mut total = 0.0;
    let mut starts = Vec::with_capacity(shots.len());
    for shot in shots {
        starts.push(total);
        if let Some(to) = shot.aim.head_angles(&station.head, sun) {
            total += slew_s(head, to, &station.head.dynamics);
            head = to;
        }
        let wanted = slot(&shot.filter);
        if wanted != filter {
            total += FILTER_CHANGE_S;
            filter = wanted;
        }
        total += exposure_s(shot, station) + READOUT_S;
    }
    (starts, total)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dynamics() -> HeadDynamics {
        HeadDynamics {
            pan_speed_deg_s: 60.0,
            tilt_speed_deg_s: 40.0,
            acceleration_deg_s2: 120.0,
            settle_s: 0.2,
        }
    }

    /// 90° at 60°/s and 120°/s²: 0.5 s up to speed (15°), 60° cruising
    /// (1 s), 0.5 s down, then 0.2 s settle = 2.2 s.
    #[test]
    fn a_90_degree_pan_takes_2_2_seconds() {
        let t = slew_s((0.0, 0.0), (90.0, 0.0), &dynamics());
        assert!((t - 2.2).abs() < 1e-12, "{t}");
    }

    /// 15° never reaches 60°/s (that needs 30°): 2 √(15/120) = 0.7071 s.
    #[test]
    fn a_short_move_is_triangular() {
        assert!((axis_move_s(15.0, 60.0, 120.0) - 2.0 * (0.125f64).sqrt()).abs() < 1e-12);
    }

    /// The slower axis sets the time: 60° of tilt at 40°/s (1.5 + 0.333 s)
    /// beats 60° of pan at 60°/s (1.5 s).
    #[test]
    fn the_slower_axis_sets_the_slew_time() {
        let t = slew_s((0.0, 0.0), (60.0, 60.0), &dynamics());
        assert!((t - (60.0 / 40.0 + 40.0 / 120.0 + 0.2)).abs() < 1e-12, "{t}");
    }

    #[test]
    fn no_move_costs_nothing() {
        assert_eq!(slew_s((10.0, 5.0), (10.0, 5.0), &dynamics()), 0.0);
    }
}
